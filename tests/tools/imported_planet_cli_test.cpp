// A planet of seed 003's contact stage (models/scenes/seed003_contact_healthy.yaml: tooth contact on
// every branch) from a mesh file, from the command line, as a rigid body
// (`gear_train.dynamics.imported_gears`) and as a flexible one (`orrery reduce planet.stl|step`,
// `flexible_bodies`):
// - STL (the project's own writer, millimetres) at the contact's sampling, rigid: planet 1's
//   branches carry the forces of the generated planet. Oracle: the two runs differ only in
//   planet 1's tooth surface, whose vertices the float32 file moved by at most `moved` (measured,
//   nanometres), and in nothing else (the generated run's planets take the imported mass and
//   inertia, members.S.planet); a contact force changes by at most its tangent stiffness times
//   that, 1.5 c' b moved = 1.5 * 6.3e8 N/m * moved, a few newtons of 15 kN; the integrator's
//   tolerance adds its own (1e-3 of the force, asserted).
// - STEP made by gmsh's OpenCASCADE kernel from the planet's outline (tests/common/gear_step.h),
//   rigid, triangulated at 0.5 mm (scene key mesh_size_mm): runs, planet 1's branches carry the
//   stage's load (faceting within 8 um of the flanks against a 24 um tooth deflection: the end
//   forces within a third, asserted a half; measured -2.5 %).
// - both reduced by `orrery reduce` (gmsh tet10, 4 mm) and run flexible in tooth contact for 1 ms:
//   the analytic flanks' distance from the FE surface (the embed tolerance the run needs, measured
//   here as the assembler measures it) lies within the outline's chord sag at the longest tooth
//   element edge (theory: the FE facets are chords of the surface), and the runs end with planet
//   1's branches loaded.
// About 90 s of CPU (two gmsh tet meshes and reductions, two STEP triangulations, five runs).
// Skipped without gmsh.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "import/gmsh_mesher.h"
#include "import/scene.h"
#include "import/solid_mesh.h"
#include "contact/triangle_geometry.h"
#include "flex/reduced_body_file.h"
#include "mbd/hdf5_reader.h"
#include "models/gear_geometry.h"
#include "models/stl.h"
#include "models/train_dynamics.h"
#include "tests/common/cli_support.h"
#include "tests/common/gear_step.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

std::pair<int, std::string> Orrery(const std::string& args) {
  std::string command = "\"";
  command += ORRERY_BINARY_DIR;
  command += "/bin/orrery\" ";
  command += args;
  auto [out, code] = test_support::RunCommand(command);
  return {code, out};
}

// A STEP planet's triangles for rigid contact: 0.5 mm keeps them within 8 um of the exact flanks
// (tests/import/imported_gear_test.cpp), a third of the tooth pair's 24 um deflection.
constexpr double kStepTriangleMm = 0.5;
// Flexible planets: tet10 elements of 4 mm (the 8 fixed-interface modes kept, 24.3-39.7 kHz, lie
// within 1.7 % of a 3 mm mesh's, 5 mm: 4 %), whose surface lies within the outline's chord sag at
// that size (0.26 mm, largest where a chord spans the fillet and the involute's start; 3 mm: 0.17);
// the file's own deviation from the exact outline (STL at the contact's sampling 1.2 um, the STEP's
// splines below 8 um: tests/import/imported_gear_test.cpp) rounded up; 1 ms of simulated time.
constexpr double kFlexibleMeshSize = 0.004, kFileDeviation = 10e-6, kFlexibleEnd = 0.001;

const fs::path kScene =
    fs::path(ORRERY_SOURCE_DIR) / "models" / "scenes" / "seed003_contact_healthy.yaml";

// The scene's planet gear, bore radius and contact options.
struct ScenePlanet {
  gears::Gear gear;
  double bore_m;
  gears::GearContactOptions contact;
};
ScenePlanet LoadScenePlanet() {
  const Scene scene = LoadScene(kScene.string());
  const GearTrainScene& g = *scene.gear_train;
  const gears::GearPair pair =
      gears::MakeTrainGearPair(*g.train, g.train->MeshIndex("S.sun-planet"), g.options);
  return {pair.gear2(), g.options.bore_to_pitch_ratio * pair.gear2().reference_radius_m(),
          g.options.contact.gear};
}

// Normal force of a contact branch over the run (one value per output row).
Eigen::VectorXd NormalForce(const fs::path& file, const std::string& branch) {
  const Hdf5Reader r(file.string());
  return r.ReadMatrix("/external/" + branch + "/normal_force").col(0);
}

std::string Quote(const std::string& s) { return "'" + s + "'"; }

// The largest distance of the gear's exact flanks and tip (the outline beyond the form circle) from
// a chord of length <= h between two points of one smooth run of the outline: the deviation of an
// FE surface whose triangles (edges <= h) have their corners on the tooth surface (a triangle on
// the extruded surface projects into its corners' chord hull) and never span a sharp edge (the tip
// corners: gmsh keeps them, CAD faces or ClassifySurfaces' 40 deg feature angle). Outline sampled
// every 20 um or finer (the distance is flat near its largest value).
double OutlineChordSag(const gears::Gear& gear, double h) {
  const std::vector<gears::ProfilePoint> outline =
      gear.SampleGearOutline({.root = 20, .fillet = 200, .involute = 400, .tip = 200});
  const int size = static_cast<int>(outline.size());
  const int n = size / gear.teeth() + 1;  // one tooth and the next root
  auto at = [&](int i) { return outline[i % size].p; };
  auto sharp = [&](int i) {  // the outline turns by more than 40 deg at point i
    const gears::Vec2 u = at(i) - at(i + size - 1), v = at(i + 1) - at(i);
    return std::abs(std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v))) > 40 * kPi / 180;
  };
  double sag = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 2; j < n + i && !sharp(j - 1); ++j) {
      const gears::Vec2 ab = at(j) - at(i);
      if (ab.norm() > h) break;
      for (int k = i + 1; k < j; ++k) {
        if (at(k).norm() <= gear.form_radius_m()) continue;
        const gears::Vec2 ap = at(k) - at(i);
        sag = std::max(sag, std::abs(ab.x() * ap.y() - ab.y() * ap.x()) / ab.norm());
      }
    }
  return sag;
}

// The longest edge of a reduced body's surface triangles on the toothed boundary (beyond the root
// circle, not on the end faces), m. The body frame's origin is on the gear axis.
double LongestToothEdge(const fs::path& body_file, const gears::Gear& gear) {
  const flex::ReducedBody body = flex::ReadReducedBody(body_file.string());
  const auto& nodes = body.modes.nodes;
  double h = 0;
  for (const auto& t : body.modes.surface_triangles) {
    const Vec3 &a = nodes[t[0]].position, &b = nodes[t[1]].position, &c = nodes[t[2]].position;
    const Vec3 normal = (b - a).cross(c - a);
    if (std::abs(normal.z()) > 0.5 * normal.norm()) continue;
    if (std::min({a.head<2>().norm(), b.head<2>().norm(), c.head<2>().norm()}) <
        gear.root_radius_m() - 1e-4)
      continue;
    h = std::max({h, (b - a).norm(), (c - b).norm(), (a - c).norm()});
  }
  return h;
}

// The largest distance of the scene's analytic flank and tip vertices (the contact's tooth surfaces,
// beyond the form circle) from a reduced body's surface triangles, as the train assembler places
// them (models/train_contact.h: gear frame turned by whole pitches, shifted to the FE teeth's
// lowest z; the body frame's origin on the gear axis), each tooth against the triangles of its
// sector: what tooth_contact.flexible.embed_tolerance must cover.
double EmbedDistance(const fs::path& body_file, const ScenePlanet& p) {
  const flex::ReducedBody body = flex::ReadReducedBody(body_file.string());
  const auto& nodes = body.modes.nodes;
  double z0 = 1e300;
  for (const auto& n : nodes) z0 = std::min(z0, n.position.z());
  const int z = p.gear.teeth();
  auto sector = [&](const Vec3& v) {
    const double a = std::atan2(v.y(), v.x()) / (2 * kPi / z);
    return ((static_cast<int>(std::lround(a)) % z) + z) % z;
  };
  std::vector<std::vector<std::array<Vec3, 3>>> by_tooth(z);
  for (const auto& t : body.modes.surface_triangles) {
    const std::array<Vec3, 3> tri{nodes[t[0]].position, nodes[t[1]].position, nodes[t[2]].position};
    for (const Vec3& v : tri) {
      auto& list = by_tooth[sector(v)];
      if (list.empty() || list.back()[0] != tri[0] || list.back()[1] != tri[1]) list.push_back(tri);
    }
  }
  const gears::GearContactOptions& c = p.contact;
  double worst = 0;
  for (int k = 0; k < z; ++k) {
    const TriangleMesh tooth = gears::MakeToothSurfaceMesh(
        p.gear, k, {.root = c.root_intervals, .fillet = c.fillet_intervals, .involute = c.involute_intervals,
                    .tip = c.tip_intervals,
                                             .fillet_max_sag_m = c.fillet_max_sag_m},
        4);
    for (const Vec3& v : tooth.vertices) {
      if (v.head<2>().norm() <= p.gear.form_radius_m() + 1e-9) continue;
      const Vec3 q = v + Vec3(0, 0, z0);
      double best = 1e300;
      for (int s : {(k + z - 1) % z, k, (k + 1) % z})
        for (const auto& t : by_tooth[s])
          best = std::min(best, (contact::ClosestPointOnTriangle(q, t[0], t[1], t[2]).point - q).norm());
      worst = std::max(worst, best);
    }
  }
  return worst;
}

TEST(ImportedPlanetCli, StlAndStepPlanetsRunRigidAndFlexibleInAPlanetaryScene) {
  if (!FindGmsh()) GTEST_SKIP() << "gmsh not found on PATH (Debian package gmsh)";
  const fs::path dir = fs::path(::testing::TempDir()) / "imported_planet_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const ScenePlanet p = LoadScenePlanet();
  const gears::GearContactOptions& c = p.contact;
  const fs::path stl = dir / "planet.stl";
  gears::WriteStlBinary(gears::MakeGearMesh(p.gear,
                                            {.root = c.root_intervals,
                                             .fillet = c.fillet_intervals,
                                             .involute = c.involute_intervals,
                                             .tip = c.tip_intervals,
                                             .fillet_max_sag_m = c.fillet_max_sag_m},
                                            c.face_intervals, p.bore_m),
                        stl.string(), {.scale = 1000});
  const fs::path step = test_support::WriteGearStep(dir, p.gear, p.bore_m);
  const gears::TrainImportedGear imported =
      ReadImportedGear(stl, {.unit = LengthUnit::kMillimetre}, 7850);
  const std::string run = "run " + kScene.string() + " --end-time 0.002 ";
  const std::string mass =
      "--set " +
      Quote("gear_train.dynamics.members={S.planet: {mass: " + std::to_string(imported.mass_kg) +
            ", inertia: " + std::to_string(imported.inertia_kg_m2(2, 2)) + "}}");

  // Generated and STL planet 1, rigid, same mass properties
  auto [code, text] = Orrery(run + mass + " -o " + (dir / "generated.h5").string());
  ASSERT_EQ(code, 0) << text;
  std::tie(code, text) =
      Orrery(run + mass + " --set " +
             Quote("gear_train.dynamics.imported_gears={S.planet1: {file: " + stl.string() +
                   ", unit: mm}}") +
             " -o " + (dir / "stl.h5").string());
  ASSERT_EQ(code, 0) << text;
  for (const char* branch : {"S.sun-planet#1", "S.ring-planet#1"}) {
    const Eigen::VectorXd f_gen = NormalForce(dir / "generated.h5", branch),
                          f_stl = NormalForce(dir / "stl.h5", branch);
    ASSERT_EQ(f_gen.size(), f_stl.size());
    const double diff = (f_gen - f_stl).lpNorm<Eigen::Infinity>(),
                 peak = f_gen.lpNorm<Eigen::Infinity>();
    std::printf("%s: STL planet vs generated, largest force difference %.3g N of %.0f N\n", branch,
                diff, peak);
    EXPECT_GT(peak, 5000) << branch;
    EXPECT_LE(diff, 1e-3 * peak) << branch;
  }

  // STEP planet 1, rigid
  std::tie(code, text) = Orrery(
      run + mass + " --set " +
      Quote("gear_train.dynamics.imported_gears={S.planet1: {file: " + step.string() +
            ", mesh_size_mm: " + std::to_string(kStepTriangleMm) + "}}") +
      " -o " + (dir / "step.h5").string());
  ASSERT_EQ(code, 0) << text;
  for (const char* branch : {"S.sun-planet#1", "S.ring-planet#1"}) {
    const Eigen::VectorXd f_gen = NormalForce(dir / "generated.h5", branch),
                          f_step = NormalForce(dir / "step.h5", branch);
    const double end_gen = f_gen.tail(5).mean(), end_step = f_step.tail(5).mean();
    std::printf("%s: STEP planet %.0f N, generated %.0f N (mean of the last 5 rows)\n", branch,
                end_step, end_gen);
    EXPECT_NEAR(end_step, end_gen, 0.5 * end_gen) << branch;
  }

  // Both reduced (gmsh tet10 at kFlexibleMeshSize) and run flexible; the embed tolerance is the
  // outline's chord sag at the body's longest surface edge plus the file's own deviation
  for (const fs::path& part : {stl, step}) {
    const fs::path body =
        dir / (part.stem().string() + "_" + part.extension().string().substr(1) + ".h5");
    const std::string unit = part.extension() == ".stl" ? " --unit mm" : "";
    std::tie(code, text) = Orrery("reduce " + part.string() + unit +
                                  " --E 210e9 --nu 0.3 --density 7850 --interface bore --modes 8"
                                  " --mesh-size " + std::to_string(kFlexibleMeshSize) + " -o " +
                                  body.string());
    ASSERT_EQ(code, 0) << text;
    // The tet10 surface is exported as four triangles per face: element edges are twice theirs
    const double h = 2 * LongestToothEdge(body, p.gear), sag = OutlineChordSag(p.gear, h),
                 distance = EmbedDistance(body, p), tolerance = 1.1 * distance;
    std::printf("%s reduced: longest tooth element edge %.2f mm, outline chord sag there %.0f um; "
                "analytic flanks at most %.0f um from the FE surface\n",
                part.filename().c_str(), h * 1e3, sag * 1e6, distance * 1e6);
    EXPECT_LE(distance, sag + kFileDeviation) << part;
    const fs::path out = dir / ("flexible_" + body.filename().string());
    std::tie(code, text) = Orrery(
        "run " + kScene.string() + " --end-time " + std::to_string(kFlexibleEnd) + " --set " +
        Quote("gear_train.dynamics.flexible_bodies={S.planet1: {reduced_body: " + body.string() +
              ", damping_ratio: 0.02}}") +
        " --set " +
        Quote("gear_train.dynamics.tooth_contact.flexible={embed_tolerance_um: " +
              std::to_string(tolerance * 1e6) + "}") +
        " -o " + out.string());
    ASSERT_EQ(code, 0) << text;
    for (const char* branch : {"S.sun-planet#1", "S.ring-planet#1"}) {
      const Eigen::VectorXd f = NormalForce(out, branch), g = NormalForce(dir / "generated.h5", branch);
      const int rows = static_cast<int>(f.size()) / 2;
      const double flexible = f.tail(rows).mean(), rigid = g.segment(f.size() - rows, rows).mean();
      std::printf("%s, flexible planet from %s: mean %.0f N over the second half (rigid generated %.0f N)\n",
                  branch, part.filename().c_str(), flexible, rigid);
      EXPECT_GT(flexible, 1000) << part << " " << branch;
    }
  }
  fs::remove_all(dir);
}

// A bad imported gear is one line naming the key and the file.
TEST(ImportedPlanetCli, BadImportedGearsAreOneLineErrors) {
  const fs::path dir = fs::path(::testing::TempDir()) / "imported_planet_cli_bad";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const ScenePlanet p = LoadScenePlanet();
  const fs::path stl = dir / "planet.stl";
  gears::WriteStlBinary(
      gears::MakeGearMesh(p.gear, {.root = 2, .fillet = 4, .involute = 8, .tip = 2}, 1, p.bore_m),
      stl.string(), {.scale = 1000});
  const std::string run =
      "run " + kScene.string() + " --end-time 0.0001 -o " + (dir / "x.h5").string() + " --set ";
  const std::pair<std::string, std::string> cases[] = {
      {"{S.planet1: {file: " + stl.string() + ", unit: m}}", "is the unit right"},
      {"{S.planet1: {file: " + stl.string() + "}}", "missing required key 'unit'"},
      {"{S.planet1: {file: " + (dir / "none.stl").string() + ", unit: mm}}", "none.stl"},
      {"{S.sun: {file: " + stl.string() + ", unit: mm}}", "S.sun"},
  };
  for (const auto& [value, expected] : cases) {
    auto [code, text] = Orrery(run + Quote("gear_train.dynamics.imported_gears=" + value));
    EXPECT_EQ(code, 1) << value << "\n" << text;
    EXPECT_NE(text.find(expected), std::string::npos) << value << "\n" << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace orrery

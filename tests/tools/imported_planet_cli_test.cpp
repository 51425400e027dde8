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
//   rigid: runs, planet 1's branches carry the stage's load (the faceting of a 16-interval
//   spline's triangulation moves the flanks by a few um against a 24 um deflection: forces within
//   a third, asserted a half).
// - both reduced by `orrery reduce` (gmsh tet10) and run flexible in tooth contact: the runs end
//   with planet 1's branches loaded.
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
#include "mbd/hdf5_reader.h"
#include "models/gear_geometry.h"
#include "models/stl.h"
#include "models/train_dynamics.h"
#include "tests/common/cli_support.h"
#include "tests/common/gear_step.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

std::pair<int, std::string> Orrery(const std::string& args) {
  std::string command = "\"";
  command += ORRERY_BINARY_DIR;
  command += "/bin/orrery\" ";
  command += args;
  auto [out, code] = test_support::RunCommand(command);
  return {code, out};
}

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

// Disabled until issue 14 is closed: its rigid part passes (STEP planet within half of the
// generated forces), but the flexible part's child process is killed (exit 137, after 209 s on
// the project's machine: the tet reduction of the imported planet at these mesh settings is too
// large). Run it with --gtest_also_run_disabled_tests while working on it.
TEST(ImportedPlanetCli, DISABLED_StlAndStepPlanetsRunRigidAndFlexibleInAPlanetaryScene) {
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
                                             .tip = c.tip_intervals},
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
      Quote("gear_train.dynamics.imported_gears={S.planet1: {file: " + step.string() + "}}") +
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

  // Both reduced and run flexible
  for (const fs::path& part : {stl, step}) {
    const fs::path body =
        dir / (part.stem().string() + "_" + part.extension().string().substr(1) + ".h5");
    const std::string unit = part.extension() == ".stl" ? " --unit mm" : "";
    std::tie(code, text) = Orrery("reduce " + part.string() + unit +
                                  " --E 210e9 --nu 0.3 --density 7850 --interface bore "
                                  "--modes 8 --mesh-size 0.005 --curvature 16 -o " +
                                  body.string());
    ASSERT_EQ(code, 0) << text;
    const fs::path out = dir / ("flexible_" + body.filename().string());
    std::tie(code, text) = Orrery(
        "run " + kScene.string() + " --end-time 0.001 --set " +
        Quote("gear_train.dynamics.flexible_bodies={S.planet1: {reduced_body: " + body.string() +
              ", damping_ratio: 0.02}}") +
        " --set gear_train.dynamics.tooth_contact.flexible.embed_tolerance_um=400 -o " +
        out.string());
    ASSERT_EQ(code, 0) << text;
    for (const char* branch : {"S.sun-planet#1", "S.ring-planet#1"}) {
      const double end = NormalForce(out, branch).tail(3).mean();
      std::printf("%s, flexible planet from %s: %.0f N at the end\n", branch,
                  part.filename().c_str(), end);
      EXPECT_GT(end, 1000) << part << " " << branch;
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

// CAD and volume meshing through the gmsh program (import/gmsh_mesher.h). The STEP files are made
// here by gmsh itself from OpenCASCADE geometry (a 100 x 50 x 20 mm plate with a 10 mm radius
// hole), so no binary CAD file is kept. Oracles:
// - triangulated surface: the hole's facets are chords of the cylinder, so the mesh volume lies
//   between the exact V = a b c - pi r^2 c and V + c r^2 (pi - (pi / t) sin t), t the largest
//   angle a hole edge subtends (each chord of angle t_i removes r^2 (t_i - sin t_i) / 2 of the
//   hole's section, and (t - sin t) / t grows with t, so n = 2 pi / t equal chords remove most);
//   the centre of mass is the plate's centre by symmetry, up to that faceting volume times its
//   distance from the centre over V;
// - units: the same STEP declaring metres instead of millimetres reads 1000 times larger;
// - tetrahedra fill the plate: curved tet10 (midside nodes on the geometry) closer to the exact
//   volume than the flat-facet bracket's width, straight-sided tet10 inside the bracket of its
//   own boundary's chords, every element right-handed;
// - a watertight box surface meshed into tet10 has exactly the box's volume.
// Skipped (GTEST_SKIP) without gmsh on PATH, except the missing-gmsh message itself.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include "flex/fe_assembly.h"
#include "flex/flexible_body_modes.h"
#include "import/bounded_file.h"
#include "import/gmsh_mesher.h"
#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/surface_mesh.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using namespace test_meshes;
constexpr double kPi = std::numbers::pi;

class GmshMesherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gmsh_ = FindGmsh();
    if (!gmsh_) GTEST_SKIP() << "gmsh not found on PATH (Debian package gmsh): CAD import skipped";
    dir_ = ScratchDir("gmsh");
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // A STEP file written by gmsh from OpenCASCADE commands (lengths in mm).
  fs::path Step(const std::string& name, const std::string& occ) {
    WriteText(dir_ / (name + ".geo"), "SetFactory(\"OpenCASCADE\");\n" + occ);
    const std::string command = "cd '" + dir_.string() + "' && '" + gmsh_->string() + "' " + name + ".geo -0 -o " +
                                name + ".step -format step > /dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return dir_ / (name + ".step");
  }
  fs::path Plate() {
    return Step("plate", "Box(1) = {0, 0, 0, 100, 50, 20};\nCylinder(2) = {50, 25, -10, 0, 0, 40, 10};\n"
                         "BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };\n");
  }
  std::optional<fs::path> gmsh_;
  fs::path dir_;
};

// The bracket of the header for the plate scaled by `s` (m per file unit / 1000).
struct Bracket {
  double lo, hi;
};
Bracket PlateVolume(const TriangleMesh& m, double s) {
  const double a = 0.1 * s, b = 0.05 * s, c = 0.02 * s, r = 0.01 * s;
  const Vec3 axis(0.05 * s, 0.025 * s, 0);
  const auto on_hole = [&](int v) { return std::abs((m.vertices[v] - axis).head<2>().norm() - r) < 1e-9 * s; };
  double t_max = 0;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      if (on_hole(t[k]) && on_hole(t[(k + 1) % 3])) {
        const double chord = (m.vertices[t[k]] - m.vertices[t[(k + 1) % 3]]).head<2>().norm();
        t_max = std::max(t_max, 2 * std::asin(std::min(1.0, chord / (2 * r))));
      }
  EXPECT_GT(t_max, 0) << "no hole edges found";
  const double exact = a * b * c - kPi * r * r * c;
  return {exact, exact + c * r * r * (kPi - kPi / t_max * std::sin(t_max))};
}

TEST_F(GmshMesherTest, StepPlateTriangulatedInItsOwnUnit) {
  const fs::path step = Plate();
  EXPECT_EQ(ReadCadLengthUnit(step), "mm");
  const SurfaceMesh s = ReadSurfaceMesh(step);
  EXPECT_EQ(s.unit, "mm");
  EXPECT_TRUE(s.unit_stated);
  EXPECT_EQ(s.region_names.size(), 7u);  // FACE1..FACE7: 6 sides and the hole
  TriangleMesh mesh = s.mesh;
  const MeshCheckReport r = CheckMesh(mesh);
  EXPECT_TRUE(r.valid_solid());
  OrientMesh(mesh, r);
  const MassProperties p = MassPropertiesOfSolid(mesh, 7850, r, step.string());
  const Bracket v = PlateVolume(mesh, 1.0);
  EXPECT_GE(p.volume_m3, v.lo * (1 - 1e-12));
  EXPECT_LE(p.volume_m3, v.hi * (1 + 1e-12));
  std::printf("plate: volume %.9g m^3, bracket [%.9g, %.9g]\n", p.volume_m3, v.lo, v.hi);
  // Centre: the faceting moves at most (hi - lo) of volume, all within sqrt(r^2 + (c/2)^2) of the
  // plate's centre, which shifts the centre by at most that volume times that lever over V
  const double lever = std::sqrt(0.01 * 0.01 + 0.01 * 0.01);
  EXPECT_LT((p.center_of_mass_m - Vec3(0.05, 0.025, 0.01)).norm(), (v.hi - v.lo) * lever / v.lo);
  // The same file declaring metres: 1000 times larger
  std::string text = ReadFileBounded(step);
  const std::size_t at = text.find("SI_UNIT(.MILLI.,.METRE.)");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 24, "SI_UNIT($,.METRE.)");
  WriteText(dir_ / "plate_m.step", text);
  EXPECT_EQ(ReadCadLengthUnit(dir_ / "plate_m.step"), "m");
  const SurfaceMesh metres = ReadSurfaceMesh(dir_ / "plate_m.step", {.max_coordinate_m = 1e6});
  Vec3 hi = Vec3::Constant(-1e300);
  for (const Vec3& x : metres.mesh.vertices) hi = hi.cwiseMax(x);
  EXPECT_LT((hi - Vec3(100, 50, 20)).norm(), 1e-9);
  // A unit given for a STEP file is refused
  try {
    ReadSurfaceMesh(step, {.unit = LengthUnit::kMillimetre});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), step.string() + ": a STEP/IGES file states its own length unit; do not give one (got mm)");
  }
}

TEST_F(GmshMesherTest, StepSolidTetrahedralized) {
  const fs::path step = Plate();
  GmshMeshing m = MeshCadVolume(step, {.max_size_m = 0.01, .curvature_elements = 16, .curved = true});
  EXPECT_EQ(m.solids, 1);
  EXPECT_EQ(m.file_unit, "mm");
  ASSERT_GT(m.mesh.mesh.num_elements(), 0);
  for (const flex::FeElement& e : m.mesh.mesh.elements()) ASSERT_EQ(e.type, flex::ElementType::kTet10);
  EXPECT_GT(m.mesh.mesh.NodeSet("FACE1").size(), 3u);
  m.mesh.mesh.AssignMaterialToAll({.name = "S", .youngs_modulus_pa = 2e11, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
  const double volume = flex::AssembleFeSystem(m.mesh.mesh).volume_m3;  // checks every element
  // The bracket of flat facets made with the same curvature setting (the curved tet10 boundary
  // lies closer to the cylinder than those chords)
  const Bracket v = PlateVolume(ReadSurfaceMesh(step, {.cad = {.curvature_elements = 16}}).mesh, 1.0);
  std::printf("plate tet10: %d elements, volume %.9g m^3, exact %.9g\n", m.mesh.mesh.num_elements(), volume, v.lo);
  EXPECT_GE(volume, v.lo - (v.hi - v.lo));
  EXPECT_LE(volume, v.hi);
  EXPECT_NE(m.description.find("curved tet10"), std::string::npos);
  // Straight-sided (the default): the chords' volume, inside the flat-facet bracket
  GmshMeshing straight = MeshCadVolume(step, {.max_size_m = 0.01, .curvature_elements = 16});
  straight.mesh.mesh.AssignMaterialToAll(
      {.name = "S", .youngs_modulus_pa = 2e11, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
  const double straight_volume = flex::AssembleFeSystem(straight.mesh.mesh).volume_m3;
  TriangleMesh boundary;
  boundary.vertices = straight.mesh.mesh.positions();
  boundary.triangles = flex::BoundaryTriangles(straight.mesh.mesh, false);
  const Bracket own = PlateVolume(boundary, 1.0);
  EXPECT_GE(straight_volume, own.lo * (1 - 1e-12));
  EXPECT_LE(straight_volume, own.hi * (1 + 1e-12));
  EXPECT_LT(std::abs(volume - v.lo), std::abs(straight_volume - v.lo));
}

TEST_F(GmshMesherTest, SeveralSolidsWhenOneIsExpected) {
  const fs::path step = Step("two", "Box(1) = {0, 0, 0, 10, 10, 10};\nBox(2) = {20, 0, 0, 10, 10, 10};\n");
  try {
    ReadSurfaceMesh(step);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), step.string() + ": 2 solids; one is expected");
  }
  EXPECT_EQ(MeshCadSurface(step, {.one_solid = false}).solids, 2);
}

TEST_F(GmshMesherTest, WatertightSurfaceTetrahedralized) {
  const TriangleMesh box = Box(0.1, 0.05, 0.02);
  for (bool remesh : {true, false}) {
    GmshMeshing m = MeshSurfaceVolume(box, "box", {.max_size_m = 0.02, .remesh_surface = remesh});
    m.mesh.mesh.AssignMaterialToAll({.name = "S", .youngs_modulus_pa = 2e11, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
    EXPECT_NEAR(flex::AssembleFeSystem(m.mesh.mesh).volume_m3, 1e-4, 1e-16) << remesh;
    EXPECT_EQ(m.mesh.mesh.NodeSet("SOLID").size(), static_cast<std::size_t>(m.mesh.mesh.num_nodes()));
  }
}

TEST(GmshMissingTest, ErrorNamesTheDebianPackage) {
  const char* path = std::getenv("PATH");
  const std::string saved = path ? path : "";
  setenv("PATH", "/nonexistent", 1);
  std::string message;
  try {
    RequireGmsh();
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  setenv("PATH", saved.c_str(), 1);
  EXPECT_EQ(message, "gmsh not found on PATH: install Debian's package gmsh (apt-get install gmsh) to read STEP/IGES "
                     "files and to tetrahedralize surface meshes");
}

}  // namespace
}  // namespace orrery

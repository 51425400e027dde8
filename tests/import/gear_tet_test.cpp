// A gear tetrahedralized by gmsh from its STL (import/volume_mesh.h, gmsh_mesher.h) against the
// structured hex20 mesh of the same gear (models/gear_fe_mesh.h) and against CalculiX on the same
// tet mesh. The gear: 12 teeth, m_n 2 mm, x 0.35 (no undercut), b 6 mm, 4 mm bore radius, steel,
// the bore held fixed; the lowest 6 natural frequencies.
//
// Oracles:
// - CalculiX (an external solver) on the very tet10 mesh gmsh made: the same discrete problem when
//   the mass is integrated with CalculiX's rule (MassQuadrature::kStiffnessRule, flex/fe_element.h),
//   so the frequencies agree to the solvers' output precision (7 digits, asserted 1e-5) - far inside
//   the 0.1 % the issue asks;
// - the hex20 mesh of the exact geometry, at two refinements: each sequence's change between its
//   two meshes estimates the coarser mesh's discretization error (convergent from above for
//   displacement elements: the frequencies fall with refinement), and the tet meshes at two
//   element sizes (2 and 1.4 mm; gmsh remeshes the STL's surface, so the geometry converges with
//   the size too) estimate theirs. The fine tet and fine hex frequencies must agree within the sum of
//   the two sequences' changes.
// Skipped without gmsh (and the CalculiX part without ccx).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "flex/calculix.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"
#include "import/gmsh_mesher.h"
#include "import/part_reduction.h"
#include "import/volume_mesh.h"
#include "models/gear_fe_mesh.h"
#include "models/gear_geometry.h"
#include "models/stl.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
constexpr int kModes = 6;
const flex::IsotropicMaterial kSteel{.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850};

gears::Gear TestGear() {
  return gears::Gear({.teeth = 12, .normal_module_m = 2e-3, .profile_shift = 0.35, .face_width_m = 6e-3});
}
constexpr double kBore = 4e-3;

std::vector<double> BoreFixedModes(const flex::FeMesh& mesh, const std::vector<int>& bore,
                                   flex::MassQuadrature mass = flex::MassQuadrature::kExact) {
  const flex::FeModes m = flex::CalcFeModes(flex::AssembleFeSystem(mesh, {.mass_quadrature = mass}),
                                            flex::NodeDofs(bore), {.num_modes = kModes});
  return m.frequencies_hz;
}

// The tet10 mesh gmsh makes of the gear's STL (profile sampled finely: the faceting is 1e-4 of
// the area) with elements of at most `size_m`, the surface remeshed.
flex::FeMesh TetMesh(const fs::path& dir, double size_m) {
  const gears::Gear gear = TestGear();
  const fs::path stl = dir / "gear.stl";
  gears::WriteStlBinary(gears::MakeGearMesh(gear, {.root = 4, .fillet = 5, .involute = 12, .tip = 4}, 1, kBore),
                        stl.string(), {.scale = 1000});
  VolumeMesh v = ReadVolumeMesh(stl, {.unit = LengthUnit::kMillimetre, .meshing = {.max_size_m = size_m}});
  v.mesh.AssignMaterialToAll(kSteel);
  v.mesh.AddToNodeSet("BORE", SelectInterface(v.mesh, "bore").nodes);
  return std::move(v.mesh);
}

// A copy with every node moved (ccx reads at most 20 characters per number; see
// tests/models/gear_fe_calculix_test.cpp).
flex::FeMesh Translated(const flex::FeMesh& mesh, const Eigen::Vector3d& offset_m) {
  flex::FeMesh out;
  for (int n = 0; n < mesh.num_nodes(); ++n) out.AddNode(mesh.node_ids()[n], mesh.positions()[n] + offset_m);
  for (const flex::FeElement& e : mesh.elements()) {
    std::vector<int> ids(flex::NodeCount(e.type));
    for (std::size_t a = 0; a < ids.size(); ++a) ids[a] = mesh.node_ids()[e.nodes[a]];
    out.AddElement(e.id, e.type, ids);
  }
  for (const auto& [name, nodes] : mesh.node_sets()) out.AddToNodeSet(name, nodes);
  out.AssignMaterialToAll(mesh.materials().at(0));
  return out;
}

TEST(GearTetTest, GmshTetMeshOfTheStlMatchesHex20AndCalculix) {
  if (!FindGmsh()) GTEST_SKIP() << "gmsh not found on PATH (Debian package gmsh): gear tet mesh validation skipped";
  const fs::path dir = test_meshes::ScratchDir("gear_tet");
  const gears::Gear gear = TestGear();
  const auto t0 = std::chrono::steady_clock::now();

  // Hex20 of the exact geometry, two refinements
  std::vector<double> hex[2];
  for (int level = 0; level < 2; ++level) {
    const int k = level + 1;
    flex::FeMesh mesh = gears::MakeGearFeMesh(
        gear, {.bore_radius_m = kBore, .type = flex::ElementType::kHex20, .flank_divisions = 2 * k, .fillet_divisions = k + 1,
               .tooth_divisions = 2 * k, .root_layer_divisions = k, .rim_divisions = k + 1, .face_divisions = k + 1,
               .material = kSteel});
    hex[level] = BoreFixedModes(mesh, mesh.NodeSet("BORE"));
  }
  // Tet10 from the STL, two samplings
  std::vector<double> tet[2];
  flex::FeMesh coarse_tet;
  for (int level = 0; level < 2; ++level) {
    flex::FeMesh mesh = TetMesh(dir, level == 0 ? 2e-3 : 1.4e-3);
    tet[level] = BoreFixedModes(mesh, mesh.NodeSet("BORE"));
    if (level == 0) coarse_tet = std::move(mesh);
  }
  const auto t1 = std::chrono::steady_clock::now();
  for (int i = 0; i < kModes; ++i) {
    const double e_hex = std::abs(hex[1][i] - hex[0][i]), e_tet = std::abs(tet[1][i] - tet[0][i]);
    const double gap = std::abs(tet[1][i] - hex[1][i]);
    std::printf("  mode %d: tet %.1f -> %.1f Hz, hex20 %.1f -> %.1f Hz; |tet - hex| %.1f Hz <= %.1f + %.1f Hz\n", i + 1,
                tet[0][i], tet[1][i], hex[0][i], hex[1][i], gap, e_tet, e_hex);
    EXPECT_LE(gap, e_tet + e_hex) << "mode " << i + 1;
  }
  std::printf("gear tet vs hex20: %.1f s\n", std::chrono::duration<double>(t1 - t0).count());

  // CalculiX on the coarser tet mesh, its mass rule
  if (const auto ccx = flex::FindCalculix()) {
    const flex::FeMesh& mesh = coarse_tet;
    const std::vector<double> w2 =
        flex::RunCalculixFrequency(*ccx, Translated(mesh, Eigen::Vector3d::Ones()), {"BORE"}, kModes, dir / "ccx");
    const std::vector<double> ours = BoreFixedModes(mesh, mesh.NodeSet("BORE"), flex::MassQuadrature::kStiffnessRule);
    const std::vector<double> exact_mass = BoreFixedModes(mesh, mesh.NodeSet("BORE"));
    ASSERT_EQ(w2.size(), static_cast<std::size_t>(kModes));
    for (int i = 0; i < kModes; ++i) {
      const double f_ccx = flex::EigenvalueToHz(w2[i]);
      std::printf("  mode %d: ccx %.2f Hz, Orrery %.2f Hz (%+.1e); with the exact tet mass %.2f Hz (%+.1e)\n", i + 1,
                  f_ccx, ours[i], ours[i] / f_ccx - 1, exact_mass[i], exact_mass[i] / f_ccx - 1);
      EXPECT_NEAR(ours[i], f_ccx, 1e-5 * f_ccx) << "mode " << i + 1;
    }
    std::printf("gear tet vs ccx: %d nodes, %.1f s\n", mesh.num_nodes(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace orrery

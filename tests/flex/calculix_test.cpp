// Cross-check of FE modes against CalculiX 2.20 (an external solver, flex/calculix.cpp): the
// cantilever 1 x 0.1 x 0.1 m (steel, nu = 0.3, face x = 0 fixed) at 12 x 2 x 2 bricks, as hex20,
// tet10, hex8 and tet4 meshes, written by WriteInp, solved by ccx (*FREQUENCY, 20 modes) and by
// CalcFeModes on the same mesh.
// Tolerance: ccx prints eigenvalues with 7 significant digits (relative rounding <= 5e-7 in w^2,
// 2.5e-7 in f) and both solvers converge to ~1e-10: the frequencies must agree to 1e-6 (far
// inside the 0.1 % the issue asks for). CalculiX integrates the mass with the stiffness rule
// (e_c3d.f), so the like-for-like comparison uses MassQuadrature::kStiffnessRule; with the exact
// tet mass (Orrery's default) the tet10 frequencies differ by O(0.1 %), which the test also
// checks, so a mass option that were ignored would fail. Hex rules are identical either way.
// Skipped (GTEST_SKIP, with a message) when no ccx program is on PATH.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "flex/box_mesher.h"
#include "flex/calculix.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"

namespace orrery::flex {
namespace {

TEST(CalculixTest, ReadsEigenvalueTable) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "orrery_flex_calculix_read";
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(dir / "x.dat");
    out << "\n     E I G E N V A L U E   O U T P U T\n\n MODE NO    EIGENVALUE                       FREQUENCY\n"
           "                                     REAL PART            IMAGINARY PART\n"
           "                           (RAD/TIME)      (CYCLES/TIME     (RAD/TIME)\n\n"
           "      1   0.2762034E+06   0.5255506E+03   0.8364397E+02   0.0000000E+00\n"
           "      2   0.9947233E+07   0.3153923E+04   0.5019625E+03   0.0000000E+00\n\n"
           "     P A R T I C I P A T I O N   F A C T O R S\n      1   0.1E+01   0.2E+01\n";
  }
  const std::vector<double> w2 = ReadCalculixEigenvalues(dir / "x.dat");
  ASSERT_EQ(w2.size(), 2u);
  EXPECT_DOUBLE_EQ(w2[0], 0.2762034e6);
  EXPECT_DOUBLE_EQ(w2[1], 0.9947233e7);
  { std::ofstream out(dir / "empty.dat"); out << "nothing\n"; }
  EXPECT_THROW(ReadCalculixEigenvalues(dir / "empty.dat"), std::runtime_error);
  std::filesystem::remove_all(dir);
}

TEST(CalculixTest, CantileverModesMatchCalculix) {
  const std::optional<std::filesystem::path> ccx = FindCalculix();
  if (!ccx) GTEST_SKIP() << "CalculiX (ccx) not found on PATH: cross-check skipped";
  constexpr int kModes = 20;
  for (ElementType t : {ElementType::kHex20, ElementType::kTet10, ElementType::kHex8, ElementType::kTet4}) {
    FeMesh mesh = MakeBoxMesh({.size_m = {1, 0.1, 0.1}, .divisions = {12, 2, 2}, .type = t});
    mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
    const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                      (std::string("orrery_flex_ccx_") + CalculixName(t) + "_" + std::to_string(::getpid()));
    const std::vector<double> w2_ccx = RunCalculixFrequency(*ccx, mesh, {"XMIN"}, kModes, dir);
    std::filesystem::remove_all(dir);
    ASSERT_EQ(static_cast<int>(w2_ccx.size()), kModes) << CalculixName(t);
    const std::vector<int> fixed = NodeDofs(mesh.NodeSet("XMIN"));
    const FeModes like = CalcFeModes(AssembleFeSystem(mesh, {.mass_quadrature = MassQuadrature::kStiffnessRule}), fixed,
                                     {.num_modes = kModes});
    const FeModes exact = CalcFeModes(AssembleFeSystem(mesh), fixed, {.num_modes = kModes});
    double worst = 0, worst_exact = 0;
    for (int i = 0; i < kModes; ++i) {
      const double f_ccx = EigenvalueToHz(w2_ccx[i]);
      worst = std::max(worst, std::abs(like.frequencies_hz[i] / f_ccx - 1));
      worst_exact = std::max(worst_exact, std::abs(exact.frequencies_hz[i] / f_ccx - 1));
    }
    std::printf("%s: %d DOFs, f1 %.5f Hz, f20 %.3f Hz (ccx %.3f); max relative difference %.2g "
                "(exact mass: %.2g)\n", CalculixName(t), static_cast<int>(like.free_dofs.size()), like.frequencies_hz[0],
                like.frequencies_hz[kModes - 1], EigenvalueToHz(w2_ccx[kModes - 1]), worst, worst_exact);
    EXPECT_LT(worst, 1e-6) << CalculixName(t);
    if (IsTet(t)) {
      EXPECT_GT(worst_exact, 1e-4) << CalculixName(t) << ": exact tet mass should differ from ccx's";
    }
    else EXPECT_LT(worst_exact, 1e-6) << CalculixName(t);
  }
}

}  // namespace
}  // namespace orrery::flex

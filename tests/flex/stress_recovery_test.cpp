// Stress recovery (flex/stress_recovery.cpp). Oracles:
//   - patch test: a linear displacement field (uniaxial tension u = (s/E x, -nu s/E y, -nu s/E z),
//     and a simple shear) lies in every element's space, so D B u is exact at every node of every
//     element type: sigma_xx = s, von Mises = s (uniaxial), sigma_xy = G gamma, von Mises
//     = sqrt(3) |tau| (shear). Rounding level.
//   - cantilever (hex20, 1 x 0.1 x 0.1 m, 20 x 2 x 2, root face clamped through an RBE2 held
//     master, tip force P along z spread equally on the tip face nodes): at mid-span, away from the
//     root and the load (Saint-Venant, 5 depths from either end), the Saint-Venant flexure solution
//     has sigma_xx = -P (L - x) z / I exactly, and the other normal stresses zero. Measured:
//     1.4e-7 of the peak (the bending stress is linear in x and z, inside the hex20 space; the
//     rigid root's Poisson constraint has decayed); bound 1e-4 of the peak, lateral stresses 5e-3.
//   - von Mises of a principal state and of pure shear (sqrt(3) tau) in closed form.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "flex/box_mesher.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/geometric_stiffness.h"
#include "flex/stress_recovery.h"

namespace orrery::flex {
namespace {

constexpr double kE = 210e9, kNu = 0.3;

FeMesh Box(ElementType t, const Eigen::Vector3d& size, std::array<int, 3> div) {
  FeMesh mesh = MakeBoxMesh({.origin_m = Eigen::Vector3d(0.1, -0.2, 0.05), .size_m = size, .divisions = div, .type = t});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = kNu, .density_kg_m3 = 7850});
  return mesh;
}

TEST(StressRecoveryTest, VonMisesClosedForms) {
  Stress6 s;
  s << 100, 40, -30, 0, 0, 0;
  EXPECT_NEAR(VonMises(s), std::sqrt((60.0 * 60 + 70.0 * 70 + 130.0 * 130) / 2), 1e-12);
  s << 0, 0, 0, 0, 25, 0;
  EXPECT_NEAR(VonMises(s), std::sqrt(3.0) * 25, 1e-12);
  // Invariant under a hydrostatic shift
  Stress6 h = s;
  h.head<3>().array() += 1e3;
  EXPECT_NEAR(VonMises(h), VonMises(s), 1e-9);
}

TEST(StressRecoveryTest, LinearFieldsAreExactInEveryElement) {
  const double s = 50e6, tau = 20e6, G = kE / (2 * (1 + kNu));
  for (ElementType t : {ElementType::kTet4, ElementType::kTet10, ElementType::kHex8, ElementType::kHex20}) {
    const FeMesh mesh = Box(t, {1.0, 0.2, 0.3}, {4, 2, 2});
    const int nn = mesh.num_nodes();
    Eigen::MatrixXd U(3 * nn, 2);
    for (int a = 0; a < nn; ++a) {
      const Eigen::Vector3d p = mesh.positions()[a];
      U.block<3, 1>(3 * a, 0) = Eigen::Vector3d(s / kE * p.x(), -kNu * s / kE * p.y(), -kNu * s / kE * p.z());
      U.block<3, 1>(3 * a, 1) = Eigen::Vector3d(tau / G * p.y(), 0, 0);  // gamma_xy = tau / G
    }
    const Eigen::MatrixXd S = CalcNodalStresses(mesh, U);
    ASSERT_EQ(S.rows(), 6 * nn);
    Stress6 uniaxial = Stress6::Zero(), shear = Stress6::Zero();
    uniaxial(0) = s;
    shear(3) = tau;
    double err = 0;
    for (int a = 0; a < nn; ++a) {
      err = std::max(err, (S.block<6, 1>(6 * a, 0) - uniaxial).cwiseAbs().maxCoeff());
      err = std::max(err, (S.block<6, 1>(6 * a, 1) - shear).cwiseAbs().maxCoeff());
      EXPECT_NEAR(VonMises(S.block<6, 1>(6 * a, 0)), s, 1e-6 * s);
    }
    EXPECT_LT(err, 1e-7 * s) << CalculixName(t);
    // A node subset returns the same rows
    const std::vector<int> some = {nn - 1, 0, nn / 2};
    const Eigen::MatrixXd Ss = CalcNodalStresses(mesh, U, some);
    for (int k = 0; k < 3; ++k) EXPECT_LT((Ss.middleRows(6 * k, 6) - S.middleRows(6 * some[k], 6)).norm(), 1e-6);
  }
}

TEST(StressRecoveryTest, CantileverBendingStressMatchesBeamTheory) {
  const double L = 1.0, b = 0.1, h = 0.1, P = 1e4;
  const Eigen::Vector3d origin(0.1, -0.2, 0.05);
  const FeMesh mesh = Box(ElementType::kHex20, {L, b, h}, {20, 2, 2});
  const FeSystem sys = AssembleFeSystem(mesh);
  const std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2)};
  // Tip force P along z, equal shares on the tip face nodes
  const std::vector<int>& tip = mesh.NodeSet("XMAX");
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(3 * mesh.num_nodes(), 1);
  for (int a : tip) F(3 * a + 2, 0) = P / tip.size();
  const Eigen::MatrixXd u = SolveStaticsHeldAtInterface(mesh, sys, ifs, 0, F);
  const Eigen::MatrixXd S = CalcNodalStresses(mesh, u);
  // Mid-span section: sigma_xx = -M z / I with M = P (L - x), z from the centroid
  const double I = b * h * h * h / 12, x = L / 2;
  const double zc = origin.z() + h / 2;
  double max_err = 0, peak = P * (L - x) * (h / 2) / I;
  int checked = 0;
  for (int a = 0; a < mesh.num_nodes(); ++a) {
    const Eigen::Vector3d p = mesh.positions()[a] - origin;
    if (std::abs(p.x() - x) > 1e-9) continue;
    const double z = mesh.positions()[a].z() - zc;
    const double expected = -P * (L - x) * z / I;
    max_err = std::max(max_err, std::abs(S(6 * a, 0) - expected));
    // Lateral normal stresses vanish in the Saint-Venant solution
    EXPECT_LT(std::abs(S(6 * a + 1, 0)), 5e-3 * peak);
    EXPECT_LT(std::abs(S(6 * a + 2, 0)), 5e-3 * peak);
    ++checked;
  }
  EXPECT_EQ(checked, 21);  // 5 x 5 lattice of a hex20 section minus the 4 face centres
  EXPECT_LT(max_err, 1e-4 * peak) << "peak " << peak << " Pa";
  std::printf("cantilever mid-span sigma_xx: max |error| / peak = %.3g\n", max_err / peak);
}

}  // namespace
}  // namespace orrery::flex

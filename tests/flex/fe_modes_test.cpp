// Natural modes of FE solids (flex/fe_modes.cpp):
//   - the shift-invert Lanczos solve against a dense generalized eigen solver on a small free-free
//     mesh (independent algorithm), rigid-body modes reported as zeros;
//   - a solid cantilever (1 x 0.1 x 0.1 m, E = 210 GPa, rho = 7850 kg/m^3, end face x = 0 fixed)
//     meshed with hex20 and tet10 at three refinements, against beam theory:
//       Euler-Bernoulli  f = 1.87510^2 / (2 pi) sqrt(E I / (rho A L^4))            = 83.55 Hz,
//       Timoshenko       root of the clamped-free frequency equation, shear correction of a
//                        rectangle kappa = 10 (1 + nu) / (12 + 11 nu) (Cowper, J. Appl. Mech. 33,
//                        1966), rotary inertia included; solved here as the constant-coefficient
//                        ODE y' = A(w) y, y = (w, w', psi, psi'), by exp(A L) and bisection on
//                        the 2x2 free-end determinant,
//       Saint-Venant     f = (1 / 4L) sqrt(G J_t / (rho I_p)), J_t = 0.140577 a^4 (square;
//                        Timoshenko & Goodier, Theory of Elasticity, sec. 109), I_p = a^4 / 6.
//     nu = 0 here: a fully fixed end face also stops the Poisson contraction there, which beam
//     theory does not; with nu = 0.3 this stiffens the first bending mode by 0.5 % (hex20
//     84.259, 83.537, 83.358 Hz, extrapolated 83.30 Hz, against Timoshenko's 82.90 Hz), a model
//     difference, not a discretization error. With nu = 0 the 3-D solid and Timoshenko's beam
//     differ by terms of order (a/L)^4 = 1e-4 only, which is the tolerance used.
//     Torsion: the fixed face also stops warping; an added constraint can only raise an
//     eigenvalue (Rayleigh), and a rigid zone of length a at the root would raise the torsion
//     frequency by at most sqrt(L / (L - a)) - 1 = 5.4 %: the extrapolated hex20 frequency lies
//     in [f_SV, 1.054 f_SV]; tet10 frequencies stay above it (Rayleigh-Ritz upper bounds) and
//     approach it.
//   Convergence: refinements h, h/2, h/4 (8x1x1, 16x2x2, 32x4x4 bricks); errors decrease
//   monotonically; Richardson extrapolation f* = f3 + (f3 - f2) / (r^p - 1) with the observed
//   order p = log2((f1 - f2) / (f2 - f3)), estimated error of f3 |f3 - f*|.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>
#include <unsupported/Eigen/MatrixFunctions>

#include "flex/box_mesher.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"

namespace orrery::flex {
namespace {

constexpr double kE = 210e9, kRho = 7850, kL = 1.0, kA = 0.1;

// The three eigen solvers (the thick-restart Lanczos, the default; Spectra's; the block Lanczos
// with purified Ritz vectors): the block Lanczos' unpurified vectors missed the residual bound by
// up to 3.7x here.
TEST(FeModesTest, LanczosMatchesDenseSolverOnFreeMesh) {
  const std::vector<std::pair<ElementType, EigenSolver>> cases = {
      {ElementType::kHex20, EigenSolver::kThickRestart},
      {ElementType::kTet10, EigenSolver::kThickRestart},
      {ElementType::kHex20, EigenSolver::kSpectra},
      {ElementType::kTet10, EigenSolver::kSpectra},
      {ElementType::kHex20, EigenSolver::kBlockLanczos},
      {ElementType::kTet10, EigenSolver::kBlockLanczos}};
  for (const auto& [t, solver] : cases) {
    FeMesh mesh = MakeBoxMesh({.size_m = {0.3, 0.1, 0.05}, .divisions = {3, 1, 1}, .type = t});
    mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = 0.3, .density_kg_m3 = kRho});
    const FeSystem sys = AssembleFeSystem(mesh);
    const FeModes modes = CalcFeModes(sys, {}, {.num_modes = 12, .solver = solver});
    SCOPED_TRACE(solver == EigenSolver::kThickRestart ? "thick restart"
                 : solver == EigenSolver::kSpectra    ? "Spectra"
                                                      : "block Lanczos");
    // Dense oracle
    const Eigen::MatrixXd K(sys.K), M(sys.M);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> dense(K, M);
    const Eigen::VectorXd w2 = dense.eigenvalues();
    const double top = w2.maxCoeff();
    EXPECT_EQ(modes.num_rigid_body_modes, 6) << CalculixName(t);
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(modes.frequencies_hz[i], 0.0);
      EXPECT_LT(std::abs(w2(i)), 1e-9 * top) << "dense rigid-body eigenvalue " << i;
    }
    for (int i = 6; i < 12; ++i)
      EXPECT_NEAR(modes.eigenvalues(i), w2(i), 1e-9 * w2(i)) << CalculixName(t) << " mode " << i;
    // M-orthonormal shapes, K phi = w^2 M phi
    const Eigen::MatrixXd& phi = modes.shapes;
    EXPECT_LT((phi.transpose() * M * phi - Eigen::MatrixXd::Identity(12, 12)).cwiseAbs().maxCoeff(), 1e-8);
    for (int i = 6; i < 12; ++i)
      EXPECT_LT((K * phi.col(i) - modes.eigenvalues(i) * M * phi.col(i)).norm(),
                1e-7 * modes.eigenvalues(i) * (M * phi.col(i)).norm());
  }
}

// The overload taking the system by rvalue (`orrery fe-modes`) frees K's and M's storage before the
// factorization and gives the same modes. Eigen 3.4's SparseMatrix keeps its storage when assigned
// an empty matrix, which is how an earlier version "released" them (230 MB of the 92k-DOF block
// stayed allocated through the factorization).
TEST(FeModesTest, RvalueSystemIsReleasedBeforeTheFactorization) {
  FeMesh mesh = MakeBoxMesh({.size_m = {0.3, 0.1, 0.1}, .divisions = {6, 2, 2}, .type = ElementType::kHex20});
  mesh.AssignMaterialToAll({.name = "S", .youngs_modulus_pa = kE, .poissons_ratio = 0.3, .density_kg_m3 = kRho});
  FeSystem sys = AssembleFeSystem(mesh);
  const std::vector<int> fixed = NodeDofs(mesh.NodeSet("XMIN"));
  const FeModes kept = CalcFeModes(sys, fixed, {.num_modes = 6});
  ASSERT_GT(sys.K.data().allocatedSize(), 0);
  const FeModes released = CalcFeModes(std::move(sys), fixed, {.num_modes = 6});
  EXPECT_EQ(sys.K.data().allocatedSize(), 0);  // NOLINT(bugprone-use-after-move): released by contract
  EXPECT_EQ(sys.M.data().allocatedSize(), 0);  // NOLINT(bugprone-use-after-move)
  for (int i = 0; i < 6; ++i) EXPECT_EQ(released.eigenvalues(i), kept.eigenvalues(i)) << "mode " << i;
}

TEST(FeModesTest, RejectsBadRequests) {
  FeMesh mesh = MakeBoxMesh({.divisions = {1, 1, 1}, .type = ElementType::kHex8});
  mesh.AssignMaterialToAll({.name = "S", .youngs_modulus_pa = kE, .poissons_ratio = 0.3, .density_kg_m3 = kRho});
  const FeSystem sys = AssembleFeSystem(mesh);
  EXPECT_THROW(CalcFeModes(sys, {}, {.num_modes = 0}), std::invalid_argument);
  EXPECT_THROW(CalcFeModes(sys, {}, {.num_modes = 24}), std::invalid_argument);
  const std::vector<int> bad{99};
  EXPECT_THROW(CalcFeModes(sys, bad, {.num_modes = 2}), std::out_of_range);
}

// Timoshenko clamped-free beam: first bending frequency (Hz).
double TimoshenkoCantileverHz(double E, double nu, double rho, double a, double L) {
  const double G = E / (2 * (1 + nu)), A = a * a, I = a * a * a * a / 12, kappa = 10 * (1 + nu) / (12 + 11 * nu);
  // y = (w, w', psi, psi'): kappa G A (w'' - psi') + rho A w^2 w = 0, E I psi'' + kappa G A (w' - psi) + rho I w^2 psi = 0
  auto free_end_det = [&](double omega) {
    Eigen::Matrix4d S = Eigen::Matrix4d::Zero();
    S(0, 1) = 1;
    S(1, 0) = -rho * omega * omega / (kappa * G);
    S(1, 3) = 1;
    S(2, 3) = 1;
    S(3, 1) = -kappa * G * A / (E * I);
    S(3, 2) = kappa * G * A / (E * I) - rho * omega * omega / E;
    const Eigen::Matrix4d P = (S * L).exp();
    // Clamped root: w = psi = 0, unknown w'(0), psi'(0); free end: psi' = 0, w' - psi = 0
    return P(3, 1) * (P(1, 3) - P(2, 3)) - P(3, 3) * (P(1, 1) - P(2, 1));
  };
  const double w_eb = 1.87510407 * 1.87510407 * std::sqrt(E * I / (rho * A * std::pow(L, 4)));
  double lo = 0.8 * w_eb, hi = 1.0 * w_eb, f_lo = free_end_det(lo);
  EXPECT_LT(f_lo * free_end_det(hi), 0) << "no sign change below the Euler-Bernoulli frequency";
  for (int it = 0; it < 100; ++it) {
    const double mid = (lo + hi) / 2, f_mid = free_end_det(mid);
    if ((f_mid < 0) == (f_lo < 0)) lo = mid, f_lo = f_mid;
    else hi = mid;
  }
  return (lo + hi) / 4 / std::numbers::pi;
}

struct CantileverFrequencies {
  double bending_hz = 0, torsion_hz = 0;
  int dofs = 0;
};

// First bending and first torsion frequency of the cantilever, face x = 0 fixed.
CantileverFrequencies SolveCantilever(ElementType t, int level, double nu) {
  FeMesh mesh = MakeBoxMesh({.size_m = {kL, kA, kA}, .divisions = {8 * level, level, level}, .type = t});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = nu, .density_kg_m3 = kRho});
  const FeSystem sys = AssembleFeSystem(mesh);
  const FeModes modes = CalcFeModes(sys, NodeDofs(mesh.NodeSet("XMIN")), {.num_modes = 8});
  // Torsion: the mode most M-parallel to a twist growing along x, u = (x / L) e_x x (p - axis)
  Eigen::VectorXd twist = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const Eigen::Vector3d& p = mesh.positions()[n];
    twist.segment<3>(3 * n) = p(0) / kL * Eigen::Vector3d(0, -(p(2) - kA / 2), p(1) - kA / 2);
  }
  const Eigen::VectorXd Mt = sys.M * twist;
  int torsion = 0;
  double best = 0;
  for (int i = 0; i < modes.shapes.cols(); ++i) {
    const double c = std::abs(modes.shapes.col(i).dot(Mt)) / std::sqrt(twist.dot(Mt));
    if (c > best) best = c, torsion = i;
  }
  EXPECT_GT(best, 0.9) << "no torsion mode among the first 8";
  return {modes.frequencies_hz[0], modes.frequencies_hz[torsion], static_cast<int>(modes.free_dofs.size())};
}

struct Richardson {
  double extrapolated = 0, order = 0, error_estimate = 0;
};
Richardson Extrapolate(double f1, double f2, double f3) {
  Richardson r;
  r.order = std::log2((f1 - f2) / (f2 - f3));
  r.extrapolated = f3 + (f3 - f2) / (std::pow(2.0, r.order) - 1);
  r.error_estimate = std::abs(f3 - r.extrapolated);
  return r;
}

TEST(FeModesTest, CantileverConvergesToBeamTheory) {
  const double nu = 0.0, G = kE / (2 * (1 + nu));
  const double I = std::pow(kA, 4) / 12, area = kA * kA;
  const double f_eb = std::pow(1.87510407, 2) / (2 * std::numbers::pi) * std::sqrt(kE * I / (kRho * area * std::pow(kL, 4)));
  const double f_timo = TimoshenkoCantileverHz(kE, nu, kRho, kA, kL);
  const double f_sv = 1 / (4 * kL) * std::sqrt(G * 0.140577 * std::pow(kA, 4) / (kRho * std::pow(kA, 4) / 6));
  EXPECT_NEAR(f_eb, 83.5517, 1e-3);
  // Shear and rotary inertia lower the frequency by terms of order (a/L)^2: 0.65 % here
  EXPECT_LT(f_timo, f_eb);
  EXPECT_GT(f_timo, 0.99 * f_eb);

  double torsion[2][3];  // hex20, tet10 at the three levels
  int k = 0;
  for (ElementType t : {ElementType::kHex20, ElementType::kTet10}) {
    CantileverFrequencies f[3];
    for (int i = 0; i < 3; ++i) f[i] = SolveCantilever(t, 1 << i, nu);
    const Richardson bend = Extrapolate(f[0].bending_hz, f[1].bending_hz, f[2].bending_hz);
    const Richardson twist = Extrapolate(f[0].torsion_hz, f[1].torsion_hz, f[2].torsion_hz);
    std::printf("%s bending (Hz): %.4f %.4f %.4f (DOFs %d %d %d), Richardson %.4f (order %.2f, error of finest %.2g), "
                "Timoshenko %.4f, Euler-Bernoulli %.4f\n",
                CalculixName(t), f[0].bending_hz, f[1].bending_hz, f[2].bending_hz, f[0].dofs, f[1].dofs, f[2].dofs,
                bend.extrapolated, bend.order, bend.error_estimate, f_timo, f_eb);
    std::printf("%s torsion (Hz): %.3f %.3f %.3f, Richardson %.3f (order %.2f, error of finest %.2g), Saint-Venant %.3f\n",
                CalculixName(t), f[0].torsion_hz, f[1].torsion_hz, f[2].torsion_hz, twist.extrapolated, twist.order,
                twist.error_estimate, f_sv);
    // Errors against the references decrease monotonically (from above: the FE model is stiffer)
    for (int i = 0; i < 2; ++i) {
      EXPECT_LT(std::abs(f[i + 1].bending_hz - f_timo), std::abs(f[i].bending_hz - f_timo)) << CalculixName(t);
      EXPECT_LT(std::abs(f[i + 1].torsion_hz - f_sv), std::abs(f[i].torsion_hz - f_sv)) << CalculixName(t);
    }
    // Bending is in the asymptotic range for both: order > 2 (quadratic elements)
    EXPECT_GT(bend.order, 2.0) << CalculixName(t);
    // Bending: within the discretization error plus the beam-model error (a/L)^4 of Timoshenko
    const double model = std::pow(kA / kL, 4) * f_timo;
    EXPECT_LT(std::abs(f[2].bending_hz - f_timo), bend.error_estimate + model) << CalculixName(t);
    EXPECT_LT(std::abs(bend.extrapolated - f_timo), model) << CalculixName(t);
    // ... and far closer to Timoshenko than to Euler-Bernoulli
    EXPECT_LT(std::abs(bend.extrapolated - f_timo), 0.05 * std::abs(f_eb - f_timo)) << CalculixName(t);
    for (int i = 0; i < 3; ++i) torsion[k][i] = f[i].torsion_hz;
    ++k;
  }
  // Torsion, hex20 (in the asymptotic range, order > 2): warping restraint at the root raises the
  // frequency above Saint-Venant's, by less than a rigid zone of length a would
  const Richardson twist = Extrapolate(torsion[0][0], torsion[0][1], torsion[0][2]);
  EXPECT_GT(twist.order, 2.0);
  EXPECT_GT(twist.extrapolated, f_sv);
  EXPECT_LT(twist.extrapolated, std::sqrt(kL / (kL - kA)) * f_sv);
  // Torsion, tet10: one brick (6 tets) across the section is outside the asymptotic range
  // (observed order 2.0 from the three levels), so no extrapolation; Rayleigh-Ritz bounds the
  // exact 3-D eigenvalue from above (conforming elements, consistent mass), and the distance to
  // the hex20 extrapolation shrinks with refinement
  for (int i = 0; i < 3; ++i) EXPECT_GT(torsion[1][i], twist.extrapolated - twist.error_estimate);
  for (int i = 0; i < 2; ++i)
    EXPECT_LT(torsion[1][i + 1] - twist.extrapolated, torsion[1][i] - twist.extrapolated);
}

}  // namespace
}  // namespace orrery::flex

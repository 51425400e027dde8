// Geometric stiffness (flex/geometric_stiffness.cpp) and the centrifugal stiffening of
// flex/flexible_body_modes.cpp. Oracles:
//   - element K_sigma against the closed form of a linear field u = A x in a uniform stress sigma:
//     u^T K_sigma u = V tr(A sigma A^T) (grad u_i is row i of A), on affinely distorted elements of
//     every type; rigid translations carry no geometric stiffness. Rounding level.
//   - Euler buckling of a cantilever column (hex20, 1 x 0.02 x 0.02 m, 20 x 1 x 1 bricks, root
//     face held plane with free Poisson contraction): the lowest lambda of (K + lambda K_sigma(sigma_xx = -1/A)) phi = 0 is the
//     critical load P_cr = pi^2 E I / (4 L^2) (Timoshenko & Gere, "Theory of Elastic Stability",
//     2nd ed., sec. 2.1). Expected deviation: shear, -P_cr / (kappa G A) = -3e-4, plus the
//     discretization; measured -1.1e-4, bound 1e-3. (Clamping every root node instead stiffens the
//     root against Poisson contraction: +0.57 %.)
//   - the six inertial load cases weighted by the products of w equal the consistent nodal
//     centrifugal force M (-w x (w x x)), whose resultant is -m w x (w x c). Rounding level.
//   - rotating cantilever (hex20 blade 1 x 0.04 x 0.02 m, 25 x 2 x 1 bricks, clamped at its root
//     through an RBE2, spinning about z): the flapwise (z) frequency obeys
//     w^2 = w0^2 + K1 W^2 to first order in W^2, with Southwell coefficient K1 = 1.1933 for the
//     first mode of a uniform cantilever without hub (Wright, Smith, Thresher & Wang, "Vibration
//     modes of centrifugally stiffened beams", J. Appl. Mech. 49 (1982) 197-202). The test also
//     recomputes K1 as the Rayleigh quotient int T phi'^2 / int phi^2 of the Euler-Bernoulli mode
//     (T = (1 - x^2) / 2 per rho A W^2 L^2): 1.193336. With one mode (M_ff = 1), K1 is G_zz(1, 1)
//     of the FE model: measured +0.33 % (3-D solid vs Euler-Bernoulli beam: shear, rotary inertia,
//     the rigid RBE2 root face, the y part of the in-plane body force), bound 0.5 %.
//     At W up to 3 w0 (eta = W / sqrt(EI / rho A L^4) up to 10.5) the lowest eigenvalue of
//     K_ff + W^2 G_zz (all modes; flap in z has no spin softening) is compared with the converged
//     Euler-Bernoulli rotating beam: a Rayleigh-Ritz model with 8 analytic clamped-free modes,
//     G_kl = int T phi_k' phi_l'. Southwell's line overestimates w^2 there (it is the one-mode
//     Rayleigh bound: 2.4 % at eta = 10), so the comparison is of w^2 - w0^2 (the stiffening)
//     relative to W^2: measured 0.34 % to 0.37 % above the beam at W / w0 = 0.5 ... 3, bound 1 %
//     (solid vs beam as for K1, the truncation of the Craig-Bampton basis at 12 fixed-interface
//     modes). The one-mode line must lie above both. The 1-D oracle itself reproduces the published
//     exact frequencies (lambda = 3.6816, 4.1373, 6.4495, 11.2023 at eta = 1, 2, 5, 10) to 1e-4.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <vector>

#include "flex/box_mesher.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_element.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "flex/geometric_stiffness.h"

namespace orrery::flex {
namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850;
constexpr double kPi = std::numbers::pi;

TEST(GeometricStiffnessTest, ElementMatchesLinearFieldClosedForm) {
  Eigen::Matrix3d Amap;  // affine distortion of the reference element
  Amap << 0.9, 0.2, -0.1, 0.05, 1.1, 0.15, -0.1, 0.1, 0.8;
  const Eigen::Vector3d shift(0.3, -0.2, 0.5);
  Eigen::Matrix<double, 6, 1> s;
  s << 3e6, -1e6, 2e6, 0.5e6, -0.7e6, 0.9e6;
  Eigen::Matrix3d sig;
  sig << s(0), s(3), s(5), s(3), s(1), s(4), s(5), s(4), s(2);
  Eigen::Matrix3d A;  // displacement gradient
  A << 1e-3, -2e-3, 0.5e-3, 0.7e-3, 0.2e-3, -1e-3, 0.3e-3, 0.9e-3, -0.4e-3;
  for (ElementType t : {ElementType::kTet4, ElementType::kTet10, ElementType::kHex8, ElementType::kHex20}) {
    const Eigen::MatrixX3d xi = NaturalNodeCoordinates(t);
    Eigen::MatrixX3d X(xi.rows(), 3);
    for (int a = 0; a < xi.rows(); ++a) X.row(a) = (Amap * xi.row(a).transpose() + shift).transpose();
    const Eigen::MatrixXd K = CalcElementGeometricStiffness(t, X, s);
    const int n = NodeCount(t);
    Eigen::VectorXd u(3 * n), tr(3 * n);
    for (int a = 0; a < n; ++a) {
      u.segment<3>(3 * a) = A * X.row(a).transpose();
      tr.segment<3>(3 * a) = Eigen::Vector3d(1, -2, 3);
    }
    const double V = CalcElementVolume(t, X);
    const double expected = V * (A * sig * A.transpose()).trace();
    EXPECT_NEAR(u.dot(K * u), expected, 1e-10 * std::abs(expected)) << CalculixName(t);
    EXPECT_LT((K * tr).norm(), 1e-9 * K.norm()) << CalculixName(t);
    EXPECT_LT((K - K.transpose()).norm(), 1e-12 * K.norm());
    // Per-point stresses equal to the uniform one give the same matrix
    const int np = static_cast<int>(GeometricStiffnessRule(t).points.size());
    const Eigen::Matrix<double, 6, Eigen::Dynamic> sp = s.replicate(1, np);
    EXPECT_LT((CalcElementGeometricStiffness(t, X, sp) - K).norm(), 1e-12 * K.norm());
    EXPECT_THROW(CalcElementGeometricStiffness(t, X, s.replicate(1, np + 1)), std::invalid_argument);
  }
}

TEST(GeometricStiffnessTest, LoadCasesSumToTheCentrifugalForce) {
  // sum_c p_c(w) F_c = M (-w x (w x x)) nodewise, for a general w and origin
  FeMesh mesh = MakeBoxMesh({.origin_m = {0.3, -0.1, 0.2}, .size_m = {0.5, 0.2, 0.1}, .divisions = {3, 2, 1},
                             .type = ElementType::kTet10});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = kNu, .density_kg_m3 = kRho});
  const FeSystem sys = AssembleFeSystem(mesh);
  const Eigen::Vector3d origin(0.1, 0.2, -0.3), w(3, -5, 7);
  const Eigen::MatrixXd F = InertialLoadCases(mesh, sys, origin);
  Eigen::Matrix<double, 6, 1> p;
  p << w.x() * w.x(), w.y() * w.y(), w.z() * w.z(), w.x() * w.y(), w.y() * w.z(), w.z() * w.x();
  Eigen::VectorXd a(3 * mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) a.segment<3>(3 * n) = -w.cross(w.cross(mesh.positions()[n] - origin));
  const Eigen::VectorXd expected = sys.M * a;
  EXPECT_LT((F * p - expected).norm(), 1e-12 * expected.norm());
  // Resultant: m |w|^2 times the centre of mass's distance from the axis
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int n = 0; n < mesh.num_nodes(); ++n) total += (F * p).segment<3>(3 * n);
  const Eigen::Vector3d c = Eigen::Vector3d(0.3, -0.1, 0.2) + Eigen::Vector3d(0.25, 0.1, 0.05) - origin;
  const Eigen::Vector3d resultant = -sys.mass_kg * w.cross(w.cross(c));
  EXPECT_LT((total - resultant).norm(), 1e-10 * resultant.norm());
}

// Rows and columns `keep` of a sparse matrix, dense.
Eigen::MatrixXd Restrict(const Eigen::SparseMatrix<double>& A, const std::vector<int>& keep) {
  const Eigen::MatrixXd D(A);
  Eigen::MatrixXd R(keep.size(), keep.size());
  for (std::size_t i = 0; i < keep.size(); ++i)
    for (std::size_t j = 0; j < keep.size(); ++j) R(i, j) = D(keep[i], keep[j]);
  return R;
}

TEST(GeometricStiffnessTest, CantileverColumnBucklesAtEulerLoad) {
  const double L = 1.0, a = 0.02;
  FeMesh mesh = MakeBoxMesh({.size_m = {L, a, a}, .divisions = {20, 1, 1}, .type = ElementType::kHex20});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = kNu, .density_kg_m3 = kRho});
  const FeSystem sys = AssembleFeSystem(mesh);
  // Uniform compression sigma_xx = -1 / A: lambda is the axial load P (N)
  Eigen::Matrix<double, 6, 1> s = Eigen::Matrix<double, 6, 1>::Zero();
  s(0) = -1 / (a * a);
  const Eigen::SparseMatrix<double> Ks = AssembleUniformGeometricStiffness(mesh, s);
  // Root clamped as Euler-Bernoulli's: the face stays plane (u_x = 0) and its centre lines do
  // not move sideways (u_y = 0 where y = 0, u_z = 0 where z = 0), free Poisson contraction
  std::vector<char> fixed(3 * mesh.num_nodes(), 0);
  for (int n : mesh.NodeSet("XMIN")) {
    const Eigen::Vector3d p = mesh.positions()[n];
    fixed[3 * n] = 1;
    if (std::abs(p.y() - a / 2) < 1e-12) fixed[3 * n + 1] = 1;
    if (std::abs(p.z() - a / 2) < 1e-12) fixed[3 * n + 2] = 1;
  }
  std::vector<int> keep;
  for (int d = 0; d < 3 * mesh.num_nodes(); ++d)
    if (!fixed[d]) keep.push_back(d);
  // K phi = P (-K_sigma) phi  <=>  (-K_sigma) phi = (1 / P) K phi, K positive definite
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(-Restrict(Ks, keep), Restrict(sys.K, keep),
                                                               Eigen::EigenvaluesOnly);
  ASSERT_EQ(ges.info(), Eigen::Success);
  const double P_fe = 1 / ges.eigenvalues().maxCoeff();
  const double I = a * a * a * a / 12;
  const double P_euler = kPi * kPi * kE * I / (4 * L * L);
  std::printf("cantilever column: P_cr FE %.6g N, Euler %.6g N, rel %.3g\n", P_fe, P_euler, P_fe / P_euler - 1);
  EXPECT_NEAR(P_fe / P_euler, 1.0, 1e-3);
  // Same stress from the displacement field of a uniform axial strain (the other overload)
  Eigen::VectorXd u(3 * mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const Eigen::Vector3d p = mesh.positions()[n];
    u.segment<3>(3 * n) = s(0) / kE * Eigen::Vector3d(p.x(), -kNu * p.y(), -kNu * p.z());
  }
  EXPECT_LT(Eigen::MatrixXd(AssembleGeometricStiffness(mesh, u) - Ks).norm(), 1e-8 * Eigen::MatrixXd(Ks).norm());
}

// Euler-Bernoulli clamped-free mode k (unit length), numerically stable form:
// phi = cosh z - cos z - s (sinh z - sin z) = ((1 - s) e^z + (1 + s) e^-z) / 2 - cos z + s sin z.
struct BeamMode {
  double beta, s, one_minus_s;
  explicit BeamMode(double b) : beta(b) {
    const double den = std::cosh(b) + std::cos(b);
    s = (std::sinh(b) - std::sin(b)) / den;
    one_minus_s = (std::exp(-b) + std::cos(b) + std::sin(b)) / den;
  }
  double phi(double x) const {
    const double z = beta * x;
    return 0.5 * (one_minus_s * std::exp(z) + (1 + s) * std::exp(-z)) - std::cos(z) + s * std::sin(z);
  }
  double dphi(double x) const {
    const double z = beta * x;
    return beta * (0.5 * (one_minus_s * std::exp(z) - (1 + s) * std::exp(-z)) + std::sin(z) + s * std::cos(z));
  }
};

// Roots of cos b cosh b = -1 (Newton from the asymptotic (k - 1/2) pi).
double ClampedFreeBeta(int k) {
  double b = k == 0 ? 1.875 : (k + 0.5) * kPi;
  for (int it = 0; it < 50; ++it) {
    const double f = std::cos(b) * std::cosh(b) + 1;
    const double df = -std::sin(b) * std::cosh(b) + std::cos(b) * std::sinh(b);
    b -= f / df;
  }
  return b;
}

// Rotating Euler-Bernoulli cantilever by Rayleigh-Ritz on nm analytic modes (unit length, EI,
// rho A): returns lambda^2 = (w / w_ref)^2 of the lowest mode at eta = W / w_ref, and the
// Southwell coefficient of mode 1.
struct RotatingBeam {
  Eigen::VectorXd beta4;
  Eigen::MatrixXd Mm, G;
  explicit RotatingBeam(int nm) : beta4(nm), Mm(nm, nm), G(nm, nm) {
    std::vector<BeamMode> modes;
    for (int k = 0; k < nm; ++k) modes.emplace_back(ClampedFreeBeta(k));
    for (int k = 0; k < nm; ++k) beta4(k) = std::pow(modes[k].beta, 4);
    // Composite Gauss-Legendre, 200 panels x 8 points
    std::vector<double> gp, gw;
    GaussLegendre(8, gp, gw);
    Mm.setZero();
    G.setZero();
    const int panels = 200;
    for (int p = 0; p < panels; ++p)
      for (std::size_t q = 0; q < gp.size(); ++q) {
        const double x = (p + 0.5 * (gp[q] + 1)) / panels, w = 0.5 * gw[q] / panels;
        const double T = 0.5 * (1 - x * x);
        for (int k = 0; k < nm; ++k)
          for (int l = 0; l < nm; ++l) {
            Mm(k, l) += w * modes[k].phi(x) * modes[l].phi(x);
            G(k, l) += w * T * modes[k].dphi(x) * modes[l].dphi(x);
          }
      }
  }
  double Southwell() const { return G(0, 0) / Mm(0, 0); }
  double LowestLambda2(double eta) const {
    // K = diag(beta^4) in the metric of Mm (the modes are orthogonal, Mm ~ identity)
    const Eigen::MatrixXd K = Mm * beta4.asDiagonal();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(0.5 * (K + K.transpose()) + eta * eta * G, Mm,
                                                                 Eigen::EigenvaluesOnly);
    return ges.eigenvalues()(0);
  }
};

TEST(GeometricStiffnessTest, RotatingCantileverFollowsSouthwell) {
  const double L = 1.0, b = 0.04, h = 0.02;
  // Root face centre at the origin: the spin axis z passes through the reference master
  FeMesh mesh = MakeBoxMesh({.origin_m = {0, -b / 2, -h / 2}, .size_m = {L, b, h}, .divisions = {25, 2, 1},
                             .type = ElementType::kHex20});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = kNu, .density_kg_m3 = kRho});
  const FeSystem sys = AssembleFeSystem(mesh);
  const std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2)};
  const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 12});
  const FlexibleBodyModes m = MakeFlexibleBodyModes(
      mesh, sys, cb, ifs, {.export_surface_nodes = false, .surface_triangles = false, .geometric_stiffness = true});
  ASSERT_EQ(m.geometric_stiffness.size(), 6u);
  EXPECT_NO_THROW(ValidateFlexibleBodyModes("blade", m));
  const Eigen::MatrixXd& Gzz = m.geometric_stiffness[2];
  EXPECT_LT((Gzz - Gzz.transpose()).norm(), 1e-12 * Gzz.norm());

  // The first flap mode: the lowest elastic mode, tip motion along z
  const int tip = mesh.NodeSet("XMAX")[0];
  const Eigen::Vector3d tip_shape = cb.shapes.block(3 * tip, 6, 3, 1);
  ASSERT_GT(std::abs(tip_shape.z()), 1e4 * std::abs(tip_shape.y()));

  // Southwell coefficient: the literature value, the Rayleigh quotient of the beam mode, the FE
  const RotatingBeam beam(8);
  EXPECT_NEAR(beam.Southwell(), 1.1933, 5e-5);
  // The 1-D oracle against published exact rotating-beam frequencies lambda = w / w_ref
  // (Wright et al. 1982; Banerjee, J. Sound Vib. 233 (2000) 857-875, Table 1, zero hub radius)
  const std::vector<std::pair<double, double>> published = {{1, 3.6816}, {2, 4.1373}, {5, 6.4495}, {10, 11.2023}};
  for (const auto& [eta, lambda] : published)
    EXPECT_NEAR(std::sqrt(beam.LowestLambda2(eta)) / lambda, 1.0, 1e-4) << "eta " << eta;
  const double K1_fe = Gzz(0, 0);  // M_ff = identity
  std::printf("Southwell K1: FE %.5f, beam %.5f\n", K1_fe, beam.Southwell());
  EXPECT_NEAR(K1_fe / beam.Southwell(), 1.0, 5e-3);

  // Frequencies up to 3 w0: stiffening of the full modal model vs the converged rotating beam
  const double A = b * h, I = b * h * h * h / 12;
  const double w_ref = std::sqrt(kE * I / (kRho * A)) / (L * L);
  const double w0_2 = m.stiffness(0, 0);
  for (double ratio : {0.5, 1.0, 2.0, 3.0}) {
    const double W = ratio * std::sqrt(w0_2);
    const Eigen::MatrixXd Kw = m.stiffness + W * W * Gzz;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Kw + Kw.transpose()), Eigen::EigenvaluesOnly);
    const double w2 = es.eigenvalues()(0);
    const double eta = W / w_ref;
    const double beam_w2 = beam.LowestLambda2(eta) * w_ref * w_ref;
    const double beam_w0_2 = beam.beta4(0) * w_ref * w_ref;
    const double stiffening_fe = (w2 - w0_2) / (W * W), stiffening_beam = (beam_w2 - beam_w0_2) / (W * W);
    std::printf("W = %.1f w0 (eta %.2f): (w^2 - w0^2) / W^2 FE %.5f, beam %.5f, Southwell %.5f\n", ratio, eta,
                stiffening_fe, stiffening_beam, beam.Southwell());
    EXPECT_NEAR(stiffening_fe / stiffening_beam, 1.0, 1e-2) << "W / w0 = " << ratio;
    EXPECT_LE(w2, w0_2 + K1_fe * W * W * (1 + 1e-12));  // one-mode Rayleigh bound
    EXPECT_LE(beam_w2, beam_w0_2 + beam.Southwell() * W * W * (1 + 1e-12));
  }
}

}  // namespace
}  // namespace orrery::flex

// Single-element checks of flex/fe_element.cpp for tet4, tet10, hex8, hex20:
//   - shape functions: Kronecker property at the nodes, partition of unity, derivatives against
//     central differences;
//   - rigid-body modes: exactly 6 zero eigenvalues of K (3 translations, 3 rotations give zero
//     strain energy; no spurious zero-energy modes);
//   - patch test: a constant-strain field u = eps x reproduces eps at every integration point,
//     the stress D eps and the energy 1/2 eps^T D eps V exactly;
//   - consistent mass: u_t^T M u_t = rho V for rigid translations; the scalar mass matrix equals
//     an independent integration (tets: the barycentric formula
//     int L1^a L2^b L3^c L4^d dV = 6 V a! b! c! d! / (a + b + c + d + 3)!; hexes: a 6x6x6 Gauss
//     rule), and CalculiX's stiffness-rule mass has the documented rank deficiency;
//   - quality checks name the element and the value.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <map>
#include <numbers>

#include "flex/fe_element.h"

namespace orrery::flex {
namespace {

constexpr ElementType kTypes[] = {ElementType::kTet4, ElementType::kTet10, ElementType::kHex8, ElementType::kHex20};
constexpr double kE = 210e9, kNu = 0.3, kRho = 7850;

// Reference element under an affine map x = A xi + b (A with det > 0, far from orthogonal).
Eigen::MatrixX3d AffineElement(ElementType t) {
  Eigen::Matrix3d A;
  A << 0.11, 0.02, -0.015, 0.01, 0.09, 0.025, -0.02, 0.015, 0.13;
  const Eigen::Vector3d b(0.3, -0.2, 0.1);
  Eigen::MatrixX3d X = NaturalNodeCoordinates(t) * A.transpose();
  X.rowwise() += b.transpose();
  return X;
}

double Factorial(int n) { return n <= 1 ? 1.0 : n * Factorial(n - 1); }

TEST(FeElementTest, ShapeFunctionsInterpolateAndSumToOne) {
  for (ElementType t : kTypes) {
    const Eigen::MatrixX3d xi = NaturalNodeCoordinates(t);
    const int n = NodeCount(t);
    Eigen::VectorXd N;
    Eigen::MatrixX3d dN;
    for (int b = 0; b < n; ++b) {
      EvalShapeFunctions(t, xi.row(b).transpose(), N, dN);
      for (int a = 0; a < n; ++a) EXPECT_NEAR(N(a), a == b ? 1.0 : 0.0, 1e-14) << CalculixName(t) << " N" << a + 1;
    }
    // Partition of unity and derivatives by central differences at an interior point
    const Eigen::Vector3d p = IsTet(t) ? Eigen::Vector3d(0.21, 0.17, 0.33) : Eigen::Vector3d(0.3, -0.45, 0.7);
    EvalShapeFunctions(t, p, N, dN);
    EXPECT_NEAR(N.sum(), 1.0, 1e-14);
    const double h = 1e-6;
    for (int d = 0; d < 3; ++d) {
      Eigen::VectorXd Np, Nm;
      Eigen::MatrixX3d unused;
      EvalShapeFunctions(t, p + h * Eigen::Vector3d::Unit(d), Np, unused);
      EvalShapeFunctions(t, p - h * Eigen::Vector3d::Unit(d), Nm, unused);
      // Central difference error h^2/6 N''' (N at most cubic here, third derivatives O(1))
      EXPECT_LT(((Np - Nm) / (2 * h) - dN.col(d)).cwiseAbs().maxCoeff(), 1e-8) << CalculixName(t) << " d" << d;
    }
  }
}

TEST(FeElementTest, QuadratureRulesIntegrateVolume) {
  // Weights sum to the reference volume (1/6, 8); the collapsed rule integrates xi^2 eta^2 exactly
  for (ElementType t : kTypes) {
    const double ref = IsTet(t) ? 1.0 / 6 : 8.0;
    double s = 0, m = 0;
    for (double w : StiffnessRule(t).weights) s += w;
    for (double w : MassRule(t).weights) m += w;
    // Gauss-Legendre weights carry a few ulps of rounding (2 / ((1 - x^2) P_n'(x)^2))
    EXPECT_NEAR(s, ref, 64 * std::numeric_limits<double>::epsilon() * ref);
    EXPECT_NEAR(m, ref, 64 * std::numeric_limits<double>::epsilon() * ref);
  }
  // int xi^2 eta^2 over the unit tet = 2! 2! 0! 0! / 7! (degree 4: tet10 mass rule)
  const QuadratureRule& r = MassRule(ElementType::kTet10);
  double v = 0;
  for (std::size_t q = 0; q < r.points.size(); ++q) v += r.weights[q] * std::pow(r.points[q](0) * r.points[q](1), 2);
  EXPECT_NEAR(v, 4.0 / Factorial(7), 1e-17);
}

TEST(FeElementTest, RigidBodyModesHaveZeroStrainEnergy) {
  const Eigen::Matrix<double, 6, 6> D = IsotropicElasticity(kE, kNu);
  for (ElementType t : kTypes) {
    const Eigen::MatrixX3d X = AffineElement(t);
    const Eigen::MatrixXd K = CalcElementStiffness(t, X, D);
    const int n = NodeCount(t);
    // Six rigid motions u = a + w x X
    Eigen::MatrixXd R(3 * n, 6);
    for (int a = 0; a < n; ++a) {
      const Eigen::Vector3d x = X.row(a).transpose();
      for (int k = 0; k < 3; ++k) {
        R.block<3, 1>(3 * a, k) = Eigen::Vector3d::Unit(k);
        R.block<3, 1>(3 * a, 3 + k) = Eigen::Vector3d::Unit(k).cross(x);
      }
    }
    // K R = 0 to rounding: |K R| <= n eps |K| |R|
    const double scale = K.cwiseAbs().maxCoeff() * R.cwiseAbs().maxCoeff() * 3 * n;
    EXPECT_LT((K * R).cwiseAbs().maxCoeff(), 100 * std::numeric_limits<double>::epsilon() * scale) << CalculixName(t);
    // Exactly six zero eigenvalues: the seventh is far from rounding
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(K);
    const Eigen::VectorXd ev = es.eigenvalues();
    const double top = ev.maxCoeff();
    for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(ev(i)), 1e-12 * top) << CalculixName(t) << " eigenvalue " << i;
    EXPECT_GT(ev(6), 1e-4 * top) << CalculixName(t) << ": spurious zero-energy mode";
    EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-15 * top);
  }
}

TEST(FeElementTest, ConstantStrainPatchIsExact) {
  const Eigen::Matrix<double, 6, 6> D = IsotropicElasticity(kE, kNu);
  // A general strain (symmetric) plus a rotation part (no energy) and a translation
  Eigen::Matrix3d grad;
  grad << 1.0e-3, 0.4e-3, -0.2e-3, -0.1e-3, -0.5e-3, 0.3e-3, 0.6e-3, 0.2e-3, 0.8e-3;
  const Eigen::Matrix3d eps = (grad + grad.transpose()) / 2;
  Eigen::Matrix<double, 6, 1> eps_v;
  eps_v << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(0, 1), 2 * eps(1, 2), 2 * eps(2, 0);
  const Eigen::Matrix<double, 6, 1> sigma = D * eps_v;
  for (ElementType t : kTypes) {
    for (bool curved : {false, true}) {
      if (curved && (t == ElementType::kTet4 || t == ElementType::kHex8)) continue;
      Eigen::MatrixX3d X = AffineElement(t);
      // Curved: move midside nodes off the straight edges (isoparametric: still exact pointwise)
      if (curved)
        for (int a = CornerCount(t); a < NodeCount(t); ++a) X.row(a) += 0.004 * Eigen::RowVector3d(std::sin(a), std::cos(a), 0.5);
      const int n = NodeCount(t);
      Eigen::VectorXd u(3 * n);
      for (int a = 0; a < n; ++a) u.segment<3>(3 * a) = grad * X.row(a).transpose() + Eigen::Vector3d(1e-4, 2e-4, -1e-4);
      double volume_stiffness_rule = 0;
      for (const Eigen::Vector3d& p : StiffnessRule(t).points) {
        double det = 0;
        const Eigen::MatrixXd B = CalcStrainDisplacement(t, X, p, &det);
        EXPECT_LT((B * u - eps_v).cwiseAbs().maxCoeff(), 1e-15) << CalculixName(t);
        EXPECT_LT((D * B * u - sigma).cwiseAbs().maxCoeff(), 1e-6 * sigma.cwiseAbs().maxCoeff()) << CalculixName(t);
      }
      for (std::size_t q = 0; q < StiffnessRule(t).points.size(); ++q) {
        double det = 0;
        CalcStrainDisplacement(t, X, StiffnessRule(t).points[q], &det);
        volume_stiffness_rule += det * StiffnessRule(t).weights[q];
      }
      const Eigen::MatrixXd K = CalcElementStiffness(t, X, D);
      const double energy = 0.5 * u.dot(K * u), exact = 0.5 * eps_v.dot(sigma) * volume_stiffness_rule;
      EXPECT_NEAR(energy, exact, 1e-12 * exact) << CalculixName(t) << (curved ? " curved" : "");
      if (!curved) {
        // Affine map: volume = det(A) times the reference volume, and every rule agrees
        EXPECT_NEAR(CalcElementVolume(t, X), volume_stiffness_rule, 1e-14);
      }
    }
  }
}

// Scalar mass (n x n) from a 3n x 3n element mass (the x-x blocks).
Eigen::MatrixXd ScalarMass(const Eigen::MatrixXd& M) {
  const int n = static_cast<int>(M.rows() / 3);
  Eigen::MatrixXd m(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) m(a, b) = M(3 * a, 3 * b);
  return m;
}

// Tet shape functions as polynomials in the barycentric coordinates L1..L4.
using Poly = std::map<std::array<int, 4>, double>;
Poly Mul(const Poly& a, const Poly& b) {
  Poly r;
  for (const auto& [ea, ca] : a)
    for (const auto& [eb, cb] : b) {
      std::array<int, 4> e;
      for (int k = 0; k < 4; ++k) e[k] = ea[k] + eb[k];
      r[e] += ca * cb;
    }
  return r;
}
std::vector<Poly> TetShapePolynomials(ElementType t) {
  auto L = [](int i) { std::array<int, 4> e{}; e[i] = 1; return Poly{{e, 1.0}}; };
  std::vector<Poly> N;
  for (int i = 0; i < 4; ++i) {
    if (t == ElementType::kTet4) {
      N.push_back(L(i));
    } else {
      Poly p = Mul(L(i), L(i));
      for (auto& [e, c] : p) c *= 2;
      std::array<int, 4> lin{};
      lin[i] = 1;
      p[lin] -= 1;
      N.push_back(p);
    }
  }
  if (t == ElementType::kTet10) {
    const int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    for (const auto& e : edges) {
      Poly p = Mul(L(e[0]), L(e[1]));
      for (auto& [k, c] : p) c *= 4;
      N.push_back(p);
    }
  }
  return N;
}

TEST(FeElementTest, ConsistentMassIsExact) {
  for (ElementType t : kTypes) {
    const Eigen::MatrixX3d X = AffineElement(t);
    const int n = NodeCount(t);
    const double V = CalcElementVolume(t, X);
    const Eigen::MatrixXd M = CalcElementMass(t, X, kRho);
    // Translational rigid mass: rho V in each direction, no coupling
    for (int d = 0; d < 3; ++d) {
      Eigen::VectorXd ut = Eigen::VectorXd::Zero(3 * n);
      for (int a = 0; a < n; ++a) ut(3 * a + d) = 1;
      EXPECT_NEAR(ut.dot(M * ut), kRho * V, 1e-13 * kRho * V) << CalculixName(t);
      Eigen::VectorXd uo = Eigen::VectorXd::Zero(3 * n);
      for (int a = 0; a < n; ++a) uo(3 * a + (d + 1) % 3) = 1;
      EXPECT_NEAR(ut.dot(M * uo), 0.0, 1e-15 * kRho * V);
    }
    // Independent integration of N_a N_b
    const Eigen::MatrixXd m = ScalarMass(M);
    Eigen::MatrixXd ref(n, n);
    if (IsTet(t)) {
      const std::vector<Poly> N = TetShapePolynomials(t);
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          double s = 0;
          for (const auto& [e, c] : Mul(N[a], N[b]))
            s += c * 6 * V * Factorial(e[0]) * Factorial(e[1]) * Factorial(e[2]) * Factorial(e[3]) /
                 Factorial(e[0] + e[1] + e[2] + e[3] + 3);
          ref(a, b) = kRho * s;
        }
    } else {
      std::vector<double> p, w;
      GaussLegendre(6, p, w);
      ref.setZero();
      Eigen::VectorXd Nv;
      Eigen::MatrixX3d dN;
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
          for (int k = 0; k < 6; ++k) {
            EvalShapeFunctions(t, Eigen::Vector3d(p[i], p[j], p[k]), Nv, dN);
            ref += kRho * w[i] * w[j] * w[k] * (dN.transpose() * X).determinant() * Nv * Nv.transpose();
          }
    }
    EXPECT_LT((m - ref).cwiseAbs().maxCoeff(), 1e-13 * ref.cwiseAbs().maxCoeff()) << CalculixName(t);
    // Positive definite
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m).eigenvalues().minCoeff(), 0) << CalculixName(t);
  }
}

TEST(FeElementTest, StiffnessRuleMassIsRankDeficientForTets) {
  // CalculiX's choice (mass by the stiffness rule): still exact total mass (sum N = 1), but the
  // scalar tet mass has the rank of the number of points (1 for C3D4, 4 for C3D10)
  for (ElementType t : {ElementType::kTet4, ElementType::kTet10}) {
    const Eigen::MatrixX3d X = AffineElement(t);
    const Eigen::MatrixXd m = ScalarMass(CalcElementMass(t, X, kRho, MassQuadrature::kStiffnessRule));
    EXPECT_NEAR(m.sum(), kRho * CalcElementVolume(t, X), 1e-12 * kRho);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(m);
    lu.setThreshold(1e-10);
    EXPECT_EQ(lu.rank(), static_cast<int>(StiffnessRule(t).points.size())) << CalculixName(t);
  }
}

TEST(FeElementTest, QualityChecksNameElementAndValue) {
  // Inverted: two corners swapped
  Eigen::MatrixX3d X = AffineElement(ElementType::kTet4);
  X.row(1).swap(X.row(2));
  try {
    CheckElementQuality(7, ElementType::kTet4, CalcElementQuality(ElementType::kTet4, X));
    FAIL() << "inverted element accepted";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("element 7 (C3D4): inverted"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Jacobian determinant -"), std::string::npos) << msg;
  }
  // Hex20 with a midside node pulled through the opposite side: negative det J at some point
  X = AffineElement(ElementType::kHex20);
  X.row(8) = X.row(10) + 0.5 * (X.row(10) - X.row(8));
  try {
    CheckElementQuality(12, ElementType::kHex20, CalcElementQuality(ElementType::kHex20, X));
    FAIL() << "inverted hex20 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("element 12 (C3D20): inverted"), std::string::npos) << e.what();
  }
  // Degenerate: a flat tet (node 4 in the plane of 1-2-3)
  X = AffineElement(ElementType::kTet4);
  X.row(3) = (X.row(0) + X.row(1) + X.row(2)) / 3;
  try {
    CheckElementQuality(3, ElementType::kTet4, CalcElementQuality(ElementType::kTet4, X));
    FAIL() << "flat element accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("element 3 (C3D4): degenerate, volume"), std::string::npos) << e.what();
  }
  // Needle: aspect ratio 2000
  X = NaturalNodeCoordinates(ElementType::kHex8);
  X.col(0) *= 2000;
  try {
    CheckElementQuality(5, ElementType::kHex8, CalcElementQuality(ElementType::kHex8, X));
    FAIL() << "needle accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("aspect ratio 2000"), std::string::npos) << e.what();
  }
  // A good element passes
  EXPECT_NO_THROW(CheckElementQuality(1, ElementType::kTet10, CalcElementQuality(ElementType::kTet10, AffineElement(ElementType::kTet10))));
}

}  // namespace
}  // namespace orrery::flex

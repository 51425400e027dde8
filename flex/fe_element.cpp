#include "flex/fe_element.h"

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace orrery::flex {
namespace {

// Natural coordinates of the hex20 nodes (CalculiX shape20h.f); the first 8 are the hex8 corners.
constexpr double kHexNodes[20][3] = {
    {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1},
    {0, -1, -1},  {1, 0, -1},  {0, 1, -1}, {-1, 0, -1}, {0, -1, 1},  {1, 0, 1},  {0, 1, 1}, {-1, 0, 1},
    {-1, -1, 0},  {1, -1, 0},  {1, 1, 0},  {-1, 1, 0}};

// Corner pairs of the tet10 midside nodes 5..10 (0-based corners).
constexpr int kTetEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
// Corner edges of a hex (the hex20 midside nodes 9..20 in this order).
constexpr int kHexEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                  {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

QuadratureRule HexRule(int n) {
  std::vector<double> p, w;
  GaussLegendre(n, p, w);
  QuadratureRule r;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        r.points.emplace_back(p[i], p[j], p[k]);
        r.weights.push_back(w[i] * w[j] * w[k]);
      }
  return r;
}

// Collapsed Gauss product rule on the unit tetrahedron (see the header).
QuadratureRule CollapsedTetRule(int n) {
  std::vector<double> p, w;
  GaussLegendre(n, p, w);
  QuadratureRule r;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double u = (p[i] + 1) / 2, v = (p[j] + 1) / 2, s = (p[k] + 1) / 2;
        r.points.emplace_back(u, v * (1 - u), s * (1 - u) * (1 - v));
        r.weights.push_back(w[i] * w[j] * w[k] / 8 * (1 - u) * (1 - u) * (1 - v));
      }
  return r;
}

QuadratureRule TetRule1() { return {{Eigen::Vector3d::Constant(0.25)}, {1.0 / 6}}; }

// Degree-2 rule: the 4 points a, a, a and permutations of b (Zienkiewicz & Taylor Table 6.3).
QuadratureRule TetRule4() {
  const double a = (5 - std::sqrt(5.0)) / 20, b = (5 + 3 * std::sqrt(5.0)) / 20;
  QuadratureRule r;
  r.points = {{a, a, a}, {b, a, a}, {a, b, a}, {a, a, b}};
  r.weights.assign(4, 1.0 / 24);
  return r;
}

void Fail(int id, ElementType t, const char* what, const std::string& detail) {
  throw std::runtime_error("element " + std::to_string(id) + " (" + CalculixName(t) + "): " + what + ", " + detail);
}

std::string Num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

}  // namespace

void GaussLegendre(int n, std::vector<double>& points, std::vector<double>& weights) {
  if (n < 1) throw std::invalid_argument("GaussLegendre: n must be >= 1");
  points.assign(n, 0.0);
  weights.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    // Newton on P_n from the Chebyshev-like guess; P_n and P_n' by the three-term recurrence
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // Recompute the derivative at the converged root
    double p0 = 1, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = n * (x * p1 - p0) / (x * x - 1);
    points[n - 1 - i] = x;
    weights[n - 1 - i] = 2 / ((1 - x * x) * dp * dp);
  }
}

const QuadratureRule& StiffnessRule(ElementType t) {
  static const QuadratureRule tet1 = TetRule1(), tet4 = TetRule4(), hex2 = HexRule(2), hex3 = HexRule(3);
  switch (t) {
    case ElementType::kTet4: return tet1;
    case ElementType::kTet10: return tet4;
    case ElementType::kHex8: return hex2;
    case ElementType::kHex20: return hex3;
  }
  return hex2;
}

const QuadratureRule& MassRule(ElementType t, MassQuadrature q) {
  static const QuadratureRule tet_c3 = CollapsedTetRule(3), tet_c4 = CollapsedTetRule(4);
  if (q == MassQuadrature::kStiffnessRule) return StiffnessRule(t);
  switch (t) {
    case ElementType::kTet4: return tet_c3;
    case ElementType::kTet10: return tet_c4;
    case ElementType::kHex8:
    case ElementType::kHex20: return StiffnessRule(t);
  }
  return StiffnessRule(t);
}

Eigen::MatrixX3d NaturalNodeCoordinates(ElementType t) {
  const int n = NodeCount(t);
  Eigen::MatrixX3d xi(n, 3);
  if (IsTet(t)) {
    const Eigen::Matrix<double, 4, 3> c{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    xi.topRows(4) = c;
    for (int k = 4; k < n; ++k) xi.row(k) = (c.row(kTetEdges[k - 4][0]) + c.row(kTetEdges[k - 4][1])) / 2;
  } else {
    for (int k = 0; k < n; ++k) xi.row(k) << kHexNodes[k][0], kHexNodes[k][1], kHexNodes[k][2];
  }
  return xi;
}

void EvalShapeFunctions(ElementType t, const Eigen::Vector3d& p, Eigen::VectorXd& N, Eigen::MatrixX3d& dN) {
  const int n = NodeCount(t);
  N.resize(n);
  dN.resize(n, 3);
  const double x = p(0), y = p(1), z = p(2);
  switch (t) {
    case ElementType::kTet4:
      N << 1 - x - y - z, x, y, z;
      dN << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
      return;
    case ElementType::kTet10: {
      // Barycentric L = (1 - x - y - z, x, y, z); corners L(2L - 1), midsides 4 L_i L_j
      const double L[4] = {1 - x - y - z, x, y, z};
      const double dL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      for (int a = 0; a < 4; ++a) {
        N(a) = L[a] * (2 * L[a] - 1);
        for (int d = 0; d < 3; ++d) dN(a, d) = (4 * L[a] - 1) * dL[a][d];
      }
      for (int m = 0; m < 6; ++m) {
        const int i = kTetEdges[m][0], j = kTetEdges[m][1];
        N(4 + m) = 4 * L[i] * L[j];
        for (int d = 0; d < 3; ++d) dN(4 + m, d) = 4 * (dL[i][d] * L[j] + L[i] * dL[j][d]);
      }
      return;
    }
    case ElementType::kHex8:
      for (int a = 0; a < 8; ++a) {
        const double xa = kHexNodes[a][0], ya = kHexNodes[a][1], za = kHexNodes[a][2];
        const double fx = 1 + x * xa, fy = 1 + y * ya, fz = 1 + z * za;
        N(a) = fx * fy * fz / 8;
        dN(a, 0) = xa * fy * fz / 8;
        dN(a, 1) = fx * ya * fz / 8;
        dN(a, 2) = fx * fy * za / 8;
      }
      return;
    case ElementType::kHex20:
      for (int a = 0; a < 20; ++a) {
        const double xa = kHexNodes[a][0], ya = kHexNodes[a][1], za = kHexNodes[a][2];
        const double fx = 1 + x * xa, fy = 1 + y * ya, fz = 1 + z * za;
        if (a < 8) {
          // Serendipity corner: (1/8) fx fy fz (x xa + y ya + z za - 2)
          const double s = x * xa + y * ya + z * za - 2;
          N(a) = fx * fy * fz * s / 8;
          dN(a, 0) = xa * fy * fz * (s + fx) / 8;
          dN(a, 1) = fx * ya * fz * (s + fy) / 8;
          dN(a, 2) = fx * fy * za * (s + fz) / 8;
        } else if (xa == 0) {
          N(a) = (1 - x * x) * fy * fz / 4;
          dN(a, 0) = -2 * x * fy * fz / 4;
          dN(a, 1) = (1 - x * x) * ya * fz / 4;
          dN(a, 2) = (1 - x * x) * fy * za / 4;
        } else if (ya == 0) {
          N(a) = fx * (1 - y * y) * fz / 4;
          dN(a, 0) = xa * (1 - y * y) * fz / 4;
          dN(a, 1) = -2 * y * fx * fz / 4;
          dN(a, 2) = fx * (1 - y * y) * za / 4;
        } else {
          N(a) = fx * fy * (1 - z * z) / 4;
          dN(a, 0) = xa * fy * (1 - z * z) / 4;
          dN(a, 1) = fx * ya * (1 - z * z) / 4;
          dN(a, 2) = -2 * z * fx * fy / 4;
        }
      }
      return;
  }
}

Eigen::Matrix<double, 6, 6> IsotropicElasticity(double E, double nu) {
  if (!(E > 0) || !(nu > -1 && nu < 0.5))
    throw std::invalid_argument("IsotropicElasticity: need E > 0 and -1 < nu < 0.5");
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
  D.topLeftCorner<3, 3>().setConstant(lambda);
  D.topLeftCorner<3, 3>().diagonal().array() += 2 * mu;
  D.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return D;
}

Eigen::MatrixXd CalcStrainDisplacement(ElementType t, const Eigen::MatrixX3d& X, const Eigen::Vector3d& xi,
                                       double* det_J) {
  const int n = NodeCount(t);
  Eigen::VectorXd N;
  Eigen::MatrixX3d dN_dxi;
  EvalShapeFunctions(t, xi, N, dN_dxi);
  // J(i, j) = dx_j / dxi_i; dN/dx = dN/dxi J^-T
  const Eigen::Matrix3d J = dN_dxi.transpose() * X;
  const double det = J.determinant();
  if (det_J) *det_J = det;
  const Eigen::MatrixX3d G = dN_dxi * J.inverse().transpose();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(6, 3 * n);
  for (int a = 0; a < n; ++a) {
    const double gx = G(a, 0), gy = G(a, 1), gz = G(a, 2);
    B(0, 3 * a) = gx;
    B(1, 3 * a + 1) = gy;
    B(2, 3 * a + 2) = gz;
    B(3, 3 * a) = gy, B(3, 3 * a + 1) = gx;
    B(4, 3 * a + 1) = gz, B(4, 3 * a + 2) = gy;
    B(5, 3 * a) = gz, B(5, 3 * a + 2) = gx;
  }
  return B;
}

Eigen::MatrixXd CalcElementStiffness(ElementType t, const Eigen::MatrixX3d& X, const Eigen::Matrix<double, 6, 6>& D) {
  const int n = NodeCount(t);
  const QuadratureRule& rule = StiffnessRule(t);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (std::size_t q = 0; q < rule.points.size(); ++q) {
    double det = 0;
    const Eigen::MatrixXd B = CalcStrainDisplacement(t, X, rule.points[q], &det);
    K.noalias() += B.transpose() * (D * B) * (det * rule.weights[q]);
  }
  // Exact symmetry (rounding in the triple product)
  return (K + K.transpose()) / 2;
}

Eigen::MatrixXd CalcElementMass(ElementType t, const Eigen::MatrixX3d& X, double rho, MassQuadrature qm) {
  const int n = NodeCount(t);
  const QuadratureRule& rule = MassRule(t, qm);
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd N;
  Eigen::MatrixX3d dN;
  for (std::size_t q = 0; q < rule.points.size(); ++q) {
    EvalShapeFunctions(t, rule.points[q], N, dN);
    const double det = (dN.transpose() * X).determinant();
    m.noalias() += N * N.transpose() * (rho * det * rule.weights[q]);
  }
  // Scalar mass into 3x3 identity blocks
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int d = 0; d < 3; ++d) M(3 * a + d, 3 * b + d) = m(a, b);
  return M;
}

double CalcElementVolume(ElementType t, const Eigen::MatrixX3d& X) {
  const QuadratureRule& rule = MassRule(t);
  Eigen::VectorXd N;
  Eigen::MatrixX3d dN;
  double v = 0;
  for (std::size_t q = 0; q < rule.points.size(); ++q) {
    EvalShapeFunctions(t, rule.points[q], N, dN);
    v += (dN.transpose() * X).determinant() * rule.weights[q];
  }
  return v;
}

ElementQuality CalcElementQuality(ElementType t, const Eigen::MatrixX3d& X) {
  ElementQuality q;
  q.volume_m3 = CalcElementVolume(t, X);
  // Jacobian determinants at the stiffness then the mass points
  q.min_det_J = std::numeric_limits<double>::infinity();
  q.max_det_J = -q.min_det_J;
  Eigen::VectorXd N;
  Eigen::MatrixX3d dN;
  int index = 0;
  for (const QuadratureRule* rule : {&StiffnessRule(t), &MassRule(t)})
    for (const Eigen::Vector3d& p : rule->points) {
      EvalShapeFunctions(t, p, N, dN);
      const double det = (dN.transpose() * X).determinant();
      if (det < q.min_det_J) q.min_det_J = det, q.min_det_J_point = index;
      q.max_det_J = std::max(q.max_det_J, det);
      ++index;
    }
  q.jacobian_ratio = q.min_det_J > 0 ? q.max_det_J / q.min_det_J : std::numeric_limits<double>::infinity();
  // Corner edges: aspect ratio and the length scale of the relative volume
  double shortest = std::numeric_limits<double>::infinity(), longest = 0, sum = 0;
  const int ne = IsTet(t) ? 6 : 12;
  for (int k = 0; k < ne; ++k) {
    const int a = IsTet(t) ? kTetEdges[k][0] : kHexEdges[k][0], b = IsTet(t) ? kTetEdges[k][1] : kHexEdges[k][1];
    const double len = (X.row(a) - X.row(b)).norm();
    shortest = std::min(shortest, len);
    longest = std::max(longest, len);
    sum += len;
  }
  const double mean = sum / ne;
  q.aspect_ratio = shortest > 0 ? longest / shortest : std::numeric_limits<double>::infinity();
  q.relative_volume = mean > 0 ? q.volume_m3 / (mean * mean * mean) : 0;
  return q;
}

void CheckElementQuality(int id, ElementType t, const ElementQuality& q, const QualityLimits& limits) {
  // A flat element first (its det J may have either sign by rounding), then an inverted one
  if (!(std::abs(q.relative_volume) >= limits.min_relative_volume))
    Fail(id, t, "degenerate",
         "volume " + Num(q.volume_m3) + " m^3 is " + Num(q.relative_volume) +
             " times its mean edge length cubed (limit " + Num(limits.min_relative_volume) + ")");
  if (!(q.min_det_J > 0))
    Fail(id, t, "inverted",
         "Jacobian determinant " + Num(q.min_det_J) + " at integration point " + std::to_string(q.min_det_J_point + 1) +
             " (volume " + Num(q.volume_m3) + " m^3)");
  if (!(q.aspect_ratio <= limits.max_aspect_ratio))
    Fail(id, t, "degenerate",
         "aspect ratio " + Num(q.aspect_ratio) + " (longest / shortest edge, limit " + Num(limits.max_aspect_ratio) + ")");
  if (!(q.jacobian_ratio <= limits.max_jacobian_ratio))
    Fail(id, t, "distorted",
         "Jacobian ratio " + Num(q.jacobian_ratio) + " (max / min det J, limit " + Num(limits.max_jacobian_ratio) + ")");
}

void QuadFaceShape8(double xi, double eta, double N[8], double dN_dxi[8], double dN_deta[8]) {
  static const double cx[4] = {-1, 1, 1, -1}, ce[4] = {-1, -1, 1, 1};
  // Corners
  for (int i = 0; i < 4; ++i) {
    const double a = xi * cx[i], b = eta * ce[i];
    N[i] = 0.25 * (1 + a) * (1 + b) * (a + b - 1);
    dN_dxi[i] = 0.25 * cx[i] * (1 + b) * (2 * a + b);
    dN_deta[i] = 0.25 * ce[i] * (1 + a) * (a + 2 * b);
  }
  // Midsides at eta = -1 (4), xi = 1 (5), eta = 1 (6), xi = -1 (7)
  N[4] = 0.5 * (1 - xi * xi) * (1 - eta), dN_dxi[4] = -xi * (1 - eta), dN_deta[4] = -0.5 * (1 - xi * xi);
  N[5] = 0.5 * (1 + xi) * (1 - eta * eta), dN_dxi[5] = 0.5 * (1 - eta * eta), dN_deta[5] = -eta * (1 + xi);
  N[6] = 0.5 * (1 - xi * xi) * (1 + eta), dN_dxi[6] = -xi * (1 + eta), dN_deta[6] = 0.5 * (1 - xi * xi);
  N[7] = 0.5 * (1 - xi) * (1 - eta * eta), dN_dxi[7] = -0.5 * (1 - eta * eta), dN_deta[7] = -eta * (1 - xi);
}

}  // namespace orrery::flex

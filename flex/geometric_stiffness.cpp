#include "flex/geometric_stiffness.h"

#include <Eigen/Dense>
#include <array>
#include <stdexcept>
#include <string>

#include "flex/cholmod_factor.h"

namespace orrery::flex {
namespace {

// Symmetric 3 x 3 tensor of a Voigt stress (xx, yy, zz, xy, yz, zx).
Eigen::Matrix3d Tensor(const Eigen::Matrix<double, 6, 1>& s) {
  Eigen::Matrix3d t;
  t << s(0), s(3), s(5), s(3), s(1), s(4), s(5), s(4), s(2);
  return t;
}

// Geometry of one element at the points of the rule: dN/dx (n x 3) and weight * det J.
struct PointGeometry {
  std::vector<Eigen::MatrixX3d> dN_dx;
  std::vector<double> w_det;
};

PointGeometry CalcPointGeometry(ElementType t, const Eigen::MatrixX3d& X) {
  const QuadratureRule& rule = GeometricStiffnessRule(t);
  PointGeometry g;
  g.dN_dx.resize(rule.points.size());
  g.w_det.resize(rule.points.size());
  Eigen::VectorXd N;
  Eigen::MatrixX3d dN_dxi;
  for (std::size_t p = 0; p < rule.points.size(); ++p) {
    EvalShapeFunctions(t, rule.points[p], N, dN_dxi);
    // J(i, j) = dx_j / dxi_i; dN/dx = dN/dxi J^-T (as CalcStrainDisplacement)
    const Eigen::Matrix3d J = dN_dxi.transpose() * X;
    g.dN_dx[p] = dN_dxi * J.inverse().transpose();
    g.w_det[p] = rule.weights[p] * J.determinant();
  }
  return g;
}

// Strain (Voigt, engineering shears) at a point from dN/dx and the element DOFs (node-major).
Eigen::Matrix<double, 6, 1> Strain(const Eigen::MatrixX3d& dN_dx, const Eigen::Ref<const Eigen::VectorXd>& u_e) {
  // grad u (3 x 3): H(i, j) = du_i / dx_j = sum_a u_a,i dN_a/dx_j
  const int n = static_cast<int>(dN_dx.rows());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int a = 0; a < n; ++a) H.noalias() += u_e.segment<3>(3 * a) * dN_dx.row(a);
  Eigen::Matrix<double, 6, 1> e;
  e << H(0, 0), H(1, 1), H(2, 2), H(0, 1) + H(1, 0), H(1, 2) + H(2, 1), H(2, 0) + H(0, 2);
  return e;
}

// H = sum_p w_p dN/dx sigma_p dN/dx^T (n x n), the scalar kernel of K_sigma = H (x) I3.
void AccumulateKernel(const PointGeometry& g, int p, const Eigen::Matrix<double, 6, 1>& stress, Eigen::MatrixXd& H) {
  const Eigen::MatrixX3d dS = g.dN_dx[p] * Tensor(stress);
  H.noalias() += (g.w_det[p] * dS) * g.dN_dx[p].transpose();
}

// Triplets of H (x) I3 at the element's global DOFs.
void ScatterKernel(const FeElement& e, const Eigen::MatrixXd& H, std::vector<Eigen::Triplet<double>>& t) {
  const int n = NodeCount(e.type);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < 3; ++i) t.emplace_back(3 * e.nodes[a] + i, 3 * e.nodes[b] + i, H(a, b));
}

std::vector<Eigen::Matrix<double, 6, 6>> Elasticities(const FeMesh& mesh) {
  std::vector<Eigen::Matrix<double, 6, 6>> D(mesh.materials().size());
  for (std::size_t m = 0; m < D.size(); ++m)
    D[m] = IsotropicElasticity(mesh.materials()[m].youngs_modulus_pa, mesh.materials()[m].poissons_ratio);
  return D;
}

int ElementMaterial(const FeMesh& mesh, int ei) {
  const int mat = mesh.element_material()[ei];
  if (mat < 0)
    throw std::runtime_error("geometric stiffness: element " + std::to_string(mesh.elements()[ei].id) +
                             " has no material");
  return mat;
}

}  // namespace

const QuadratureRule& GeometricStiffnessRule(ElementType t) { return MassRule(t, MassQuadrature::kExact); }

Eigen::MatrixXd CalcElementGeometricStiffness(ElementType t, const Eigen::MatrixX3d& X,
                                              const Eigen::Ref<const Eigen::Matrix<double, 6, Eigen::Dynamic>>& stress) {
  const int n = NodeCount(t);
  const int np = static_cast<int>(GeometricStiffnessRule(t).points.size());
  if (stress.cols() != 1 && stress.cols() != np)
    throw std::invalid_argument("CalcElementGeometricStiffness: " + std::to_string(stress.cols()) +
                                " stress columns, need 1 or " + std::to_string(np));
  const PointGeometry g = CalcPointGeometry(t, X);
  // Scalar kernel, then H (x) I3
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  for (int p = 0; p < np; ++p) AccumulateKernel(g, p, stress.col(stress.cols() == 1 ? 0 : p), H);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < 3; ++i) K(3 * a + i, 3 * b + i) = 0.5 * (H(a, b) + H(b, a));
  return K;
}

Eigen::SparseMatrix<double> AssembleUniformGeometricStiffness(const FeMesh& mesh,
                                                              const Eigen::Matrix<double, 6, 1>& stress) {
  std::vector<Eigen::Triplet<double>> t;
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    const int n = NodeCount(e.type);
    const PointGeometry g = CalcPointGeometry(e.type, mesh.ElementPositions(ei));
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t p = 0; p < g.w_det.size(); ++p) AccumulateKernel(g, static_cast<int>(p), stress, H);
    ScatterKernel(e, 0.5 * (H + H.transpose()), t);
  }
  Eigen::SparseMatrix<double> K(3 * mesh.num_nodes(), 3 * mesh.num_nodes());
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

Eigen::SparseMatrix<double> AssembleGeometricStiffness(const FeMesh& mesh, const Eigen::Ref<const Eigen::VectorXd>& u) {
  if (u.size() != 3 * mesh.num_nodes())
    throw std::invalid_argument("AssembleGeometricStiffness: displacement size " + std::to_string(u.size()) +
                                ", mesh DOFs " + std::to_string(3 * mesh.num_nodes()));
  const std::vector<Eigen::Matrix<double, 6, 6>> D = Elasticities(mesh);
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd ue;
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    const int n = NodeCount(e.type);
    const int mat = ElementMaterial(mesh, ei);
    ue.resize(3 * n);
    for (int a = 0; a < n; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * e.nodes[a]);
    const PointGeometry g = CalcPointGeometry(e.type, mesh.ElementPositions(ei));
    // sigma = D eps(u) at each point, into the kernel
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t p = 0; p < g.w_det.size(); ++p)
      AccumulateKernel(g, static_cast<int>(p), D[mat] * Strain(g.dN_dx[p], ue), H);
    ScatterKernel(e, 0.5 * (H + H.transpose()), t);
  }
  Eigen::SparseMatrix<double> K(3 * mesh.num_nodes(), 3 * mesh.num_nodes());
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

std::vector<Eigen::MatrixXd> ProjectGeometricStiffness(const FeMesh& mesh, const Eigen::Ref<const Eigen::MatrixXd>& U,
                                                       const Eigen::Ref<const Eigen::MatrixXd>& Phi) {
  const int ndof = 3 * mesh.num_nodes();
  if (U.rows() != ndof || Phi.rows() != ndof)
    throw std::invalid_argument("ProjectGeometricStiffness: fields have " + std::to_string(U.rows()) + " and " +
                                std::to_string(Phi.rows()) + " rows, mesh DOFs " + std::to_string(ndof));
  const int ncase = static_cast<int>(U.cols()), nf = static_cast<int>(Phi.cols());
  const std::vector<Eigen::Matrix<double, 6, 6>> D = Elasticities(mesh);
  std::vector<Eigen::MatrixXd> G(ncase, Eigen::MatrixXd::Zero(nf, nf));
  Eigen::MatrixXd Ue, H, HP;
  std::array<Eigen::MatrixXd, 3> Pe;  // element mode shapes per component (n x nf)
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    const int n = NodeCount(e.type);
    const int mat = ElementMaterial(mesh, ei);
    // Gather the element's load-case displacements and mode shapes
    Ue.resize(3 * n, ncase);
    for (int i = 0; i < 3; ++i) Pe[i].resize(n, nf);
    for (int a = 0; a < n; ++a) {
      Ue.middleRows(3 * a, 3) = U.middleRows(3 * e.nodes[a], 3);
      for (int i = 0; i < 3; ++i) Pe[i].row(a) = Phi.row(3 * e.nodes[a] + i);
    }
    const PointGeometry g = CalcPointGeometry(e.type, mesh.ElementPositions(ei));
    for (int c = 0; c < ncase; ++c) {
      // Kernel of load case c, then G_c += sum_i Pe_i^T H Pe_i
      H.setZero(n, n);
      for (std::size_t p = 0; p < g.w_det.size(); ++p)
        AccumulateKernel(g, static_cast<int>(p), D[mat] * Strain(g.dN_dx[p], Ue.col(c)), H);
      for (int i = 0; i < 3; ++i) {
        HP.noalias() = H * Pe[i];
        G[c].noalias() += Pe[i].transpose() * HP;
      }
    }
  }
  for (Eigen::MatrixXd& Gc : G) Gc = 0.5 * (Gc + Gc.transpose()).eval();
  return G;
}

Eigen::MatrixXd InertialLoadCases(const FeMesh& mesh, const FeSystem& system, const Eigen::Vector3d& p_origin_m) {
  const int nn = mesh.num_nodes();
  if (system.M.rows() != 3 * nn) throw std::invalid_argument("InertialLoadCases: mass matrix size differs from the mesh");
  // Nodal values of the unit body forces per density v_c (header)
  constexpr int kPairs[3][2] = {{0, 1}, {1, 2}, {2, 0}};
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(3 * nn, 6);
  for (int a = 0; a < nn; ++a) {
    const Eigen::Vector3d x = mesh.positions()[a] - p_origin_m;
    for (int i = 0; i < 3; ++i) {
      V.block<3, 1>(3 * a, i) = x;
      V(3 * a + i, i) = 0;
    }
    for (int k = 0; k < 3; ++k) {
      const int i = kPairs[k][0], j = kPairs[k][1];
      V(3 * a + i, 3 + k) = -x(j);
      V(3 * a + j, 3 + k) = -x(i);
    }
  }
  // Consistent loads F_c = M v_c
  return system.M * V;
}

Eigen::MatrixXd SolveStaticsHeldAtInterface(const FeMesh& mesh, const FeSystem& system,
                                            std::span<const FeInterface> interfaces, int reference,
                                            const Eigen::Ref<const Eigen::MatrixXd>& F) {
  const int nif = static_cast<int>(interfaces.size());
  if (reference < 0 || reference >= nif)
    throw std::invalid_argument("SolveStaticsHeldAtInterface: reference interface " + std::to_string(reference) +
                                " out of range [0, " + std::to_string(nif) + ")");
  if (F.rows() != 3 * mesh.num_nodes() || system.K.rows() != F.rows())
    throw std::invalid_argument("SolveStaticsHeldAtInterface: load rows " + std::to_string(F.rows()) +
                                ", mesh DOFs " + std::to_string(3 * mesh.num_nodes()));
  // u = T q with the reference master's 6 coordinates removed: T' = T S
  const InterfaceTransform it = MakeInterfaceTransform(mesh, interfaces);
  const int nq = static_cast<int>(it.T.cols());
  std::vector<Eigen::Triplet<double>> sel;
  for (int c = 0, k = 0; c < nq; ++c)
    if (c < 6 * reference || c >= 6 * reference + 6) sel.emplace_back(c, k++, 1.0);
  Eigen::SparseMatrix<double> S(nq, nq - 6);
  S.setFromTriplets(sel.begin(), sel.end());
  const Eigen::SparseMatrix<double> T = it.T * S;
  const Eigen::SparseMatrix<double> Tt = T.transpose();
  const Eigen::SparseMatrix<double> Kr = Tt * system.K * T;
  // K' x = T'^T F by sparse Cholesky; u = T' x
  CholmodCholesky chol;
  if (!chol.factorize(Kr))
    throw std::runtime_error("SolveStaticsHeldAtInterface: stiffness with interface '" + interfaces[reference].name +
                             "' held is not positive definite: the interface does not hold the body");
  const Eigen::MatrixXd B = Tt * F;
  Eigen::MatrixXd X(B.rows(), B.cols());
  if (B.cols() > 0) chol.solve(B.data(), X.data(), static_cast<int>(B.cols()));  // all columns at once
  return T * X;
}

}  // namespace orrery::flex

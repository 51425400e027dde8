#include "flex/fe_interface.h"

#include <Eigen/Dense>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace orrery::flex {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

}  // namespace

FeInterface MakeInterface(const FeMesh& mesh, std::string_view node_set, InterfaceKind kind) {
  FeInterface f;
  f.name = UpperName(node_set);
  f.kind = kind;
  f.nodes = mesh.NodeSet(node_set);
  return f;
}

Eigen::Vector3d InterfaceMasterPosition(const FeMesh& mesh, const FeInterface& interface) {
  if (interface.nodes.empty()) throw std::invalid_argument("interface '" + interface.name + "' has no nodes");
  if (interface.master_position_m) return *interface.master_position_m;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int n : interface.nodes) c += mesh.positions().at(n);
  return c / static_cast<double>(interface.nodes.size());
}

Eigen::MatrixXd RigidKinematicMatrix(const FeMesh& mesh, std::span<const int> nodes, const Eigen::Vector3d& p_master_m) {
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(nodes.size()), 6);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    // u_s = u_m + theta x r = u_m - skew(r) theta
    G.block<3, 3>(3 * k, 0).setIdentity();
    G.block<3, 3>(3 * k, 3) = -Skew(mesh.positions().at(nodes[k]) - p_master_m);
  }
  return G;
}

Eigen::MatrixXd Rbe3AveragingMatrix(const FeMesh& mesh, const FeInterface& interface) {
  const int ns = static_cast<int>(interface.nodes.size());
  if (!interface.weights.empty() && static_cast<int>(interface.weights.size()) != ns)
    throw std::invalid_argument("interface '" + interface.name + "': " + std::to_string(interface.weights.size()) +
                                " weights for " + std::to_string(ns) + " nodes");
  const Eigen::MatrixXd G = RigidKinematicMatrix(mesh, interface.nodes, InterfaceMasterPosition(mesh, interface));
  // G^T W, W = diag(w_s I3)
  Eigen::MatrixXd GtW = G.transpose();
  for (int k = 0; k < ns; ++k) {
    const double w = interface.weights.empty() ? 1.0 : interface.weights[k];
    if (!(w > 0)) throw std::invalid_argument("interface '" + interface.name + "': weights must be positive");
    GtW.middleCols(3 * k, 3) *= w;
  }
  // R = (G^T W G)^-1 G^T W; G^T W G is singular for collinear slaves (rotation about the line)
  const Eigen::Matrix<double, 6, 6> A = GtW * G;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(A);
  if (!(eig.eigenvalues()(0) > 1e-10 * eig.eigenvalues()(5)))
    throw std::invalid_argument("interface '" + interface.name +
                                "': slave nodes do not determine a rigid motion (need 3 non-collinear nodes)");
  return A.ldlt().solve(GtW);
}

InterfaceTransform MakeInterfaceTransform(const FeMesh& mesh, std::span<const FeInterface> interfaces) {
  const int n = 3 * mesh.num_nodes();
  const int ni = static_cast<int>(interfaces.size());
  InterfaceTransform t;
  t.num_boundary = 6 * ni;
  // Owner interface of each node (-1: none); interfaces may not share nodes
  std::vector<int> owner(mesh.num_nodes(), -1);
  for (int j = 0; j < ni; ++j)
    for (int node : interfaces[j].nodes) {
      if (node < 0 || node >= mesh.num_nodes())
        throw std::invalid_argument("interface '" + interfaces[j].name + "': node index out of range");
      if (owner[node] >= 0 && owner[node] != j)
        throw std::invalid_argument("interfaces '" + interfaces[owner[node]].name + "' and '" + interfaces[j].name +
                                    "' share node " + std::to_string(mesh.node_ids()[node]));
      owner[node] = j;
    }
  // Interior coordinates: DOFs of nodes outside any interface, then per RBE3 the independent slave
  // DOFs; dependent[dof] marks DOFs expressed through the masters
  std::vector<int> column(n, -1);
  auto add_interior = [&](int dof) {
    column[dof] = t.num_boundary + static_cast<int>(t.interior_dofs.size());
    t.interior_dofs.push_back(dof);
  };
  for (int node = 0; node < mesh.num_nodes(); ++node)
    if (owner[node] < 0)
      for (int c = 0; c < 3; ++c) add_interior(3 * node + c);

  std::vector<Eigen::Triplet<double>> trip;
  for (int dof = 0; dof < n; ++dof)
    if (column[dof] >= 0) trip.emplace_back(dof, column[dof], 1.0);
  for (int j = 0; j < ni; ++j) {
    const FeInterface& f = interfaces[j];
    const Eigen::Vector3d p_m = InterfaceMasterPosition(mesh, f);
    t.master_positions.push_back(p_m);
    const int ns = static_cast<int>(f.nodes.size());
    const int mcol = 6 * j;
    if (f.kind == InterfaceKind::kRbe2) {
      // u_s = G u_m
      const Eigen::MatrixXd G = RigidKinematicMatrix(mesh, f.nodes, p_m);
      for (int k = 0; k < ns; ++k)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 6; ++c)
            if (G(3 * k + r, c) != 0) trip.emplace_back(3 * f.nodes[k] + r, mcol + c, G(3 * k + r, c));
      continue;
    }
    // RBE3: 6 dependent slave DOFs d chosen by column-pivoted QR of R, the others independent
    const Eigen::MatrixXd R = Rbe3AveragingMatrix(mesh, f);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(R);
    std::vector<bool> is_dependent(3 * ns, false);
    std::vector<int> dep;
    for (int k = 0; k < 6; ++k) {
      const int local = qr.colsPermutation().indices()(k);
      is_dependent[local] = true;
      dep.push_back(local);
    }
    std::vector<int> indep;
    for (int local = 0; local < 3 * ns; ++local)
      if (!is_dependent[local]) {
        indep.push_back(local);
        const int dof = 3 * f.nodes[local / 3] + local % 3;
        add_interior(dof);
        trip.emplace_back(dof, column[dof], 1.0);
      }
    // u_d = R_d^-1 u_m - R_d^-1 R_z z
    Eigen::Matrix<double, 6, 6> Rd;
    for (int k = 0; k < 6; ++k) Rd.col(k) = R.col(dep[k]);
    Eigen::PartialPivLU<Eigen::Matrix<double, 6, 6>> lu(Rd);
    const Eigen::Matrix<double, 6, 6> Rd_inv = lu.inverse();
    Eigen::MatrixXd Rz(6, indep.size());
    for (std::size_t k = 0; k < indep.size(); ++k) Rz.col(k) = R.col(indep[k]);
    const Eigen::MatrixXd C = -Rd_inv * Rz;
    for (int k = 0; k < 6; ++k) {
      const int dof = 3 * f.nodes[dep[k] / 3] + dep[k] % 3;
      for (int c = 0; c < 6; ++c)
        if (Rd_inv(k, c) != 0) trip.emplace_back(dof, mcol + c, Rd_inv(k, c));
      for (std::size_t z = 0; z < indep.size(); ++z) {
        const int zdof = 3 * f.nodes[indep[z] / 3] + indep[z] % 3;
        if (C(k, z) != 0) trip.emplace_back(dof, column[zdof], C(k, z));
      }
    }
  }
  t.T.resize(n, t.num_boundary + static_cast<int>(t.interior_dofs.size()));
  t.T.setFromTriplets(trip.begin(), trip.end());
  return t;
}

Eigen::SparseMatrix<double> InterfaceCoordinatesMatrix(const InterfaceTransform& t,
                                                       const Eigen::SparseMatrix<double>& A,
                                                       bool upper_only) {
  using Sparse = Eigen::SparseMatrix<double>;
  const Sparse& T = t.T;
  if (A.rows() != T.rows() || A.cols() != T.rows())
    throw std::invalid_argument("InterfaceCoordinatesMatrix: matrix of size " +
                                std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                                " for " + std::to_string(T.rows()) + " FE DOFs");
  // Column b of T^T A T is the sum over T's entries T(j, b) of T(j, b) T^T A(:, j); T^T A(:, j)
  // gathers A(i, j) into the coordinates of FE DOF i, row i of T (Gustavson's column-by-column
  // product with a dense accumulator). Most rows of T are one coordinate with the factor 1 (the
  // interior DOFs): `single` holds that coordinate (-1 for the other rows), read instead of the
  // row; 1 * w is w, so the sums are the same to the bit.
  using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  RowMajor rows_of_T = T;
  rows_of_T.makeCompressed();
  const Eigen::Index nq = T.cols();
  std::vector<int> single(static_cast<std::size_t>(T.rows()), -1);
  const int* Tp = rows_of_T.outerIndexPtr();
  for (Eigen::Index i = 0; i < rows_of_T.outerSize(); ++i)
    if (Tp[i + 1] - Tp[i] == 1 && rows_of_T.valuePtr()[Tp[i]] == 1.0)
      single[static_cast<std::size_t>(i)] = rows_of_T.innerIndexPtr()[Tp[i]];
  std::vector<double> sum(nq, 0.0);
  std::vector<char> touched(nq, 0);
  std::vector<int> hit;
  hit.reserve(static_cast<std::size_t>(std::min<Eigen::Index>(nq, 4096)));
  const int* Ap = A.outerIndexPtr();
  const int* An = A.innerNonZeroPtr();  // null when A is compressed
  const int* Ai = A.innerIndexPtr();
  const double* Ax = A.valuePtr();
  Sparse B(nq, nq);
  B.reserve((upper_only ? A.nonZeros() / 2 + A.rows() : A.nonZeros()) + 2 * T.nonZeros());
  for (Eigen::Index b = 0; b < nq; ++b) {
    B.startVec(b);
    hit.clear();
    auto add = [&](int a, double value) {
      if (upper_only && a > b) return;
      if (!touched[a]) {
        touched[a] = 1;
        sum[a] = 0.0;
        hit.push_back(a);
      }
      sum[a] += value;
    };
    for (Sparse::InnerIterator tj(T, b); tj; ++tj) {
      const int j = static_cast<int>(tj.row());
      const int end = An ? Ap[j] + An[j] : Ap[j + 1];
      for (int k = Ap[j]; k < end; ++k) {
        const double w = Ax[k] * tj.value();
        const int a = single[static_cast<std::size_t>(Ai[k])];
        if (a >= 0) {
          add(a, w);
          continue;
        }
        for (RowMajor::InnerIterator ti(rows_of_T, Ai[k]); ti; ++ti)
          add(static_cast<int>(ti.col()), ti.value() * w);
      }
    }
    if (!std::is_sorted(hit.begin(), hit.end())) std::sort(hit.begin(), hit.end());
    for (int a : hit) {
      B.insertBack(a, b) = sum[a];
      touched[a] = 0;
    }
  }
  B.finalize();
  return B;
}

}  // namespace orrery::flex

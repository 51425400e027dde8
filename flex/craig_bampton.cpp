#include "flex/craig_bampton.h"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <stdexcept>
#include <string>

#include "flex/cholmod_factor.h"
#include "flex/fe_modes.h"

namespace orrery::flex {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

Eigen::MatrixXd Symmetrized(const Eigen::MatrixXd& A) { return 0.5 * (A + A.transpose()); }

}  // namespace

CraigBamptonModel ReduceCraigBampton(const FeMesh& mesh, const FeSystem& system,
                                     std::span<const FeInterface> interfaces, const CraigBamptonOptions& options) {
  const int nif = static_cast<int>(interfaces.size());
  if (nif < 1) throw std::invalid_argument("Craig-Bampton reduction needs at least one interface");
  const int ref = options.reference_interface;
  if (ref < 0 || ref >= nif)
    throw std::invalid_argument("reference interface " + std::to_string(ref) + " out of range [0, " +
                                std::to_string(nif) + ")");
  if (options.num_modes < 0) throw std::invalid_argument("number of fixed-interface modes must be >= 0");

  // Interface coordinates q = [u_b | u_i]: K_q = T^T K T, M_q = T^T M T
  const InterfaceTransform it = MakeInterfaceTransform(mesh, interfaces);
  const Eigen::SparseMatrix<double> Tt = it.T.transpose();
  const Eigen::SparseMatrix<double> Kq = Tt * system.K * it.T;
  const Eigen::SparseMatrix<double> Mq = Tt * system.M * it.T;
  const int nb = it.num_boundary;
  const int nq = static_cast<int>(Kq.rows());
  const int nI = nq - nb;
  if (options.num_modes >= nI)
    throw std::invalid_argument("number of fixed-interface modes must be below the " + std::to_string(nI) +
                                " interior DOFs, got " + std::to_string(options.num_modes));
  const Eigen::SparseMatrix<double> Kii = Kq.block(nb, nb, nI, nI);
  const Eigen::SparseMatrix<double> Mii = Mq.block(nb, nb, nI, nI);
  const Eigen::MatrixXd Kib = Eigen::MatrixXd(Kq.block(nb, 0, nI, nb));

  // Static constraint modes Psi = -K_ii^-1 K_ib: one supernodal Cholesky factorization (CHOLMOD),
  // nb solves
  CholmodCholesky chol;
  if (!chol.factorize(Kii))
    throw std::runtime_error("interior stiffness K_ii is not positive definite: the interfaces do not hold the body");
  auto solve = [&](const Eigen::MatrixXd& B) {
    Eigen::MatrixXd X(B.rows(), B.cols());
    for (Eigen::Index c = 0; c < B.cols(); ++c) chol.solve(B.col(c).data(), X.col(c).data());
    return X;
  };
  const Eigen::MatrixXd Psi = -solve(Kib);

  // Fixed-interface normal modes of (K_ii, M_ii), by count and optionally by cutoff
  CraigBamptonModel r;
  Eigen::MatrixXd Phi(nI, 0);
  if (options.num_modes > 0) {
    const FeModes modes = SolveLowestModes(Kii, Mii, {.num_modes = options.num_modes, .tolerance = options.tolerance});
    int keep = options.num_modes;
    if (options.cutoff_hz > 0) {
      keep = 0;
      while (keep < options.num_modes && modes.frequencies_hz[keep] <= options.cutoff_hz) ++keep;
      r.cutoff_reached = keep < options.num_modes;
    }
    Phi = modes.shapes.leftCols(keep);
    r.fixed_interface_eigenvalues = modes.eigenvalues.head(keep);
  }
  if (options.inertial_load_modes) {
    // Unit inertial body-force fields g (per unit density, linear in x - p_r), loads T^T M g.
    const Eigen::Vector3d p_r = it.master_positions[options.reference_interface];
    const int nn = mesh.num_nodes();
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3 * nn, 12);
    for (int i = 0; i < nn; ++i) {
      const Eigen::Vector3d x = mesh.positions()[i] - p_r;
      for (int a = 0; a < 3; ++a) {
        const Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
        G.block<3, 1>(3 * i, a) = e;                    // translational acceleration
        G.block<3, 1>(3 * i, 3 + a) = e.cross(x);       // angular acceleration
        G.block<3, 1>(3 * i, 6 + a) = x - e * x(a);     // centrifugal (a, a)
        const int b = (a + 1) % 3;                      // centrifugal (a, b): xy, yz, zx
        G.block<3, 1>(3 * i, 9 + a) = -(e * x(b) + Eigen::Vector3d::Unit(b) * x(a));
      }
    }
    const Eigen::MatrixXd Fq = Tt * (system.M * G);
    Eigen::MatrixXd X = solve(Fq.bottomRows(nI));
    // Remove what the normal modes span (M-orthogonal projection), then an M-orthonormal basis of
    // the rest, dropping directions below 1e-8 of the largest.
    if (Phi.cols() > 0) X -= Phi * (Phi.transpose() * (Mii * X));
    const Eigen::MatrixXd MX = Symmetrized(X.transpose() * (Mii * X));
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(MX);
    const double top = es.eigenvalues().maxCoeff();
    std::vector<int> keep;
    for (int k = 0; k < 12; ++k)
      if (top > 0 && es.eigenvalues()(k) > 1e-8 * top) keep.push_back(k);
    const int na = static_cast<int>(keep.size());
    Eigen::MatrixXd Xo(nI, na);
    for (int k = 0; k < na; ++k)
      Xo.col(k) = X * es.eigenvectors().col(keep[k]) / std::sqrt(es.eigenvalues()(keep[k]));
    Eigen::MatrixXd aug(nI, Phi.cols() + na);
    aug << Phi, Xo;
    Phi = aug;
    r.num_load_modes = na;
  }
  const int nm = static_cast<int>(Phi.cols());
  const int ncb = nb + nm;

  // Basis T_cb = [[I, 0], [Psi, Phi]] and the reduced matrices
  Eigen::MatrixXd Tcb = Eigen::MatrixXd::Zero(nq, ncb);
  Tcb.topLeftCorner(nb, nb).setIdentity();
  Tcb.bottomLeftCorner(nI, nb) = Psi;
  Tcb.bottomRightCorner(nI, nm) = Phi;
  const Eigen::MatrixXd Kcb = Symmetrized(Tcb.transpose() * (Kq * Tcb));
  const Eigen::MatrixXd Mcb = Symmetrized(Tcb.transpose() * (Mq * Tcb));

  // Rigid motions of the body about the reference master, in CB coordinates
  const Eigen::Vector3d p_r = it.master_positions[ref];
  Eigen::MatrixXd Rig = Eigen::MatrixXd::Zero(ncb, 6);
  for (int j = 0; j < nif; ++j) {
    Rig.block<3, 3>(6 * j, 0).setIdentity();
    Rig.block<3, 3>(6 * j, 3) = -Skew(it.master_positions[j] - p_r);
    Rig.block<3, 3>(6 * j + 3, 3).setIdentity();
  }
  // Elastic columns: every CB coordinate except the reference interface's 6 (body clamped there)
  const int ne = ncb - 6;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(ncb, ne);
  for (int c = 0, k = 0; c < ncb; ++c)
    if (c < 6 * ref || c >= 6 * ref + 6) E(c, k++) = 1;

  // Re-orthogonalize the elastic block: (E^T K E) v = w^2 (E^T M E) v, V^T M V = I
  Eigen::MatrixXd V(ne, 0);
  Eigen::VectorXd w2(ne);
  if (ne > 0) {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(Symmetrized(E.transpose() * Kcb * E),
                                                                   Symmetrized(E.transpose() * Mcb * E));
    if (ges.info() != Eigen::Success) throw std::runtime_error("reduced eigenproblem failed");
    V = ges.eigenvectors();
    w2 = ges.eigenvalues();
  }
  Eigen::MatrixXd F(ncb, 6 + ne);
  F.leftCols(6) = Rig;
  F.rightCols(ne) = E * V;

  // Final reduced matrices and shapes
  r.num_elastic = ne;
  r.reference_interface = ref;
  r.master_positions_m = it.master_positions;
  r.K = Symmetrized(F.transpose() * Kcb * F);
  r.M = Symmetrized(F.transpose() * Mcb * F);
  r.eigenvalues = Eigen::VectorXd::Zero(6 + ne);
  r.eigenvalues.tail(ne) = w2;
  r.frequencies_hz.resize(6 + ne);
  for (int k = 0; k < 6 + ne; ++k) r.frequencies_hz[k] = EigenvalueToHz(r.eigenvalues(k));
  const Eigen::MatrixXd qF = Tcb * F;
  r.master_shapes = qF.topRows(nb);
  r.shapes = it.T * qF;

  // Mass properties from the rigid block [[m I, -skew(S)], [skew(S), I_Ro]], S = m p_RoCm
  const Eigen::Matrix<double, 6, 6> Mrr = r.M.topLeftCorner(6, 6);
  r.mass_kg = Mrr.topLeftCorner<3, 3>().trace() / 3;
  const Eigen::Matrix3d Mvt = Mrr.block<3, 3>(0, 3);
  const Eigen::Vector3d S(-Mvt(2, 1), -Mvt(0, 2), -Mvt(1, 0));
  r.p_RoCm_m = S / r.mass_kg;
  r.I_Ro_kgm2 = Mrr.bottomRightCorner<3, 3>();
  return r;
}

}  // namespace orrery::flex

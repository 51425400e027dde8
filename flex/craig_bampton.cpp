#include "flex/craig_bampton.h"

#include <Eigen/Dense>
#include <stdexcept>
#include <string>

#include "flex/fe_modes.h"
#include "flex/geometric_stiffness.h"
#include "flex/sparse_ldlt_shift_invert.h"

namespace orrery::flex {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

Eigen::MatrixXd Symmetrized(const Eigen::MatrixXd& A) { return 0.5 * (A + A.transpose()); }

// The interface coordinates' matrices and K_ii's factorization (sigma = 0), shared by the stages.
struct InterfaceProblem {
  InterfaceTransform it;
  Eigen::SparseMatrix<double> Tt, Kq, Mq;  // T^T, T^T K T, T^T M T (upper triangles)
  Eigen::SparseMatrix<double> Mii;         // interior block of M_q, upper triangle
  ShiftedFactor Kii;                       // Cholesky of the interior block of K_q
  int nb = 0, nI = 0;
  // X = K_ii^-1 B (nI x k), one solve for all columns.
  Eigen::MatrixXd Solve(const Eigen::MatrixXd& B) const {
    Eigen::MatrixXd X(B.rows(), B.cols());
    if (B.cols() > 0) Kii.Solve(B.data(), X.data(), static_cast<int>(B.cols()));
    return X;
  }
};

// Interior map of the coordinates q = [u_b | u_i] (u_b's entries -1).
std::vector<int> InteriorMap(int nq, int nb) {
  std::vector<int> map(nq, -1);
  for (int c = nb; c < nq; ++c) map[c] = c - nb;
  return map;
}

void FactorizeInterior(const FeMesh& mesh, const FeSystem& system, std::span<const FeInterface> interfaces,
                       int num_modes, InterfaceProblem& p) {
  // Interface coordinates q = [u_b | u_i]: K_q = T^T K T, M_q = T^T M T
  p.it = MakeInterfaceTransform(mesh, interfaces);
  p.Tt = p.it.T.transpose();
  p.Kq = InterfaceCoordinatesMatrix(p.it, system.K, /*upper_only=*/true);
  p.Mq = InterfaceCoordinatesMatrix(p.it, system.M, /*upper_only=*/true);
  p.nb = p.it.num_boundary;
  const int nq = static_cast<int>(p.Kq.rows());
  p.nI = nq - p.nb;
  if (num_modes >= p.nI)
    throw std::invalid_argument("number of fixed-interface modes must be below the " + std::to_string(p.nI) +
                                " interior DOFs, got " + std::to_string(num_modes));
  // One supernodal Cholesky of K_ii (CHOLMOD) for the constraint modes, the normal modes
  // (shift-invert at sigma = 0: K_ii is positive definite) and the held statics
  const std::vector<int> map = InteriorMap(nq, p.nb);
  p.Mii = RestrictUpper(p.Mq, map);
  if (!p.Kii.FactorizeIfPositiveDefinite(RestrictUpper(p.Kq, map), 0.0))
    throw std::runtime_error("interior stiffness K_ii is not positive definite: the interfaces do not hold the body");
}

// Fixed-interface normal modes (by count and optionally by cutoff), then the optional inertial-load
// columns; returns Phi (nI x nm).
Eigen::MatrixXd InteriorModes(const FeMesh& mesh, const FeSystem& system, const InterfaceProblem& p,
                              const CraigBamptonOptions& options, CraigBamptonModel& r) {
  Eigen::MatrixXd Phi(p.nI, 0);
  if (options.num_modes > 0) {
    const FeModes modes = SolveLowestModes(p.Kii, p.Mii, {.num_modes = options.num_modes, .tolerance = options.tolerance});
    r.lanczos_operations = modes.operations;
    int keep = options.num_modes;
    if (options.cutoff_hz > 0) {
      keep = 0;
      while (keep < options.num_modes && modes.frequencies_hz[keep] <= options.cutoff_hz) ++keep;
      r.cutoff_reached = keep < options.num_modes;
    }
    Phi = modes.shapes.leftCols(keep);
    r.fixed_interface_eigenvalues = modes.eigenvalues.head(keep);
  }
  if (!options.inertial_load_modes) return Phi;
  // Unit inertial body-force fields g (per unit density, linear in x - p_r), loads T^T M g.
  const Eigen::Vector3d p_r = p.it.master_positions[options.reference_interface];
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
  const Eigen::MatrixXd Fq = p.Tt * (system.M * G);
  Eigen::MatrixXd X = p.Solve(Fq.bottomRows(p.nI));
  // Remove what the normal modes span (M-orthogonal projection), then an M-orthonormal basis of
  // the rest, dropping directions below 1e-8 of the largest.
  const auto Mii = p.Mii.selfadjointView<Eigen::Upper>();
  if (Phi.cols() > 0) X -= Phi * (Phi.transpose() * (Mii * X));
  const Eigen::MatrixXd MX = Symmetrized(X.transpose() * (Mii * X));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(MX);
  const double top = es.eigenvalues().maxCoeff();
  std::vector<int> keep;
  for (int k = 0; k < 12; ++k)
    if (top > 0 && es.eigenvalues()(k) > 1e-8 * top) keep.push_back(k);
  const int na = static_cast<int>(keep.size());
  Eigen::MatrixXd Xo(p.nI, na);
  for (int k = 0; k < na; ++k) Xo.col(k) = X * es.eigenvectors().col(keep[k]) / std::sqrt(es.eigenvalues()(keep[k]));
  Eigen::MatrixXd aug(p.nI, Phi.cols() + na);
  aug << Phi, Xo;
  r.num_load_modes = na;
  return aug;
}

// Static displacements (3 N x 6) under the six unit centrifugal load cases (geometric_stiffness.h
// InertialLoadCases) with the reference master held and the other masters free, through K_ii's
// factor: with b' the other masters' coordinates and Psi = -K_ii^-1 K_ib,
//   (K_b'b' + K_b'i Psi_b') x_b' = f_b' + Psi_b'^T f_i,   x_i = K_ii^-1 f_i + Psi_b' x_b',
// where K_b'b' + K_b'i Psi_b' is the b' block of the reduced stiffness K_cb (block elimination,
// exact; the same solution as a factorization of the held stiffness, SolveStaticsHeldAtInterface).
Eigen::MatrixXd HeldInertialStatics(const FeMesh& mesh, const FeSystem& system, const InterfaceProblem& p, int ref,
                                    const Eigen::MatrixXd& Psi, const Eigen::MatrixXd& Kcb) {
  const Eigen::MatrixXd F = InertialLoadCases(mesh, system, p.it.master_positions[ref]);
  const Eigen::MatrixXd Fq = p.Tt * F;
  Eigen::MatrixXd Xi = p.Solve(Fq.bottomRows(p.nI));
  Eigen::MatrixXd Xq = Eigen::MatrixXd::Zero(p.nb + p.nI, F.cols());
  // Free masters: every interface coordinate except the reference's 6
  std::vector<int> free;
  for (int c = 0; c < p.nb; ++c)
    if (c < 6 * ref || c >= 6 * ref + 6) free.push_back(c);
  const int nf = static_cast<int>(free.size());
  if (nf > 0) {
    Eigen::MatrixXd S(nf, nf), Pf(p.nI, nf), rhs(nf, F.cols());
    for (int a = 0; a < nf; ++a) {
      Pf.col(a) = Psi.col(free[a]);
      rhs.row(a) = Fq.row(free[a]);
      for (int b = 0; b < nf; ++b) S(a, b) = Kcb(free[a], free[b]);
    }
    rhs.noalias() += Pf.transpose() * Fq.bottomRows(p.nI);
    const Eigen::MatrixXd xb = Eigen::LDLT<Eigen::MatrixXd>(Symmetrized(S)).solve(rhs);
    Xi.noalias() += Pf * xb;
    for (int a = 0; a < nf; ++a) Xq.row(free[a]) = xb.row(a);
  }
  Xq.bottomRows(p.nI) = Xi;
  return p.it.T * Xq;
}

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
  InterfaceProblem p;
  FactorizeInterior(mesh, system, interfaces, options.num_modes, p);
  const int nb = p.nb, nI = p.nI, nq = nb + nI;
  const InterfaceTransform& it = p.it;

  // Static constraint modes Psi = -K_ii^-1 K_ib: one solve of all nb columns
  // (K_ib = K_bi^T: the upper triangle holds K_bi)
  const Eigen::MatrixXd Psi = -p.Solve(Eigen::MatrixXd(p.Kq.block(0, nb, nb, nI)).transpose());
  CraigBamptonModel r;
  const Eigen::MatrixXd Phi = InteriorModes(mesh, system, p, options, r);
  const int nm = static_cast<int>(Phi.cols());
  const int ncb = nb + nm;

  // Basis T_cb = [[I, 0], [Psi, Phi]] and the reduced matrices
  Eigen::MatrixXd Tcb = Eigen::MatrixXd::Zero(nq, ncb);
  Tcb.topLeftCorner(nb, nb).setIdentity();
  Tcb.bottomLeftCorner(nI, nb) = Psi;
  Tcb.bottomRightCorner(nI, nm) = Phi;
  const Eigen::MatrixXd Kcb =
      Symmetrized(Tcb.transpose() * (p.Kq.selfadjointView<Eigen::Upper>() * Tcb));
  const Eigen::MatrixXd Mcb =
      Symmetrized(Tcb.transpose() * (p.Mq.selfadjointView<Eigen::Upper>() * Tcb));
  r.inertial_load_statics = HeldInertialStatics(mesh, system, p, ref, Psi, Kcb);

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

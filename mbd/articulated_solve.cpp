#include "mbd/articulated_solve.h"

#include <algorithm>
#include <cmath>

namespace orrery {
namespace {

// Cholesky factor L of a symmetric positive definite N x N matrix (D = L L^T, lower triangle
// of `L`), written out for the fixed sizes. false when a pivot L_jj^2 is not above 1e-13 of D's
// largest diagonal entry (not numerically positive definite).
template <int N>
bool Cholesky(const Eigen::Matrix<double, N, N>& D, Eigen::Matrix<double, 6, 6>& L) {
  const double floor = 1e-13 * D.diagonal().maxCoeff();
  for (int j = 0; j < N; ++j) {
    double pivot = D(j, j);
    for (int k = 0; k < j; ++k) pivot -= L(j, k) * L(j, k);
    if (!(pivot > floor)) return false;
    L(j, j) = std::sqrt(pivot);
    for (int i = j + 1; i < N; ++i) {
      double sum = D(i, j);
      for (int k = 0; k < j; ++k) sum -= L(i, k) * L(j, k);
      L(i, j) = sum / L(j, j);
    }
  }
  return true;
}

// r <- D^-1 r = L^-T L^-1 r (forward, then back substitution).
template <int N>
void CholeskySolve(const Eigen::Matrix<double, 6, 6>& L, Eigen::Matrix<double, N, 1>& r) {
  for (int i = 0; i < N; ++i) {
    for (int k = 0; k < i; ++k) r(i) -= L(i, k) * r(k);
    r(i) /= L(i, i);
  }
  for (int i = N - 1; i >= 0; --i) {
    for (int k = i + 1; k < N; ++k) r(i) -= L(k, i) * r(k);
    r(i) /= L(i, i);
  }
}

// Joint j's pivot block for N = nv_j coordinates (fixed sizes: the products unrolled): U and the
// Cholesky factor of D into the blocks' leading columns, and the parent's share
// I^A - U D^-1 U^T = I^A - W W^T, W = U L^-T, added to `parent_inertia` (nullptr: the parent is
// the world, or a 6-DOF joint, which hands on nothing). false when D is not positive definite.
template <int N>
bool FactorJoint(const Eigen::Matrix<double, 6, 6>& inertia, const Eigen::Matrix<double, 6, N>& S,
                 Eigen::Matrix<double, 6, 6>& u_block, Eigen::Matrix<double, 6, 6>& cholesky,
                 Eigen::Matrix<double, 6, 6>* parent_inertia) {
  const Eigen::Matrix<double, 6, N> U = inertia * S;
  const Eigen::Matrix<double, N, N> D = S.transpose() * U;
  if (!Cholesky<N>(D, cholesky)) return false;
  u_block.leftCols<N>() = U;
  if (parent_inertia) {
    // W = U L^-T: each row w solves L w^T = u^T
    Eigen::Matrix<double, 6, N> W = U;
    for (int r = 0; r < 6; ++r)
      for (int i = 0; i < N; ++i) {
        for (int k = 0; k < i; ++k) W(r, i) -= cholesky(i, k) * W(r, k);
        W(r, i) /= cholesky(i, i);
      }
    *parent_inertia += inertia;
    parent_inertia->noalias() -= W * W.transpose();
  }
  return true;
}

// Solve's leaves-to-root step of joint j for N coordinates: u_j = tau_j - S^T p^A_b and the
// parent's share p^A_b + U D^-1 u_j (added to `parent_bias`; nullptr: the world).
template <int N>
void BiasJoint(const Eigen::Matrix<double, 6, 6>& u_block,
               const Eigen::Matrix<double, 6, 6>& cholesky, const double* tau,
               const Eigen::Matrix<double, 6, N>& S, const Eigen::Matrix<double, 6, 1>& bias,
               Eigen::Matrix<double, 6, 1>& u, Eigen::Matrix<double, 6, 1>* parent_bias) {
  Eigen::Matrix<double, N, 1> uj =
      Eigen::Map<const Eigen::Matrix<double, N, 1>>(tau) - S.transpose() * bias;
  u.head<N>() = uj;
  if (!parent_bias) return;
  CholeskySolve<N>(cholesky, uj);
  *parent_bias += bias + u_block.leftCols<N>() * uj;
}

// Solve's root-to-leaves step of joint j for N coordinates: x_j and the child's acceleration.
template <int N>
void SolveJoint(const Eigen::Matrix<double, 6, 6>& u_block,
                const Eigen::Matrix<double, 6, 6>& cholesky, const Eigen::Matrix<double, 6, 1>& u,
                const Eigen::Matrix<double, 6, N>& S, const Eigen::Matrix<double, 6, 1>& a_parent,
                double* x, Eigen::Matrix<double, 6, 1>& a_child) {
  Eigen::Matrix<double, N, 1> xj = u.head<N>() - u_block.leftCols<N>().transpose() * a_parent;
  CholeskySolve<N>(cholesky, xj);
  Eigen::Map<Eigen::Matrix<double, N, 1>> x_j(x);
  x_j = xj;
  a_child = a_parent + S * xj;
}

}  // namespace

ArticulatedSolve::ArticulatedSolve(const Model& model)
    : applies_(model.flexible_bodies.empty()),
      inertia_(model.nbodies, Block::Zero()),
      u_block_(model.joints.size(), Block::Zero()),
      cholesky_(model.joints.size(), Block::Zero()),
      bias_(model.nbodies, Vec6::Zero()),
      accel_(model.nbodies, Vec6::Zero()),
      u_(model.joints.size(), Vec6::Zero()),
      root_(model.joints.size(), -1),
      active_(model.joints.size(), 0) {
  for (const JointIndex j : model.tree_order) {
    const BodyIndex parent = model.joints[j].spec.parent;
    root_[j] = parent == kWorldBody ? j : root_[model.bodies[parent].parent_joint];
  }
}

bool ArticulatedSolve::Factorize(const Model& model, const Data& data,
                                 const Eigen::Ref<const Eigen::MatrixXd>& rows) {
  if (!applies_) return false;
  // The subtrees below the world that the right-hand sides touch
  std::fill(active_.begin(), active_.end(), 0);
  for (size_t j = 0; j < model.joints.size(); ++j)
    for (int k = 0; k < model.joints[j].nv; ++k)
      if (rows.col(model.joints[j].v_start + k).cwiseAbs().maxCoeff() > 0) active_[root_[j]] = 1;
  for (BodyIndex b = 0; b < model.nbodies; ++b) inertia_[b] = data.I_W[b].Matrix();
  // Leaves to root: each joint's pivot block D_j and what its subtree hands its parent
  for (auto it = model.tree_order.rbegin(); it != model.tree_order.rend(); ++it) {
    const Joint& jt = model.joints[*it];
    if (!active_[root_[*it]]) continue;
    const BodyIndex b = jt.spec.child, parent = jt.spec.parent;
    const int nv = jt.nv;
    if (nv == 0) {
      if (parent != kWorldBody) inertia_[parent] += inertia_[b];
      continue;
    }
    const JointIndex j = *it;
    Block* to_parent = parent == kWorldBody || nv == 6 ? nullptr : &inertia_[parent];
    bool factored = false;
    switch (nv) {
      case 1:
        factored = FactorJoint<1>(inertia_[b], data.S.middleCols<1>(jt.v_start), u_block_[j],
                                  cholesky_[j], to_parent);
        break;
      case 2:
        factored = FactorJoint<2>(inertia_[b], data.S.middleCols<2>(jt.v_start), u_block_[j],
                                  cholesky_[j], to_parent);
        break;
      case 3:
        factored = FactorJoint<3>(inertia_[b], data.S.middleCols<3>(jt.v_start), u_block_[j],
                                  cholesky_[j], to_parent);
        break;
      case 6:
        factored = FactorJoint<6>(inertia_[b], data.S.middleCols<6>(jt.v_start), u_block_[j],
                                  cholesky_[j], to_parent);
        break;
      default: factored = false;  // no joint type has 4 or 5 coordinates
    }
    if (!factored) return false;
  }
  return true;
}

void ArticulatedSolve::Solve(const Model& model, const Data& data,
                             const Eigen::Ref<const Eigen::VectorXd>& tau,
                             Eigen::Ref<Eigen::VectorXd> x) {
  for (Vec6& p : bias_) p.setZero();
  // Leaves to root: the bias forces the subtrees hand their parents
  for (auto it = model.tree_order.rbegin(); it != model.tree_order.rend(); ++it) {
    const Joint& jt = model.joints[*it];
    if (!active_[root_[*it]]) continue;
    const BodyIndex b = jt.spec.child, parent = jt.spec.parent;
    const int nv = jt.nv;
    const JointIndex j = *it;
    Vec6* to_parent = parent == kWorldBody ? nullptr : &bias_[parent];
    const double* tau_j = tau.data() + jt.v_start;
    switch (nv) {
      case 0:
        if (to_parent) *to_parent += bias_[b];
        break;
      case 1:
        BiasJoint<1>(u_block_[j], cholesky_[j], tau_j, data.S.middleCols<1>(jt.v_start), bias_[b],
                     u_[j], to_parent);
        break;
      case 2:
        BiasJoint<2>(u_block_[j], cholesky_[j], tau_j, data.S.middleCols<2>(jt.v_start), bias_[b],
                     u_[j], to_parent);
        break;
      case 3:
        BiasJoint<3>(u_block_[j], cholesky_[j], tau_j, data.S.middleCols<3>(jt.v_start), bias_[b],
                     u_[j], to_parent);
        break;
      default:
        BiasJoint<6>(u_block_[j], cholesky_[j], tau_j, data.S.middleCols<6>(jt.v_start), bias_[b],
                     u_[j], to_parent);
        break;
    }
  }
  // Root to leaves: the accelerations, which with zero velocities and no gravity are M^-1 tau
  accel_[kWorldBody].setZero();
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    const int nv = jt.nv;
    if (!active_[root_[j]]) {
      x.segment(jt.v_start, nv).setZero();
      continue;
    }
    const BodyIndex b = jt.spec.child;
    const Vec6& a_parent = accel_[jt.spec.parent];
    double* x_j = x.data() + jt.v_start;
    switch (nv) {
      case 0: accel_[b] = a_parent; break;
      case 1:
        SolveJoint<1>(u_block_[j], cholesky_[j], u_[j], data.S.middleCols<1>(jt.v_start), a_parent,
                      x_j, accel_[b]);
        break;
      case 2:
        SolveJoint<2>(u_block_[j], cholesky_[j], u_[j], data.S.middleCols<2>(jt.v_start), a_parent,
                      x_j, accel_[b]);
        break;
      case 3:
        SolveJoint<3>(u_block_[j], cholesky_[j], u_[j], data.S.middleCols<3>(jt.v_start), a_parent,
                      x_j, accel_[b]);
        break;
      default:
        SolveJoint<6>(u_block_[j], cholesky_[j], u_[j], data.S.middleCols<6>(jt.v_start), a_parent,
                      x_j, accel_[b]);
        break;
    }
  }
}

}  // namespace orrery

#include "mbd/articulated_solve.h"

#include <algorithm>
#include <cmath>

namespace orrery {
namespace {

// D^-1 of a symmetric positive definite N x N matrix by its Cholesky factor L (D = L L^T,
// D^-1 = L^-T L^-1), written out for the fixed sizes (Eigen's LLT solves the identity through its
// general-size blocked triangular solver). false when a pivot L_jj^2 is not above 1e-13 of D's
// largest diagonal entry (not numerically positive definite).
template <int N>
bool InverseSpd(const Eigen::Matrix<double, N, N>& D, Eigen::Matrix<double, N, N>& D_inverse) {
  const double floor = 1e-13 * D.diagonal().maxCoeff();
  Eigen::Matrix<double, N, N> L = Eigen::Matrix<double, N, N>::Zero();
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
  // L^-1, lower triangular, column by column
  Eigen::Matrix<double, N, N> L_inverse = Eigen::Matrix<double, N, N>::Zero();
  for (int j = 0; j < N; ++j) {
    L_inverse(j, j) = 1 / L(j, j);
    for (int i = j + 1; i < N; ++i) {
      double sum = 0;
      for (int k = j; k < i; ++k) sum -= L(i, k) * L_inverse(k, j);
      L_inverse(i, j) = sum / L(i, i);
    }
  }
  D_inverse.noalias() = L_inverse.transpose() * L_inverse;
  return true;
}

// Joint j's pivot block for N = nv_j coordinates (fixed sizes: the products unrolled): U, D^-1,
// U D^-1 into the blocks' leading columns, and the parent's share I^A - U D^-1 U^T added to
// `parent_inertia` (nullptr: the parent is the world). false when D is not positive definite.
template <int N>
bool FactorJoint(const Eigen::Matrix<double, 6, 6>& inertia, const Eigen::Matrix<double, 6, N>& S,
                 Eigen::Matrix<double, 6, 6>& u_block, Eigen::Matrix<double, 6, 6>& d_inverse,
                 Eigen::Matrix<double, 6, 6>& u_dinv, Eigen::Matrix<double, 6, 6>* parent_inertia) {
  const Eigen::Matrix<double, 6, N> U = inertia * S;
  const Eigen::Matrix<double, N, N> D = S.transpose() * U;
  Eigen::Matrix<double, N, N> D_inverse;
  if (!InverseSpd<N>(D, D_inverse)) return false;
  const Eigen::Matrix<double, 6, N> U_dinv = U * D_inverse;
  u_block.leftCols<N>() = U;
  d_inverse.topLeftCorner<N, N>() = D_inverse;
  u_dinv.leftCols<N>() = U_dinv;
  if (parent_inertia) {
    *parent_inertia += inertia;
    parent_inertia->noalias() -= U_dinv * U.transpose();
  }
  return true;
}

// Solve's leaves-to-root step of joint j for N coordinates: u_j = tau_j - S^T p^A_b and the
// parent's share p^A_b + U D^-1 u_j (added to `parent_bias`; nullptr: the world).
template <int N>
void BiasJoint(const Eigen::Matrix<double, 6, 6>& u_dinv, const double* tau, const Eigen::Matrix<double, 6, N>& S,
               const Eigen::Matrix<double, 6, 1>& bias, Eigen::Matrix<double, 6, 1>& u,
               Eigen::Matrix<double, 6, 1>* parent_bias) {
  u.head<N>() = Eigen::Map<const Eigen::Matrix<double, N, 1>>(tau) - S.transpose() * bias;
  if (parent_bias) *parent_bias += bias + u_dinv.leftCols<N>() * u.head<N>();
}

// Solve's root-to-leaves step of joint j for N coordinates: x_j and the child's acceleration.
template <int N>
void SolveJoint(const Eigen::Matrix<double, 6, 6>& u_block, const Eigen::Matrix<double, 6, 6>& d_inverse,
                const Eigen::Matrix<double, 6, 1>& u, const Eigen::Matrix<double, 6, N>& S,
                const Eigen::Matrix<double, 6, 1>& a_parent, double* x, Eigen::Matrix<double, 6, 1>& a_child) {
  const Eigen::Matrix<double, N, 1> r = u.head<N>() - u_block.leftCols<N>().transpose() * a_parent;
  const Eigen::Matrix<double, N, 1> xj = d_inverse.topLeftCorner<N, N>() * r;
  Eigen::Map<Eigen::Matrix<double, N, 1>> x_j(x);
  x_j = xj;
  a_child = a_parent + S * xj;
}

}  // namespace

ArticulatedSolve::ArticulatedSolve(const Model& model)
    : applies_(model.flexible_bodies.empty()),
      inertia_(model.nbodies, Block::Zero()),
      u_block_(model.joints.size(), Block::Zero()),
      u_dinv_(model.joints.size(), Block::Zero()),
      d_inverse_(model.joints.size(), Block::Zero()),
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
      case 1: factored = FactorJoint<1>(inertia_[b], data.S.middleCols<1>(jt.v_start), u_block_[j], d_inverse_[j], u_dinv_[j], to_parent); break;
      case 2: factored = FactorJoint<2>(inertia_[b], data.S.middleCols<2>(jt.v_start), u_block_[j], d_inverse_[j], u_dinv_[j], to_parent); break;
      case 3: factored = FactorJoint<3>(inertia_[b], data.S.middleCols<3>(jt.v_start), u_block_[j], d_inverse_[j], u_dinv_[j], to_parent); break;
      case 6: factored = FactorJoint<6>(inertia_[b], data.S.middleCols<6>(jt.v_start), u_block_[j], d_inverse_[j], u_dinv_[j], to_parent); break;
      default: factored = false;  // no joint type has 4 or 5 coordinates
    }
    if (!factored) return false;
  }
  return true;
}

void ArticulatedSolve::Solve(const Model& model, const Data& data,
                             const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> x) {
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
      case 0: if (to_parent) *to_parent += bias_[b]; break;
      case 1: BiasJoint<1>(u_dinv_[j], tau_j, data.S.middleCols<1>(jt.v_start), bias_[b], u_[j], to_parent); break;
      case 2: BiasJoint<2>(u_dinv_[j], tau_j, data.S.middleCols<2>(jt.v_start), bias_[b], u_[j], to_parent); break;
      case 3: BiasJoint<3>(u_dinv_[j], tau_j, data.S.middleCols<3>(jt.v_start), bias_[b], u_[j], to_parent); break;
      default: BiasJoint<6>(u_dinv_[j], tau_j, data.S.middleCols<6>(jt.v_start), bias_[b], u_[j], to_parent); break;
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
      case 1: SolveJoint<1>(u_block_[j], d_inverse_[j], u_[j], data.S.middleCols<1>(jt.v_start), a_parent, x_j, accel_[b]); break;
      case 2: SolveJoint<2>(u_block_[j], d_inverse_[j], u_[j], data.S.middleCols<2>(jt.v_start), a_parent, x_j, accel_[b]); break;
      case 3: SolveJoint<3>(u_block_[j], d_inverse_[j], u_[j], data.S.middleCols<3>(jt.v_start), a_parent, x_j, accel_[b]); break;
      default: SolveJoint<6>(u_block_[j], d_inverse_[j], u_[j], data.S.middleCols<6>(jt.v_start), a_parent, x_j, accel_[b]); break;
    }
  }
}

}  // namespace orrery

#include "mbd/dae.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

#include "mbd/constraints.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/flexible_dynamics.h"
#include "mbd/force_elements.h"
#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"

namespace orrery {
namespace {
constexpr double kFdStep = 1.5e-8;  // ~ sqrt(machine epsilon): forward-difference step
}

DaeSystem::DaeSystem(const Model& model)
    : model_(model),
      data_(model),
      nq_(model.nq),
      nv_(model.nv),
      nc_(model.n_constraints),
      nh_(model.n_holonomic),
      n_(model.nq + model.nv + model.n_constraints + model.n_holonomic) {
  qdot_.setZero(nq_);
  w_.setZero(nv_);
  q_pert_.setZero(nq_);
  v_pert_.setZero(nv_);
  dv_.setZero(nv_);
  rv0_.setZero(nv_);
  rv1_.setZero(nv_);
  rl0_.setZero(nc_);
  rl1_.setZero(nc_);
  dq_dv_.setZero(nq_, nv_);
  dv_dq_.setZero(nv_, nq_);
  G_ref_.setZero(nc_, nv_);
  Jv_.setZero(nv_ + nc_, nv_);
  Cv_.setZero(nv_, nv_);
  kkt_.setZero(nv_ + nc_, nv_ + nc_);
  kkt_rhs_.setZero(nv_ + nc_);
  kkt_x_.setZero(nv_ + nc_);
  kkt_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(nv_ + nc_);
  gamma_.setZero(nc_);
  zero_nv_.setZero(nv_);
  any_element_tangents_ = !model.gear_meshes.empty();
  for (const auto& element : model.external_forces) any_element_tangents_ |= element->HasTangents();
  mesh_row_.setZero(nv_);
  mesh_phase_row_.setZero(nv_);
  rvz_.setZero(nv_);
  rlz_.setZero(nc_);
  tau_base_.setZero(nv_);
  GroupDifferences();
  analytic_column_.assign(nv_, 0);
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    if (fb.nf == 0 || !ModalColumnsAreLocal(model, static_cast<int>(i))) continue;
    analytic_modal_bodies_.push_back(static_cast<int>(i));
    for (int k = 0; k < fb.nf; ++k) analytic_column_[fb.v_start + k] = 1;
  }
}

int DaeSystem::differenced_columns() const {
  if (!use_analytic_modal_ || analytic_modal_bodies_.empty() ||
      !(use_element_tangents_ || model_.external_forces.empty()))
    return nv_;
  int n = 0;
  for (const char analytic : analytic_column_) n += analytic ? 0 : 1;
  return n;
}

void DaeSystem::GroupDifferences() {
  const Model& m = model_;
  if (!m.loop_closures.empty() || !m.gear_constraints.empty() || !m.external_forces.empty() ||
      !m.flexible_bodies.empty() || m.gear_meshes.empty())
    return;
  // Subtrees on the world by their root joint, joined by the differenced elements (union-find)
  const int nj = static_cast<int>(m.joints.size());
  std::vector<int> root(nj, -1), parent(nj);
  for (const JointIndex j : m.tree_order) {
    const BodyIndex p = m.joints[j].spec.parent;
    root[j] = p == kWorldBody ? j : root[m.bodies[p].parent_joint];
  }
  for (int j = 0; j < nj; ++j) parent[j] = j;
  auto find = [&](int j) {
    while (parent[j] != j) j = parent[j] = parent[parent[j]];
    return j;
  };
  auto body_class = [&](FrameIndex f) {
    const BodyIndex b = m.frames[f].body;
    return b == kWorldBody ? -1 : root[m.bodies[b].parent_joint];
  };
  auto join = [&](FrameIndex a, FrameIndex b) {
    const int ca = body_class(a), cb = body_class(b);
    if (ca >= 0 && cb >= 0) parent[find(ca)] = find(cb);
  };
  for (const auto& s : m.translational_springs) join(s.frame_a, s.frame_b);
  for (const auto& s : m.rotational_springs) join(s.frame_a, s.frame_b);
  for (const auto& s : m.bushings) join(s.frame_a, s.frame_b);
  for (const auto& s : m.bearings) join(s.frame_a, s.frame_b);
  // Classes numbered in order of their first coordinate; rows: coordinates, then drivers
  std::vector<int> class_index(nj, -1), columns_in(0);
  std::vector<std::vector<int>> columns;
  std::vector<int> row_class(nv_ + nc_, -1);
  for (int k = 0; k < nv_; ++k) {
    const int c = find(root[m.joint_of_v[k]]);
    if (class_index[c] < 0) {
      class_index[c] = static_cast<int>(columns.size());
      columns.emplace_back();
    }
    columns[class_index[c]].push_back(k);
    row_class[k] = class_index[c];
  }
  for (size_t d = 0; d < m.drivers.size(); ++d)
    row_class[nv_ + m.driver_row[d]] = class_index[find(root[m.drivers[d].spec.joint])];
  if (columns.size() < 2) return;
  size_t groups = 0;
  for (const auto& c : columns) groups = std::max(groups, c.size());
  group_columns_.assign(groups, {});
  for (const auto& c : columns)
    for (size_t g = 0; g < c.size(); ++g) group_columns_[g].push_back(c[g]);
  class_of_row_ = std::move(row_class);
}

void DaeSystem::DynamicRows(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& v,
                            const Eigen::Ref<const Eigen::VectorXd>& vdot,
                            const Eigen::Ref<const Eigen::VectorXd>& lambda,
                            Eigen::Ref<Eigen::VectorXd> rv, Eigen::Ref<Eigen::VectorXd> rl) {
  EvaluateDynamics(model_, t, q, v, vdot, data_);
  rv = data_.tau_id;
  if (nc_ > 0) {
    AddConstraintForces(data_.G, lambda, rv);
    rl = data_.g_t;
    rl.noalias() += data_.G * v;
  }
}

void DaeSystem::Residual(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                         const Eigen::Ref<const Eigen::VectorXd>& yp,
                         Eigen::Ref<Eigen::VectorXd> r) {
  ++residual_evaluations_;
  const auto q = y.segment(0, nq_);
  const auto v = y.segment(nq_, nv_);
  const auto lambda = y.segment(nq_ + nv_, nc_);
  const auto mu = y.segment(nq_ + nv_ + nc_, nh_);
  // Dynamics and velocity constraints.
  DynamicRows(t, q, v, yp.segment(nq_, nv_), lambda, r.segment(nq_, nv_), r.segment(nq_ + nv_, nc_));
  // Position constraints.
  r.segment(nq_ + nv_ + nc_, nh_) = data_.phi;
  // Kinematic rows with the GGL projection.
  w_ = v;
  if (nh_ > 0) w_.noalias() += data_.G.topRows(nh_).transpose() * mu;
  CalcQDot(model_, q, w_, qdot_);
  r.segment(0, nq_) = yp.segment(0, nq_) - qdot_;
}

void DaeSystem::Jacobian(double t, double cj, const Eigen::Ref<const Eigen::VectorXd>& y,
                         const Eigen::Ref<const Eigen::VectorXd>& yp,
                         Eigen::Ref<Eigen::MatrixXd> J) {
  const auto q = y.segment(0, nq_);
  const auto v = y.segment(nq_, nv_);
  const auto lambda = y.segment(nq_ + nv_, nc_);
  const auto mu = y.segment(nq_ + nv_ + nc_, nh_);
  const auto vdot = yp.segment(nq_, nv_);
  const int iv = nq_, il = nq_ + nv_, im = nq_ + nv_ + nc_;
  J.setZero();

  // N(q) and its left inverse, block by block (identity except unit quaternions).
  dq_dv_.setZero();
  dv_dq_.setZero();
  for (const Joint& jt : model_.joints) {
    // Identity for the coordinates before the quaternion (all of them without one).
    const int quat = JointInfo(jt.spec.type).quaternion;
    const int n_plain = quat < 0 ? jt.nv : quat;
    for (int k = 0; k < n_plain; ++k)
      dq_dv_(jt.q_start + k, jt.v_start + k) = dv_dq_(jt.v_start + k, jt.q_start + k) = 1;
    if (quat < 0) continue;
    const int qs = jt.q_start + quat, vs = jt.v_start + quat;
    const double q0 = q(qs);
    const Vec3 u = q.segment<3>(qs + 1);
    // N = 1/2 [-u^T; q0 I - [u]x],  2E = 2 [-u, q0 I + [u]x]  (E N = I for unit q).
    dq_dv_.block<1, 3>(qs, vs) = -0.5 * u.transpose();
    dq_dv_.block<3, 3>(qs + 1, vs) = 0.5 * (q0 * Mat3::Identity() - Skew(u));
    dv_dq_.block<3, 1>(vs, qs) = -2.0 * u;
    dv_dq_.block<3, 3>(vs, qs + 1) = 2.0 * (q0 * Mat3::Identity() + Skew(u));
    // r_q = qdot - N(q) w: d/dq of (0, w) x q / 2 = 1/2 [0 -w^T; w [w]x].
    const Vec3 w = v.segment<3>(vs);  // mu-term neglected (mu = 0 on the solution)
    J.block<1, 3>(qs, qs + 1) += 0.5 * w.transpose();
    J.block<3, 1>(qs + 1, qs) += -0.5 * w;
    J.block<3, 3>(qs + 1, qs + 1) += -0.5 * Skew(w);
  }
  for (const FlexibleBody& fb : model_.flexible_bodies)
    for (int k = 0; k < fb.nf; ++k)
      dq_dv_(fb.q_start + k, fb.v_start + k) = dv_dq_(fb.v_start + k, fb.q_start + k) = 1;

  // q- and v-dependence of the generalized forces and of G (leaves data at the base point).
  Tangents(t, q, v, vdot, lambda, Jv_, Cv_);
  if (nv_ > 0) J.block(iv, 0, nv_ + nc_, nq_).noalias() = Jv_ * dv_dq_;

  // Structural blocks.
  J.block(0, 0, nq_, nq_).diagonal().array() += cj;
  J.block(0, iv, nq_, nv_) -= dq_dv_;
  if (nh_ > 0) {
    J.block(0, im, nq_, nh_).noalias() -= dq_dv_ * data_.G.topRows(nh_).transpose();
    J.block(im, 0, nh_, nq_).noalias() = data_.G.topRows(nh_) * dv_dq_;
  }
  (void)mu;
  J.block(iv, iv, nv_, nv_) = cj * data_.M + Cv_;
  if (nc_ > 0) {
    J.block(iv, il, nv_, nc_) = data_.G.transpose();
    J.block(il, iv, nc_, nv_) = data_.G;
  }
}

void DaeSystem::Tangents(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& v,
                         const Eigen::Ref<const Eigen::VectorXd>& vdot,
                         const Eigen::Ref<const Eigen::VectorXd>& lambda,
                         Eigen::Ref<Eigen::MatrixXd> Kq, Eigen::Ref<Eigen::MatrixXd> Cv) {
  // Elements with analytic tangents are left out of the differences below.
  data_.skip_elements_with_tangents = use_element_tangents_ && any_element_tangents_;
  // The modal columns of leaf flexible bodies from their equations (at the end), when every
  // external element is left out of the differences (ModalColumnsAreLocal asks that they all have
  // analytic tangents).
  const bool modal = use_analytic_modal_ && !analytic_modal_bodies_.empty() &&
                     (use_element_tangents_ || model_.external_forces.empty());
  // Positions: q <- q (+) h e_k, the whole pipeline per column (per group of uncoupled columns).
  const bool grouped = use_groups_ && data_.skip_elements_with_tangents && !class_of_row_.empty();
  DynamicRows(t, q, v, vdot, lambda, rv0_, rl0_);
  if (grouped) {
    GroupedPositionColumns(t, q, v, vdot, lambda, Kq);
  } else {
    for (int k = 0; k < nv_; ++k) {
      if (modal && analytic_column_[k]) continue;
      q_pert_ = q;
      dv_.setZero();
      dv_(k) = kFdStep;
      IntegratePositions(model_, dv_, q_pert_);
      DynamicRows(t, q_pert_, v, vdot, lambda, rv1_, rl1_);
      Kq.col(k).head(nv_) = (rv1_ - rv0_) / kFdStep;
      Kq.col(k).tail(nc_) = (rl1_ - rl0_) / kFdStep;
    }
  }
  // Back to the base point; velocities: only the velocity stages rerun (positions unchanged).
  DynamicRows(t, q, v, vdot, lambda, rv0_, rl0_);
  CalcMassMatrix(model_, data_);
  G_ref_ = data_.G;
  tau_base_ = data_.tau_id;
  if (nc_ > 0) {
    w_.noalias() = G_ref_.transpose() * lambda;
    rv0_ -= w_;  // rv0_ = tau_id at the base point
  }
  if (grouped) {
    GroupedVelocityColumns(t, v, vdot, Cv);
  } else {
    for (int k = 0; k < nv_; ++k) {
      if (modal && analytic_column_[k]) continue;
      v_pert_ = v;
      const double h = kFdStep * std::max(1.0, std::abs(v(k)));
      v_pert_(k) += h;
      CalcVelocityKinematics(model_, v_pert_, data_);
      CalcForceElements(model_, t, v_pert_, data_);
      CalcInverseDynamics(model_, vdot, data_);
      Cv.col(k) = (data_.tau_id - rv0_) / h;
    }
  }
  // Leave data at the base point, every element applied (where the last evaluation was at this
  // very state, a residual's at the iterate being refreshed, the external elements' results are
  // added again, not computed: CalcExternalForces); those with analytic tangents add them there.
  const bool add_element_tangents = data_.skip_elements_with_tangents;
  data_.skip_elements_with_tangents = false;
  CalcVelocityKinematics(model_, v, data_);
  CalcForceElements(model_, t, v, data_);
  CalcInverseDynamics(model_, vdot, data_);
  if (modal)
    for (const int i : analytic_modal_bodies_)
      SetFlexibleModalTangents(model_, data_, i, vdot, Kq, Cv);
  if (add_element_tangents) {
    CalcBodyJacobians(model_, data_);
    AddGearMeshTangents(model_, data_, Kq.topRows(nv_), Cv, mesh_row_, mesh_phase_row_);
    for (size_t i = 0; i < model_.external_forces.size(); ++i) {
      const ExternalForceElement& element = *model_.external_forces[i];
      if (element.HasTangents())
        element.AddTangents(model_, data_, *data_.external[i], Kq.topRows(nv_), Cv);
    }
    // AddTangents may use the workspaces as scratch: the next evaluation computes them again.
    data_.tangent_elements_t = std::numeric_limits<double>::quiet_NaN();
  }
}

void DaeSystem::GroupedPositionColumns(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                                       const Eigen::Ref<const Eigen::VectorXd>& v,
                                       const Eigen::Ref<const Eigen::VectorXd>& vdot,
                                       const Eigen::Ref<const Eigen::VectorXd>& lambda,
                                       Eigen::Ref<Eigen::MatrixXd> Kq) {
  // The rows a column of another class sees: q (+) 0 (quaternions renormalized) against rv0_
  q_pert_ = q;
  dv_.setZero();
  IntegratePositions(model_, dv_, q_pert_);
  DynamicRows(t, q_pert_, v, vdot, lambda, rvz_, rlz_);
  for (const std::vector<int>& group : group_columns_) {
    q_pert_ = q;
    dv_.setZero();
    for (const int k : group) dv_(k) = kFdStep;
    IntegratePositions(model_, dv_, q_pert_);
    DynamicRows(t, q_pert_, v, vdot, lambda, rv1_, rl1_);
    for (const int k : group) {
      const int c = class_of_row_[k];
      for (int r = 0; r < nv_; ++r)
        Kq(r, k) = ((class_of_row_[r] == c ? rv1_(r) : rvz_(r)) - rv0_(r)) / kFdStep;
      for (int r = 0; r < nc_; ++r)
        Kq(nv_ + r, k) = ((class_of_row_[nv_ + r] == c ? rl1_(r) : rlz_(r)) - rl0_(r)) / kFdStep;
    }
  }
}

void DaeSystem::GroupedVelocityColumns(double t, const Eigen::Ref<const Eigen::VectorXd>& v,
                                       const Eigen::Ref<const Eigen::VectorXd>& vdot,
                                       Eigen::Ref<Eigen::MatrixXd> Cv) {
  for (const std::vector<int>& group : group_columns_) {
    v_pert_ = v;
    for (const int k : group) v_pert_(k) += kFdStep * std::max(1.0, std::abs(v(k)));
    CalcVelocityKinematics(model_, v_pert_, data_);
    CalcForceElements(model_, t, v_pert_, data_);
    CalcInverseDynamics(model_, vdot, data_);
    for (const int k : group) {
      const int c = class_of_row_[k];
      const double h = kFdStep * std::max(1.0, std::abs(v(k)));
      for (int r = 0; r < nv_; ++r)
        Cv(r, k) = ((class_of_row_[r] == c ? data_.tau_id(r) : tau_base_(r)) - rv0_(r)) / h;
    }
  }
}

void DaeSystem::SolveAccelerations(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                                   const Eigen::Ref<const Eigen::VectorXd>& v,
                                   Eigen::Ref<Eigen::VectorXd> vdot,
                                   Eigen::Ref<Eigen::VectorXd> lambda) {
  // gamma = d/dt (G v + g_t) at fixed v, by central differences along the motion.
  zero_nv_.setZero();
  gamma_.setZero();
  if (nc_ > 0) {
    const double h = 1e-6 / std::max(1.0, v.lpNorm<Eigen::Infinity>());
    q_pert_ = q;
    dv_ = h * v;
    IntegratePositions(model_, dv_, q_pert_);
    EvaluateDynamics(model_, t + h, q_pert_, v, zero_nv_, data_);
    gamma_.noalias() = data_.G * v;
    gamma_ += data_.g_t;
    q_pert_ = q;
    dv_ = -h * v;
    IntegratePositions(model_, dv_, q_pert_);
    EvaluateDynamics(model_, t - h, q_pert_, v, zero_nv_, data_);
    rl1_.noalias() = data_.G * v;
    rl1_ += data_.g_t;
    gamma_ = (gamma_ - rl1_) / (2 * h);
  }
  // KKT system at vdot = 0: tau_id is then C - Q.
  EvaluateDynamics(model_, t, q, v, zero_nv_, data_);
  CalcMassMatrix(model_, data_);
  kkt_.setZero();
  kkt_.topLeftCorner(nv_, nv_) = data_.M;
  kkt_.topRightCorner(nv_, nc_) = data_.G.transpose();
  kkt_.bottomLeftCorner(nc_, nv_) = data_.G;
  kkt_rhs_.head(nv_) = -data_.tau_id;
  kkt_rhs_.tail(nc_) = -gamma_;
  kkt_lu_.compute(kkt_);
  // Singular when a free coordinate has no mass or constraints are redundant: the pivots show it.
  const double pivot_floor = 1e-13 * kkt_.lpNorm<Eigen::Infinity>();
  if (!(kkt_lu_.matrixLU().diagonal().cwiseAbs().minCoeff() > pivot_floor)) {
    // Name the rows when the constraints lose a rank (a singular position); else the mass.
    const std::string rows = DependentConstraintRows(model_, data_.G, 1e-8);
    std::ostringstream s;
    s << "t = " << t << " s: ";
    if (!rows.empty())
      s << "the constraint Jacobian loses a rank (" << rows
        << "): the mechanism is at a singular position (a four-bar's links in line, say), where the "
           "multipliers of those rows are unbounded";
    else
      s << "the mass matrix with the constraint Jacobian is singular: a body without mass on a free "
           "coordinate, or redundant constraints";
    throw std::runtime_error(s.str());
  }
  kkt_x_.noalias() = kkt_lu_.solve(kkt_rhs_);
  vdot = kkt_x_.head(nv_);
  lambda = kkt_x_.tail(nc_);
}

void DaeSystem::ConsistentInitial(const State& state, Eigen::Ref<Eigen::VectorXd> y,
                                  Eigen::Ref<Eigen::VectorXd> yp) {
  y.setZero();
  yp.setZero();
  y.segment(0, nq_) = state.q;
  y.segment(nq_, nv_) = state.v;
  SolveAccelerations(state.t, state.q, state.v, yp.segment(nq_, nv_), y.segment(nq_ + nv_, nc_));
  CalcQDot(model_, state.q, state.v, yp.segment(0, nq_));
}

}  // namespace orrery

#include "contact/contact_tangents.h"

namespace orrery::contact {

ContactTangents::ContactTangents(const FlexibleContactSurface* flexible_a,
                                 const FlexibleContactSurface* flexible_b, int nv)
    : flexible_{flexible_a, flexible_b},
      nf_{flexible_a ? flexible_a->nf() : 0, flexible_b ? flexible_b->nf() : 0} {
  m_ = 6 + nf_[0] + nf_[1];
  for (int s = 0; s < 2; ++s) {
    modal_[s].setZero(3, nf_[s]);
    R_[s].setIdentity();
  }
  K_z_.setZero(m_, m_);
  C_z_.setZero(m_, m_);
  u_.setZero(m_);
  w_.setZero(m_);
  U_K_.setZero(m_, kBlock);
  W_K_.setZero(m_, kBlock);
  U_C_.setZero(m_, 3 * kBlock);
  W_C_.setZero(m_, 3 * kBlock);
  support_.reserve(nv);
  in_support_.assign(nv, 0);
  J_s_.setZero(6, nv);
  X_.setZero(m_, nv);
  Y_.setZero(nv, m_);
  Z_.setZero(nv, nv);
}

void ContactTangents::Clear() {
  K_z_.setZero();
  C_z_.setZero();
  columns_k_ = columns_c_ = 0;
  points_ = 0;
}

void ContactTangents::Project(const Vec3& x, Eigen::Ref<Eigen::VectorXd> out) const {
  // Rigid rows: T_p^T x = (p x x, x) on V_WA - V_WB, + when the node is on A.
  out.segment<3>(0) = sign_[0] * p_W_.cross(x);
  out.segment<3>(3) = sign_[0] * x;
  // Modal rows (their signs are in modal_): Phi^T R^T x.
  int offset = 6;
  for (int s = 0; s < 2; ++s) {
    if (nf_[s] == 0) continue;
    const Vec3 x_B = R_[s].transpose() * x;
    out.segment(offset, nf_[s]).noalias() = modal_[s].transpose() * x_B;
    offset += nf_[s];
  }
}

void ContactTangents::AddPoint(const TangentPoint& point, const NodeForceTangent& law,
                               const Vec3& n_W, const Mat3& R_WA, const Mat3& R_WB) {
  if (law.k_n == 0 && law.c_n == 0 && law.slip_directions == 0) return;
  // Room for this point's columns (one for K, up to three for C).
  if (columns_k_ == kBlock || columns_c_ > 3 * kBlock - 3) Flush();
  p_W_ = point.p_W;
  const int node_side = point.node_on_a ? 0 : 1;
  sign_[node_side] = 1;
  sign_[1 - node_side] = -1;
  R_[0] = R_WA;
  R_[1] = R_WB;
  // This point's modal rows: the node's shapes on its side, minus the face point's on the other.
  if (nf_[node_side] > 0) modal_[node_side] = flexible_[node_side]->VertexShapes(point.node_vertex);
  const int face_side = 1 - node_side;
  if (nf_[face_side] > 0) {
    modal_[face_side].setZero();
    for (int k = 0; k < 3; ++k)
      modal_[face_side].noalias() -=
          point.face_weights(k) * flexible_[face_side]->VertexShapes(point.face_vertices[k]);
  }
  // Rank-1 terms: (J^T a)(J^T n)^T for the normal force, (J^T d)(J^T d)^T for the slip, as
  // columns of U and W (the product is made in Flush()).
  Project(law.a, u_);
  Project(n_W, w_);
  if (law.k_n != 0) {
    U_K_.col(columns_k_) = law.k_n * u_;
    W_K_.col(columns_k_++) = w_;
  }
  if (law.c_n != 0) {
    U_C_.col(columns_c_) = law.c_n * u_;
    W_C_.col(columns_c_++) = w_;
  }
  for (int i = 0; i < law.slip_directions; ++i) {
    Project(law.slip_direction[i], W_C_.col(columns_c_));
    U_C_.col(columns_c_) = law.slip_damping * W_C_.col(columns_c_);
    ++columns_c_;
  }
  ++points_;
}

void ContactTangents::Flush() {
  if (columns_k_ > 0)
    K_z_.noalias() += U_K_.leftCols(columns_k_) * W_K_.leftCols(columns_k_).transpose();
  if (columns_c_ > 0)
    C_z_.noalias() += U_C_.leftCols(columns_c_) * W_C_.leftCols(columns_c_).transpose();
  columns_k_ = columns_c_ = 0;
}

void ContactTangents::Scatter(const Model& model, const Data& data, BodyIndex body_a,
                              BodyIndex body_b, Eigen::Ref<Eigen::MatrixXd> K,
                              Eigen::Ref<Eigen::MatrixXd> C) {
  if (points_ == 0) return;
  Flush();
  // The support: the velocity coordinates of the joints from each body to the root, the only
  // columns where J_WB can be nonzero (CalcBodyJacobians); the world takes none. J_s: those
  // columns of J_A - J_B (the rigid rows of L).
  for (const int k : support_) in_support_[k] = 0;
  support_.clear();
  for (const BodyIndex body : {body_a, body_b}) {
    if (body == kWorldBody) continue;
    for (JointIndex j = model.bodies[body].parent_joint; j >= 0;
         j = model.bodies[model.joints[j].spec.parent].parent_joint) {
      const Joint& jt = model.joints[j];
      for (int k = jt.v_start; k < jt.v_start + jt.nv; ++k) {
        if (in_support_[k]) continue;
        in_support_[k] = 1;
        support_.push_back(k);
      }
    }
  }
  const int ns = static_cast<int>(support_.size());
  for (int i = 0; i < ns; ++i) {
    const int k = support_[i];
    J_s_.col(i).setZero();
    if (body_a != kWorldBody) J_s_.col(i) += data.J_WB[body_a].col(k);
    if (body_b != kWorldBody) J_s_.col(i) -= data.J_WB[body_b].col(k);
  }
  // The modal coordinates of the flexible sides: rows offset_[s] of z, v_start_[s] of v.
  int offset = 6;
  for (const auto& [s, body] : {std::pair{0, body_a}, std::pair{1, body_b}}) {
    offset_[s] = offset;
    v_start_[s] = nf_[s] > 0 ? model.flexible_bodies[model.bodies[body].flexible].v_start : 0;
    offset += nf_[s];
  }
  ScatterOne(K_z_, K);
  ScatterOne(C_z_, C);
}

void ContactTangents::ScatterOne(const Eigen::MatrixXd& M, Eigen::Ref<Eigen::MatrixXd> out) {
  // L = [J_A - J_B; E] with E the modal coordinates' selector; J_s the support's columns of
  // J_A - J_B. L^T M L by blocks: support x support J_s^T M_rr J_s, support x modal J_s^T M_rf,
  // modal x support M_fr J_s, modal x modal M_ff (r: the 6 rigid rows of z).
  const int ns = static_cast<int>(support_.size());
  const auto J = J_s_.leftCols(ns);
  auto X = X_.leftCols(ns);  // M_{., r} J_s: m x ns
  auto Y = Y_.topRows(ns);   // J_s^T M_{r, .}: ns x m
  auto Z = Z_.topLeftCorner(ns, ns);
  X.noalias() = M.leftCols<6>() * J;
  Y.noalias() = J.transpose() * M.topRows<6>();
  Z.noalias() = J.transpose() * X.topRows<6>();
  for (int j = 0; j < ns; ++j)
    for (int i = 0; i < ns; ++i) out(support_[i], support_[j]) += Z(i, j);
  for (int s = 0; s < 2; ++s) {
    if (nf_[s] == 0) continue;
    for (int i = 0; i < ns; ++i) {
      out.row(support_[i]).segment(v_start_[s], nf_[s]) += Y.row(i).segment(offset_[s], nf_[s]);
      out.col(support_[i]).segment(v_start_[s], nf_[s]) += X.col(i).segment(offset_[s], nf_[s]);
    }
    for (int t = 0; t < 2; ++t) {
      if (nf_[t] == 0) continue;
      out.block(v_start_[s], v_start_[t], nf_[s], nf_[t]) +=
          M.block(offset_[s], offset_[t], nf_[s], nf_[t]);
    }
  }
}

}  // namespace orrery::contact

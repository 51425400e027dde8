#include "contact/contact_tangents.h"

namespace orrery::contact {

ContactTangents::ContactTangents(const FlexibleContactSurface* flexible_a,
                                 const FlexibleContactSurface* flexible_b, int nv)
    : flexible_{flexible_a, flexible_b},
      nf_{flexible_a ? flexible_a->nf() : 0, flexible_b ? flexible_b->nf() : 0} {
  m_ = 12 + nf_[0] + nf_[1];
  for (int s = 0; s < 2; ++s) {
    modal_[s].setZero(3, nf_[s]);
    R_[s].setIdentity();
  }
  K_z_.setZero(m_, m_);
  C_z_.setZero(m_, m_);
  u_.setZero(m_);
  w_.setZero(m_);
  s_.setZero(m_);
  L_.setZero(m_, nv);
  LK_.setZero(m_, nv);
}

void ContactTangents::Clear() {
  K_z_.setZero();
  C_z_.setZero();
  points_ = 0;
}

void ContactTangents::Project(const Vec3& x, Eigen::VectorXd& out) const {
  // Rigid rows: T_p^T x = (p x x, x), + on the node's side, - on the face's.
  const Vec3 moment = p_W_.cross(x);
  for (int s = 0; s < 2; ++s) {
    out.segment<3>(6 * s) = sign_[s] * moment;
    out.segment<3>(6 * s + 3) = sign_[s] * x;
  }
  // Modal rows (their signs are in modal_): Phi^T R^T x.
  int offset = 12;
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
  // Rank-1 terms: (J^T a)(J^T n)^T for the normal force, (J^T d)(J^T d)^T for the slip.
  Project(law.a, u_);
  Project(n_W, w_);
  if (law.k_n != 0) K_z_.noalias() += law.k_n * u_ * w_.transpose();
  if (law.c_n != 0) C_z_.noalias() += law.c_n * u_ * w_.transpose();
  for (int i = 0; i < law.slip_directions; ++i) {
    Project(law.slip_direction[i], s_);
    C_z_.noalias() += law.slip_damping * s_ * s_.transpose();
  }
  ++points_;
}

void ContactTangents::Scatter(const Model& model, const Data& data, BodyIndex body_a,
                              BodyIndex body_b, Eigen::Ref<Eigen::MatrixXd> K,
                              Eigen::Ref<Eigen::MatrixXd> C) {
  if (points_ == 0) return;
  // L: the body Jacobians, then the modal coordinates of the flexible sides.
  L_.setZero();
  if (body_a != kWorldBody) L_.topRows<6>() = data.J_WB[body_a];
  if (body_b != kWorldBody) L_.middleRows<6>(6) = data.J_WB[body_b];
  int offset = 12;
  for (const auto& [s, body] : {std::pair{0, body_a}, std::pair{1, body_b}}) {
    if (nf_[s] == 0) continue;
    const FlexibleBody& f = model.flexible_bodies[model.bodies[body].flexible];
    for (int k = 0; k < nf_[s]; ++k) L_(offset + k, f.v_start + k) = 1;
    offset += nf_[s];
  }
  LK_.noalias() = K_z_ * L_;
  K.noalias() += L_.transpose() * LK_;
  LK_.noalias() = C_z_ * L_;
  C.noalias() += L_.transpose() * LK_;
}

}  // namespace orrery::contact

#pragma once
// Stiffness and damping of a contact element's points for Newton's iteration matrix: the
// AddTangents() of contact_element.h and flexible_contact_element.h (mbd/external_force.h).
//
// A contact point P, where a node of side N touches a face of side F, carries the force f on N
// and -f on F at the node's position p (world). Its relative velocity is linear in the element's
// local velocities
//   z = [V_WA (6); V_WB (6); q_f-dot of A (nf_A); q_f-dot of B (nf_B)]   (m = 12 + nf_A + nf_B)
// as v_rel = J_P z, with the rigid rows +T_p on N's twist and -T_p on F's, T_p = [-[p]x, I]
// (v_p = v + w x p, spatial velocities about the world origin), and the modal rows R_WN Phi_node
// on a flexible N and -sum_k w_k R_WF Phi_k on a flexible F (w_k the barycentric coordinates of
// the face point, Phi_k its vertices' shapes). The same J_P maps f to the local generalized
// forces, Q_z = sum_P J_P^T f. With the law's tangent (contact_law.h: df = -K_P dx_rel -
// C_P dv_rel) and z = L v (L: the body Jacobians data.J_WB of A and B, and the modal
// coordinates' places in v),
//   K += L^T (sum_P J_P^T K_P J_P) L,   C += L^T (sum_P J_P^T C_P J_P) L.
// K_P and C_P are a few rank-1 terms (k_n a n^T, c_n a n^T, the slip directions), so a point
// costs O(m^2) and the scatter O(m nv^2) per element. What is left out: the turning of n and of
// the lever p with the bodies (terms of the order of the force, not of the stiffness), which
// only slows Newton's convergence where forces are large against stiffness times lengths.
// Nothing is allocated after construction.
//
// Usage (inside an element's AddTangents):
//   ContactTangents& t = ws.tangents;   // ContactTangents(nf_a, nf_b, model.nv)
//   t.Clear();
//   for each contact point: t.AddPoint(point, EvaluateContactLawTangent(...), n_W);
//   t.Scatter(model, data, body_a, body_b, K, C);
#include <array>

#include <Eigen/Core>

#include "contact/contact_law.h"
#include "contact/flexible_contact_surface.h"
#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery::contact {

// One contact point as the tangents see it.
struct TangentPoint {
  Vec3 p_W = Vec3::Zero();  // the node's (deformed) position
  bool node_on_a = true;    // the node is on side A (then the face is on B)
  // Flexible node side: the node's surface vertex; flexible face side: the face's three
  // vertices and the face point's barycentric weights. Ignored for a rigid side.
  int node_vertex = -1;
  std::array<int, 3> face_vertices = {-1, -1, -1};
  Vec3 face_weights = Vec3::Zero();
};

class ContactTangents {
 public:
  // flexible_a / flexible_b: the flexible surfaces of the sides (nullptr for rigid ones, or for
  // a flexible side whose body has no modal coordinates); nv the model's velocity count.
  ContactTangents(const FlexibleContactSurface* flexible_a, const FlexibleContactSurface* flexible_b,
                  int nv);

  void Clear();
  // One point with its law tangent and normal (world; towards the node side). R_WA, R_WB: the
  // body rotations (for the modal rows of flexible sides).
  void AddPoint(const TangentPoint& point, const NodeForceTangent& law, const Vec3& n_W,
                const Mat3& R_WA, const Mat3& R_WB);
  // K += L^T K_z L, C += L^T C_z L for the element between body_a and body_b (kWorldBody takes
  // no rows); needs data.J_WB (CalcBodyJacobians).
  void Scatter(const Model& model, const Data& data, BodyIndex body_a, BodyIndex body_b,
               Eigen::Ref<Eigen::MatrixXd> K, Eigen::Ref<Eigen::MatrixXd> C);

  int points() const { return points_; }

 private:
  // x -> J_P^T x for the current point (m), into out.
  void Project(const Vec3& x, Eigen::VectorXd& out) const;

  const FlexibleContactSurface* flexible_[2];
  int nf_[2];
  int m_;
  // The current point's rows: T_p^T x = (p x x, x) is formed directly; the modal rows are kept
  // as 3 x nf blocks in the body axes (R^T applied to x first).
  Vec3 p_W_ = Vec3::Zero();
  double sign_[2] = {1, -1};  // +1 on the node's side, -1 on the face's
  Eigen::Matrix<double, 3, Eigen::Dynamic> modal_[2];  // 3 x nf: Phi rows of the point, per side
  Mat3 R_[2];
  Eigen::MatrixXd K_z_, C_z_;  // m x m
  Eigen::VectorXd u_, w_, s_;  // m
  Eigen::MatrixXd L_, LK_;     // m x nv
  int points_ = 0;
};

}  // namespace orrery::contact

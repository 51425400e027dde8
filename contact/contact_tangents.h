#pragma once
// Stiffness and damping of a contact element's points for Newton's iteration matrix: the
// AddTangents() of contact_element.h and flexible_contact_element.h (mbd/external_force.h).
//
// A contact point P, where a node of side N touches a face of side F, carries the force f on N
// and -f on F at the node's position p (world). Its relative velocity is linear in the element's
// local velocities
//   z = [V_WA - V_WB (6); q_f-dot of A (nf_A); q_f-dot of B (nf_B)]   (m = 6 + nf_A + nf_B)
// as v_rel = J_P z, with the rigid rows +T_p when the node is on A and -T_p when it is on B,
// T_p = [-[p]x, I] (v_p = v + w x p, spatial velocities about the world origin: both sides'
// rigid motions act at the same point p, so only the difference of their twists enters), and
// the modal rows R_WN Phi_node on a flexible N and -sum_k w_k R_WF Phi_k on a flexible F (w_k
// the barycentric coordinates of the face point, Phi_k its vertices' shapes). The same J_P maps
// f to the local generalized forces, Q_z = sum_P J_P^T f. With the law's tangent (contact_law.h:
// df = -K_P dx_rel - C_P dv_rel) and z = L v (L = [J_A - J_B; E]: the body Jacobians data.J_WB
// of A and B, and E the modal coordinates' places in v),
//   K += L^T (sum_P J_P^T K_P J_P) L,   C += L^T (sum_P J_P^T C_P J_P) L.
// K_P and C_P are a few rank-1 terms (k_n a n^T, c_n a n^T, the slip directions): a point's
// columns J_P^T x go into preallocated blocks of kBlock points, and K_z = U diag(k_n) W^T (C_z
// likewise) is made one block at a time as a matrix product (a GEMM of m x m x kBlock, not a
// rank-1 update per term). The scatter uses the structure of L: the body Jacobians are nonzero
// only in the columns of the bodies' joint chains (a few in a torsional train) and E is a
// selector, so L^T K_z L costs O(m ns (6 + ns)) with ns those columns, not O(m nv^2). What is
// left out: the turning of n and of the lever p with the bodies (terms of the order of the
// force, not of the stiffness), which only slows Newton's convergence where forces are large
// against stiffness times lengths.
// Nothing is allocated after construction.
//
// Usage (inside an element's AddTangents):
//   ContactTangents& t = ws.tangents;   // ContactTangents(nf_a, nf_b, model.nv)
//   t.Clear();
//   for each contact point: t.AddPoint(point, EvaluateContactLawTangent(...), n_W);
//   t.Scatter(model, data, body_a, body_b, K, C);
#include <array>
#include <vector>

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
  // Points per block of gathered columns (K: one column per point, C: up to three).
  static constexpr int kBlock = 32;

 private:
  // x -> J_P^T x for the current point (m), into out.
  void Project(const Vec3& x, Eigen::Ref<Eigen::VectorXd> out) const;
  // K_z += U_K W_K^T, C_z += U_C W_C^T over the columns gathered since the last flush.
  void Flush();
  // out += L^T M L (M: K_z or C_z) with the support's columns of the body Jacobians in J_s_.
  void ScatterOne(const Eigen::MatrixXd& M, Eigen::Ref<Eigen::MatrixXd> out);

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
  Eigen::VectorXd u_, w_;      // m: J^T a and J^T n of the current point
  // Gathered columns: k_n J^T a and J^T n per point (m x kBlock); c_n J^T a and J^T n, and
  // slip_damping J^T d and J^T d per slip direction (m x 3 kBlock).
  Eigen::MatrixXd U_K_, W_K_, U_C_, W_C_;
  int columns_k_ = 0, columns_c_ = 0;
  // Scatter: the velocity coordinates the body Jacobians can touch (the joints from each body
  // to the root; filled in each Scatter, capacity nv), their columns of J_A - J_B (6 x nv, the
  // first support_.size() used), and products (m x nv, nv x m, nv x nv).
  std::vector<int> support_;
  std::vector<char> in_support_;  // nv: support_'s membership
  Eigen::MatrixXd J_s_, X_, Y_, Z_;
  int offset_[2] = {6, 6};    // each side's modal rows in z (Scatter sets both)
  int v_start_[2] = {0, 0};   // and their coordinates in v
  int points_ = 0;
};

}  // namespace orrery::contact

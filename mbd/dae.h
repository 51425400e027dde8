#pragma once
// The equations of motion as a stabilized index-2 DAE (Gear-Gupta-Leimkuhler), for IDA.
//
// Unknowns y = (q [nq], v [nv], lambda [nc], mu [nh]) and their derivatives yp. Residual:
//   r_q   = q-dot - N(q) (v + G_h^T mu)          (GGL: mu = 0 on the exact solution)
//   r_v   = M(q) v-dot + C(q, v) - Q(q, v, t) + G^T lambda
//   r_lam = G(q) v + g_t(t)                      (velocity constraints, all rows)
//   r_mu  = Phi(q, t)                            (position constraints, holonomic rows)
// G_h: the holonomic rows of G. The GGL projection uses N G_h^T in place of Phi_q^T: since
// Phi_q N = G_h, differentiating r_mu along a solution gives G_h G_h^T mu = 0, so mu = 0 exactly as
// in the original form, and no constraint partial with respect to quaternion coordinates is
// needed. lambda and mu are algebraic (excluded from IDA's error test).
//
// Sign of the multipliers (every integrator, Linearize and the result file share it): r_v = 0 reads
// M v-dot + C = Q - G^T lambda, so the constraints apply the generalized force -G^T lambda, and a
// row's multiplier is the force the constraint exerts *against* the direction in which its row
// grows. Per kind of row:
//   driver (v_k = f(t) or q_k = f(t); G row e_k): the driver applies -lambda to coordinate k; its
//     effort (torque or force along the coordinate, /drivers/<name>/effort) is -lambda: positive
//     when the driver pushes the coordinate forward;
//   gear constraint (delta_drive = 0, model.h GearConstraintSpec): lambda is the tooth force on
//     gear b along n_drive (/gear_constraints/<name>/force);
//   loop closure (rows of LoopClosureSpec in world or frame-A axes): the bodies of A and B feel
//     the wrenches -c lambda (constraints.h CalcConstraintForces); /loop_closures/<name>/reaction
//     is the wrench on frame B's body.
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "mbd/data.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {

class DaeSystem {
 public:
  explicit DaeSystem(const Model& model);

  int size() const { return n_; }
  int nq() const { return nq_; }
  int nv() const { return nv_; }
  int nc() const { return nc_; }
  int nh() const { return nh_; }
  // Offsets of the blocks in y.
  int q_offset() const { return 0; }
  int v_offset() const { return nq_; }
  int lambda_offset() const { return nq_ + nv_; }
  int mu_offset() const { return nq_ + nv_ + nc_; }

  // r(t, y, yp) (all size()). Allocation-free.
  void Residual(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                const Eigen::Ref<const Eigen::VectorXd>& yp, Eigen::Ref<Eigen::VectorXd> r);

  // J = dr/dy + cj dr/dyp (size() x size(), column-major). Analytic in the block structure
  // (cj I, cj M, N, N G_h^T, G, G^T, quaternion kinematics); the q- and v-dependence of the
  // generalized forces and of G is taken by forward differences in velocity space (one pipeline
  // evaluation per column). Allocation-free.
  void Jacobian(double t, double cj, const Eigen::Ref<const Eigen::VectorXd>& y,
                const Eigen::Ref<const Eigen::VectorXd>& yp, Eigen::Ref<Eigen::MatrixXd> J);

  // Tangent matrices at (t, q, v, vdot, lambda), by forward differences in velocity space:
  //   Kq ((nv + nc) x nv): d(r_v, r_lam)/d(dq) for q <- q (+) dq,   Cv (nv x nv): d r_v / d v.
  // Elements with analytic tangents (lumped gear meshes, gear_mesh.h; external elements,
  // external_force.h) are left out of the differences and add their own at the base point
  // (unless set_element_tangents(false)). Then coordinates of subtrees that no differenced element
  // couples share a perturbed evaluation (GroupDifferences; seed 002: 24 evaluations for 36
  // columns), with the same result to the last bit.
  // Leaves data() at the base point with data().M computed.
  void Tangents(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                const Eigen::Ref<const Eigen::VectorXd>& v,
                const Eigen::Ref<const Eigen::VectorXd>& vdot,
                const Eigen::Ref<const Eigen::VectorXd>& lambda, Eigen::Ref<Eigen::MatrixXd> Kq,
                Eigen::Ref<Eigen::MatrixXd> Cv);

  // Consistent accelerations and multipliers at a state on the constraint manifold: solves
  // [M G^T; G 0] [vdot; lambda] = [Q - C; -gamma], gamma = d/dt (G v + g_t) at vdot = 0.
  // Fills y and yp for the state (mu = 0). Throws std::runtime_error if the KKT matrix is
  // singular.
  void ConsistentInitial(const State& state, Eigen::Ref<Eigen::VectorXd> y,
                         Eigen::Ref<Eigen::VectorXd> yp);

  // Accelerations and multipliers at (t, q, v) (same KKT solve), into vdot (nv), lambda (nc).
  // Allocation-free; throws std::runtime_error if the KKT matrix is singular.
  void SolveAccelerations(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> vdot,
                          Eigen::Ref<Eigen::VectorXd> lambda);

  // Whether Tangents() takes the analytic tangents of the elements that have them (default) or
  // differences through them too (the oracle in tests).
  void set_element_tangents(bool use) { use_element_tangents_ = use; }

  // Whether Tangents() perturbs coordinates of uncoupled subtrees together (default; the
  // Jacobians are the same to the last bit, GroupDifferences) or one column per evaluation (the
  // oracle in tests).
  void set_grouped_differences(bool use) { use_groups_ = use; }
  // Whether Tangents() takes the modal columns of leaf flexible bodies from their equations
  // (default; SetFlexibleModalTangents, when ModalColumnsAreLocal and the element tangents are
  // used) or by differences like every other column (the oracle in tests).
  void set_analytic_modal_columns(bool use) { use_analytic_modal_ = use; }
  // Columns Tangents() takes by differences (with the analytic modal columns: nv less the modal
  // coordinates of the bodies they serve).
  int differenced_columns() const;

  // Pipeline evaluations per set of position (or velocity) differences when grouped: the number
  // of groups (0: the model's columns are not grouped).
  int difference_groups() const { return static_cast<int>(group_columns_.size()); }

  Data& data() { return data_; }
  const Data& data() const { return data_; }
  const Model& model() const { return model_; }
  long residual_evaluations() const { return residual_evaluations_; }

 private:
  // r_v and r_lam at (t, q, v, vdot, lambda) into rv (nv), rl (nc); runs the pipeline.
  void DynamicRows(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                   const Eigen::Ref<const Eigen::VectorXd>& v,
                   const Eigen::Ref<const Eigen::VectorXd>& vdot,
                   const Eigen::Ref<const Eigen::VectorXd>& lambda, Eigen::Ref<Eigen::VectorXd> rv,
                   Eigen::Ref<Eigen::VectorXd> rl);

  // Classes of coordinates whose differences may share one perturbed evaluation (Tangents with
  // the analytic element tangents): the subtrees on the world, joined where an element that is
  // differenced (springs, bushings, bearings) connects two of them. Set by the constructor when
  // the model allows it (no loop closures, gear constraints, external elements or flexible
  // bodies, at least two classes); class_of_row_ then names each row's class (nv + nc), and
  // group_columns_ lists per group the coordinates perturbed together (one per class).
  void GroupDifferences();
  // Tangents' differences with one perturbed evaluation per group: the columns of each class
  // from the rows of its class, every other row as the one-column differences leave it (the
  // rounding of q (+) 0 and of the base's rv0_ against the evaluated rows: from rz_ and tau_base_).
  void GroupedPositionColumns(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                              const Eigen::Ref<const Eigen::VectorXd>& v,
                              const Eigen::Ref<const Eigen::VectorXd>& vdot,
                              const Eigen::Ref<const Eigen::VectorXd>& lambda,
                              Eigen::Ref<Eigen::MatrixXd> Kq);
  void GroupedVelocityColumns(double t, const Eigen::Ref<const Eigen::VectorXd>& v,
                              const Eigen::Ref<const Eigen::VectorXd>& vdot,
                              Eigen::Ref<Eigen::MatrixXd> Cv);

  const Model& model_;
  Data data_;
  int nq_, nv_, nc_, nh_, n_;
  long residual_evaluations_ = 0;
  bool any_element_tangents_ = false;  // lumped meshes or an external element with analytic tangents
  bool use_element_tangents_ = true;
  bool use_groups_ = true;
  bool use_analytic_modal_ = true;
  // Flexible bodies whose modal columns SetFlexibleModalTangents makes (ModalColumnsAreLocal),
  // and per velocity coordinate whether it is one of theirs (nv).
  std::vector<int> analytic_modal_bodies_;
  std::vector<char> analytic_column_;
  std::vector<int> class_of_row_;                // nv + nc (empty: no grouping)
  std::vector<std::vector<int>> group_columns_;  // per group: the coordinates perturbed together
  Eigen::VectorXd rvz_, rlz_, tau_base_;         // grouped differences' scratch (nv, nc, nv)
  // Scratch, sized once.
  Eigen::VectorXd mesh_row_, mesh_phase_row_;  // AddGearMeshTangents' scratch rows (nv)
  Eigen::VectorXd qdot_, w_, q_pert_, v_pert_, dv_, rv0_, rl0_, rv1_, rl1_;
  Eigen::MatrixXd dq_dv_;   // nq x nv: d(q (+) dv)/d(dv) at dv = 0  (N for quaternion blocks)
  Eigen::MatrixXd dv_dq_;   // nv x nq: its left inverse (2 E(q) for quaternions)
  Eigen::MatrixXd G_ref_, Jv_, Cv_;  // nc x nv, (nv+nc) x nv, nv x nv
  Eigen::MatrixXd kkt_;
  Eigen::VectorXd kkt_rhs_, kkt_x_, gamma_, zero_nv_;
  Eigen::PartialPivLU<Eigen::MatrixXd> kkt_lu_;
};

}  // namespace orrery

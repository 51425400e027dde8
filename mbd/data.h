#pragma once
// Workspace of the step pipeline: every intermediate result, sized once from the model.
// Each field says which function fills it and its size; nothing here allocates after
// construction.
#include <exception>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "mbd/model.h"

namespace orrery {

struct Data {
  explicit Data(const Model& model);

  // --- CalcPositionKinematics (kinematics.cpp) ---
  std::vector<Transform> X_WB;        // nbodies: body poses (X_WB[0] = identity)
  std::vector<Transform> X_WF;        // njoints: pose of each joint's frame F
  std::vector<Transform> X_FM;        // njoints: joint transform
  std::vector<Transform> X_WFrame;    // nframes: pose of every named frame
  Eigen::Matrix<double, 6, Eigen::Dynamic> S;  // 6 x nv: joint motion subspaces, world origin
  std::vector<SpatialInertia> I_W;    // nbodies: body spatial inertia about the world origin
  Eigen::VectorXd q_normalized;       // nq: q with unit quaternions (what kinematics used)
  // Frames on flexible-body nodes: d V_WFrame / d q_f-dot (6 x nf of the frame's body, world
  // origin); empty for other frames.
  std::vector<Eigen::Matrix<double, 6, Eigen::Dynamic>> J_frame_modal;  // nframes

  // Per flexible body, what its modal coordinates make of the invariants (flexible_body.h), in
  // B axes about B's origin; filled by CalcPositionKinematics, used by the dynamics stages.
  struct FlexibleBodyTerms {
    Eigen::VectorXd qf;          // nf: modal coordinates (position stage)
    Eigen::VectorXd qf_dot;      // nf: modal rates (velocity stage)
    Vec3 S = Vec3::Zero();       // first moment int rho u dV (kg m)
    Mat3 J = Mat3::Zero();       // inertia about B's origin (kg m^2)
    Eigen::Matrix<double, 3, Eigen::Dynamic> D;  // 3 x 3 nf: D_l = int rho u Phi_l^T, block l
    Eigen::Matrix<double, 3, Eigen::Dynamic> L;  // 3 x nf: int rho u x Phi_l
    Eigen::Matrix<double, 6, Eigen::Dynamic> F_W;  // 6 x nf: spatial force on B (world origin)
                                                   // per unit modal acceleration (M_rf)
    Eigen::MatrixXd K_geo;       // nf x nf: geometric stiffness at the current omega (force
                                 //   elements stage)
    Eigen::VectorXd scratch;     // nf
    // The modal Coriolis sums g_l = sum_k q_f-dot_k mode_cross_kl (column l; model.h), made by
    // CalcFlexibleBodyForce.
    Eigen::Matrix<double, 3, Eigen::Dynamic> G;  // 3 x nf
    // What the O(nf^2) sums above were made from, so that a stage called again at the same
    // modal coordinates (the position differences of DaeSystem::Tangents over rigid coordinates,
    // its base points) reuses them; compared bit for bit (flexible_dynamics.cpp).
    Eigen::VectorXd qf_of_D;      // nf: the qf that S, J, D, L were made at (position stage)
    Eigen::VectorXd qf_dot_of_G;  // nf: the qf_dot that G was made at (inverse-dynamics stage)
    bool D_made = false, G_made = false;
  };
  std::vector<FlexibleBodyTerms> flex;  // n flexible bodies

  // --- CalcBodyJacobians (kinematics.cpp), on demand (DaeSystem::Tangents) ---
  // nbodies x (6 x nv): V_WB = J_WB v; empty unless the model has lumped gear meshes or an
  // external element with analytic tangents.
  std::vector<Eigen::Matrix<double, 6, Eigen::Dynamic>> J_WB;

  // --- CalcVelocityKinematics (kinematics.cpp) ---
  std::vector<Vec6> V_WB;             // nbodies: body spatial velocities, world origin
  std::vector<Vec6> c_J;              // njoints: S-dot v of each joint (velocity-product accel.)
  std::vector<Vec6> V_WFrame;         // nframes: spatial velocity of each frame (its body's, plus
                                      //   the node's deformation rate for node frames)

  // --- CalcForceElements (force_elements.cpp) ---
  std::vector<Vec6> f_ext;            // nbodies: external spatial forces on bodies, world origin
  Eigen::VectorXd tau_applied;        // nv: generalized forces applied on joint coordinates
  double potential_energy = 0;        // J: elastic energy of force elements (gravity excluded)
  double power_applied = 0;           // W: power of applied loads and joint loads
  double power_dissipated = 0;        // W: power taken out by the dampers (>= 0)
  std::vector<double> mesh_force;     // n_meshes: tooth force along the contact normal (N)
  std::vector<double> mesh_deflection;  // n_meshes: compression of the engaged flank (m)
  std::vector<double> mesh_stiffness;   // n_meshes: k at the current mesh phase (N/m)
  std::vector<double> mesh_phase;       // n_meshes: mesh phase (cycles)
  std::vector<int> mesh_contact;        // n_meshes: +1 drive flank, -1 coast flank, 0 apart
  std::vector<double> gear_angle;       // Model::gear_angles: each gear's angle (rad), filled by
                                        //   CalcGearAngles before the meshes
  // One per Model::external_forces element, made by the element (its caches and outputs); filled
  // by the element's Apply() at the end of CalcForceElements.
  std::vector<std::unique_ptr<ExternalForceWorkspace>> external;
  // The state (t, q_normalized, v) whose results the workspaces of the external elements with
  // analytic tangents and split Apply() hold (their last evaluation that did not skip them): an
  // evaluation at that very state, bit for bit, adds those results again (AddTo) instead of
  // computing them (Apply is a function of (t, q, v), external_force.h): DaeSystem::Tangents'
  // last pass at the iterate a residual was just evaluated at. Filled by CalcExternalForces;
  // t NaN: none (before the first evaluation, during one, after a failed one, a warm start or
  // the elements' AddTangents).
  double tangent_elements_t = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd tangent_elements_q, tangent_elements_v;  // nq, nv
  // Set by DaeSystem::Tangents while it takes finite differences: CalcForceElements then leaves
  // out the elements with analytic tangents (the lumped gear meshes, and the external elements
  // whose ExternalForceElement::HasTangents() is true).
  bool skip_elements_with_tangents = false;
  // Threads over which CalcForceElements spreads the external elements whose SplitsApply() is
  // true (set once by the integrator from IntegratorOptions::threads; 1: all on the caller's).
  int threads = 1;
  // One per external element: an exception its Compute() threw on a worker thread, rethrown by
  // CalcForceElements in element order after the parallel loop.
  std::vector<std::exception_ptr> external_errors;

  // --- CalcInverseDynamics (dynamics.cpp) ---
  std::vector<Vec6> A_WB;             // nbodies: body spatial accelerations (gravity included
                                      //   as a base acceleration -g, Featherstone's trick); also
                                      //   filled alone by CalcAccelerationKinematics
  std::vector<Vec6> f_joint;          // nbodies: spatial force transmitted by each body's parent
                                      //   joint from parent to child, world origin
  Eigen::VectorXd tau_id;             // nv: M v-dot + C(q, v) - Q_ext(q, v, t)

  // --- CalcMassMatrix (dynamics.cpp) ---
  std::vector<SpatialInertia> I_c;    // nbodies: composite inertias of subtrees
  Eigen::MatrixXd M;                  // nv x nv: joint-space mass matrix (lower and upper filled)

  // --- CalcConstraints (constraints.cpp) ---
  Eigen::VectorXd phi;                // n_holonomic: position constraint values Phi(q, t)
  Eigen::MatrixXd G;                  // n_constraints x nv: velocity Jacobian (Phi_q N for
                                      //   holonomic rows)
  Eigen::VectorXd g_t;                // n_constraints: G v + g_t = 0 is the velocity constraint
  std::vector<Vec6> c_rows_a, c_rows_b;  // n_loop_rows: each loop row's partials w.r.t. the
                                      //   spatial velocities of bodies a and b (world origin)
  std::vector<Vec6> c_gear_a, c_gear_b, c_gear_c;  // n_gear_constraints: partials w.r.t. the
                                      //   spatial velocities of gears a, b and the reference body

  // --- CalcSensorSignals (sensor_signals.cpp) ---
  Eigen::VectorXd sensor_values;      // model.n_sensor_channels: every sensor's reading, in the
                                      //   order of Model::sensors (Sensor::channel_start)
  Eigen::VectorXd element_outputs;    // largest Sensor::element_values: scratch for the outputs
                                      //   of an external element a sensor reads

  // --- scratch for the stages above ---
  Eigen::VectorXd scratch_nv;         // nv
};

// Adds the spatial force f (world origin) acting on frame `frame` to the generalized forces:
// data.f_ext of its body, and for a frame on a flexible-body node the modal forces J^T f.
void AddFrameForce(const Model& model, Data& data, FrameIndex frame, const Vec6& f);

// S_j x: the spatial motion of joint columns [v_start, v_start + nv) times the matching entries
// of x (nv-length loops beat Eigen's dynamic-size products for the 1-6 columns of a joint).
template <class Vector>
inline Vec6 JointMotion(const Data& data, int v_start, int nv, const Vector& x) {
  Vec6 m = Vec6::Zero();
  for (int k = 0; k < nv; ++k) m.noalias() += data.S.col(v_start + k) * x(v_start + k);
  return m;
}

}  // namespace orrery

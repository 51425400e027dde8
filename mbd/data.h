#pragma once
// Workspace of the step pipeline: every intermediate result, sized once from the model.
// Each field says which function fills it and its size; nothing here allocates after
// construction.
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

  // --- CalcVelocityKinematics (kinematics.cpp) ---
  std::vector<Vec6> V_WB;             // nbodies: body spatial velocities, world origin
  std::vector<Vec6> c_J;              // njoints: S-dot v of each joint (velocity-product accel.)

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

  // --- CalcInverseDynamics (inverse_dynamics.cpp) ---
  std::vector<Vec6> A_WB;             // nbodies: body spatial accelerations (gravity included
                                      //   as a base acceleration -g, Featherstone's trick)
  std::vector<Vec6> f_joint;          // nbodies: spatial force transmitted by each body's parent
                                      //   joint from parent to child, world origin
  Eigen::VectorXd tau_id;             // nv: M v-dot + C(q, v) - Q_ext(q, v, t)

  // --- CalcMassMatrix (mass_matrix.cpp) ---
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

  // --- scratch for the stages above ---
  Eigen::VectorXd scratch_nv;         // nv
};

// S_j x: the spatial motion of joint columns [v_start, v_start + nv) times the matching entries
// of x (nv-length loops beat Eigen's dynamic-size products for the 1-6 columns of a joint).
template <class Vector>
inline Vec6 JointMotion(const Data& data, int v_start, int nv, const Vector& x) {
  Vec6 m = Vec6::Zero();
  for (int k = 0; k < nv; ++k) m.noalias() += data.S.col(v_start + k) * x(v_start + k);
  return m;
}

}  // namespace orrery

#pragma once
// Recursive kinematics over the joint tree (first stages of a step).
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Fills data.q_normalized, X_WF, X_FM, X_WB, X_WFrame, S and I_W from positions q (nq).
// Body poses: X_WB = X_WP X_PF X_FM(q) X_MC. Joint motion subspaces S (6 x nv) are world-origin
// spatial vectors: a body's spatial velocity is V_WB = V_WP + S_j v_j (seed 003 eq. 3, V = B v).
void CalcPositionKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                            Data& data);

// The poses part of CalcPositionKinematics: data.q_normalized, X_WF, X_FM, X_WB, S, X_WFrame
// (node frames with their modal Jacobians J_frame_modal) and the modal coordinates, without the
// inertias I_W and the flexible bodies' inertia terms (what sensors need).
void CalcFramePoses(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q, Data& data);

// Fills data.V_WB and data.c_J from velocities v (nv); needs CalcPositionKinematics first.
// c_J = S-dot v = V_WP x (S v) + Ad(X_WF) (dS_F/dt v) is the velocity-product acceleration.
void CalcVelocityKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& v,
                            Data& data);

// Fills data.A_WB (nbodies, world-origin spatial accelerations) from accelerations vdot (nv):
// A_WB = A_WP + S_j vdot_j + c_J, with the world accelerating at (0, -g) as in
// CalcInverseDynamics (which fills the same values), so a body's own acceleration is
// A_WB - (0, -g). Needs CalcVelocityKinematics first.
void CalcAccelerationKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& vdot,
                                Data& data);

// Fills data.J_WB: each body's spatial velocity (world origin) as V_WB = J_WB v, the sums of the
// motion subspaces S of the joints from the root to the body (a flexible body's own modal
// coordinates do not move its frame). Needs CalcPositionKinematics first and data.J_WB sized
// (Data sizes it when an external element has analytic tangents).
void CalcBodyJacobians(const Model& model, Data& data);

// q-dot = N(q) v (nq from nv); identity except quaternion blocks: q-dot = 1/2 (0, w_F) x q.
void CalcQDot(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> qdot);

// q <- q (+) dv: adds a velocity-space increment (nv) to positions; quaternion blocks are turned
// by the rotation vector dv_w (exponential map) and renormalized.
void IntegratePositions(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& dv,
                        Eigen::Ref<Eigen::VectorXd> q);

// Normalizes the quaternion blocks of q in place.
void NormalizeQuaternions(const Model& model, Eigen::Ref<Eigen::VectorXd> q);

}  // namespace orrery

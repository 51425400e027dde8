#pragma once
// The floating-frame terms of flexible bodies (flexible_body.h), one function per pipeline stage
// that needs them; each is called by that stage and does nothing for a model without flexible
// bodies.
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Position stage, poses (CalcFramePoses, after the body poses): the modal coordinates
// data.flex[i].qf and the poses of node frames with their modal Jacobians data.J_frame_modal.
void CalcNodeFramePoses(const Model& model, const Eigen::VectorXd& q, Data& data);

// Position stage, inertias (CalcPositionKinematics, after CalcNodeFramePoses): data.flex terms
// (S, J, D, L, F_W) and the deformed spatial inertia data.I_W of each flexible body.
void CalcFlexibleInertiaTerms(const Model& model, Data& data);

// Velocity stage: data.V_WFrame of every frame (node frames add J_frame_modal q_f-dot) and the
// modal rates data.flex[i].qf_dot.
void CalcFrameVelocities(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& v, Data& data);

// Force-element stage: elastic, damping and geometric-stiffening forces -(K + K_g) q_f - D q_f-dot
// into data.tau_applied; returns (elastic energy 1/2 q^T K q, dissipated power q-dot^T D q-dot).
std::pair<double, double> CalcFlexibleInternalForces(const Model& model, Data& data);

// Inverse-dynamics stage, forward pass: the spatial force (world origin) that body b's rigid
// frame needs for the accelerations A = data.A_WB[b] and vdot, minus data.f_ext[b], and the modal
// rows of data.tau_id (before the applied forces are subtracted).
Vec6 CalcFlexibleBodyForce(const Model& model, const FlexibleBody& fb,
                           const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data);

// Mass-matrix stage: the rigid-modal coupling and modal blocks (the rigid block comes from the
// composite-rigid-body pass with the deformed inertia).
void AddFlexibleMassMatrix(const Model& model, Data& data);

// Kinetic energy beyond 1/2 V^T I_W V of the flexible bodies: V^T F_W q-dot + 1/2 q-dot^T M q-dot.
double FlexibleKineticEnergy(const Model& model, const Data& data);

// Spatial momentum (world origin) of the whole model: sum of I_W V plus the flexible bodies'
// F_W q-dot. Needs the kinematics stages.
Vec6 CalcSpatialMomentum(const Model& model, const Data& data);

}  // namespace orrery

#pragma once
// Inverse dynamics (recursive Newton-Euler) and the joint-space mass matrix (composite rigid
// body algorithm), Featherstone "Rigid Body Dynamics Algorithms" ch. 5-6, in world coordinates.
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// data.tau_id = M(q) vdot + C(q, v) - Q(q, v, t): the generalized forces that, added to the
// applied ones (data.tau_applied, data.f_ext, gravity), produce the accelerations vdot (nv).
// Needs CalcPositionKinematics, CalcVelocityKinematics and CalcForceElements. Also fills
// data.A_WB (with the base acceleration -g) and data.f_joint (subtree spatial forces).
void CalcInverseDynamics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& vdot,
                         Data& data);

// data.M (nv x nv, symmetric, both triangles) by the composite-rigid-body pass; needs
// CalcPositionKinematics.
void CalcMassMatrix(const Model& model, Data& data);

// The diagonal of the rigid tree's mass matrix (nv), equal to CalcMassMatrix's to the last bit
// (the same composite inertias data.I_c, which it fills, and the same products S_k . (I_c S_k)),
// without the off-diagonal entries. Needs CalcPositionKinematics. Flexible bodies' coordinates
// are not filled (CalcMassMatrix adds them): for models without flexible bodies.
void CalcMassMatrixDiagonal(const Model& model, Data& data, Eigen::Ref<Eigen::VectorXd> diagonal);

// Kinetic energy 1/2 v^T M v (J) from body velocities; needs the kinematics stages.
double CalcKineticEnergy(const Model& model, const Data& data);
// Gravitational potential energy -m g.p_cm summed over bodies (J); needs position kinematics.
double CalcGravityPotential(const Model& model, const Data& data);

}  // namespace orrery

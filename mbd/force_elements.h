#pragma once
// Force elements: applied loads, spring-dampers and bushings (gravity is handled as a base
// acceleration in CalcInverseDynamics).
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Fills data.f_ext (spatial forces on bodies, world origin), data.tau_applied (forces on joint
// coordinates), data.potential_energy, and the power bookkeeping data.power_applied (loads) and
// data.power_dissipated (dampers) at time t. Needs position and velocity kinematics;
// reads joint coordinates from data.q_normalized and velocities from `v` (nv).
void CalcForceElements(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& v,
                       Data& data);

}  // namespace orrery

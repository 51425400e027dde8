#pragma once
// One evaluation of the equations of motion: the table of contents of a step.
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Runs the pipeline at (t, q, v, vdot):
//   CalcPositionKinematics -> CalcVelocityKinematics -> CalcForceElements -> CalcConstraints
//   -> CalcInverseDynamics
// after which data.tau_id = M vdot + C - Q, data.phi, data.G and data.g_t hold the equations'
// terms. Allocation-free.
void EvaluateDynamics(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& v,
                      const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data);

}  // namespace orrery

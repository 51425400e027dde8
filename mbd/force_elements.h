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

// The external elements' part of CalcForceElements (mbd/external_force.h): with data.threads > 1
// the elements whose SplitsApply() is true are computed in parallel (OpenMP, GCC's libgomp:
// a parallel loop over a handful of heavy elements per evaluation, with no task graph to
// express), then every element's results are added to data on this thread in element order, so
// the sums are bit-identical for any thread count. An exception thrown by an element on a worker
// thread is rethrown here (the first in element order). An element with analytic tangents and
// split Apply() whose workspace holds this very state (data.tangent_elements_*: t, q_normalized
// and v bit for bit) is not computed again: its results are added (AddTo).
void CalcExternalForces(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& v,
                        Data& data);

// ExternalForceElement::WarmStart of every external element from source's workspaces into
// target's (two Data of the same model): the recorder's evaluation at an output row then
// starts its tracking from the integrator's last evaluation, a step away, instead of from the
// last row. target's workspaces no longer hold its last state (data.tangent_elements_t).
// target is to be evaluated next, before source changes (an element may copy from source at
// that evaluation: ExternalForceElement::WarmStart). Allocation-free.
void WarmStartExternalWorkspaces(const Model& model, const Data& source, Data& target);

}  // namespace orrery

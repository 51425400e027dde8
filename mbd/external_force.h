#pragma once
// Force elements implemented outside mbd/ (tooth contact in contact/, which owns FCL): the model
// holds them as immutable descriptions, and each Data gets the element's mutable workspace
// (caches, broad-phase state, output values) once, at construction. The step calls Apply() after
// the built-in force elements; Apply() must not allocate.
//
// Apply() adds spatial forces (world coordinates, about the world origin) to data.f_ext[body],
// generalized forces to data.tau_applied (for example modal forces of flexible bodies), its
// elastic energy to data.potential_energy and the power it dissipates to data.power_dissipated.
// Its stiffness and damping reach the integrators' Jacobians in one of two ways:
// - by the differences DaeSystem::Tangents takes in q and v (one whole pipeline evaluation per
//   coordinate), so Apply() must be a deterministic function of (t, q, v) apart from caching;
// - or, for an element whose HasTangents() is true, from its own AddTangents(): such an element
//   is left out of the differences (its Apply() is not called for the perturbed states) and adds
//   its stiffness and damping at the state of its last Apply(). Tooth contact does this: a
//   difference column costs a contact evaluation, and a perturbed modal coordinate moves every
//   tracked node of a flexible surface.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace orrery {

class Model;
struct Data;

class ExternalForceWorkspace {
 public:
  virtual ~ExternalForceWorkspace() = default;
};

// One output of an element, recorded per output step under /external/<element>/<name>: a series
// of `columns` values per row (a contact's total normal force: 1; its n largest contact points'
// positions: 3 n), in SI `unit` ("N", "m", "N/m", "1").
struct OutputDescription {
  std::string name;
  std::string unit = "1";
  int columns = 1;
};

// Every method is required: an element states whether it has analytic tangents and what it
// outputs (an empty list is an answer), so that no kind forgets either.
class ExternalForceElement {
 public:
  virtual ~ExternalForceElement() = default;

  virtual const std::string& name() const = 0;
  // Called once per Data, after the model is finalized.
  virtual std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model& model) const = 0;
  // Needs position and velocity kinematics (data.X_WB, X_WFrame, V_WB, V_WFrame).
  virtual void Apply(const Model& model, double t, Data& data,
                     ExternalForceWorkspace& workspace) const = 0;

  // Apply() in two halves, so that the elements of one evaluation can be computed on several
  // threads (Data::threads, force_elements.cpp): Compute() does Apply()'s work into the
  // workspace alone, reading data (kinematics, modal coordinates) and writing nothing else, and
  // AddTo() adds the workspace's results to data. The loop calls AddTo() on one thread in element
  // order, so a run writes the same numbers to the last bit whatever the thread count; Apply()
  // must be Compute() then AddTo(). An element whose SplitsApply() is false (the default) is
  // applied by Apply() in that serial loop.
  virtual bool SplitsApply() const { return false; }
  virtual void Compute(const Model& /*model*/, double /*t*/, const Data& /*data*/,
                       ExternalForceWorkspace& /*workspace*/) const {}
  virtual void AddTo(const Model& /*model*/, const ExternalForceWorkspace& /*workspace*/,
                     Data& /*data*/) const {}

  // Analytic tangents. false: the element is left to DaeSystem::Tangents' finite differences
  // and AddTangents() is never called. true: AddTangents() adds, at the state of the element's
  // last Apply() (which DaeSystem::Tangents makes the base point),
  //   K (nv x nv) += -dQ/d(dq),   C (nv x nv) += -dQ/dv,
  // Q the element's generalized forces, dq a position increment in velocity space (q (+) dq).
  // Body velocities are V_WB = data.J_WB[b] v (CalcBodyJacobians, filled before the call).
  // Terms of the order of the forces times the lever changes (the turning of a force's
  // direction and point of action) may be left out: the tangents feed Newton's iteration
  // matrix, whose accuracy sets the convergence rate, not the solution.
  virtual bool HasTangents() const = 0;
  virtual void AddTangents(const Model& model, const Data& data,
                           ExternalForceWorkspace& workspace, Eigen::Ref<Eigen::MatrixXd> K,
                           Eigen::Ref<Eigen::MatrixXd> C) const = 0;

  // Warm start: copies what `source` keeps from one evaluation to the next to steer the next
  // (a contact's tracked closest faces, sleeping nodes and odometers, tracked_gaps.h) into
  // `target`, a workspace of the same element in another Data, so that target's next evaluation
  // starts from where source's last one stood instead of from its own older one. It must not
  // change what that evaluation computes (only how much work it takes), nor copy a cache whose
  // validity `target` tracks itself without what its validity is tracked by (a contact's last
  // gaps go with their poses); it must not allocate. It may keep source's address until
  // target's next evaluation, to copy from there what that evaluation needs (a contact at the
  // gaps' poses needs no tracking state): the caller evaluates target next, before source
  // changes, and target drops the address at that evaluation. Default: nothing.
  // The result recorder calls it before each row with the integrator's workspace as source
  // (WarmStartExternalWorkspaces, mbd/force_elements.h).
  virtual void WarmStart(const ExternalForceWorkspace& /*source*/,
                         ExternalForceWorkspace& /*target*/) const {}

  // The element's outputs, fixed from construction (the recorder declares them once).
  virtual const std::vector<OutputDescription>& outputs() const = 0;
  // Writes the outputs' values of the last Apply(), in the order of outputs(), each output's
  // columns in turn (sum of the columns values in all).
  virtual void GetOutputs(const ExternalForceWorkspace& workspace, double* values) const = 0;
};

// Number of values GetOutputs() writes: the sum of the outputs' columns.
int OutputValueCount(const std::vector<OutputDescription>& outputs);

}  // namespace orrery

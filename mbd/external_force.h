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
//   tracked tooth of a flexible gear.
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

class ExternalForceElement {
 public:
  virtual ~ExternalForceElement() = default;

  virtual const std::string& name() const = 0;
  // Called once per Data, after the model is finalized.
  virtual std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model& model) const = 0;
  // Needs position and velocity kinematics (data.X_WB, X_WFrame, V_WB, V_WFrame).
  virtual void Apply(const Model& model, double t, Data& data,
                     ExternalForceWorkspace& workspace) const = 0;

  // Analytic tangents (optional; the default leaves the element to the finite differences).
  // AddTangents() adds, at the state of the element's last Apply() (which DaeSystem::Tangents
  // makes the base point),
  //   K (nv x nv) += -dQ/d(dq),   C (nv x nv) += -dQ/dv,
  // Q the element's generalized forces, dq a position increment in velocity space (q (+) dq).
  // Body velocities are V_WB = data.J_WB[b] v (CalcBodyJacobians, filled before the call).
  // Terms of the order of the forces times the lever changes (the turning of a force's
  // direction and point of action) may be left out: the tangents feed Newton's iteration
  // matrix, whose accuracy sets the convergence rate, not the solution.
  virtual bool HasTangents() const { return false; }
  virtual void AddTangents(const Model& /*model*/, const Data& /*data*/,
                           ExternalForceWorkspace& /*workspace*/,
                           Eigen::Ref<Eigen::MatrixXd> /*K*/,
                           Eigen::Ref<Eigen::MatrixXd> /*C*/) const {}

  // Scalar outputs recorded per output step under /external/<name>/<output name> (for example a
  // contact's total normal force and number of contact points).
  virtual std::vector<std::string> OutputNames() const { return {}; }
  // SI unit of each output ("N", "m", "1"); empty: all "1".
  virtual std::vector<std::string> OutputUnits() const { return {}; }
  // Columns of each output (empty: one each); an output with k columns is recorded as an
  // (rows x k) series.
  virtual std::vector<int> OutputColumns() const { return {}; }
  // Writes the outputs' values (the sum of their columns, in order) from the workspace of the
  // last Apply().
  virtual void GetOutputs(const ExternalForceWorkspace& /*workspace*/, double* /*values*/) const {}
};

}  // namespace orrery

#pragma once
// Force elements implemented outside mbd/ (tooth contact in contact/, which owns FCL): the model
// holds them as immutable descriptions, and each Data gets the element's mutable workspace
// (caches, broad-phase state, output values) once, at construction. The step calls Apply() after
// the built-in force elements; Apply() must not allocate.
//
// Apply() adds spatial forces (world coordinates, about the world origin) to data.f_ext[body],
// generalized forces to data.tau_applied (for example modal forces of flexible bodies), its
// elastic energy to data.potential_energy and the power it dissipates to data.power_dissipated.
// Its stiffness and damping reach the integrators' Jacobians through the differences they take
// in q and v (DaeSystem, generalized-alpha), so Apply() must be a deterministic function of
// (t, q, v) apart from caching.
#include <memory>
#include <string>
#include <vector>

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

  // Scalar outputs recorded per output step under /external/<name>/<output name> (for example a
  // contact's total normal force and number of contact points).
  virtual std::vector<std::string> OutputNames() const { return {}; }
  // SI unit of each output ("N", "m", "1"); empty: all "1".
  virtual std::vector<std::string> OutputUnits() const { return {}; }
  // Writes OutputNames().size() values from the workspace of the last Apply().
  virtual void GetOutputs(const ExternalForceWorkspace& /*workspace*/, double* /*values*/) const {}
};

}  // namespace orrery

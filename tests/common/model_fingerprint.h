#pragma once
// What a model is, as one vector, for tests that require a changed input to change the model (the
// key audits of the scene readers): its linearization at the initial state (mass, stiffness and
// damping matrices) and its generalized forces at rest at t = 0.1 s.
#include <vector>

#include <Eigen/Core>

#include "import/scene.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/linearization.h"

namespace orrery::test_support {

inline Eigen::VectorXd ModelFingerprint(const Scene& scene) {
  const Model& model = *scene.model;
  const State start = State::Initial(model);
  const LinearModel lin = Linearize(model, start);
  Data data(model);
  EvaluateDynamics(model, 0.1, start.q, start.v, Eigen::VectorXd::Zero(model.nv), data);
  std::vector<double> f(lin.M.data(), lin.M.data() + lin.M.size());
  f.insert(f.end(), lin.K.data(), lin.K.data() + lin.K.size());
  f.insert(f.end(), lin.D.data(), lin.D.data() + lin.D.size());
  f.insert(f.end(), data.tau_id.data(), data.tau_id.data() + data.tau_id.size());
  return Eigen::Map<const Eigen::VectorXd>(f.data(), static_cast<Eigen::Index>(f.size()));
}

}  // namespace orrery::test_support

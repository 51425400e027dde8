#pragma once
// The state the integrators advance: time, positions q (model.nq) and velocities v (model.nv).
#include <Eigen/Core>

#include "mbd/model.h"

namespace orrery {

struct State {
  double t = 0;
  Eigen::VectorXd q;  // nq: joint coordinates in tree order (quaternions w, x, y, z)
  Eigen::VectorXd v;  // nv: joint velocities

  // The model's initial state (joint defaults and values set in the builder), at t = 0.
  static State Initial(const Model& model) { return State{0.0, model.q_initial, model.v_initial}; }
};

}  // namespace orrery

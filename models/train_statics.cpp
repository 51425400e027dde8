// After the assembly: a train model's static equilibrium (the start of a run without the step
// response of loads applied to an undeformed train) and its planet-pin bearing forces.
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "mbd/evaluate.h"
#include "mbd/kinematics.h"
#include "mbd/linearization.h"
#include "models/train_dynamics.h"

namespace orrery::gears {

State SolveTrainStaticState(const TrainModel& tm, const State& guess, int max_iterations) {
  const Model& m = *tm.model;
  State x = guess;
  Data d(m);
  const Eigen::VectorXd zero_a = Eigen::VectorXd::Zero(m.nv);
  const Eigen::VectorXd zero_l = Eigen::VectorXd::Zero(m.n_constraints);
  double r0 = -1, r = 0;
  for (int it = 0; it <= max_iterations; ++it) {
    // Residual on the free coordinates: T^T (C - Q) at zero acceleration.
    EvaluateDynamics(m, x.t, x.q, x.v, zero_a, d);
    const LinearModel lin = Linearize(m, x, zero_a, zero_l);
    const Eigen::VectorXd rr = lin.T.transpose() * d.tau_id;
    r = rr.lpNorm<Eigen::Infinity>();
    if (r0 < 0) r0 = r;
    if (r <= 1e-9 * r0 || r == 0) return x;
    if (it == max_iterations) break;
    // Newton step on the null-space coordinates.
    const Eigen::VectorXd dx = lin.K_r.colPivHouseholderQr().solve(-rr);
    const Eigen::VectorXd dq = lin.T * dx;
    IntegratePositions(m, dq, x.q);
  }
  throw std::runtime_error("train model: static equilibrium not found (residual " + std::to_string(r) +
                           " of initial " + std::to_string(r0) + " after " + std::to_string(max_iterations) +
                           " Newton iterations)");
}

std::vector<double> CalcPlanetPinForces(const TrainModel& tm, const State& x, Data& data) {
  std::vector<double> out;
  if (tm.dofs == TrainDofs::kTorsional) return out;
  const Model& m = *tm.model;
  CalcPositionKinematics(m, x.q, data);
  CalcVelocityKinematics(m, x.v, data);
  for (size_t s = 0; s < tm.planet_bearings.size(); ++s) {
    for (int idx : tm.planet_bearings[s]) {
      if (tm.dofs == TrainDofs::kPlanar) {
        // x and y coordinate springs of the planet joint.
        double f2 = 0;
        for (int k = 0; k < 2; ++k) {
          const CoordinateSpringSpec& cs = m.coordinate_springs[idx + k];
          const double f = cs.stiffness * (x.q(m.coordinate_spring_q_index[idx + k]) - cs.q0) +
                           cs.damping * x.v(m.coordinate_spring_v_index[idx + k]);
          f2 += f * f;
        }
        out.push_back(std::sqrt(f2));
        continue;
      }
      // Spatial: the bearing's radial spring-damper force in the pin frame's axes (as in
      // force_elements.cpp).
      const BearingSpec& bs = m.bearings[idx];
      const BodyIndex ba = m.frames[bs.frame_a].body, bb = m.frames[bs.frame_b].body;
      const Transform& Xa = data.X_WFrame[bs.frame_a];
      const Transform& Xb = data.X_WFrame[bs.frame_b];
      const Vec3 delta = Xb.p - Xa.p;
      const Vec3 w_a = data.V_WB[ba].head<3>();
      const Vec3 delta_dot = PointVelocity(data.V_WB[bb], Xb.p) - PointVelocity(data.V_WB[ba], Xa.p);
      const Vec3 d = Xa.R.transpose() * delta;
      const Vec3 d_dot = Xa.R.transpose() * (delta_dot - w_a.cross(delta));
      const double fx = bs.radial_stiffness * d.x() + bs.radial_damping * d_dot.x();
      const double fy = bs.radial_stiffness * d.y() + bs.radial_damping * d_dot.y();
      out.push_back(std::hypot(fx, fy));
    }
  }
  return out;
}

}  // namespace orrery::gears

// Generalized-alpha's Newton test against the rounding of large coordinates.
// A stiff spring on an angle of many radians: one ulp of the angle moves the spring's force by
// k ulp(theta), which no iterate can go below, so a Newton tolerance under it can never be met
// (mbd/generalized_alpha.cpp UpdateRoundingFloor). Two closed forms where it is so:
// - a rotor held at its static equilibrium q* = q0 + T/k by a coordinate spring (k = 1e10
//   N m/rad, q0 = 1000 rad) against a load torque T: q(t) = q* and v(t) = 0 for ever;
// - a rotor dragged at constant speed through a rotational spring (k = 1e8 N m/rad) by a
//   speed-driven rotor whose angle starts at 1000 rad, against a load torque T on the dragged
//   one: it turns at the driver's speed, twisted by T/k for ever.
// Both at newton_tolerance 1e-12 (1e-11 N m against a floor of 1e-4 to 1e-3 N m): the runs
// must take no failed step and stay on the closed forms to a few ulps of the angles.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "mbd/integrator.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

IntegratorOptions Options() {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = 1e-5;
  o.rho_inf = 0.5;
  o.newton_tolerance = 1e-12;
  o.max_step_halvings = 2;  // a stalled iteration fails fast instead of halving for long
  return o;
}

TEST(GeneralizedAlphaRoundingFloor, StiffSpringHoldsARotorAtALargeAngle) {
  constexpr double kK = 1e10, kQ0 = 1000, kT = 100;  // N m/rad, rad, N m
  ModelBuilder b;
  const BodyIndex rotor = b.AddBody("rotor", 1.0, Vec3::Zero(), Mat3::Identity());
  JointSpec j;
  j.name = "shaft", j.type = JointType::kRevolute, j.parent = kWorldBody, j.child = rotor;
  const JointIndex shaft = b.AddJoint(j);
  b.AddCoordinateSpring({.name = "spring", .joint = shaft, .coordinate = 0, .stiffness = kK, .q0 = kQ0});
  b.AddJointLoad({.name = "load", .joint = shaft, .coordinate = 0, .function = TimeFunction::Constant(kT)});
  const double q_star = kQ0 + kT / kK;
  b.SetJointPosition(shaft, Eigen::VectorXd::Constant(1, q_star));
  const auto model = std::move(b).Finalize();
  // Not vacuous: one ulp of the angle moves the spring by more than the tolerance asks for.
  const double ulp = std::nextafter(kQ0, 2 * kQ0) - kQ0;
  ASSERT_GT(kK * ulp / 2, 1e3 * Options().newton_tolerance * kT);

  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, Options());
  integ->Initialize(State::Initial(*model));
  ASSERT_NO_THROW(integ->AdvanceTo(2e-3));  // 200 steps, 20 periods of sqrt(k / I)
  EXPECT_EQ(integ->stats().newton_failures, 0);
  const double q = integ->state().q(0), v = integ->state().v(0);
  std::printf("[rounding floor, static] q - q* = %.3g rad (ulp %.3g), v = %.3g rad/s\n", q - q_star, ulp, v);
  EXPECT_LE(std::abs(q - q_star), 4 * ulp);
  // A residual of the floor's size, k ulp / 2, leaves an oscillation of about ulp / 2 at
  // sqrt(k / I) = 1e5 rad/s.
  EXPECT_LE(std::abs(v), 4 * ulp * std::sqrt(kK));
}

TEST(GeneralizedAlphaRoundingFloor, RotorDraggedThroughAStiffSpringKeepsItsTwist) {
  constexpr double kK = 1e8, kTheta0 = 1000, kW = 100, kT = 10;  // N m/rad, rad, rad/s, N m
  ModelBuilder b;
  const BodyIndex input = b.AddBody("input", 1.0, Vec3::Zero(), Mat3::Identity());
  const BodyIndex output = b.AddBody("output", 1.0, Vec3::Zero(), Mat3::Identity());
  JointSpec j;
  j.name = "input", j.type = JointType::kRevolute, j.parent = kWorldBody, j.child = input;
  const JointIndex ji = b.AddJoint(j);
  j.name = "output", j.child = output;
  const JointIndex jo = b.AddJoint(j);
  b.AddDriver({.name = "drive", .joint = ji, .coordinate = 0, .mode = DriverSpec::Mode::kSpeed,
               .function = TimeFunction::Constant(kW)});
  b.AddRotationalSpring({.name = "spring", .frame_a = b.body_frame(input), .frame_b = b.body_frame(output),
                         .stiffness = kK});
  b.AddJointLoad({.name = "load", .joint = jo, .coordinate = 0, .function = TimeFunction::Constant(kT)});
  const double twist = kT / kK;  // -k (theta_o - theta_i) + T = 0
  b.SetJointPosition(ji, Eigen::VectorXd::Constant(1, kTheta0));
  b.SetJointPosition(jo, Eigen::VectorXd::Constant(1, kTheta0 + twist));
  b.SetJointVelocity(ji, Eigen::VectorXd::Constant(1, kW));
  b.SetJointVelocity(jo, Eigen::VectorXd::Constant(1, kW));
  const auto model = std::move(b).Finalize();
  const double t_end = 0.02;  // 2000 steps, 2 rad further
  const double ulp = std::nextafter(kTheta0 + kW * t_end, 1e9) - (kTheta0 + kW * t_end);
  ASSERT_GT(kK * ulp / 2, 1e3 * Options().newton_tolerance * kT);

  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, Options());
  integ->Initialize(State::Initial(*model));
  ASSERT_NO_THROW(integ->AdvanceTo(t_end));
  EXPECT_EQ(integ->stats().newton_failures, 0);
  const Eigen::VectorXd& q = integ->state().q;
  const Eigen::VectorXd& v = integ->state().v;
  std::printf("[rounding floor, dragged] twist - T/k = %.3g rad (ulp %.3g), speeds - w = %.3g, %.3g rad/s\n",
              q(1) - q(0) - twist, ulp, v(0) - kW, v(1) - kW);
  // The driven angle adds h w to about 1000 rad at each step: up to half an ulp each.
  EXPECT_NEAR(q(0), kTheta0 + kW * t_end, 2000 * ulp / 2);
  EXPECT_NEAR(q(1) - q(0), twist, 8 * ulp);
  EXPECT_NEAR(v(1), kW, 8 * ulp * std::sqrt(kK));
}

}  // namespace
}  // namespace orrery

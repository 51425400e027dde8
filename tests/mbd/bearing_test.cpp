// Bearing element: static radial, axial and tilt stiffness against F/k and M/k_tilt, free spin
// through many turns (where a bushing's rotation vector would wrap), and the radial natural
// frequency sqrt(k/m) of a shaft on one bearing.
#include <gtest/gtest.h>

#include <cmath>

#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/linearization.h"
#include "mbd/model.h"

namespace orrery {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Shaft {
  std::shared_ptr<const Model> model;
  JointIndex joint = -1;
};

// A disc (m = 3 kg) on a free joint, held by a bearing at its centre to the world.
Shaft Build(double spin = 0) {
  ModelBuilder b;
  const BodyIndex disc = b.AddBody("disc", 3.0, Vec3::Zero(), Vec3(0.02, 0.02, 0.04).asDiagonal());
  Shaft s;
  s.joint = b.AddJoint({.name = "float", .type = JointType::kFree, .parent = kWorldBody, .child = disc});
  b.AddBearing({.name = "bearing", .frame_a = kWorldFrame, .frame_b = b.body_frame(disc),
                .radial_stiffness = 2e7, .axial_stiffness = 5e6, .tilt_stiffness = 1e4});
  Eigen::VectorXd v = Eigen::VectorXd::Zero(6);
  v(5) = spin;  // angular velocity about z
  b.SetJointVelocity(s.joint, v);
  s.model = std::move(b).Finalize();
  return s;
}

TEST(Bearing, StaticStiffnessRadialAxialTilt) {
  const Shaft s = Build();
  Data d(*s.model);
  State st = State::Initial(*s.model);
  const int q = s.model->joints[s.joint].q_start;
  st.q.segment<3>(q) = Vec3(1e-5, -2e-5, 3e-5);
  const double tilt = 1e-4;  // rad about x
  const Quat r(Eigen::AngleAxisd(tilt, Vec3::UnitX()));
  st.q.segment<4>(q + 3) << r.w(), r.x(), r.y(), r.z();
  EvaluateDynamics(*s.model, 0, st.q, st.v, Eigen::VectorXd::Zero(6), d);
  const Vec6& f = d.f_ext[1];  // on the disc, about the world origin (disc centre moved by ~1e-5)
  EXPECT_NEAR(f(3), -2e7 * 1e-5, 1e-9 * 2e2);
  EXPECT_NEAR(f(4), 2e7 * 2e-5, 1e-9 * 4e2);
  EXPECT_NEAR(f(5), -5e6 * 3e-5, 1e-9 * 1.5e2);
  // Moment about x at the disc centre: -k_tilt sin(tilt) (z_A x z_B = sin(tilt) about x).
  const Vec3 p = st.q.segment<3>(q);
  const Vec3 m = f.head<3>() - p.cross(f.tail<3>());
  EXPECT_NEAR(m.x(), -1e4 * std::sin(tilt), 1e-12);
  EXPECT_NEAR(m.y(), 0.0, 1e-12);
  EXPECT_NEAR(m.z(), 0.0, 1e-12);  // free about the axis
}

TEST(Bearing, SpinsFreelyThroughManyTurns) {
  const double spin = 200.0;  // rad/s: 0.2 s are more than six turns
  const Shaft s = Build(spin);
  IntegratorOptions o;
  o.rtol = 1e-9;
  o.atol = 1e-12;
  auto integ = MakeIntegrator(*s.model, o);
  integ->Initialize(State::Initial(*s.model));
  const int q = s.model->joints[s.joint].q_start, v = s.model->joints[s.joint].v_start;
  double worst = 0;
  for (int k = 1; k <= 20; ++k) {
    integ->AdvanceTo(0.01 * k);
    worst = std::max(worst, integ->state().q.segment<3>(q).norm());
    EXPECT_NEAR(integ->state().v(v + 5), spin, 1e-9 * spin);
  }
  EXPECT_LT(worst, 1e-12);  // no spurious force pushes the centre off
}

TEST(Bearing, RadialAndTiltFrequencies) {
  const Shaft s = Build();
  const ModalResult modes = CalcModes(Linearize(*s.model, State::Initial(*s.model)));
  ASSERT_EQ(modes.frequencies_hz.size(), 6u);
  // Ascending: spin (0), tilt x2 sqrt(k_t / I_xx), axial sqrt(k_a/m), radial x2 sqrt(k_r/m).
  const double f_spin = 0, f_tilt = std::sqrt(1e4 / 0.02) / (2 * kPi);
  const double f_axial = std::sqrt(5e6 / 3.0) / (2 * kPi), f_radial = std::sqrt(2e7 / 3.0) / (2 * kPi);
  const double expected[6] = {f_spin, f_tilt, f_tilt, f_axial, f_radial, f_radial};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(modes.frequencies_hz[i], expected[i], 1e-6 * f_radial) << i;
}

}  // namespace
}  // namespace orrery

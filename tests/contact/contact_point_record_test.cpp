// Recorded contact points (contact/contact_point_record.h): the n largest by normal force in
// order, NaN beyond the points there are; through a gear contact element, the recorded forces
// are the largest of the element's nodes (their sum bounded by the total normal force) and the
// points lie on gear 1's flanks (within its tip circle and face width). The element's
// evaluation in a model (Compute) leaves the points and the monitor's outputs to the first read
// of the outputs: they must be those of an evaluation that makes them at once (CalcForces).
#include "contact/contact_point_record.h"

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "models/gear_contact.h"
#include "models/gear_geometry.h"
#include "tests/contact/two_mesh_model.h"

namespace orrery::contact {
namespace {

using namespace orrery::gears;  // gear surfaces as the workload

TEST(ContactPointRecord, LargestFirstThenNaN) {
  ContactPointRecord r(8);
  const std::vector<double> f = {3, 7, 1, 7, 5};
  for (size_t i = 0; i < f.size(); ++i) r.Add(Vec3(double(i), 0, 0), f[i]);
  std::vector<double> p(3 * 7), forces(7);
  r.Write(7, p.data(), forces.data());
  const std::vector<double> want_f = {7, 7, 5, 3, 1};
  const std::vector<double> want_x = {1, 3, 4, 0, 2};  // ties in the order added
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(forces[k], want_f[k]);
    EXPECT_EQ(p[3 * k], want_x[k]);
  }
  for (int k = 5; k < 7; ++k) {
    EXPECT_TRUE(std::isnan(forces[k]));
    EXPECT_TRUE(std::isnan(p[3 * k + 2]));
  }
}

TEST(ContactPointRecord, GearElementRecordsItsLargestPointsOnGearOne) {
  const double pi = 3.14159265358979323846;
  gears::GearSpec s1{.teeth = 18, .normal_module_m = 1.5e-3,
                     .normal_pressure_angle_rad = 21.3 * pi / 180, .face_width_m = 0.03};
  gears::GearSpec s2 = s1;
  s2.teeth = 34;
  const gears::GearPair pair{gears::Gear(s1), gears::Gear(s2)};
  GearContactOptions o;
  o.involute_intervals = 24;
  o.record_points = 10;
  // Gear 1 (on body 1) turned: its body frame is not the world's.
  o.X_B1G1 = Transform(AxisAngle(Vec3::UnitZ(), 0.3), Vec3::Zero());
  const ContactElement element(MakeGearContactSpec("mesh", pair, 1, 2, o));
  const std::vector<OutputDescription>& outputs = element.outputs();
  ASSERT_GE(outputs.size(), 2u);
  ASSERT_EQ(outputs[outputs.size() - 2].name, "point_positions");
  EXPECT_EQ(outputs[outputs.size() - 2].columns, 30);
  EXPECT_EQ(outputs.back().name, "point_normal_forces");
  EXPECT_EQ(outputs.back().columns, 10);
  const int total = OutputValueCount(outputs);
  ContactWorkspace ws(*element.spec().surface_a, *element.spec().surface_b);
  // Gear 1 pressed 3 um ahead of its kinematic angle at roll 0 (gear 1's frame turned by 0.3
  // in its body, so the body is turned back by 0.3).
  const double rb1 = pair.gear1().base_radius_m();
  const Transform X_W1(AxisAngle(Vec3::UnitZ(), -0.3 + 3e-6 / rb1), Vec3::Zero());
  const Transform X_W2(AxisAngle(Vec3::UnitZ(), pi + pi / 34), Vec3(pair.center_distance_m(), 0, 0));
  element.UpdateGaps(X_W1, X_W2, ws);
  Vec6 f1, f2;
  double e = 0, p = 0;
  element.CalcForces(Vec6::Zero(), Vec6::Zero(), ws, &f1, &f2, &e, &p);
  ASSERT_GT(ws.contact_points, 10);
  std::vector<double> out(total);
  element.GetOutputs(ws, out.data());
  const double* pos = out.data() + total - 40;
  const double* force = out.data() + total - 10;
  double sum = 0;
  for (int k = 0; k < 10; ++k) {
    EXPECT_GT(force[k], 0);
    if (k > 0) {
      EXPECT_LE(force[k], force[k - 1]);
    }
    sum += force[k];
    // In body 1's frame, gear 1's frame is turned by 0.3 about z: radius and height unchanged.
    const double r = std::hypot(pos[3 * k], pos[3 * k + 1]);
    EXPECT_LE(r, pair.gear1().tip_radius_m() + 1e-9);
    EXPECT_GE(r, pair.gear1().root_radius_m());
    EXPECT_GE(pos[3 * k + 2], -1e-12);
    EXPECT_LE(pos[3 * k + 2], pair.face_width_m() + 1e-12);
  }
  EXPECT_LE(sum, ws.normal_force * (1 + 1e-12));
}

// The outputs of a model's evaluation (Compute: the points and the monitor's outputs made when
// GetOutputs first reads them) against those of UpdateGaps and CalcForces in a workspace of the
// same element given the same poses and velocities (the points and the monitor made during the
// evaluation), to the bit: an 18/34 pair on revolute joints, turning (the Hunt-Crossley damping
// reads the velocities) and pressed 1 to 5 um ahead, rolled through a mesh period.
TEST(ContactPointRecord, OutputsMadeOnReadEqualThoseOfTheEvaluation) {
  const double pi = 3.14159265358979323846;
  ModelBuilder b;
  const test_scenes::SpurPair sp = test_scenes::AddSpurPair(b);
  const gears::GearPair& pair = sp.pair;
  const BodyIndex g1 = sp.pinion, g2 = sp.gear;
  GearContactOptions o;
  o.involute_intervals = 16;
  o.face_intervals = 2;
  o.record_points = 6;
  const auto element =
      std::make_shared<ContactElement>(MakeGearContactSpec("mesh", pair, g1, g2, o));
  ASSERT_NE(element->spec().monitor, nullptr);
  b.AddExternalForce(element);
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  const Model& m = *model;
  Data data(m);
  State s = State::Initial(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  ContactWorkspace eager(*element->spec().surface_a, *element->spec().surface_b, 0,
                         element->spec().monitor.get());
  const int n = OutputValueCount(element->outputs());
  std::vector<double> lazy_out(n), eager_out(n), again(n);
  const int iq1 = m.joints[0].q_start, iq2 = m.joints[1].q_start;
  int pressed = 0;
  for (int k = 0; k < 60; ++k) {
    const double theta1 = 2 * pi / 18 * k / 60;
    s.q(iq1) = theta1 + (3e-6 + 2e-6 * std::sin(0.3 * k)) / pair.gear1().base_radius_m();
    s.q(iq2) = -theta1 * 18.0 / 34.0;
    s.v(m.joints[0].v_start) = 20;
    s.v(m.joints[1].v_start) = -20 * 18.0 / 34.0 + 0.01 * std::cos(0.7 * k);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, data);
    const auto& lazy = static_cast<const ContactWorkspace&>(*data.external[0]);
    EXPECT_TRUE(lazy.outputs_pending) << "step " << k;
    element->UpdateGaps(data.X_WB[g1], data.X_WB[g2], eager);
    Vec6 f1, f2;
    double e = 0, p = 0;
    element->CalcForces(data.V_WB[g1], data.V_WB[g2], eager, &f1, &f2, &e, &p);
    ASSERT_TRUE(f1 == lazy.f_A) << "step " << k;
    element->GetOutputs(lazy, lazy_out.data());
    EXPECT_FALSE(lazy.outputs_pending);
    element->GetOutputs(eager, eager_out.data());
    element->GetOutputs(lazy, again.data());  // read twice: made once
    // Bit for bit (NaN where no point is recorded, in both).
    ASSERT_EQ(std::memcmp(lazy_out.data(), eager_out.data(), sizeof(double) * n), 0)
        << "step " << k;
    ASSERT_EQ(std::memcmp(again.data(), eager_out.data(), sizeof(double) * n), 0) << "step " << k;
    pressed += lazy.contact_points > 6;
  }
  // Most poses press more points than are recorded (47 of the 60).
  EXPECT_GT(pressed, 40);
}

}  // namespace
}  // namespace orrery::contact

// Recorded contact points (contact/contact_point_record.h): the n largest by normal force in
// order, NaN beyond the points there are; through a gear contact element, the recorded forces
// are the largest of the element's nodes (their sum bounded by the total normal force) and the
// points lie on gear 1's flanks (within its tip circle and face width).
#include "contact/contact_point_record.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "models/gear_contact.h"
#include "models/gear_geometry.h"

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

}  // namespace
}  // namespace orrery::contact

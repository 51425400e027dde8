// Mesh outputs of a gear contact element (models/gear_mesh_monitor.cpp) against independent
// measures of the same quantities:
//   - transmission error: the quasi-static sweep (SweepGearMesh) sets TE itself, turning gear 1
//     by TE / r_b1 off its kinematic angle; the element reads it back from the poses alone, also
//     with the whole pair moved and turned, gear 2 a whole turn further, external and internal;
//   - line-of-action force: the sweep's load (its moment balance on gear 1);
//   - mesh stiffness: central differences of the contact's force along the line of action
//     (moment on gear 1 over r_b1) in TE, at the sweep's equilibria. The output leaves out the
//     turning of the normals over the faces (a term of the order of the force over the flank's
//     radius of curvature against the stiffness: delta / rho, 1e-3 here);
//   - pattern: the sweep's own per-tooth extents along the line of action (its ContactPattern,
//     points on gear 1's surface) have the element's as their envelope; the face width bounds
//     it axially.
#include "models/gear_mesh_monitor.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "models/gear_contact.h"
#include "models/gear_geometry.h"

namespace orrery::gears {
namespace {

using namespace orrery::contact;  // the engine the gear layer builds on

constexpr double kPi = 3.14159265358979323846;

// Seed 001's sun-planet pair (external) and seed 003's planet-ring pair (internal).
gears::GearPair ExternalPair() {
  const double deg = kPi / 180;
  gears::GearSpec s1{.teeth = 18, .normal_module_m = 1.5e-3,
                     .normal_pressure_angle_rad = 21.3 * deg, .face_width_m = 0.03};
  gears::GearSpec s2 = s1;
  s2.teeth = 34;
  return gears::GearPair(gears::Gear(s1), gears::Gear(s2));
}

gears::GearPair InternalPair() {
  const double deg = kPi / 180;
  gears::GearSpec p{.teeth = 14, .normal_module_m = 4e-3, .normal_pressure_angle_rad = 22.5 * deg,
                    .face_width_m = 0.04};
  gears::GearSpec r = p;
  r.teeth = 50;
  r.internal = true;
  r.addendum_coef = 0.85;
  r.root_fillet_coef = 0.25;
  return gears::GearPair(gears::Gear(p), gears::Gear(r));
}

void CheckPair(const gears::GearPair& pair, double load_n) {
  GearContactOptions o;
  o.involute_intervals = 40;
  const ContactElement element(MakeGearContactSpec("mesh", pair, 1, 2, o));
  const auto* monitor = dynamic_cast<const GearMeshMonitor*>(element.spec().monitor.get());
  ASSERT_NE(monitor, nullptr);
  const GearMeshInfo& info = monitor->info();
  const MeshSweep sweep = SweepGearMesh(pair, o, load_n, 6);
  const double z1 = pair.gear1().teeth(), z2 = pair.gear2().teeth();
  const double rb1 = pair.gear1().base_radius_m(), a = pair.center_distance_m();
  const Vec3 p2 = pair.internal() ? Vec3(-a, 0, 0) : Vec3(a, 0, 0);
  // A rigid motion of the whole pair (must not change the TE).
  const Transform moved(AxisAngle(Vec3(0.3, -0.2, 1).normalized(), 0.7), Vec3(0.1, -0.4, 2.0));
  ContactWorkspace ws(*element.spec().surface_a, *element.spec().surface_b, 0, monitor);
  for (const MeshSweepPoint& pt : sweep.points) {
    const double theta2 = pair.internal() ? kPi / z2 + z1 / z2 * pt.roll_angle_rad
                                          : kPi + kPi / z2 - z1 / z2 * pt.roll_angle_rad;
    auto pose1 = [&](double te) {
      return Transform(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + te / rb1), Vec3::Zero());
    };
    const Transform X_W1 = pose1(pt.transmission_error_m);
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), theta2), p2);
    const Transform X_W2_turned(AxisAngle(Vec3::UnitZ(), theta2 + 2 * kPi), p2);
    const double te = pt.transmission_error_m;
    EXPECT_NEAR(GearTransmissionError(info, X_W1, X_W2), te, 1e-12);
    EXPECT_NEAR(GearTransmissionError(info, moved * X_W1, moved * X_W2), te, 1e-12);
    EXPECT_NEAR(GearTransmissionError(info, X_W1, X_W2_turned), te, 1e-12);
    // Mesh stiffness against central differences of the line-of-action force.
    auto line_force = [&](double t) {
      element.UpdateGaps(pose1(t), X_W2, ws);
      Vec6 f1, f2;
      double e = 0, p = 0;
      element.CalcForces(Vec6::Zero(), Vec6::Zero(), ws, &f1, &f2, &e, &p);
      return -f1(2) / rb1;
    };
    const double h = 1e-4 * te;
    const double k_fd = (line_force(te + h) - line_force(te - h)) / (2 * h);
    line_force(te);
    const GearMeshOutputs& out = GearMeshMonitor::Outputs(*ws.monitor);
    EXPECT_NEAR(out.transmission_error_m, te, 1e-12);
    // The sweep balanced the load's moment F r_b1 with the contact's (to its tolerance).
    EXPECT_NEAR(out.line_of_action_force_n, load_n, 1e-6 * load_n);
    EXPECT_NEAR(out.mesh_stiffness_n_per_m, k_fd, 2e-3 * k_fd) << "roll " << pt.roll_angle_rad;
    // Pattern: the envelope of the sweep's per-tooth extents, within gear 1's tip.
    double lo = 1e300, hi = -1e300;
    for (int k = 0; k < std::min(3, pt.teeth_in_contact); ++k) {
      lo = std::min(lo, pt.pattern_min_m[k]);
      hi = std::max(hi, pt.pattern_max_m[k]);
    }
    ASSERT_GE(pt.teeth_in_contact, 1);
    ASSERT_LE(pt.teeth_in_contact, 3);
    EXPECT_NEAR(out.pattern_roll_min_m, lo, 1e-12);
    EXPECT_NEAR(out.pattern_roll_max_m, hi, 1e-12);
    EXPECT_LE(hi, std::sqrt(std::pow(pair.gear1().tip_radius_m(), 2) - rb1 * rb1) + 1e-9);
    EXPECT_NEAR(out.pattern_axial_min_m, 0, 1e-12);
    EXPECT_NEAR(out.pattern_axial_max_m, pair.face_width_m(), 1e-12);
    std::printf("roll %.4f: TE %.4f um, k %.1f N/um (differences %.1f), pattern %.3f..%.3f mm\n",
                pt.roll_angle_rad, te * 1e6, out.mesh_stiffness_n_per_m * 1e-6, k_fd * 1e-6,
                out.pattern_roll_min_m * 1e3, out.pattern_roll_max_m * 1e3);
  }
}

TEST(GearMeshMonitor, ExternalPairAgainstTheSweep) { CheckPair(ExternalPair(), 1429); }

TEST(GearMeshMonitor, InternalPairAgainstTheSweep) { CheckPair(InternalPair(), 8000); }

TEST(GearMeshMonitor, NoContactLeavesThePatternUnset) {
  const gears::GearPair pair = ExternalPair();
  GearContactOptions o;
  o.involute_intervals = 16;
  const ContactElement element(MakeGearContactSpec("mesh", pair, 1, 2, o));
  ContactWorkspace ws(*element.spec().surface_a, *element.spec().surface_b, 0,
                      element.spec().monitor.get());
  // Gear 1 ahead by 5 um along the line of action, gear 2 pulled out by 1 mm: the flanks are
  // apart, the angles unchanged.
  const double rb1 = pair.gear1().base_radius_m();
  element.UpdateGaps(Transform(AxisAngle(Vec3::UnitZ(), 5e-6 / rb1), Vec3::Zero()),
                     Transform(AxisAngle(Vec3::UnitZ(), kPi + kPi / 34),
                               Vec3(pair.center_distance_m() + 1e-3, 0, 0)),
                     ws);
  Vec6 f1, f2;
  double e = 0, p = 0;
  element.CalcForces(Vec6::Zero(), Vec6::Zero(), ws, &f1, &f2, &e, &p);
  EXPECT_EQ(ws.contact_points, 0);
  const GearMeshOutputs& out = GearMeshMonitor::Outputs(*ws.monitor);
  EXPECT_NEAR(out.transmission_error_m, 5e-6, 1e-12);
  EXPECT_EQ(out.mesh_stiffness_n_per_m, 0);
  EXPECT_TRUE(std::isnan(out.pattern_roll_min_m));
}

}  // namespace
}  // namespace orrery::gears

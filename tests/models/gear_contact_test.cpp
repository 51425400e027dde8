// Gear contact from gear geometry (models/gear_contact.h) on seed 001's 18/34 sun-planet pair
// (m = 1.5 mm, 21.3 deg, b = 30 mm).
//   Faceting: a perfect rigid involute pair under light load (50 N) has no transmission error
//   apart from the load sharing; the flat facets add a false TE that vanishes as the flanks are
//   refined. Oracle: the sweep at 240 involute intervals (false TE of a resolution = peak to peak
//   of its TE minus the reference's). The default resolution must stay under 0.1 um (DESIGN.md,
//   "Tooth contact"), and a coarse one (24) must not, or the test could not fail.
//   Calibration: k_A from the closed form of the header reproduces delta_ref = F / (c' b).
#include "models/gear_contact.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "models/mesh_stiffness.h"

namespace orrery::gears {
namespace {

using namespace orrery::contact;  // the engine the gear layer builds on

gears::GearPair Seed001SunPlanet() {
  const double deg = 3.14159265358979323846 / 180;
  gears::GearSpec planet{.teeth = 18, .normal_module_m = 1.5e-3,
                         .normal_pressure_angle_rad = 21.3 * deg, .face_width_m = 0.03};
  gears::GearSpec sun = planet;
  sun.teeth = 34;
  return gears::GearPair(gears::Gear(planet), gears::Gear(sun));
}

std::vector<double> Te(const gears::GearPair& pair, int involute_intervals, double load) {
  GearContactOptions o;
  o.involute_intervals = involute_intervals;
  std::vector<double> te;
  for (const MeshSweepPoint& p : SweepGearMesh(pair, o, load, 12).points)
    te.push_back(p.transmission_error_m);
  return te;
}

double PeakToPeakDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double lo = 1e300, hi = -1e300;
  for (size_t i = 0; i < a.size(); ++i) {
    lo = std::min(lo, a[i] - b[i]);
    hi = std::max(hi, a[i] - b[i]);
  }
  return hi - lo;
}

TEST(GearContactTest, DefaultFlankResolutionKeepsFalseTeBelowOneTenthMicrometre) {
  const gears::GearPair pair = Seed001SunPlanet();
  const std::vector<double> reference = Te(pair, 240, 50);
  const double false_default = PeakToPeakDifference(Te(pair, GearContactOptions{}.involute_intervals, 50), reference);
  const double false_coarse = PeakToPeakDifference(Te(pair, 24, 50), reference);
  EXPECT_LT(false_default, 0.1e-6);
  EXPECT_GT(false_coarse, 0.1e-6);
}

// Frictionless involute flanks push along the line of action, at the working pressure angle
// alpha_w to the normal of the line of centres (closed form). On facets the force follows the
// facet's normal, off the involute's by up to half a facet angle (40 intervals on the
// 18-tooth gear's flank: about 0.9 degrees a facet); with the smoothed normals
// (contact_surface.h) it follows the involute's normal interpolated at the closest point. Over
// the single-pair zone (one tooth pair in contact, away from the tip corners, whose contact
// pushes off the line of action with either normal: 1.7 degrees at the zone's ends) the
// smoothed force keeps within 0.05 degrees of the line (a twentieth of a facet: what is left
// is the penalty patch spanning several facets), the facets' within 0.1 degrees only at best.
TEST(GearContactTest, SmoothedNormalsPushAlongTheLineOfAction) {
  const gears::GearPair pair = Seed001SunPlanet();
  const double alpha_w = pair.working_pressure_angle_rad();
  auto worst = [&](bool smooth) {
    GearContactOptions o;
    o.involute_intervals = 40;
    o.smooth_normals = smooth;
    double w = 0;
    int single = 0;
    for (const MeshSweepPoint& p : SweepGearMesh(pair, o, 1000, 24).points) {
      if (p.teeth_in_contact != 1) continue;
      ++single;
      w = std::max(w, std::abs(std::atan2(std::abs(p.force_x_n), std::abs(p.force_y_n)) - alpha_w));
    }
    EXPECT_GE(single, 6);
    return w;
  };
  const double deg = 3.14159265358979323846 / 180;
  EXPECT_LT(worst(true), 0.05 * deg);
  EXPECT_GT(worst(false), 0.1 * deg);
}

TEST(GearContactTest, PenaltyCalibrationFollowsTheLineContactClosedForm) {
  const gears::GearPair pair = Seed001SunPlanet();
  GearContactOptions o;
  o.calibration_load_n = 1429;
  const GearContactCalibration c = CalibrateGearContact(pair, o);
  EXPECT_DOUBLE_EQ(c.single_pair_stiffness_n_per_m,
                   gears::CalcIso6336Stiffness(pair).c_single_n_per_m);
  // w = (4/3) sqrt(2 rho) k_A delta^(3/2) at delta_ref carries the load per face width.
  const double w = 4.0 / 3.0 * std::sqrt(2 * c.equivalent_radius_m) * c.stiffness_per_area *
                   std::pow(c.reference_deflection_m, 1.5);
  EXPECT_NEAR(w * pair.face_width_m(), 1429, 1e-9 * 1429);
  EXPECT_NEAR(c.reference_deflection_m * c.single_pair_stiffness_n_per_m, 1429, 1e-9 * 1429);
}

TEST(GearContactTest, PenetrationLimitIsHalfTheThinnerToothAtTheReferenceCircle) {
  // Unshifted, unthinned teeth are pi m / 2 thick at the reference circle (ISO 21771): the stop
  // lies at pi m / 4, and the element carries it as a stopping check beside the margin's warning.
  const gears::GearPair pair = Seed001SunPlanet();
  const contact::PenetrationLimit limit = GearPenetrationLimit(pair);
  EXPECT_NEAR(limit.depth_m, 3.14159265358979323846 * 1.5e-3 / 4, 1e-9);
  EXPECT_NE(limit.reason.find("the teeth have passed through each other"), std::string::npos);
  const ContactElement element(MakeGearContactSpec("pair", pair, 1, 2, GearContactOptions{}));
  const std::vector<ElementHealthCheck> checks = element.HealthChecks();
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_EQ(checks[0].name, "penetration");
  EXPECT_FALSE(checks[0].stops);
  EXPECT_DOUBLE_EQ(checks[0].limit, GearContactOptions{}.margin_m);
  EXPECT_EQ(checks[1].name, "penetration_limit");
  EXPECT_TRUE(checks[1].stops);
  EXPECT_DOUBLE_EQ(checks[1].limit, limit.depth_m);
  // Thinned for a normal backlash j_n shared half and half: each tooth loses (j_n / 2) / cos(alpha)
  // of its transverse thickness (spur, at the standard centre distance), the limit a quarter of
  // j_n / cos(alpha)
  GearContactOptions thinned;
  thinned.normal_backlash_m = 100e-6;
  const ContactElement loose(MakeGearContactSpec("loose", pair, 1, 2, thinned));
  const double alpha = 21.3 * 3.14159265358979323846 / 180;
  EXPECT_NEAR(loose.HealthChecks()[1].limit, limit.depth_m - 100e-6 / (4 * std::cos(alpha)), 1e-7);
}

}  // namespace
}  // namespace orrery::gears

// Kinematics of models/planetary_kinematics.cpp against hand-derived relations that do not go
// through the A w = B assembly: the tabular (Willis) method -- hold the carrier, chain the tooth
// ratios along the branch, add the carrier speed back:
//   single-planet  (w_r - w_c)/(w_s - w_c) = (-Z_s/Z_p)(+Z_p/Z_r)               = -Z_s/Z_r
//   double-planet  (w_r - w_c)/(w_s - w_c) = (-Z_s/Z_b)(-Z_b/Z_d)(+Z_d/Z_r)     = +Z_s/Z_r
//   Ravigneaux     (w_r - w_c)/(w_s1 - w_c) = (-Z_s1/Z_a)(-Z_a/Z_b)(+Z_b/Z_r)  = +Z_s1/Z_r
//                  (w_r - w_c)/(w_s2 - w_c) = (-Z_s2/Z_b)(+Z_b/Z_r)            = -Z_s2/Z_r
// and the fault-frequency definitions counted by hand (teeth passing per carrier-relative turn).
// Tolerance: the systems have integer entries below 200 and condition numbers below 1e4, so the
// solution carries rounding of about 1e4 * 1e-16 relative; 1e-12 relative is used.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "models/planetary_kinematics.h"
#include "models/planetary_train.h"

namespace orrery::gears {
namespace {

constexpr double kRel = 1e-12;
constexpr double kTwoPi = 2 * std::numbers::pi;

void ExpectRel(double actual, double expected, const char* what) {
  EXPECT_NEAR(actual, expected, kRel * std::max(1.0, std::abs(expected))) << what;
}

TEST(PlanetaryKinematics, DoublePlanetRingHeldMatchesTheTabularMethod) {
  PlanetaryTrainBuilder b;
  const int zs = 30, zb = 15, zd = 17, zr = 90;
  b.AddDoublePlanetStage({.name = "D", .sun = {zs}, .inner_planet = {zb}, .outer_planet = {zd},
                          .ring = {zr}, .num_planets = 3});
  b.AddBrake("B", "D.ring");
  b.AddRange("r", {"B"});
  b.AddInput("D.sun");
  b.SetOutput("D.carrier");
  auto t = std::move(b).Finalize();
  const double ws = 100.0;
  const PlanetaryKinematics k = SolvePlanetaryKinematics(*t, 0, Eigen::VectorXd::Constant(1, ws));
  // Ring at rest: -w_c = (Z_s/Z_r)(w_s - w_c)  =>  w_c = w_s Z_s / (Z_s - Z_r)  (reverse).
  const double wc = ws * zs / (zs - zr);
  const double wb = wc - (ws - wc) * zs / zb;        // sun -> inner
  const double wd = wc + (ws - wc) * zs / zd;        // inner -> outer: sign flips again
  ExpectRel(k.speeds_rad_s(t->MemberIndex("D.carrier")), wc, "carrier");
  ExpectRel(k.speeds_rad_s(t->MemberIndex("D.ring")), 0.0, "ring");
  ExpectRel(k.speeds_rad_s(t->num_members() + t->PlanetSetIndex("D.inner")), wb, "inner");
  ExpectRel(k.speeds_rad_s(t->num_members() + t->PlanetSetIndex("D.outer")), wd, "outer");
  ExpectRel(k.ratio, (zs - zr) / double(zs), "ratio");
  // All three meshes pass teeth at Z_s |w_s - w_c| / 2 pi.
  const double fm = zs * std::abs(ws - wc) / kTwoPi;
  for (int m = 0; m < 3; ++m) ExpectRel(k.mesh_frequencies_hz(m), fm, t->meshes[m].name.c_str());
  // Every planet tooth flank meets two partners per relative turn.
  ExpectRel(k.gear_fault_frequencies_hz(t->planet_sets[0].gear), 2 * std::abs(wb - wc) / kTwoPi,
            "inner fault");
}

// Ravigneaux stage with Z_s1 30, Z_s2 36, short 18, long 21, ring 78, 3 branches:
// (36 + 78)/3 = 38 and (78 - 30)/3 = 16 are integers.
std::shared_ptr<const PlanetaryTrain> Ravigneaux() {
  PlanetaryTrainBuilder b;
  b.AddRavigneauxStage({.name = "R", .small_sun = {30}, .large_sun = {36}, .short_planet = {18},
                        .long_planet = {21}, .ring = {78}, .num_planets = 3});
  b.AddBrake("Bc", "R.carrier");
  b.AddBrake("Bs2", "R.sun2");
  b.AddRange("carrier held", {"Bc"});
  b.AddRange("large sun held", {"Bs2"});
  b.AddInput("R.sun1");
  b.SetOutput("R.ring");
  return std::move(b).Finalize();
}

TEST(PlanetaryKinematics, RavigneauxRangesMatchTheTabularMethod) {
  const auto t = Ravigneaux();
  const double z1 = 30, z2 = 36, za = 18, zb = 21, zr = 78, w1 = 100.0;
  const int s2 = t->MemberIndex("R.sun2"), r = t->MemberIndex("R.ring"),
            c = t->MemberIndex("R.carrier");
  const int pa = t->num_members() + t->PlanetSetIndex("R.short");
  const int pb = t->num_members() + t->PlanetSetIndex("R.long");
  {
    // Carrier held: w_r = w_s1 Z_s1/Z_r, w_s2 = -w_r Z_r/Z_s2.
    const PlanetaryKinematics k =
        SolvePlanetaryKinematics(*t, t->RangeIndex("carrier held"), Eigen::VectorXd::Constant(1, w1));
    ExpectRel(k.speeds_rad_s(r), w1 * z1 / zr, "ring");
    ExpectRel(k.speeds_rad_s(s2), -w1 * z1 / z2, "sun2");
    ExpectRel(k.speeds_rad_s(pa), -w1 * z1 / za, "short");
    ExpectRel(k.speeds_rad_s(pb), w1 * z1 / zb, "long");
    ExpectRel(k.ratio, zr / z1, "ratio");
  }
  {
    // Large sun held: w_r - w_c = w_c Z_s2/Z_r and (w_s1 - w_c) Z_s1/Z_r
    //   => w_c = w_s1 Z_s1/(Z_s1 + Z_s2), w_r = w_c (1 + Z_s2/Z_r).
    const PlanetaryKinematics k = SolvePlanetaryKinematics(*t, t->RangeIndex("large sun held"),
                                                           Eigen::VectorXd::Constant(1, w1));
    const double wc = w1 * z1 / (z1 + z2);
    const double wr = wc * (1 + z2 / zr);
    ExpectRel(k.speeds_rad_s(c), wc, "carrier");
    ExpectRel(k.speeds_rad_s(r), wr, "ring");
    ExpectRel(k.ratio, w1 / wr, "ratio");
    // Planets relative to the carrier: short -Z_s1/Z_a, long +Z_s1/Z_b times (w_s1 - w_c).
    ExpectRel(k.planet_relative_speeds_rad_s(t->PlanetSetIndex("R.short")), -(w1 - wc) * z1 / za,
              "short rel");
    ExpectRel(k.planet_relative_speeds_rad_s(t->PlanetSetIndex("R.long")), (w1 - wc) * z1 / zb,
              "long rel");
    // All four meshes pass teeth at one rate; sun and ring faults n f_m / Z; long planet 3 meshes.
    const double fm = z1 * (w1 - wc) / kTwoPi;
    for (int m = 0; m < 4; ++m) ExpectRel(k.mesh_frequencies_hz(m), fm, t->meshes[m].name.c_str());
    ExpectRel(k.gear_fault_frequencies_hz(t->members[r].gear), 3 * std::abs(wr - wc) / kTwoPi,
              "ring fault");
    ExpectRel(k.gear_fault_frequencies_hz(t->planet_sets[1].gear), 3 * fm / zb, "long fault");
  }
}

TEST(PlanetaryKinematics, SinglePlanetFaultFrequenciesCountTeethPassing) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {22}, .planet = {14}, .ring = {50},
                          .num_planets = 3});
  b.AddBrake("B", "S.ring");
  b.AddRange("r", {"B"});
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  auto t = std::move(b).Finalize();
  const double ws = 72.0;  // w_c = w_s 22/72 = 22 rad/s
  const PlanetaryKinematics k = SolvePlanetaryKinematics(*t, 0, Eigen::VectorXd::Constant(1, ws));
  const double wc = 22.0, wp_rel = -(ws - wc) * 22.0 / 14.0;
  ExpectRel(k.speeds_rad_s(t->MemberIndex("S.carrier")), wc, "carrier");
  ExpectRel(k.planet_relative_speeds_rad_s(0), wp_rel, "planet relative");
  // A sun tooth meets 3 planets per turn relative to the carrier; a ring tooth likewise.
  ExpectRel(k.gear_fault_frequencies_hz(t->members[t->MemberIndex("S.sun")].gear),
            3 * (ws - wc) / kTwoPi, "sun");
  ExpectRel(k.gear_fault_frequencies_hz(t->members[t->MemberIndex("S.ring")].gear),
            3 * wc / kTwoPi, "ring");
  // A planet tooth: once on each flank per relative turn.
  ExpectRel(k.gear_fault_frequencies_hz(t->planet_sets[0].gear), 2 * std::abs(wp_rel) / kTwoPi,
            "planet");
  // Input size is checked.
  EXPECT_THROW(SolvePlanetaryKinematics(*t, 0, Eigen::VectorXd::Zero(2)), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::gears

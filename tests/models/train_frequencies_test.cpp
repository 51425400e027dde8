// The kinematic frequencies of a train (models/train_frequencies.cpp) against seed 003's Table 1
// (docs/validation/scenarios.md: with the sun turning against the ring, mesh frequency 220.3 Hz
// and planet relative to the carrier 15.74 Hz in case 1 (sun 10 rad/s), 268.9 and 19.21 Hz in
// case 2 (30 rad/s); carrier 52.92 and 46.81 rad/s, planet 151.8 and 167.5 rad/s), and the
// relations between the lines written out by hand: f_m = Z_r |f_r - f_c| = Z_p f_p^H, planet
// pass N |f_c| and N |f_c - f_r|, fault lines N f_m / Z for the central gears and 2 f_m / Z_p for
// the planet (Feng & Zuo 2012).
#include "models/train_frequencies.h"

#include <cmath>
#include <map>
#include <numbers>

#include <gtest/gtest.h>

#include "models/planetary_scenes.h"

namespace orrery::gears {
namespace {

std::map<std::string, TrainFrequency> ByName(const std::vector<TrainFrequency>& lines) {
  std::map<std::string, TrainFrequency> m;
  for (const TrainFrequency& f : lines) m[f.name] = f;
  return m;
}

TEST(TrainFrequencies, Seed003TableOne) {
  const auto train = MakeSeed003SteeringDifferential();
  const double two_pi = 2 * std::numbers::pi;
  struct Case {
    double sun, f_m, f_ph, carrier, planet;
  };
  // Published to 4 digits: tolerance half a unit of the last digit.
  for (const Case c : {Case{-10, 220.3, 15.74, 52.92, 151.8}, Case{-30, 268.9, 19.21, 46.81, 167.5}}) {
    const PlanetaryKinematics k = SolvePlanetaryKinematics(*train, 0, Eigen::Vector2d(80.6, c.sun));
    const auto f = ByName(CalcTrainFrequencies(*train, k));
    EXPECT_NEAR(f.at("f_m").frequency_hz, c.f_m, 0.05);
    EXPECT_EQ(f.at("f_m").kind, "mesh");
    EXPECT_NEAR(f.at("f_p^H").frequency_hz, c.f_ph, 0.005);
    EXPECT_NEAR(f.at("f_c").frequency_hz * two_pi, c.carrier, 0.005);
    EXPECT_NEAR(f.at("f_p").frequency_hz * two_pi, c.planet, 0.05);
    // Relations among the lines.
    const double fm = f.at("f_m").frequency_hz, fc = f.at("f_c").frequency_hz, fr = f.at("f_r").frequency_hz;
    EXPECT_NEAR(fm, 50 * std::abs(fr - fc), 1e-9 * fm);
    EXPECT_NEAR(fm, 14 * f.at("f_p^H").frequency_hz, 1e-9 * fm);
    EXPECT_NEAR(f.at("f_pp").frequency_hz, 3 * fc, 1e-12 * fm);
    EXPECT_NEAR(f.at("f_pp^R").frequency_hz, 3 * std::abs(fc - fr), 1e-12 * fm);
    EXPECT_NEAR(f.at("f_fault S.sun").frequency_hz, 3 * fm / 22, 1e-9 * fm);
    EXPECT_NEAR(f.at("f_fault S.ring").frequency_hz, 3 * fm / 50, 1e-9 * fm);
    EXPECT_NEAR(f.at("f_fault S.planet").frequency_hz, 2 * fm / 14, 1e-9 * fm);
    EXPECT_EQ(f.at("f_fault S.planet").kind, "fault");
  }
}

// A held member has no line; a train of several stages names the stage in each per-stage line.
TEST(TrainFrequencies, HeldMembersAndStageNames) {
  const auto train = MakeSeed001AutomaticTransmission();
  const PlanetaryKinematics k = SolvePlanetaryKinematics(*train, train->RangeIndex("1st"), Eigen::VectorXd::Constant(1, 100.0));
  const auto f = ByName(CalcTrainFrequencies(*train, k));
  EXPECT_EQ(f.count("f_s S1"), 0u);  // the first-range brake holds stage 1's sun
  ASSERT_EQ(f.count("f_m S1"), 1u);
  EXPECT_NEAR(f.at("f_m S1").frequency_hz, k.stage_mesh_frequencies_hz(0), 1e-12);
  EXPECT_EQ(f.count("f_m"), 0u);
}

}  // namespace
}  // namespace orrery::gears

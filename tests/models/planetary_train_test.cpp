// Builder checks of models/planetary_train.cpp: reference geometry against an identity the code
// does not use, the assembly (equal-spacing) condition, planet overlap, and determinacy of gear
// ranges, each error naming the member or value.
//
// Oracles:
// - base pitch identity p_bt = 2 pi r_b / z = pi m_n cos(alpha_n) / cos(beta_b) with
//   sin(beta_b) = sin(beta) cos(alpha_n) (involute helicoid; the code computes r_b from alpha_t);
// - assembly condition counted by hand: (34 + 70)/3 = 34.67 is not an integer, (34 + 70)/4 = 26 is;
// - planet overlap by hand: 8 planets of 14 teeth on the 22/50 pin circle (radius 18 m) are
//   2 * 18 * sin(pi/8) = 13.78 m apart, less than two tip radii 2 * 8 m = 16 m.
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "models/planetary_train.h"

namespace orrery::gears {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Runs f, expects std::invalid_argument whose message contains every fragment.
template <class F>
void ExpectInvalid(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    for (const std::string& s : fragments) EXPECT_NE(msg.find(s), std::string::npos) << msg;
  }
}

SinglePlanetStageSpec Seed001Stage(const std::string& name, int planets) {
  return {.name = name, .sun = {34}, .planet = {18}, .ring = {70}, .num_planets = planets,
          .tooth_form = ToothForm{.normal_module_m = 0.0015,
                                  .normal_pressure_angle_rad = 21.3 * kDeg}};
}

TEST(PlanetaryTrain, HelicalReferenceGeometryMatchesBasePitchIdentity) {
  PlanetaryTrainBuilder b;
  const double mn = 0.016, an = 20 * kDeg, beta = 7 * kDeg;
  b.AddSinglePlanetStage({.name = "S", .sun = {19}, .planet = {34}, .ring = {89},
                          .num_planets = 3,
                          .tooth_form = ToothForm{.normal_module_m = mn,
                                                  .normal_pressure_angle_rad = an,
                                                  .helix_angle_rad = beta}});
  const double beta_b = std::asin(std::sin(beta) * std::cos(an));
  const double p_bt = std::numbers::pi * mn * std::cos(an) / std::cos(beta_b);
  for (const TrainGear& g : b.draft().gears) {
    // Pitch radius by definition, base radius through the base pitch.
    EXPECT_NEAR(g.pitch_radius_m, mn * g.teeth / (2 * std::cos(beta)), 1e-15) << g.name;
    EXPECT_NEAR(2 * std::numbers::pi * g.base_radius_m / g.teeth, p_bt, 1e-15) << g.name;
    EXPECT_NEAR(g.tip_radius_m, g.pitch_radius_m + (g.internal ? -mn : mn), 1e-15) << g.name;
  }
}

TEST(PlanetaryTrain, EqualSpacingImpossibleNamesTheToothSum) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage(Seed001Stage("S1", 4));  // 104 / 4 = 26
  ExpectInvalid([&] { b.AddSinglePlanetStage(Seed001Stage("S2", 3)); },
                {"'S2'", "3 planets cannot be equally spaced", "104/3", "34.6667"});
  // The failed stage left no trace; assemblable angles are accepted.
  EXPECT_EQ(b.draft().stages.size(), 1u);
  SinglePlanetStageSpec s = Seed001Stage("S2", 3);
  s.planet_angles_rad = AssemblablePlanetAngles(104, 3);
  EXPECT_NO_THROW(b.AddSinglePlanetStage(s));
  // 0, 35 and 69 tooth pitches of 360/104 deg.
  const std::vector<double>& a = b.draft().planet_sets.back().angles_rad;
  EXPECT_NEAR(a[1], 2 * std::numbers::pi * 35 / 104, 1e-15);
  EXPECT_NEAR(a[2], 2 * std::numbers::pi * 69 / 104, 1e-15);
}

TEST(PlanetaryTrain, ExplicitAnglesMustSatisfyTheAssemblyCondition) {
  PlanetaryTrainBuilder b;
  SinglePlanetStageSpec s = Seed001Stage("S2", 3);
  s.planet_angles_rad = {0.0, 120 * kDeg, 240 * kDeg};  // 104/3 teeth: not integer
  ExpectInvalid([&] { b.AddSinglePlanetStage(s); },
                {"'S2'", "planet 1", "120 deg", "34.6667"});
  // Double-planet: (Z_r - Z_s)/n must be an integer: (90 - 31)/3 is not.
  ExpectInvalid([&] {
    b.AddDoublePlanetStage({.name = "D", .sun = {31}, .inner_planet = {15},
                            .outer_planet = {17}, .ring = {90}, .num_planets = 3});
  }, {"'D'", "Z_r - Z_s", "59/3"});
}

TEST(PlanetaryTrain, OverlappingPlanetsAreRejectedWithTheDistances) {
  PlanetaryTrainBuilder b;
  // 6 planets fit (distance 18 m > 16 m), 8 do not (13.78 m < 16 m); (22 + 50)/8 = 9.
  EXPECT_NO_THROW(b.AddSinglePlanetStage(
      {.name = "six", .sun = {22}, .planet = {14}, .ring = {50}, .num_planets = 6}));
  ExpectInvalid([&] {
    b.AddSinglePlanetStage(
        {.name = "eight", .sun = {22}, .planet = {14}, .ring = {50}, .num_planets = 8});
  }, {"'eight'", "planets overlap", "planet 0", "planet 1", "13.7", "16"});
  // With a module of 4 mm the message is in metres: 0.0551 < 0.064.
  ExpectInvalid([&] {
    b.AddSinglePlanetStage({.name = "eight_mm", .sun = {22}, .planet = {14}, .ring = {50},
                            .num_planets = 8,
                            .tooth_form = ToothForm{.normal_module_m = 0.004}});
  }, {"0.0551", "0.064"});
}

TEST(PlanetaryTrain, DoublePlanetPairMustCloseItsTriangle) {
  PlanetaryTrainBuilder b;
  // Inner pin radius (20 + 10)/2 = 15, outer (90 - 10)/2 = 40, pair distance 10: 15 + 10 < 40.
  ExpectInvalid([&] {
    b.AddDoublePlanetStage({.name = "D", .sun = {20}, .inner_planet = {10},
                            .outer_planet = {10}, .ring = {90}, .num_planets = 2});
  }, {"'D'", "cannot mesh", "15", "40", "10"});
}

TEST(PlanetaryTrain, UnderDeterminedRangeNamesTheFreeMembers) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage(Seed001Stage("S1", 4));
  b.AddSinglePlanetStage(Seed001Stage("S2", 4));
  b.AddConnection("c", "S1.carrier", "S2.ring");
  b.AddBrake("B1", "S1.sun");
  b.AddBrake("B2", "S2.sun");
  b.AddRange("ok", {"B1", "B2"});
  b.AddRange("loose", {"B2"});
  b.AddInput("S1.ring");
  b.SetOutput("S2.carrier");
  // Without B1, S1.sun, S1.carrier = S2.ring and S2.carrier turn with the input held.
  ExpectInvalid([&] { std::move(b).Finalize(); },
                {"gear range 'loose' is under-determined (1 free motion", "S1.sun", "S1.carrier",
                 "S2.ring", "S2.carrier"});
}

TEST(PlanetaryTrain, OverDeterminedRangeNamesTheConflictingConstraints) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage(Seed001Stage("S1", 4));
  b.AddBrake("B1", "S1.sun");
  b.AddBrake("B2", "S1.carrier");
  b.AddRange("locked", {"B1", "B2"});
  b.AddInput("S1.ring");
  b.SetOutput("S1.carrier");
  ExpectInvalid([&] { std::move(b).Finalize(); },
                {"gear range 'locked' is over-determined", "brake B1", "brake B2",
                 "input S1.ring"});
}

TEST(PlanetaryTrain, ElementErrorsNameTheElement) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage(Seed001Stage("S1", 4));
  ExpectInvalid([&] { b.AddConnection("x", "S1.sun", "S1.ring"); }, {"'x'", "same stage"});
  ExpectInvalid([&] { b.AddBrake("B", "S1.moon"); }, {"brake 'B'", "'S1.moon'"});
  ExpectInvalid([&] { b.AddRange("r", {"K9"}); }, {"'r'", "'K9'"});
  ExpectInvalid([&] { b.AddSinglePlanetStage({.name = "T", .sun = {0}, .planet = {18},
                                              .ring = {70}, .num_planets = 2}); },
                {"'T.sun'", "teeth = 0"});
}

}  // namespace
}  // namespace orrery::gears

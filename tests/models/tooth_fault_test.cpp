// Tooth fault descriptions (models/tooth_fault.h). Oracles: Chen & Shao's (2011) crack front
// written out by hand (q^2 linear along the width), the involute's roll distance
// sqrt(r^2 - r_b^2), and the validation messages naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "models/tooth_fault.h"

namespace orrery::gears {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

Gear Planet() {
  return Gear({.teeth = 18, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kDeg, .face_width_m = 0.03});
}

std::string ErrorOf(const Gear& g, const ToothFaultSpec& f) {
  try {
    ValidateToothFault(g, f);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ToothFault, CrackFrontFollowsChenShao) {
  const Gear g = Planet();
  const double b = g.spec().face_width_m;
  ToothFaultSpec c{.kind = ToothFaultSpec::Kind::kRootCrack, .crack_depth_m = 1e-3, .crack_angle_rad = 45 * kDeg,
                   .crack_face_fraction = 0.5};
  // Uniform depth over L_c = b / 2 from the z = 0 face, nothing beyond.
  EXPECT_EQ(CrackDepthAt(g, c, 0.0), 1e-3);
  EXPECT_EQ(CrackDepthAt(g, c, 0.49 * b), 1e-3);
  EXPECT_EQ(CrackDepthAt(g, c, 0.51 * b), 0.0);
  // First stage: the parabolic front q^2 = q0^2 (1 - z'/L_c) running out at L_c.
  c.crack_end_depth_m = 0.0;
  for (double t : {0.0, 0.25, 0.5, 0.9, 1.0})
    EXPECT_NEAR(CrackDepthAt(g, c, t * 0.5 * b), 1e-3 * std::sqrt(1 - t), 1e-15) << t;
  // From the other face: mirrored.
  c.from_face = ToothFaultSpec::FromFace::kZmax;
  EXPECT_NEAR(CrackDepthAt(g, c, b - 0.25 * 0.5 * b), 1e-3 * std::sqrt(0.75), 1e-15);
  EXPECT_EQ(CrackDepthAt(g, c, 0.1 * b), 0.0);
  // Second stage: through the width, q from 1 mm down to 0.4 mm, q^2 linear.
  c = {.kind = ToothFaultSpec::Kind::kRootCrack, .crack_depth_m = 1e-3, .crack_angle_rad = 45 * kDeg,
       .crack_face_fraction = 1.0, .crack_end_depth_m = 0.4e-3};
  EXPECT_NEAR(CrackDepthAt(g, c, 0.5 * b), std::sqrt(0.5 * (1e-6 + 0.16e-6)), 1e-15);
  EXPECT_NEAR(CrackDepthAt(g, c, b), 0.4e-3, 1e-15);
  // Axial ranges.
  EXPECT_EQ(FaultAxialRange(g, c), std::make_pair(0.0, b));
  const ToothFaultSpec broken{.kind = ToothFaultSpec::Kind::kBrokenTooth, .face_fraction = 0.25,
                              .from_face = ToothFaultSpec::FromFace::kZmax};
  EXPECT_NEAR(FaultAxialRange(g, broken).first, 0.75 * b, 1e-15);
  EXPECT_EQ(FaultAxialRange(g, broken).second, b);
  EXPECT_NEAR(BreakRadius(g, {.height_fraction = 0.5}), 0.5 * (g.tip_radius_m() + g.root_radius_m()), 1e-15);
}

TEST(ToothFault, RollDistanceAndRootThickness) {
  const Gear g = Planet();
  const double rb = g.base_radius_m(), ra = g.tip_radius_m();
  EXPECT_NEAR(RollDistance(g, ra), std::sqrt(ra * ra - rb * rb), 1e-15);
  EXPECT_EQ(RollDistance(g, 0.9 * rb), 0.0);
  // Root circle inside the base circle (18 teeth, 21.3 deg): the straight extension's half
  // thickness r_b sin(psi(r_b)).
  ASSERT_LT(g.root_radius_m(), rb);
  EXPECT_NEAR(BeamRootHalfThickness(g), rb * std::sin(g.HalfToothAngle(rb)), 1e-15);
}

TEST(ToothFault, ValidationNamesTheField) {
  const Gear g = Planet();
  EXPECT_NE(ErrorOf(g, {.tooth = 18}).find("tooth = 18"), std::string::npos);
  EXPECT_NE(ErrorOf(g, {.height_fraction = 1.5}).find("height_fraction"), std::string::npos);
  EXPECT_EQ(ErrorOf(g, {.height_fraction = 0.0}), "");  // nothing lost: allowed
  const ToothFaultSpec deep{.kind = ToothFaultSpec::Kind::kRootCrack, .crack_depth_m = 5e-3,
                            .crack_angle_rad = 90 * kDeg};
  EXPECT_NE(ErrorOf(g, deep).find("centre line"), std::string::npos);
  const double rho_a = RollDistance(g, g.tip_radius_m()), rho_f = RollDistance(g, g.form_radius_m());
  ToothFaultSpec spall{.kind = ToothFaultSpec::Kind::kSpall, .roll_start_m = rho_a - 1e-4, .roll_end_m = rho_a + 5e-4,
                       .axial_start_m = 0, .axial_end_m = 0.01, .depth_m = 2e-5};
  EXPECT_NE(ErrorOf(g, spall).find("leaves the involute"), std::string::npos);  // beyond the tip
  spall.roll_start_m = rho_f;
  spall.roll_end_m = rho_a;
  EXPECT_EQ(ErrorOf(g, spall), "");
  spall.depth_m = 0;
  EXPECT_NE(ErrorOf(g, spall).find("depth_m"), std::string::npos);
  spall.depth_m = 1e-5;
  spall.axial_end_m = 0.04;
  EXPECT_NE(ErrorOf(g, spall).find("axial range"), std::string::npos);
  // Two geometric faults on one tooth are rejected; a crack with a spall is fine.
  spall.axial_end_m = 0.01;
  EXPECT_THROW(ValidateToothFaults(g, {spall, {.kind = ToothFaultSpec::Kind::kBrokenTooth}}), std::invalid_argument);
  EXPECT_NO_THROW(ValidateToothFaults(g, {spall, {.kind = ToothFaultSpec::Kind::kRootCrack, .crack_depth_m = 1e-4}}));
}

TEST(ToothFault, NamesParseAndDescribe) {
  for (auto k : {ToothFaultSpec::Kind::kBrokenTooth, ToothFaultSpec::Kind::kRootCrack, ToothFaultSpec::Kind::kSpall})
    EXPECT_EQ(ParseFaultKind(KindName(k)), k);
  EXPECT_EQ(ParseFlank("minus"), ToothFaultSpec::Flank::kMinus);
  EXPECT_EQ(ParseFromFace("zmax"), ToothFaultSpec::FromFace::kZmax);
  EXPECT_THROW(ParseFaultKind("pitting"), std::invalid_argument);
  const ToothFaultSpec a{.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 3, .height_fraction = 0.5};
  ToothFaultSpec b = a;
  EXPECT_EQ(DescribeToothFault(a), DescribeToothFault(b));
  EXPECT_EQ(DescribeToothFault(a), "broken_tooth tooth=3 height_fraction=0.5 face_fraction=1 from_face=zmin");
  b.height_fraction = 0.5000000001;
  EXPECT_NE(DescribeToothFault(a), DescribeToothFault(b));
}

}  // namespace
}  // namespace orrery::gears

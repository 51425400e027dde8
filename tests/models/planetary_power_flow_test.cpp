// Power flow of models/planetary_power_flow.cpp against free-body and energy arguments that do not
// use the constraint multipliers:
// - a stage with one member held: T_s + T_r + T_c = 0 (moment balance) and sum T w = 0 (ideal
//   train, held member does no work) fix the three external torques from the speeds alone;
// - single-planet carrier moment balance with equal load sharing: the sun-planet force F_t acts at
//   r_s and the ring-planet force F_t at r_r, so |T_c| = n F_t (r_s + r_r), F_t the tangential
//   force at the reference pitch circles;
// - line-of-action and normal forces: F_bt = F_t / cos(alpha_t), F_n = F_t / (cos(alpha_n) cos(beta))
//   (the standard decomposition of the normal force into tangential, radial and axial parts).
// Tolerance: 1e-12 relative (rounding of a solve with integer entries, see the kinematics test).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "models/planetary_kinematics.h"
#include "models/planetary_power_flow.h"
#include "models/planetary_train.h"

namespace orrery::gears {
namespace {

constexpr double kRel = 1e-12;
constexpr double kDeg = std::numbers::pi / 180.0;

TEST(PlanetaryPowerFlow, DoublePlanetTorquesFollowFromBalanceAndPower) {
  PlanetaryTrainBuilder b;
  b.AddDoublePlanetStage({.name = "D", .sun = {30}, .inner_planet = {15}, .outer_planet = {17},
                          .ring = {90}, .num_planets = 3});
  b.AddBrake("B", "D.ring");
  b.AddRange("r", {"B"});
  b.AddInput("D.sun");
  b.SetOutput("D.carrier");
  auto t = std::move(b).Finalize();
  const PlanetaryKinematics k = SolvePlanetaryKinematics(*t, 0, Eigen::VectorXd::Constant(1, 50.0));
  const PlanetaryPowerFlow p = CalcPlanetaryPowerFlow(*t, k, t->MemberIndex("D.sun"), 100.0);
  const int s = t->MemberIndex("D.sun"), c = t->MemberIndex("D.carrier"), r = t->MemberIndex("D.ring");
  // Energy: T_c = -T_s w_s / w_c; balance: T_r = -T_s - T_c.
  const double tc = -100.0 * k.speeds_rad_s(s) / k.speeds_rad_s(c);
  EXPECT_NEAR(p.port_torques_n_m(c), tc, kRel * 300);
  EXPECT_NEAR(p.brake_torques_n_m(0), -100.0 - tc, kRel * 300);
  EXPECT_NEAR(p.external_torques_n_m(r), -100.0 - tc, kRel * 300);
  EXPECT_LT(p.torque_residual_n_m, kRel * 300);
  EXPECT_LT(p.power_residual_w, kRel * 300 * 50);
  EXPECT_NEAR(p.input_power_w, p.output_power_w, kRel * 5000);
  // All three meshes carry the same tangential load per tooth (in magnitude).
  for (int m = 1; m < 3; ++m)
    EXPECT_NEAR(std::abs(p.mesh_loads_n_m(m)), std::abs(p.mesh_loads_n_m(0)), kRel * 10);
  for (bool loaded : p.member_loaded) EXPECT_TRUE(loaded);
}

TEST(PlanetaryPowerFlow, HelicalMeshForcesMatchTheCarrierMomentBalance) {
  PlanetaryTrainBuilder b;
  const double mn = 0.016, an = 20 * kDeg, beta = 7 * kDeg;
  b.AddSinglePlanetStage({.name = "S", .sun = {19}, .planet = {34}, .ring = {89},
                          .num_planets = 3,
                          .tooth_form = ToothForm{.normal_module_m = mn,
                                                  .normal_pressure_angle_rad = an,
                                                  .helix_angle_rad = beta}});
  b.AddBrake("B", "S.ring");
  b.AddRange("run", {"B"});
  b.AddInput("S.carrier");
  b.SetOutput("S.sun");
  auto t = std::move(b).Finalize();
  const double tc = 3e5;
  const PlanetaryKinematics k = SolvePlanetaryKinematics(*t, 0, Eigen::VectorXd::Constant(1, 2.0));
  const PlanetaryPowerFlow p = CalcPlanetaryPowerFlow(*t, k, t->MemberIndex("S.carrier"), tc);
  // Carrier moment balance: T_c = n F_t (r_s + r_r), r = m_n z / (2 cos beta).
  const double rs = mn * 19 / (2 * std::cos(beta)), rr = mn * 89 / (2 * std::cos(beta));
  const double ft = tc / (3 * (rs + rr));
  const double at = std::atan(std::tan(an) / std::cos(beta));
  for (int m = 0; m < 2; ++m) {
    EXPECT_NEAR(p.mesh_tangential_forces_n(m), ft, kRel * ft) << t->meshes[m].name;
    EXPECT_NEAR(p.mesh_line_of_action_forces_n(m), ft / std::cos(at), kRel * ft);
    EXPECT_NEAR(p.mesh_normal_forces_n(m), ft / (std::cos(an) * std::cos(beta)), kRel * ft);
  }
  // Output torque on the sun: -T_c Z_s / (Z_s + Z_r).
  EXPECT_NEAR(p.port_torques_n_m(t->MemberIndex("S.sun")), -tc * 19 / 108, kRel * tc);
}

TEST(PlanetaryPowerFlow, KnownTorqueMustBeOnAPort) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {22}, .planet = {14}, .ring = {50},
                          .num_planets = 3});
  b.AddBrake("B", "S.ring");
  b.AddRange("r", {"B"});
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  auto t = std::move(b).Finalize();
  const PlanetaryKinematics k = SolvePlanetaryKinematics(*t, 0, Eigen::VectorXd::Constant(1, 1.0));
  try {
    CalcPlanetaryPowerFlow(*t, k, t->MemberIndex("S.ring"), 1.0);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'S.ring' is neither an input nor the output"),
              std::string::npos) << e.what();
  }
  // No tooth form: forces are NaN, torques are there.
  const PlanetaryPowerFlow p = CalcPlanetaryPowerFlow(*t, k, t->MemberIndex("S.sun"), 22.0);
  EXPECT_TRUE(std::isnan(p.mesh_tangential_forces_n(0)));
  EXPECT_NEAR(p.mesh_gear_a_torques_n_m(0), -22.0, kRel * 22);
}

}  // namespace
}  // namespace orrery::gears

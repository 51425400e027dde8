// A train in a housing on elastic mounts (TrainModelOptions::housing, models/train_members.cpp).
// Oracle: on mounts much softer than the bearings, the train moves with the housing as one rigid
// mass in the mounts' translational mode, f = sqrt(k_mount / M) / (2 pi) with M the housing's and
// every member's and planet's mass, once for x and once for y; the bearings' compliance in series
// lowers it by a relative k_mount / k_bearing (1e-5 here). The members seat in the housing: their
// joints' parent is the housing body.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "models/modal_analysis.h"
#include "models/train_dynamics.h"

namespace orrery::gears {
namespace {

std::shared_ptr<const PlanetaryTrain> Stage() {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {22}, .planet = {14}, .ring = {50}, .num_planets = 3,
                          .tooth_form = ToothForm{.normal_module_m = 4e-3,
                                                  .normal_pressure_angle_rad = 22.5 * std::numbers::pi / 180}});
  b.AddRange("steer", {});
  b.AddInput("S.ring");
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  return std::move(b).Finalize();
}

TEST(TrainHousing, TranslationalMountModeCarriesTheWholeTrain) {
  const auto train = Stage();
  TrainModelOptions o;
  o.dofs = TrainDofs::kPlanar;
  o.face_width_m = 0.04;
  o.input = TrainModelOptions::Input::kNone;
  o.radial_bearing_stiffness_n_per_m = 1e10;
  const double k_mount = 1e5;
  o.housing = TrainHousing{.mass_kg = 40, .polar_inertia_kg_m2 = 1.5,
                           .mount_radial_stiffness_n_per_m = k_mount,
                           .mount_torsional_stiffness_n_m_per_rad = 1e6};
  const TrainModel tm = BuildTrainModel(*train, 0, o);
  ASSERT_GE(tm.housing_body, 0);
  for (JointIndex j : tm.member_joints) EXPECT_EQ(tm.model->joints[j].spec.parent, tm.housing_body);
  double mass = o.housing->mass_kg;
  for (const TrainBodyParams& p : tm.member_params) mass += p.mass_kg;
  for (size_t s = 0; s < train->planet_sets.size(); ++s)
    mass += tm.planet_params[s].mass_kg * train->planet_sets[s].angles_rad.size();
  const double f = std::sqrt(k_mount / mass) / (2 * std::numbers::pi);
  const TrainModes modes = CalcTrainModes(tm);
  int found = 0;
  for (const TrainMode& m : modes.modes)
    if (std::abs(m.frequency_hz - f) < 1e-4 * f) ++found;
  EXPECT_EQ(found, 2) << "expected the x and y mount modes at " << f << " Hz";
}

}  // namespace
}  // namespace orrery::gears

#include "models/seed_models.h"

#include <cmath>
#include <numbers>

#include "models/gear_geometry.h"

namespace orrery::gears {

std::shared_ptr<const PlanetaryTrain> Seed002ShiftedStage() {
  constexpr double kPi = std::numbers::pi;
  const ToothForm tf{.normal_module_m = 0.016, .normal_pressure_angle_rad = 20 * kPi / 180,
                     .helix_angle_rad = 7 * kPi / 180};
  GearSpec s{.teeth = 19, .normal_module_m = 0.016, .helix_angle_rad = tf.helix_angle_rad,
             .profile_shift = 0.3, .face_width_m = 0.33};
  GearSpec p = s;
  p.teeth = 34;
  p.hand = HelixHand::kLeft;
  p.profile_shift = 0.2;
  const double pin_radius = GearPair(Gear(s), Gear(p)).center_distance_m();
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {19}, .planet = {34}, .ring = {89}, .num_planets = 3,
                          .tooth_form = tf, .pin_radius_m = pin_radius});
  b.AddBrake("B", "S.ring");
  b.AddRange("run", {"B"});
  b.AddInput("S.carrier");
  b.SetOutput("S.sun");
  return std::move(b).Finalize();
}

TrainModelOptions Seed002DynamicsOptions(const TimeFunction& carrier_speed) {
  TrainModelOptions o;
  o.dofs = TrainDofs::kSpatial;
  o.input = TrainModelOptions::Input::kSpeed;
  o.input_speed_functions = {carrier_speed};
  o.input_torque_n_m = 3e5;
  o.face_width_m = 0.33;
  o.members["S.carrier"].polar_inertia_kg_m2 = 15;
  o.members["S.sun"].polar_inertia_kg_m2 = 0.25;
  o.members["S.sun"].profile_shift = 0.3;
  o.members["S.planet"].profile_shift = 0.2;
  o.members["S.ring"].profile_shift = 0.27;
  o.mesh_stiffness_source = MeshStiffnessSource::kTvms;
  o.mesh_damping_ratio = 0.05;
  o.radial_bearing_stiffness_n_per_m = 2e9;
  o.axial_bearing_stiffness_n_per_m = 1e9;
  o.tilt_bearing_stiffness_n_m_per_rad = 1e9;
  o.bearing_damping_n_s_per_m = 2 * 0.05 * std::sqrt(2e9 * 513.0);  // planet mass 513 kg
  return o;
}

}  // namespace orrery::gears

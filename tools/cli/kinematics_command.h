#pragma once
// `orrery kinematics SCENE [--json] [--range NAME]`: the static picture of a gear scene.
//
// gear_train scenes, in the scene's range (or --range) at the scene's operating point (the input
// speeds of GearTrainScene::input_speeds_rad_s, the input torque):
//   - member speeds (SolvePlanetaryKinematics) and torques (CalcPlanetaryPowerFlow): the torque
//     of a member is the torque its stage's meshes put on it (carrier: the pin reactions; 0 for
//     an unloaded member), the external torque (ports and brake reactions) is listed beside it;
//   - planet sets: absolute speed and speed relative to the carrier;
//   - per mesh: mesh frequency, static forces per planet (tangential at the pitch circle, along
//     the line of action, normal to the flank), and from the involute geometry of the pair
//     (import/train_mesh_geometry.h: reference gears at the zero-backlash centre distance) base
//     radii, transverse contact ratio, overlap ratio, working pressure angle, ISO 6336-1 c'_th,
//     c', c_gamma_alpha, c_gamma_beta in N/(mm um) (CalcIso6336Stiffness) and the mean, minimum,
//     maximum and range of the time-varying mesh stiffness (CalcTvms) in N/m, plus the mean
//     stiffness of the scene's dynamic model when the range is the scene's. A mesh whose gears
//     have no tooth form, or whose geometry GearPair rejects, gets null values and
//     "geometry_error";
//   - local tooth-fault frequencies per gear (planetary_kinematics.h).
// lumped_stage scenes: what the scene defines (DOF set, members, meshes, drivers and loads).
//
// JSON layout (--json), gear_train:
//   {"scene", "kind": "gear_train", "range", "ratio" (null for several inputs),
//    "inputs": [{"member", "speed_rad_s"}], "input_torque_n_m",
//    "members": {NAME: {"speed_rad_s", "speed_rpm", "torque_n_m", "external_torque_n_m", "loaded"}},
//    "planet_sets": {NAME: {"speed_rad_s", "relative_speed_rad_s", "relative_frequency_hz"}},
//    "stage_mesh_frequencies_hz": {STAGE: Hz},
//    "meshes": [{"name", "stage", "mesh_frequency_hz", "static_force_n", "line_of_action_force_n",
//                "normal_force_n", "loaded", "gear_1", "gear_2", "base_radius_1_m",
//                "base_radius_2_m", "contact_ratio", "overlap_ratio", "working_pressure_angle_deg",
//                "face_width_m", "c_prime_th", "c_prime", "c_gamma_alpha", "c_gamma_beta",
//                "tvms_mean_n_per_m", "tvms_min_n_per_m", "tvms_max_n_per_m",
//                "tvms_range_n_per_m", "model_stiffness_n_per_m", ["geometry_error"]}],
//    "fault_frequencies_hz": {GEAR NAME: Hz},      (an object keyed by train gear name)
//    "scene_faults": [{"gear", "branch" (1-based), "kind", "tooth", "fault_frequency_hz"}]}
//                                                  (the scene's dynamics.faults)
// lumped_stage: {"scene", "kind": "lumped_stage", "dofs", "planets",
//    "members": {NAME: {"mass_kg", "inertia_kg_m2", "radius_m", "bearing_stiffness_n_per_m",
//                       "torsional_stiffness_n_m_per_rad", "teeth"}},
//    "meshes": [{"name", "stiffness_n_per_m", "pressure_angle_deg"}],
//    "ports": [{"member", "kind": "speed" | "torque", "role": "input" | "load", "function"}]}
// Failures (a bodies/joints scene, an unknown range) print one line "orrery: error: <reason>" and
// return kExitFailure.
#include <ostream>
#include <string>
#include <vector>

namespace orrery::cli {

struct KinematicsArgs {
  std::string scene_path;
  std::vector<std::string> overrides;  // --set key.path=value
  std::string range;                   // --range: "" for the scene's
  bool json = false;
};

int KinematicsCommand(const KinematicsArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

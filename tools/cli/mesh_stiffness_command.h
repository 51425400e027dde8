#pragma once
// `orrery mesh-stiffness SCENE --mesh NAME[#k] [--load N] [--points K] [--fault K=V,...] [--json]`: quasi-static mesh
// stiffness and transmission error of one gear mesh of a gear_train scene with rigid tooth
// contact (the `contact` mesh model, models/gear_contact.h SweepGearMesh):
//   - the mesh's GearPair as the lumped models see it (import/train_mesh_geometry.h: gear 1 the
//     sun of a sun-planet mesh, the planet of a ring-planet mesh);
//   - tooth surfaces and penalty from GearContactOptions' defaults, calibrated so that one tooth
//     pair at the load has the ISO 6336 single-pair stiffness c' b;
//   - gear 2 held at the kinematic angle of each of K roll angles of gear 1 over one mesh period
//     2 pi / z1, gear 1 loaded with load * r_b1 and turned until the contact balances it.
// Definitions: load = force along the transverse line of action (N; the tangential force at the
// reference circle is load * cos(alpha_wt)); transmission error TE = r_b1 (theta1 -
// theta1_kinematic) along the line of action (m); stiffness = load / TE (secant, N/m).
//
// Text: one line per roll angle (TE, stiffness, contact points, teeth in contact, contact
// pattern on gear 1 as roll distances along the line of action) and a summary with the oracles.
// JSON (--json): "scene", "mesh", "load_n", arrays "roll_angle_rad", "transmission_error_m",
// "stiffness_n_per_m", "normal_force_n", "contact_points", "teeth_in_contact"; numbers
// "mean_stiffness_n_per_m", "te_peak_to_peak_m", "iso6336_single_pair_n_per_m" (c' b),
// "iso6336_c_gamma_alpha_n_per_m" (c_gamma_alpha b), "tvms_mean_n_per_m" (potential-energy TVMS
// of the lumped model), "penalty_stiffness_per_area" (k_A, N/m^3).
// Faults (the scene's `dynamics.faults` and `--fault KEY=VALUE,...` entries on the pair's gears,
// planets of branch k with `--mesh NAME#k`): healthy and faulty sweeps over the first fault's
// tooth engagement and the lumped TVMS with the same faults; text: per roll angle both
// stiffnesses, their ratio and the TVMS's, then the rows of docs/faults.md's cross-level table
// (mesh_stiffness_faults.h; JSON: its keys).
// Failures print one line "orrery: error: <reason>" and return kExitFailure.
#include <ostream>
#include <string>
#include <vector>

#include "models/gear_contact.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {

struct MeshStiffnessArgs {
  std::string scene_path;
  std::string mesh;
  double load_n = 1000;
  int points = 40;
  std::vector<std::string> overrides;  // --set key.path=value
  bool json = false;
  // --flexible: FE-reduced gears instead of rigid ones (flexible_mesh_stiffness.h); --fe-level.
  bool flexible = false;
  int fe_level = 1;
  // --fault KEY=VALUE,... (repeatable): faults added to the scene's (mesh_stiffness_faults.h).
  std::vector<std::string> faults;
};

int MeshStiffnessCommand(const MeshStiffnessArgs& args, std::ostream& out, std::ostream& err);

// The per-point arrays of a sweep's JSON (roll_angle_rad, transmission_error_m,
// stiffness_n_per_m, normal_force_n, contact_points, teeth_in_contact); shared by the rigid and
// the flexible sweep.
void WriteSweepPoints(JsonWriter& w, const std::vector<gears::MeshSweepPoint>& points);

}  // namespace orrery::cli

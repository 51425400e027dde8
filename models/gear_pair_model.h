#pragma once
// The simplest gear scene: a parallel-axis gear pair (external or internal, spur or helical) on
// two shafts. Gear 1 turns on a revolute joint at the origin, gear 2 on one at the centre
// distance along +x (internal: the ring's centre at -x); both about z. The mesh is `kinematic`
// (an ideal gear constraint whose multiplier is the tooth force) or `lumped` (the mesh element
// of mbd/model.h) with stiffness from ISO 6336 (c_gamma_alpha b), the time-varying stiffness of
// the potential-energy method (with tooth faults), or a given value.
//
// Mesh phase convention: at t = 0 tooth pair (0, 0) of the TVMS enters contact (Tvms sample 0);
// teeth are numbered in mesh order for gear 1 turning +z, as in mesh_stiffness.h.
//
// Usage:
//   GearPair pair(Gear(pinion_spec), Gear(wheel_spec));
//   GearPairModelOptions o;  o.input_speed = TimeFunction::Ramp(0, 0.1, 0, 100);
//   o.load_torque = TimeFunction::Constant(-50);
//   GearPairModel m = BuildGearPairModel(pair, o);
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "mbd/model.h"
#include "models/gear_geometry.h"
#include "models/mesh_stiffness.h"

namespace orrery::gears {

struct GearPairModelOptions {
  enum class MeshModel { kKinematic, kLumped } mesh_model = MeshModel::kLumped;
  enum class Stiffness { kIso6336, kTvms, kGiven } stiffness = Stiffness::kTvms;
  double given_stiffness_n_per_m = 0;       // Stiffness::kGiven
  GearMeshSpec::Contact contact = GearMeshSpec::Contact::kTwoSided;
  // Backlash along the transverse line of action; NaN: from the pair's geometry.
  double backlash_m = std::numeric_limits<double>::quiet_NaN();
  double damping_ratio = 0.05;
  double density_kg_m3 = 7850;
  double bore_radius1_m = 0, bore_radius2_m = 0;  // gear 2 internal: its outer rim radius
  GearMaterial material1, material2;
  std::vector<TvmsFault> faults;            // TVMS only (mesh order, mesh_stiffness.h)
  // > 0: the TVMS load (TvmsOptions::load_n): spalls then add their no-load transmission error
  // (GearMeshSpec::ste_table_m) where the flanks reach the spall's floor.
  double tvms_load_n = 0;
  int tvms_samples_per_period = 128;
  // Loads: a speed driver or a torque on gear 1 (one of them), a load torque on gear 2.
  std::optional<TimeFunction> input_speed;  // rad/s about +z
  std::optional<TimeFunction> input_torque; // N m about +z
  std::optional<TimeFunction> load_torque;  // N m about +z on gear 2
  double initial_speed1 = 0;                // rad/s; gear 2 starts at the kinematic speed
};

struct GearPairModel {
  std::shared_ptr<const Model> model;
  JointIndex shaft1 = -1, shaft2 = -1;
  double inertia1 = 0, inertia2 = 0;        // kg m^2 about the axes
  double mesh_stiffness_mean_n_per_m = 0;   // lumped meshes
  std::optional<Tvms> tvms;                 // when the TVMS was used
  double ratio = 0;                         // w2 / w1 (negative for an external pair)
};

// Throws std::invalid_argument naming the option that is missing or inconsistent.
GearPairModel BuildGearPairModel(const GearPair& pair, const GearPairModelOptions& options);

}  // namespace orrery::gears

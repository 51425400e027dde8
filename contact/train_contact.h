#pragma once
// The `contact` mesh model on the meshes of a planetary train (models/train_dynamics.h): the
// train model is built with no lumped element on the chosen meshes
// (TrainModelOptions::meshes_without_element), and a tooth-contact element
// (contact/gear_contact.h) is added on every branch of each of them, through the builder hook
// TrainModelOptions::before_finalize. Single-planet stages: sun-planet (external) and
// ring-planet (internal) meshes, rigid planets.
//
// Gear frames and tooth phasing. Every gear's teeth are placed so that the train at q = 0 is in
// its kinematic mesh with both flanks just touching (less any backlash): tooth 0 of the sun on
// the sun body's +x; with psi the planet angle on the carrier (the planet body's x points
// radially out), a space of the planet faces each sun tooth on the line of centres, i.e. the
// planet gear frame is turned in its body by
//   pi + pi / z_p + (z_s / z_p) psi,
// and the ring gear frame in the ring body by (from the planet's, SweepGearMesh's convention)
//   psi + pi / z_r + (z_p / z_r) (pi + pi / z_p + (z_s / z_p) psi),
// the same for every planet modulo the ring pitch 2 pi / z_r when (z_s + z_r) / n is an integer
// (equal spacing); each ring-planet element carries its own ring surface, so unequal spacing is
// placed per planet.
//
// Flexible planets (TrainModelOptions::flexible_planets, Craig-Bampton-reduced FE gears from the
// gear mesher, models/gear_fe_mesh.h): their sun-planet and ring-planet branches are
// FlexibleContactElements (contact/flexible_contact_element.h), the planet side flexible, the
// sun / ring side the rigid surface of the rigid builder (thinned for backlash as there).
//   Phasing: the FE teeth are fixed in the body frame B (tooth k on polar angle 2 pi k / z_p), so
//   the planet's joint starts at the angle delta = planet_rot - (2 pi / z_p) m (m the nearest whole
//   number of pitches, |delta| <= pi / z_p) instead of 0, and its analytic surface is turned by
//   the whole pitches 2 pi m / z_p in B: the teeth stand in the world where the rigid planet's
//   stand at q = 0 (tooth indices of missing_teeth are the rigid builder's gear frame indices).
//   Axial position: B's origin is the bore master, mid-face (z0 = -b/2 to +b/2 in B); the gear
//   surfaces of the rigid builder span z in [0, b] of their frames, so every gear frame of a
//   flexible branch is shifted by z0 (the lowest z of the FE tooth nodes) along the axis: no
//   change in torsional and planar models; in spatial models that branch's contact acts b/2
//   lower on the sun and ring than a rigid branch's.
//   Surface: the planet's analytic tooth outlines (MakeToothSurfaceMesh with the contact's
//   resolution and flexible.face_intervals across the face) embedded in the FE surface triangles
//   of the node sets TOOTHk_FLANK_PLUS / _MINUS, TOOTHk_FILLET_PLUS / _MINUS, TOOTHk_TIP and ROOT
//   (FlexibleContactSurface's embedded form; every one must be in the reduced body, which
//   `orrery reduce` keeps by default: every surface node and its node sets). Triangles with a
//   vertex farther than flexible.embed_tolerance_m from those FE triangles are left out (the
//   chordal error of the FE faces, largest at the fillets); an involute or tip vertex that far
//   is an error (the reduce input's gear differs from the train's).
//   Penalty: the local contact compliance only, CalibrateFlexibleGearContact
//   (contact/flexible_gear_mesh.h): Hertz in series with the rigid gear's own tooth compliance
//   (its bore bore_to_pitch_ratio r, a ring's rim ring_rim_modules m_n), material
//   TrainModelOptions::gear_material, secant at the contact's calibration load; the planet's tooth
//   bending, shear and foundation are in its modes (as far as they hold them).
//
// Gear geometry: the train's tooth forms (module, pressure and helix angle; sun right hand,
// planet left, ring left), face widths and profile shifts from the TrainModelOptions overrides
// as MakeTrainGearPair, at the pin-circle radius; rings with `ring_addendum_coefficient` and
// `ring_root_fillet_coefficient` (seed 003's 14/50 planet-ring pair needs h_a* < 0.897 for the
// ring tip to stay outside the planet's interference point, and rho_fP* < 0.38 for the ring's
// fillets to fit). Backlash: the central gear's teeth are thinned (WithNormalBacklash), not the
// planet's (a small planet is near undercut).
//
// Usage:
//   TrainContactOptions c;                 // every mesh of the range
//   c.gear.hunt_crossley_s_per_m = 0.5;
//   TrainContactModel m = BuildTrainContactModel(train, range, options, c);
//   auto integ = MakeIntegrator(*m.train_model.model, integrator_options);
#include <string>
#include <vector>

#include "contact/gear_contact.h"
#include "models/train_dynamics.h"

namespace orrery::contact {

struct TrainContactOptions {
  GearContactOptions gear;            // resolution, margin, slack, law (every contact mesh)
  std::vector<std::string> meshes;    // train mesh names; empty: every mesh of the train
  double normal_backlash_m = 0;       // per mesh, taken by the central gear
  double ring_addendum_coefficient = 0.85;
  double ring_root_fillet_coefficient = 0.25;
  // A broken tooth: teeth (gear frame indices) removed from a train gear ("S.sun") or from the
  // planet of one branch ("S.planet", branch 0-based).
  struct MissingTeeth {
    std::string gear;
    int branch = 0;
    std::vector<int> teeth;
  };
  std::vector<MissingTeeth> missing_teeth;
  // Flexible planets (header).
  struct Flexible {
    int face_intervals = 4;               // across the face width of the planet's surface
    double embed_tolerance_m = 50e-6;     // analytic vertex to FE triangle
    double deformation_allowance_m = 50e-6;  // FlexibleContactSurfaceSpec
  };
  Flexible flexible;
};

// One contact element of the model.
struct TrainContactMesh {
  std::string name;                   // "<train mesh>#<branch + 1>"
  int train_mesh = -1, branch = -1;
  BodyIndex body1 = -1, body2 = -1;   // gear 1 (sun; planet of a ring mesh), gear 2
  int external_force = -1;            // index into Model::external_forces
  double base_radius1_m = 0, base_radius2_m = 0, base_helix_angle_rad = 0;
  double transverse_pressure_angle_rad = 0;
  double rotation1_rad = 0, rotation2_rad = 0;  // gear frame in the body frame (about z)
  GearContactCalibration calibration;
  int flexible_side = 0;              // 0: rigid gears (ContactElement); 1 or 2: that gear is a
                                      // flexible planet (FlexibleContactElement)
  double planet_initial_angle_rad = 0;  // flexible: delta of the header
};

struct TrainContactModel {
  gears::TrainModel train_model;
  std::vector<TrainContactMesh> contacts;
};

// Throws std::invalid_argument for a mesh name that is not in the train, a planet-planet mesh, a
// gear without tooth form, geometry the gear classes reject (with their reason), a flexible
// planet whose reduced body lacks a tooth node set or whose FE teeth do not carry the planet's
// involutes (naming the planet, the set or the distance).
TrainContactModel BuildTrainContactModel(const gears::PlanetaryTrain& train, int range,
                                         gears::TrainModelOptions options,
                                         const TrainContactOptions& contact);

// The GearPair of a contact mesh as BuildTrainContactModel builds it (before backlash): gear 1
// the sun (sun-planet) or the planet (ring-planet).
gears::GearPair MakeTrainContactPair(const gears::PlanetaryTrain& train, int mesh,
                                     const gears::TrainModelOptions& options,
                                     const TrainContactOptions& contact);

}  // namespace orrery::contact

#pragma once
// The `contact` mesh model on the mesh branches of a planetary train (models/train_dynamics.h):
// BuildTrainModel puts a tooth-contact element (models/gear_contact.h) on every branch whose mesh
// model is `contact` (train_contact_meshes.cpp). Sun-planet (external) and ring-planet (internal)
// meshes of single-planet stages; planet-planet meshes are not supported yet.
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
// Flexible gears (TrainModelOptions::flexible_bodies: Craig-Bampton-reduced FE gears from the gear
// mesher, models/gear_fe_mesh.h, a planet or an external central gear): their contact branches
// are FlexibleContactElements (contact/flexible_contact_element.h), the flexible gear's side its
// FE teeth, a rigid partner's the rigid builder's surface (thinned for backlash as there). What
// follows is written for a planet; a flexible sun is the same with its own frame (its teeth stand
// at q = 0 as the rigid sun's: no turn, no joint offset).
//   Phasing: the FE teeth are fixed in the body frame B (tooth k on polar angle 2 pi k / z_p), and
//   B is the planet's gear frame: FE tooth k is gear-frame tooth k (the index of missing_teeth,
//   of a tooth fault and of the reduce input's `fault:` alike), so the planet's joint starts at
//   the angle delta = planet_rot (above) instead of 0 and its analytic surface stands in B
//   unturned: the teeth stand in the world where the rigid planet's stand at q = 0.
//   Axial position: B's origin is the bore master, mid-face (z0 = -b/2 to +b/2 in B); the gear
//   surfaces of the rigid builder span z in [0, b] of their frames, so every gear frame of a
//   flexible branch is shifted by z0 (the lowest z of the FE tooth nodes) along the axis: no
//   change in torsional and planar models; in spatial models that branch's contact acts b/2
//   lower on the sun and ring than a rigid branch's.
//   Surface: the planet's analytic tooth outlines (MakeToothSurfaceMesh with the contact's
//   resolution and flexible.face_intervals across the face) embedded in the FE surface triangles
//   of the node sets TOOTHk_FLANK_PLUS / _MINUS, TOOTHk_FILLET_PLUS / _MINUS, TOOTHk_TIP and ROOT
//   (contact::FlexibleContactSurface's embedded form; every one must be in the reduced body, which
//   `orrery reduce` keeps by default: every surface node and its node sets). Triangles with a
//   vertex farther than flexible.embed_tolerance_m from those FE triangles are left out (the
//   chordal error of the FE faces, largest at the fillets); an involute or tip vertex that far
//   is an error (the reduce input's gear differs from the train's). A reduced body without tooth
//   node sets (a part from a mesh file: `orrery reduce planet.stl|planet.step`, a tet mesh of
//   gmsh) embeds the outlines in its whole exported surface instead; its facets are chords of the
//   file's surface (remeshed at the mesh size), so the embed tolerance must cover their deviation
//   from the involute (about h^2 / (8 rho) for facets of size h on a flank of curvature radius
//   rho). The contact geometry stays the analytic outline; the FE faces carry its deformation.
//
// Imported planets (TrainModelOptions::imported_gears, rigid): their tooth surface is the file's
// triangles (models/imported_gear.h), placed in the body as the rigid planet's gear frame.
//   Penalty: the local contact compliance only, CalibrateFlexibleGearContact
//   (models/flexible_gear_mesh.h): Hertz in series with a rigid partner's own tooth compliance
//   (its bore bore_to_pitch_ratio r, a ring's rim ring_rim_modules m_n), material
//   TrainModelOptions::gear_material, secant at the contact's calibration load; the flexible
//   gear's tooth bending, shear and foundation are in its modes (as far as they hold them); two
//   flexible gears: Hertz alone.
//
// Gear geometry: MakeTrainGearPair's (train_dynamics.h: the same gears the lumped stiffness
// models describe), at the pin-circle radius. Backlash: the central gear's teeth are thinned
// (WithNormalBacklash), not the planet's (a small planet is near undercut).
//
#include <string>
#include <vector>

#include "models/gear_contact.h"

namespace orrery::gears {

struct PlanetaryTrain;
struct TrainModelOptions;

// Options of every contact branch of a train (TrainModelOptions::contact).
struct TrainContactOptions {
  GearContactOptions gear;            // resolution, margin, slack, law (every contact mesh)
  double normal_backlash_m = 0;       // per mesh, taken by the central gear
  // A broken tooth: teeth (gear frame indices) removed from a train gear ("S.sun") or from the
  // planet of one branch ("S.planet", branch 0-based).
  struct MissingTeeth {
    std::string gear;
    int branch = 0;
    std::vector<int> teeth;
  };
  std::vector<MissingTeeth> missing_teeth;
  // Flexible gears' surfaces (header).
  struct Flexible {
    int face_intervals = 4;               // across the face width of the gear's surface
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
  int flexible_side = 0;              // 0: rigid gears (ContactElement); 1, 2: that gear is
                                      // flexible, 3: both (FlexibleContactElement)
  double planet_initial_angle_rad = 0;  // a flexible planet's joint offset delta (header)
};

}  // namespace orrery::gears

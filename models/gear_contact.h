#pragma once
// Tooth contact of a gear pair (models/gear_geometry.h GearPair) as a contact::ContactElement: the
// `contact` mesh model built from the gears' own geometry, and the quasi-static mesh sweep that
// measures its transmission error and mesh stiffness.
//
// Surfaces: every tooth of each gear is one part (the broad phase's unit): its whole outline
// (root, fillet, involute flanks, tip) from gears::MakeToothSurfaceMesh, with
// `involute_intervals` along each flank and `face_intervals` across the face width. Missing teeth
// (a broken tooth with its geometry removed) are left out.
//
// Tooth faults (faults1, faults2; models/tooth_fault.h, gear-frame tooth indices): a broken tooth
// or a spall changes its tooth's surface (models/tooth_fault_geometry.h MakeFaultyToothSurfaceMesh:
// the fracture chord, the spall's depression; the face intervals are split at their axial
// limits). A root crack leaves the surface and lowers the penalty of its tooth: the tooth is two
// parts (the minus and the plus half, split at the tooth's centre line), and the half on the
// crack's flank carries the stiffness scale (contact_surface.h) R^(3/2), R the ratio of the
// cracked to the healthy tooth pair's stiffness of the potential-energy model averaged over the
// path of contact (mesh_stiffness.h CrackStiffnessRatio: Chen & Shao's crack, Hertz, both teeth
// and their fillet foundations with rim_radius1_m / rim_radius2_m; a constant per tooth, not a
// function of the roll position). The power 3/2: the penalty's force grows as k_A delta^(3/2)
// (below), so the secant stiffness at any load scales as k_A^(2/3) and R^(3/2) scales it by R.
// The other flank's half is unchanged (a crack on the compression side closes).
//
// Penalty calibration (rigid gears): the linear penalty per unit area k_A of contact_law.h on
// two convex flanks (equivalent radius rho = rho1 rho2 / (rho1 +- rho2), + external, - internal,
// at the pitch point) pressed by an approach delta along the normal gives a contact strip of
// half width sqrt(2 rho delta) and a force per unit face width
//   w = k_A int (delta - x^2 / (2 rho)) dx = (4/3) sqrt(2 rho) k_A delta^(3/2).
// k_A is chosen so that one tooth pair carrying the calibration load F deflects by
// delta_ref = F / (c' b) along the line of action, i.e. its secant stiffness at that load is the
// single-pair stiffness c' b of ISO 6336-1 (models/mesh_stiffness.h; or a given value, e.g. the
// TVMS of one pair):
//   k_A = (F / b) / ((4/3) sqrt(2 rho) delta_ref^(3/2)).
// The force grows as delta^(3/2), so the tangent stiffness at F is 1.5 c' b, and two pairs
// sharing F deflect by (1/2)^(2/3) delta_ref each. The rigid pair's compliance then stands for the
// whole tooth pair (bending, shear, foundation and Hertz); for flexible gears only the local
// contact compliance would be left to the penalty.
//
// Quasi-static sweep (SweepGearMesh): gear 2 is held at the kinematic angle of each roll angle
// theta1 of gear 1 over one mesh period 2 pi / z1; gear 1 carries the torque F r_b1 and is
// turned until the contact balances it (safeguarded secant on the moment). Transmission error
// TE = r_b1 (theta1 - theta1_kinematic) along the line of action (> 0: gear 1 ahead, flanks
// pressed), mesh stiffness k = F / TE (secant). Frames: gear 1 at the origin, gear 2 at
// (a, 0, 0) (external) or (-a, 0, 0) (internal ring), gear axes +z, gear 1 driving
// counter-clockwise; at theta1 = 0 a space of gear 2 faces tooth 0 of gear 1.
//
// Usage:
//   gears::GearPair pair(gears::Gear(sun), gears::Gear(planet));
//   GearContactOptions o;
//   contact::ContactElementSpec spec = MakeGearContactSpec("sun_planet", pair, sun_body, planet_body, o);
//   builder.AddExternalForce(std::make_shared<contact::ContactElement>(spec));
//   MeshSweep sweep = SweepGearMesh(pair, o, /*load_n=*/1429, /*points=*/40);
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "contact/contact_element.h"
#include "models/gear_geometry.h"
#include "models/gear_mesh_monitor.h"
#include "models/mesh_stiffness.h"
#include "models/tooth_fault.h"

namespace orrery::gears {

struct GearContactOptions {
  // Surface resolution. Faceting study (seed 001's 18/34 sun-planet pair, m = 1.5 mm, 21.3 deg,
  // b = 30 mm, 40 roll angles per mesh period; false TE = peak to peak of TE(n) - TE(240)):
  //   involute intervals      16     24     40     60     100
  //   at   50 N (um)        0.99   0.73   0.18   0.100  0.041
  //   at 1429 N (um)        0.93   0.52   0.20   0.055  0.054
  // 100 keeps it below 0.1 um at light and full load. Spur contact lines run along the axis, so
  // 2 face intervals integrate a uniform load exactly (helical gears need more). A healthy spur
  // tooth, and each half of a cracked one, is an extruded part (contact/contact_surface.h): with
  // rigid gears turning about parallel axes its rows of nodes share one row's gaps
  // (contact/tracked_gaps.h) and one contact-law call per profile point (contact_element.h),
  // so more face intervals cost their rows' list entries, not their tracking or their forces (a
  // tooth broken across part of its width, its face intervals split at the break's end, is
  // tracked node by node).
  int involute_intervals = 100;
  int root_intervals = 2, fillet_intervals = 6, tip_intervals = 4;
  // Fillet chords within this of the fillet (ProfileResolution::fillet_max_sag_m): a fillet's
  // chords lie in the tooth space, and seed 003's ring tips pass the 14-tooth planet's fillets
  // 23 um away at the centred kinematic position (10 um from the flanks): 6 even intervals put
  // a chord 52 um into the space there and the unloaded ring-planet mesh touched with 3.8 kN,
  // radially (docs/faults.md). 1 um: 21 to 36 intervals per fillet there.
  double fillet_max_sag_m = 1e-6;
  int face_intervals = 2;
  // The contact force along the flank normal interpolated across the facets, not the facet's own
  // (contact/contact_surface.h smooth_normals): a facet's normal turns by ~1 degree from one
  // involute interval to the next, and on a flexible gear the deformed faces' normals differ
  // across its FE element boundaries, where a spur pair's mid-face row of nodes sits; the force
  // turning with the face a node took was a jump in the residual that Newton could not settle
  // (docs/fault_study.md).
  bool smooth_normals = true;
  double margin_m = 30e-6;   // above the largest penetration (delta_ref is a few um)
  double slack_m = 100e-6;   // per surface: pairs are kept for relative motions up to this
  std::vector<int> missing_teeth1, missing_teeth2;  // teeth removed (gear frame indices)
  std::vector<gears::ToothFaultSpec> faults1, faults2;  // tooth faults (header), gear frame indices
  // For a crack's stiffness ratio: fillet-foundation rims of gear 1 (bore) and gear 2 (bore, or
  // outer rim of a ring); 0 leaves the foundation out. Material of both gears.
  double rim_radius1_m = 0, rim_radius2_m = 0;
  gears::GearMaterial material;
  // Normal backlash j_n of the pair (m, >= 0; WithNormalBacklash): MakeGearContactSpec thins
  // both gears' teeth by the same normal thickness allowance. 0: the pair as given (a standard
  // pair at the reference centre distance has none, and both flanks then lie within the search
  // distance).
  double normal_backlash_m = 0;
  double backlash_share1 = 0.5;  // share of the thinning taken by gear 1 (0: gear 2 only)
  // Penalty calibration: c' b (N/m along the line of action) of one tooth pair, default ISO 6336
  // c' times the face width; the load at which the secant stiffness equals it, default 1000 N.
  std::optional<double> single_pair_stiffness_n_per_m;
  double calibration_load_n = 1000;
  double hunt_crossley_s_per_m = 0;
  double friction_coefficient = 0;
  double slip_velocity_m_s = 1e-3;
  // Poses of the gear frames in the body frames (default: the same frame).
  Transform X_B1G1, X_B2G2;
  // Imported tooth surfaces (models/imported_gear.h SplitImportedGearTeeth: one mesh per tooth,
  // gear frame) replacing the generated outlines of gear 1 / gear 2; null: generated. Missing
  // teeth are left out as for generated ones; faults and backlash thinning cannot reshape them
  // (an error).
  std::shared_ptr<const std::vector<TriangleMesh>> imported_teeth1, imported_teeth2;
  // > 0: record this many contact points per output row (contact_point_record.h).
  int record_points = 0;
};

struct GearContactCalibration {
  double single_pair_stiffness_n_per_m = 0;  // c' b
  double equivalent_radius_m = 0;            // rho at the pitch point
  double reference_deflection_m = 0;         // delta_ref = F / (c' b)
  double stiffness_per_area = 0;             // k_A (N/m^3)
};

// Throws std::invalid_argument for a non-positive load or stiffness.
GearContactCalibration CalibrateGearContact(const gears::GearPair& pair,
                                            const GearContactOptions& options);

// The surface of one gear (gear frame, then X_BG), one part per present tooth, with the faults'
// geometry (header); crack_scales: (tooth, stiffness scale of the cracked half) per cracked tooth,
// from CrackStiffnessScales; imported: the gear's imported tooth surfaces (#teeth, gear frame)
// instead of generated ones. Throws std::invalid_argument for a missing-tooth index out of range,
// no tooth left, invalid faults, faults on an imported gear or imported teeth of another count.
std::shared_ptr<const contact::ContactSurface> MakeGearContactSurface(
    const gears::Gear& gear, const GearContactOptions& options, const std::vector<int>& missing,
    const Transform& X_BG, const std::vector<gears::ToothFaultSpec>& faults = {},
    const std::vector<std::pair<int, double>>& crack_scales = {},
    const std::vector<TriangleMesh>* imported = nullptr);

// The stiffness scale R^(3/2) of each cracked tooth of gear `gear` (1 or 2) of the pair (header),
// as (tooth, scale).
std::vector<std::pair<int, double>> CrackStiffnessScales(const gears::GearPair& pair, int gear,
                                                         const GearContactOptions& options);

// The pair with its teeth thinned (GearSpec::thickness_allowance_m: gear 1 takes gear1_share of
// the thinning, gear 2 the rest; thinning a small pinion moves it towards undercut, so give the
// share to the larger gear there) so that its normal backlash (GearPair::normal_backlash_m) is
// the given value, at the same centre distance. Throws std::invalid_argument for a negative
// backlash, a share outside [0, 1] or gears that reject the thinning (undercut, pointed tip).
gears::GearPair WithNormalBacklash(const gears::GearPair& pair, double normal_backlash_m,
                                   double gear1_share = 0.5);

// The depth at which a gear pair's tooth contact stops standing for its teeth
// (contact::PenetrationLimit, the stop of contact_outputs.h): half the thinner tooth's transverse
// thickness at its reference circle, min(s_1, s_2) / 2 (gears::Gear::ToothThickness; after any
// thinning in `pair`). The contact is carried around the pitch point, where the tooth's middle
// lies at least s / 2 behind the flank (the inscribed circle tangent to the flank there has a
// radius of (s / 2) / cos(alpha) on a straight-sided tooth): a node pressed that deep has reached
// the middle of the tooth it entered, where the closest face of the gaps turns to the tooth's
// other flank and the penalty pushes it on through, and the teeth pass through each other.
// Seed 003 (m = 4 mm, 14-tooth planet): 3.13 mm, against 1.6 mm reached by contact 10 times softer
// than ISO's under the full load (which meets Willis) and the pass-through of one 100 times softer
// (docs/extremes.md).
contact::PenetrationLimit GearPenetrationLimit(const gears::GearPair& pair);

// The element's spec: body1 carries gear 1, body2 gear 2; law from CalibrateGearContact() of the
// pair with options.normal_backlash_m (WithNormalBacklash); penetration limit from
// GearPenetrationLimit of the thinned pair.
contact::ContactElementSpec MakeGearContactSpec(const std::string& name, const gears::GearPair& pair,
                                       BodyIndex body1, BodyIndex body2,
                                       const GearContactOptions& options);

// One roll angle of the sweep.
struct MeshSweepPoint {
  double roll_angle_rad = 0;       // theta1 (kinematic) of gear 1
  double transmission_error_m = 0; // along the line of action
  double stiffness_n_per_m = 0;    // load / TE
  double normal_force_n = 0;       // sum of the node normal forces
  double friction_force_n = 0;
  // Gear 1's contact force in the sweep frame (x, y; N, its bearing load from the mesh): along
  // the line of action for frictionless involute flanks, at the working pressure angle to y.
  double force_x_n = 0, force_y_n = 0;
  int contact_points = 0;
  int teeth_in_contact = 0;        // teeth of gear 1 with a penetrating node or face
  int teeth[3] = {-1, -1, -1};     // their gear-frame indices, in the order of the pattern slots
  // Contact pattern on gear 1: extent of the contact along the line of action (roll distance
  // sqrt(r^2 - r_b1^2) of the contact nodes, m), per tooth in contact up to 3.
  double pattern_min_m[3] = {0, 0, 0}, pattern_max_m[3] = {0, 0, 0};
  int evaluations = 0;             // contact evaluations of the equilibrium search
};

// Records the contact pattern of a sweep point: each contact (world point p_W on tooth `tooth`
// of gear 1) widens that tooth's extent along the line of action, for up to 3 teeth; later teeth
// are ignored. X_1W maps world points into gear 1's frame (axis z), rb1 its base radius.
class ContactPattern {
 public:
  ContactPattern(MeshSweepPoint& point, const Transform& X_1W, double rb1)
      : point_(point), X_1W_(X_1W), rb1_(rb1) {}
  void Add(int tooth, const Vec3& p_W);  // tooth: gear 1's gear-frame tooth index

 private:
  MeshSweepPoint& point_;
  Transform X_1W_;
  double rb1_;
  int teeth_[3] = {-1, -1, -1};
};

struct MeshSweep {
  std::vector<MeshSweepPoint> points;
  double load_n = 0;
  double mean_stiffness_n_per_m = 0;
  double te_peak_to_peak_m = 0;
  GearContactCalibration calibration;
  long searches = 0;               // candidate searches over the sweep
};

// The roll angles of a sweep: `points` angles from start_rad over span_rad (0: one mesh period
// 2 pi / z1), end excluded. A faulty tooth k of gear 1 meshes around theta1 = -2 pi k / z1
// (mod 2 pi): its engagement is a span of about eps_alpha mesh periods there.
struct MeshSweepRange {
  double start_rad = 0;
  double span_rad = 0;
};

// Quasi-static sweep of gear 1 at `points` roll angles of `range`; load_n along the line of
// action; the options' X_BG transforms are ignored (gears in their own frames).
// Throws std::runtime_error if the equilibrium is not bracketed (no contact within 20 delta_ref).
MeshSweep SweepGearMesh(const gears::GearPair& pair, const GearContactOptions& options,
                        double load_n, int points, const MeshSweepRange& range = {});

}  // namespace orrery::gears

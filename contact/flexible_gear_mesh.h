#pragma once
// Quasi-static mesh stiffness of a spur pair with FLEXIBLE (FE-reduced) gears in tooth contact:
// the flexible counterpart of SweepGearMesh (gear_contact.h), same frames, roll angles, load and
// definitions (TE along the line of action, stiffness = load / TE).
//
// Bodies: each gear is meshed (models/gear_fe_mesh.h) and held at its bore (RBE2 master = body
// frame B, the reference interface of the reduction). Reduced basis: the static response of the
// FE model, bore held, to unit transverse loads (x and y) at every node of the loaded flanks of
// the teeth that pass through the mesh zone over one mesh period (teeth within +-teeth_each_side
// of the line of centres; the flank facing the positive rotation sense, which carries the load
// for gear 1 driving counter-clockwise and gear 2 driven clockwise) -- the attachment modes of
// tooth-contact analysis. For frictionless spur contact every load lies in their span, so the
// reduced statics equal the full FE statics (no truncation); fixed-interface normal modes alone
// converge slowly to such local loads (tests/contact/flexible_contact_element_test.cpp measures
// 25 % error with 30 of 150 modes on a block). Their stiffness U^T K U is read off U at the
// loaded DOFs (K U = F away from the held bore) and diagonalized, U^T K U = V Lambda V^T: modes
// Phi = U V with K = Lambda, kept only at the contact nodes. These are static modes (no mass
// normalization, no inertia invariants): for this quasi-static sweep only.
//
// Contact surface: by default the analytic flank and tip of each of those teeth
// (MakeToothSurfaceMesh, the triangles on the loaded flank's and tip's FE faces only) embedded in
// the FE faces: a vertex at local coordinates (xi, eta) of an 8-node face (hex20) moves by
// sum_i N_i(xi, eta) u_i with the serendipity shape functions N_i, so its force reaches the FE
// nodes as the consistent load (negative shares at the corners included). Why: a Hertzian strip
// (tenths of a millimetre) is narrower than an FE face; on the FE surface's own nodes it would sit
// on one node row at a time, and lumped positive loads on hex20 corner nodes are far too soft
// (measured on seed 001: TE jumping between 2.5 and 7 um from one roll angle to the next).
//
// Penalty (flexible gears: the local contact compliance only; bending, shear and fillet
// foundation are in the FE model): the linear penalty per area of gear_contact.h calibrated so
// that one tooth pair at the load has the Hertzian line-contact stiffness of the lumped TVMS
// (Yang & Lin 1987, models/mesh_stiffness.h HertzStiffness):
//   k_h = pi E b / (4 (1 - nu^2))   (equal materials),
//   k_A = (F / b) / ((4/3) sqrt(2 rho) (F / k_h)^(3/2))   (gear_contact.h, rho at the pitch point).
// A coarse FE mesh has little of the near-field Hertz flattening, so the two do not overlap much;
// the finer the mesh under the contact, the more the FE model double-counts it.
//
// Static equilibrium at each roll angle: unknowns x = (TE, q_1, q_2), total potential
//   Pi = 1/2 q_1^T K_1 q_1 + 1/2 q_2^T K_2 q_2 + U_contact(TE, q_1, q_2) - F TE
// (gear 2 held at its kinematic angle, gear 1 loaded by F r_b1), minimized by Newton's method with
// the contact's Gauss-Newton Hessian sum_P c_P r_P r_P^T (r_P = d(gap)/dx, c_P the node's
// penalty) and a backtracking line search on Pi (the full step where it finds no descent);
// converged when the TE step is below 1 pm and the moment residual below 1e-5 F. A point where
// Newton stalls (contacts switching features at a tip corner) is kept if the residual is below
// 1 % of F and counted (unconverged_points). Warm start from the previous roll angle.
//
// Measured (seed 001's sun-planet pair of models/scenes/seed001_sun_planet_contact.yaml, tip
// diameters 52.74 / 30.5 mm, eps_alpha 1.344, 1429 N; orrery mesh-stiffness --flexible):
//   mesh (hex20)          FE nodes        modes    mean    single   double   N/um
//   default (level 1)     8670 + 4590     276+276  485     416      579      (40 points, 15 s)
//   --fe-level 2          49776 + 26352   828+828  463     392      562      (12 points, 130 s)
//   oracles: published (seed 001 Table 2) 437; ISO 6336 c_gamma_alpha b 476, c' b 378;
//   lumped TVMS (same blanks) mean 515, min 363, max 735.
// Zones: the single/double-pair zones sit where the unloaded path of contact puts them; the load
// lengthens the double-pair zone by about one roll angle step at the end of the path.
//
// Usage:
//   FlexibleGearMeshOptions o;  o.fe.flank_divisions = 4;
//   FlexibleMeshSweep s = SweepFlexibleGearMesh(pair, o, /*load_n=*/1429, /*points=*/20);
#include <vector>

#include "contact/gear_contact.h"
#include "mbd/flexible_body.h"
#include "models/gear_fe_mesh.h"
#include "models/mesh_stiffness.h"

namespace orrery::contact {

struct FlexibleGearMeshOptions {
  // FE mesh of both gears (bore radii below). Default: coarse hex20 that a CI test affords.
  gears::GearFeMeshSpec fe{.type = flex::ElementType::kHex20, .flank_divisions = 4,
                           .fillet_divisions = 2, .tooth_divisions = 3, .root_layer_divisions = 2,
                           .rim_divisions = 2, .face_divisions = 1, .smoothing_iterations = 200};
  // 0: 0.4 times the reference radius, the lumped models' default (TrainModelOptions::
  // bore_to_pitch_ratio), so that the TVMS oracle sees the same blanks.
  double bore_radius1_m = 0, bore_radius2_m = 0;
  int teeth_each_side = 2;          // teeth with attachment modes: -n..n around the mesh
  // Contact surface: the analytic flanks and tips embedded in the FE surface
  // (FlexibleContactSurface's embedded form) with these resolutions (the rigid faceting study of
  // gear_contact.h: 100 involute intervals keep the false TE under 0.1 um), or the FE surface.
  bool embedded_flanks = true;
  // Across the face: this many intervals per FE element layer, so that a line load reaches the
  // hex20 nodes as the consistent load (vertex rows only on the element layers' node rows would put
  // positive point loads on corner nodes: measured 2.5 times too soft at fe level 2 with 2 rows).
  int involute_intervals = 100, tip_intervals = 4, face_intervals_per_element = 8;
  double embed_tolerance_m = 5e-6;
  double gap_margin_m = 30e-6;
  double deformation_allowance_m = 60e-6;
  double calibration_load_n = 0;    // 0: the sweep's load
  // Sweep tolerance and Newton limits.
  int max_newton_iterations = 25;
};

// One reduced gear: modes (nodes = the flank and tip nodes of the chosen teeth) and counts.
struct FlexibleGearBody {
  std::shared_ptr<const FlexibleBodyModes> modes;
  std::vector<std::string> contact_sets;  // node sets of the contact surface
  std::vector<int> teeth;                 // teeth with attachment modes
  // With options.embedded_flanks: the analytic loaded flank and tip of each of those teeth (one
  // part per tooth, gear frame) and their shapes (3 #V x nf) from the serendipity shape functions
  // of the FE faces they lie on.
  std::vector<TriangleMesh> fine_parts;
  Eigen::MatrixXd fine_shapes;
  int fe_nodes = 0;
  double reduce_seconds = 0;
};

// The reduced gear of the header (teeth_each_side around the line of centres of SweepGearMesh's
// frame: gear 1 towards +x, gear 2 (second = true) towards -x at roll angle 0).
FlexibleGearBody ReduceGearForContact(const gears::Gear& gear, bool second,
                                      const FlexibleGearMeshOptions& options, double bore_radius_m);

struct FlexibleMeshSweep {
  std::vector<MeshSweepPoint> points;   // same fields as the rigid sweep
  std::vector<double> max_deformation_m;  // per point: the larger deformation bound
  // Per point: tooth pairs on the unloaded path of contact [s_start, s_end] (GearPair) with the
  // contacts p_b apart and the phase of the first loaded contact (centre of its pattern); the
  // single/double zones of the rigid geometry to compare with teeth_in_contact.
  std::vector<int> predicted_pairs;
  double load_n = 0;
  double mean_stiffness_n_per_m = 0, te_peak_to_peak_m = 0;
  // Means over the points with one and with two teeth in contact (0 if none).
  double single_zone_stiffness_n_per_m = 0, double_zone_stiffness_n_per_m = 0;
  double hertz_stiffness_n_per_m = 0;   // k_h of the penalty calibration
  double stiffness_per_area = 0;        // k_A
  int nf1 = 0, nf2 = 0, fe_nodes1 = 0, fe_nodes2 = 0;
  double reduce_seconds = 0, sweep_seconds = 0;
  long evaluations = 0;
  long inflation_exceeded = 0;
  // Points where Newton stalled with the moment balanced to better than 1 % of the load (kept),
  // and the largest such residual (fraction of the load).
  int unconverged_points = 0;
  double max_moment_residual = 0;
};

// The penalty of a pair with one or two flexible gears (header, "Penalty"): k_A of
// gear_contact.h (CalibrateGearContact, rho at the pitch point, secant at calibration_load_n)
// for the single-pair stiffness that the FE models do not hold: the Hertzian line contact k_h
// (HertzStiffness, equal materials) in series with the whole tooth compliance (bending, shear,
// axial and fillet foundation, CalcToothCompliance at the reference circle) of each RIGID gear of
// the pair, whose teeth have no FE model:
//   1 / k = 1 / k_h + sum over rigid gears (1/k_b + 1/k_s + 1/k_a + 1/k_f).
// rim_radius_m per gear: the bore (external) or the outer rim radius (internal) of the fillet
// foundation; <= 0 leaves the foundation out. Both gears flexible: k = k_h (the sweep below).
// Throws std::invalid_argument for a non-positive load or an invalid material.
struct FlexiblePairPenalty {
  bool rigid1 = false, rigid2 = false;   // gears of the pair without an FE model
  double rim_radius1_m = 0, rim_radius2_m = 0;
};
GearContactCalibration CalibrateFlexibleGearContact(const gears::GearPair& pair,
                                                    const gears::GearMaterial& material,
                                                    double calibration_load_n,
                                                    const FlexiblePairPenalty& penalty = {});

// Throws std::invalid_argument for an internal pair, a helical pair, a non-positive load or
// points < 1; std::runtime_error if Newton fails at a roll angle.
FlexibleMeshSweep SweepFlexibleGearMesh(const gears::GearPair& pair,
                                        const FlexibleGearMeshOptions& options, double load_n,
                                        int points);

}  // namespace orrery::contact

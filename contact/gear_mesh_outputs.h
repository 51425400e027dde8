#pragma once
// What a tooth contact between two gears reports beyond its forces (ContactElement and
// FlexibleContactElement with a GearMeshInfo): the transmission error, the instantaneous mesh
// stiffness and the contact pattern, per evaluation.
//
// Transmission error, in the conventions of SweepGearMesh (gear_contact.h): in the frame F with
// its origin on gear 1's axis, z along it and x towards gear 2's axis (external pair) or away
// from it (internal gear 2), theta_1 and theta_2 are the angles of the gear frames' x axes about
// z; at zero TE gear 2 stands at its kinematic angle for theta_1,
//   external: theta_2 = pi + pi / z_2 - (z_1 / z_2) theta_1,
//   internal: theta_2 = pi / z_2 + (z_1 / z_2) theta_1,
// and TE = r_b1 (theta_1 - theta_1,kinematic(theta_2)) along the line of action, > 0 with gear 1
// ahead (counter-clockwise, its flanks pressed into gear 2's), wrapped to one base pitch
// p_b = 2 pi r_b1 / z_1 about zero:
//   external: TE = r_b1 theta_1 + r_b2 theta_2 - r_b2 (pi + pi / z_2),
//   internal: TE = r_b1 theta_1 - r_b2 theta_2 + r_b2 pi / z_2.
// Unthinned rigid flanks touch at TE = 0; with a normal backlash j_n taken by thinning teeth
// symmetrically (the builders' way) the flanks pressed at TE > 0 touch at TE = j_n / 2, the
// others at -j_n / 2. F follows the current line of centres, so a displaced centre shows as a
// rotation of both gears, not as TE.
//
// Line-of-action force: the contact's moment on gear 1 about its axis over r_b1, positive when
// it resists gear 1 turning ahead (TE > 0): the transmitted force, which the power flow gives in
// the mean. The normal force (the sum of the nodes' F_N) exceeds it where contact leaves the
// line of action (a tip corner on the mating flank's fillet).
//
// Mesh stiffness: the contact's stiffness along the TE, sum over the penetrating nodes P of
// k_P (n_P . u_P)^2, k_P = dF_N/d(depth) of the node's law (contact_law.h) and u_P = the
// motion of the contact point per unit TE when gear 1 turns, (z x (p_P - c_1)) / r_b1 (for an
// involute contact n . u = 1). For rigid gears it is the whole tooth pair's (the penalty is
// calibrated to it); for a flexible gear the penalty holds only the local contact compliance
// and the teeth's bending lies in the modes, so it is that of the contact layer alone (the
// whole mesh stiffness of flexible gears: `orrery mesh-stiffness --flexible`).
//
// Contact pattern: the extent of the penetrating nodes on gear 1 along the line of action (roll
// distance sqrt(r^2 - r_b1^2), r the distance from its axis: where on the flank, the envelope
// over the teeth in contact as a marking compound shows it) and along its axis (in its gear
// frame), NaN without contact.
#include <array>
#include <limits>

#include "mbd/spatial.h"

namespace orrery::contact {

// The gears of a contact: frames (z: axis) on the bodies of sides a (gear 1) and b (gear 2).
struct GearMeshInfo {
  Transform X_AG1, X_BG2;
  double base_radius1_m = 0, base_radius2_m = 0;
  int teeth1 = 0, teeth2 = 0;
  bool internal = false;  // gear 2 internal (a ring)
};

struct GearMeshOutputs {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double transmission_error_m = kNaN;
  double line_of_action_force_n = 0;
  double mesh_stiffness_n_per_m = 0;
  double pattern_roll_min_m = kNaN, pattern_roll_max_m = kNaN;
  double pattern_axial_min_m = kNaN, pattern_axial_max_m = kNaN;
};

// The output names and units, in the order WriteGearMeshOutputs writes them.
inline constexpr std::array<const char*, 7> kGearMeshOutputNames = {
    "transmission_error", "line_of_action_force", "mesh_stiffness",   "pattern_roll_min",
    "pattern_roll_max",   "pattern_axial_min",    "pattern_axial_max"};
inline constexpr std::array<const char*, 7> kGearMeshOutputUnits = {"m", "N", "N/m", "m",
                                                                    "m", "m", "m"};

// Accumulates one evaluation's outputs: Start with the gear poses, Add each penetrating node.
class GearMeshObserver {
 public:
  void Start(const GearMeshInfo& info, const Transform& X_WA, const Transform& X_WB);
  // A penetrating node: its point on gear 1 (world: the node itself when it is gear 1's, else
  // its closest point on gear 1's face), the normal n_W and the normal stiffness k (N/m).
  void Add(const Vec3& p1_W, const Vec3& n_W, double k);
  // The spatial force of the contact on gear 1's body (world origin).
  void Finish(const Vec6& f1_W);
  const GearMeshOutputs& outputs() const { return out_; }

 private:
  GearMeshOutputs out_;
  Transform X_G1W_;  // gear 1 frame from world
  double base_radius1_m_ = 0;
};

// The transmission error of the header at these poses (m).
double GearTransmissionError(const GearMeshInfo& info, const Transform& X_WA, const Transform& X_WB);

// Writes the outputs in the order of kGearMeshOutputNames.
void WriteGearMeshOutputs(const GearMeshOutputs& o, double* values);

}  // namespace orrery::contact

#pragma once
// What a tooth contact between two gears reports beyond its forces: the transmission error, the
// instantaneous mesh stiffness and the contact pattern, per evaluation. GearMeshMonitor is the
// gear layer's ContactMonitor (contact/contact_monitor.h): a contact element (ContactElement,
// FlexibleContactElement) with one in its spec adds these outputs after its own.
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
#include <memory>
#include <vector>

#include "contact/contact_monitor.h"
#include "mbd/spatial.h"

namespace orrery::gears {

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

// The outputs above, as a contact element records them: transmission_error (m),
// line_of_action_force (N), mesh_stiffness (N/m), pattern_roll_min / _max, pattern_axial_min /
// _max (m).
class GearMeshMonitor final : public contact::ContactMonitor {
 public:
  explicit GearMeshMonitor(const GearMeshInfo& info);

  const GearMeshInfo& info() const { return info_; }
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  std::unique_ptr<contact::ContactMonitorState> MakeState() const override;
  void Start(const Transform& X_WA, const Transform& X_WB,
             contact::ContactMonitorState& state) const override;
  void Add(const Vec3& p_a_W, const Vec3& n_W, double k,
           contact::ContactMonitorState& state) const override;
  void Finish(const Vec6& f_A_W, contact::ContactMonitorState& state) const override;
  void Write(const contact::ContactMonitorState& state, double* values) const override;

  // The outputs of the last Finish held in a state of this monitor.
  static const GearMeshOutputs& Outputs(const contact::ContactMonitorState& state);

 private:
  GearMeshInfo info_;
  std::vector<OutputDescription> outputs_;
};

// The transmission error of the header at these poses of the bodies of sides a and b (m).
double GearTransmissionError(const GearMeshInfo& info, const Transform& X_WA, const Transform& X_WB);

}  // namespace orrery::gears

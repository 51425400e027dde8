#pragma once
// One damaged tooth of one gear, described once and applied at whatever level the gear's meshes
// and body use (DESIGN.md, fidelity ladder; docs/faults.md):
//   lumped mesh     the potential-energy TVMS with the changed tooth, and a static transmission
//                   error where a spall lets the flanks approach (mesh_stiffness.h CalcTvms);
//   tooth contact   the changed flank geometry (gear_geometry.h MakeFaultyToothSurfaceMesh) and,
//                   for a crack, a per-tooth factor on the calibrated penalty (CrackStiffnessRatio);
//   flexible gear   the changed FE mesh (gear_fe_mesh.h MakeGearFeMesh with faults).
// Which gear of a train and which planet (branch) carry the fault is the train's business.
//
// The three kinds:
// - kBrokenTooth: the part of the tooth above the fracture circle r_break is gone over an axial
//   range starting at one end face:
//     r_break = r_a - height_fraction (r_a - r_f)   (internal gears alike: r_a is their tip),
//     z in [0, face_fraction b] (from_face kZmin) or [b - face_fraction b, b] (kZmax).
//   The fracture surface is the plane through the two flank points at r_break, parallel to the
//   axis (in every transverse section: the chord of the tooth at r_break).
// - kRootCrack: a straight crack at the root of the tooth on the side of `flank`, of depth q at
//   angle nu (crack_angle_rad) to the tooth centre line (Tian 2004; Chen & Shao 2011, Engineering
//   Failure Analysis 18:2149-2164). The crack starts on the root circle at the root section of the
//   tooth beam and leaves the cracked side a half thickness h_q = h_root - q sin(nu) (see
//   mesh_stiffness.h). Across the face width the crack front is Chen & Shao's parabola: with z'
//   the distance from the start face (from_face) and L_c = crack_face_fraction b,
//     q(z')^2 = q_0^2 + (q_1^2 - q_0^2) z' / L_c   for z' <= L_c,   q = 0 beyond,
//   q_0 = crack_depth_m, q_1 = crack_end_depth_m (Chen & Shao's first stage: q_1 = 0, the crack
//   running out at L_c; their second stage: L_c = b, q_1 > 0; q_1 unset: a uniform depth q_0,
//   Tian's through-width crack).
// - kSpall: a depression of depth `depth_m` in the flank surface of `flank` over the roll
//   distances [roll_start_m, roll_end_m] and the axial range [axial_start_m, axial_end_m]. The
//   roll distance of a flank point at radius r is rho = sqrt(r^2 - r_b^2): the length of the
//   base-circle tangent from its tangency point to the point (ISO 21771's roll length; on a pair's
//   line of action, the distance of the contact point from T1 for gear 1).
//
// Flanks: kPlus / kMinus as in gear_geometry.h (the plus flank of tooth 0 lies at positive polar
// angles). A crack or spall affects a mesh only while its flank carries the load (a crack on the
// compression side closes; a spall on the unloaded flank is not touched).
//
// Usage:
//   ToothFaultSpec broken{.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 3,
//                         .height_fraction = 0.5, .face_fraction = 0.5};
//   ValidateToothFault(gear, broken);  // throws std::invalid_argument naming the bad field
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "models/gear_geometry.h"

namespace orrery::gears {

struct ToothFaultSpec {
  enum class Kind { kBrokenTooth, kRootCrack, kSpall };
  enum class FromFace { kZmin, kZmax };
  enum class Flank { kPlus, kMinus };
  Kind kind = Kind::kBrokenTooth;
  int tooth = 0;                     // index in the gear's frame: tooth k centred on 2 pi k / z
  // kBrokenTooth: the part lost.
  double height_fraction = 1.0;      // of the tooth height r_a - r_f, from the tip (1: at the root)
  double face_fraction = 1.0;        // of the face width, from from_face
  FromFace from_face = FromFace::kZmin;  // where a partial-width break or a crack starts
  // kRootCrack (Chen & Shao 2011; header).
  double crack_depth_m = 0;          // q_0, at from_face
  double crack_angle_rad = 0;        // nu, to the tooth centre line, in [0, pi/2]
  double crack_face_fraction = 1.0;  // L_c / b
  std::optional<double> crack_end_depth_m;  // q_1 at z' = L_c (unset: q_0 across L_c)
  // kRootCrack and kSpall: the flank whose side is damaged.
  Flank flank = Flank::kPlus;
  // kSpall: roll distances on the flank's involute (m, from the base-circle tangency), axial
  // range (m, z from the z = 0 face), depth (m, along the flank normal).
  double roll_start_m = 0, roll_end_m = 0;
  double axial_start_m = 0, axial_end_m = 0;
  double depth_m = 0;
};

// Throws std::invalid_argument naming the field and value for: a tooth index outside [0, z),
// a broken tooth's fractions outside [0, 1] (0: nothing lost), a crack face fraction outside
// (0, 1], a negative crack depth or end depth, a
// crack angle outside [0, pi/2], a crack reaching past the tooth centre line (q sin(nu) >= half
// the root thickness), a spall with an empty or reversed range, a roll range outside the
// involute (form circle to tip), an axial range outside [0, b] or a depth <= 0.
void ValidateToothFault(const Gear& gear, const ToothFaultSpec& fault);

// Throws std::invalid_argument when two faults of one gear change the same tooth's geometry
// (a broken tooth and a spall, two breaks or two spalls on one tooth: not modelled), or when
// a fault is invalid (ValidateToothFault).
void ValidateToothFaults(const Gear& gear, const std::vector<ToothFaultSpec>& faults);

// r_break of a broken tooth (header).
double BreakRadius(const Gear& gear, const ToothFaultSpec& fault);

// Axial range [z0, z1] (m) of a broken part or a crack (L_c from from_face), or of a spall.
std::pair<double, double> FaultAxialRange(const Gear& gear, const ToothFaultSpec& fault);

// Crack depth q(z) (m) of a kRootCrack at axial position z (m, from the z = 0 face): Chen & Shao's
// front (header); 0 outside the crack's axial range and for other kinds.
double CrackDepthAt(const Gear& gear, const ToothFaultSpec& fault, double z_m);

// Half thickness h_root of the root section of the tooth beam of the potential-energy model
// (mesh_stiffness.h): at the base circle r_b sin(psi(r_b)) where the root circle lies inside it
// (external gears), else on the involute at the root circle. The crack's reference h_ref.
double BeamRootHalfThickness(const Gear& gear);

// Roll distance sqrt(r^2 - r_b^2) (m) of the involute point at radius r (0 inside the base circle).
double RollDistance(const Gear& gear, double radius_m);

// True when `flank` of the fault is the given flank.
inline bool OnFlank(const ToothFaultSpec& fault, ToothFaultSpec::Flank flank) { return fault.flank == flank; }

// Names used by the YAML reader, the provenance and messages: "broken_tooth", "root_crack",
// "spall"; "plus", "minus"; "zmin", "zmax". Parse* throw std::invalid_argument naming the value.
const char* KindName(ToothFaultSpec::Kind kind);
const char* FlankName(ToothFaultSpec::Flank flank);
const char* FaceName(ToothFaultSpec::FromFace face);
ToothFaultSpec::Kind ParseFaultKind(const std::string& name);
ToothFaultSpec::Flank ParseFlank(const std::string& name);
ToothFaultSpec::FromFace ParseFromFace(const std::string& name);

// One line with every field that matters for the kind (17 significant digits), e.g.
// "broken_tooth tooth=3 height_fraction=0.5 face_fraction=1 from_face=zmin": the provenance of a
// reduced faulty body and the text of messages. Equal faults give equal text.
std::string DescribeToothFault(const ToothFaultSpec& fault);

}  // namespace orrery::gears

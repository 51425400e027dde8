#pragma once
// Tooth surfaces with the geometry of tooth faults (tooth_fault.h): the `contact` level of a
// broken tooth or a spall. A root crack does not change the surface (the contact layer lowers
// the cracked tooth's penalty instead, mesh_stiffness.h CrackStiffnessRatio).
//
// Construction. The face width is cut at the fault's axial limits into segments; in each segment
// every transverse section of the tooth has one profile (rotated by the helix twist), swept as a
// ruled strip as in gear_geometry.h:
// - broken tooth: the outline from the minus flank's point at r_break along the chord of the
//   tooth to the plus flank's point at r_break (the fracture plane), the tip part dropped; the
//   chord carries tip_intervals + 2 intervals;
// - spall: the flank points with roll distance in [roll_start, roll_end] moved by depth_m along
//   the transverse profile normal into the material, with the walls at both roll limits (the
//   profile passes from a surface point to the depressed point at the same profile parameter).
// Profile points are inserted exactly at the fault's limits (the fracture radius on both flanks,
// the spall's roll limits), so the faulty outline shares every other point with the healthy one.
// Where two segments meet, a planar step closes the surface: the region between the two profiles
// (the fracture's end face of the remaining tooth; the spall's end walls), triangulated by
// zipping the two polylines by arc length, its normal out of the material. Vertices at equal
// positions are merged and zero-area triangles dropped, so the surface is one connected manifold
// (open at the root ends, as the healthy strip). The spall depth is measured in the transverse
// section (along the profile normal); for a helical gear the normal depth is depth cos(beta_b).
//
// Usage:
//   ToothFaultSpec spall{.kind = ToothFaultSpec::Kind::kSpall, .tooth = 2, .roll_start_m = 6e-3,
//                        .roll_end_m = 7e-3, .axial_start_m = 0.01, .axial_end_m = 0.02,
//                        .depth_m = 20e-6};
//   TriangleMesh t = MakeFaultyToothSurfaceMesh(gear, 2, {}, 8, {spall});
#include <vector>

#include "models/gear_geometry.h"
#include "models/tooth_fault.h"

namespace orrery::gears {

// Profile parameter s in [0, 7] (Gear::ProfileAt) of the outline point at radius r on the minus
// (plus_side = false) or plus side of tooth 0, between the root circle's fillet end and the tip
// (bisection on |p(s)|, monotone there). Throws std::invalid_argument for a radius outside
// [r_f, r_a] (internal gears: [r_a, r_f]).
double ProfileParameterAtRadius(const Gear& gear, double radius_m, bool plus_side);

// The surface of tooth `tooth` as MakeToothSurfaceMesh (root middle to root middle, n_face
// intervals across the face width, split in proportion to the segments' widths, at least one
// each), with the geometric faults of this tooth among `faults` (others are ignored). Throws
// std::invalid_argument for invalid faults (ValidateToothFaults) or n_face < 1.
TriangleMesh MakeFaultyToothSurfaceMesh(const Gear& gear, int tooth, const ProfileResolution& res, int n_face,
                                        const std::vector<ToothFaultSpec>& faults);

// The closed gear body of MakeGearMesh with the faults' geometry. The end faces need a
// star-shaped outline: a spall that reaches an end face (axial_start_m = 0 or axial_end_m = b)
// is rejected with std::invalid_argument, as are the inputs MakeGearMesh rejects.
TriangleMesh MakeFaultyGearMesh(const Gear& gear, const ProfileResolution& res, int n_face, double rim_radius_m,
                                const std::vector<ToothFaultSpec>& faults);

}  // namespace orrery::gears

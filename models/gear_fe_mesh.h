#pragma once
// Structured all-hex FE mesh (hex8 / hex20) of an external spur or helical gear, with node sets
// for the bore, the end faces and every tooth's flanks, fillets and tip; plus small helpers that
// select mesh nodes by geometry (cylinder, plane).
//
// Transverse layout (one sector per tooth, tooth k centred on polar angle 2 pi k / z, the tooth
// indexing of gear_geometry.h; the sector spans +-pi/z about it, from space middle to space
// middle):
//
//           tip arc                T  tooth block. Sides: the exact minus / plus profile from the
//         /---------\                tip down the involute to the form circle, along the fillet
//        | involutes |               and the half root arc to the space middle M (root circle,
//        |     T     |               polar angle -+pi/z), then radially down to the base circle
//      M  \_fillet__/  M             r_base = r_f - root_layer_depth_coef m_n. Bottom: the arc of
//      |  root        root |         r_base over the sector. Top: the tip arc.
//      +-------------------+ r_base  R  rim block: polar grid r_bore..r_base matching T's base.
//      |         R         |
//      +-------------------+ r_bore
//
// Every boundary node lies on the exact profile (Gear::ProfileAt), the root circle, the tip circle
// or the bore (midside nodes of hex20 included); fillet and root-arc nodes are spaced evenly in
// arc length along the (C1) fillet + root curve. T's interior is a transfinite (Coons) map of its
// four sides, relaxed by Winslow's elliptic smoothing (inverse Laplace; Thompson, Warsi & Mastin,
// "Numerical Grid Generation", 1985, ch. 6) on the non-uniform computational coordinates of the
// boundary distribution, so the element lines turn smoothly round the fillet and the 90-degree
// turns of T's sides at M, and the grading is kept. Sector meshes are rotated copies; nodes on the
// shared radial lines are merged, so the mesh is conforming. The transverse mesh is extruded over
// z in [0, b]; a helical gear's layer at height z is rotated by z tan(beta) / r (sign by hand,
// Gear::twist_per_length), the helix of the reference cylinder.
//
// Grading: across the tooth (tip arc and base arc) the element sizes grow geometrically from both
// sides to the middle (flank_bias = middle / side size), so elements are finest at the flanks and
// under the root spaces; in the rim from r_base to the bore (rim_bias = bore / root size); the
// fillet and the root layer have their own division counts. Elements round the bore per tooth:
// tooth_divisions.
//
// Optional web (GearWebSpec): a rim of thickness rim_thickness_m below the root circle, a hub from
// the bore to hub_radius_m, and between them an axially centred web of thickness
// web_thickness_m; elements of the web's radial range outside the web's axial range are omitted.
//
// Node sets (names upper case): "NALL", "BORE" (nodes on the bore cylinder), "FACE_ZMIN",
// "FACE_ZMAX" (z = 0 and z = b; with a web, only the gear's end faces: rim and hub), "ROOT"
// (nodes on the root arcs, root circle), and per tooth k = 0..z-1: "TOOTHk_FLANK_PLUS",
// "TOOTHk_FLANK_MINUS" (involute, form circle to tip, all axial layers), "TOOTHk_FILLET_PLUS",
// "TOOTHk_FILLET_MINUS" (fillet nodes, form circle included), "TOOTHk_TIP". Nodes on a form
// circle or a tip edge are in both sets that meet there. Element sets: "EALL", and "WEB" with a
// web.
// Tooth faults (tooth_fault.h; GearFeMeshSpec::faults). The faulted tooth's block is generated
// with a lattice row along the fault, so the mesh stays conforming:
// - broken tooth: the row through the two flank points at r_break is the fracture chord; the
//   tooth's side pieces are split there (at least one element row below and above; a point
//   within 0.3 of an element of a piece boundary (root curve / involute) takes that row). The
//   elements above the row are left out over the broken axial range, whose limits are element
//   layer boundaries (the layers end at the break). Node set "TOOTHk_FRACTURE": the fracture
//   surface's nodes.
// - root crack: the row starts at the crack's mouth on the damaged flank's fillet, where the
//   fillet's half thickness equals the tooth beam's root half thickness h_root of the
//   potential-energy model (mesh_stiffness.h; the nearest fillet end if none), runs straight
//   along the crack, A + t q_max (-cos nu, +-sin nu) (towards the root and the centre line), to
//   the crack tip (the element corner of the row nearest to it) and on to the other flank. The
//   row's points nearer the mouth than the local depth q(z) (Chen & Shao's front, rounded to
//   the row's points), inside the crack's axial range, are duplicated: the elements above the
//   row use the copies, so the crack faces share no node and carry nothing across (open crack,
//   no contact between its faces). Node set "TOOTHk_CRACK": both faces' nodes.
// - spall: no change (its depth, tens of micrometres, is far below an element): the contact
//   surface carries it (tooth_fault_geometry.h).
// Throws std::invalid_argument when a fault folds the tooth block's elements (a crack too deep
// for the mesh), for a crack with tooth_divisions < 2, or a tooth with both a break and a crack.
// Node ids 1, 2, ... and element ids 1, 2, ...; elements in CalculiX node order (fe_mesh.h) with
// positive Jacobian. The material is assigned to "EALL".
//
// Usage:
//   gears::Gear g({.teeth = 18, .normal_module_m = 1.5e-3, .face_width_m = 0.03});
//   flex::FeMesh mesh = gears::MakeGearFeMesh(g, {.bore_radius_m = 7e-3,
//                                                 .type = flex::ElementType::kHex20});
//   const std::vector<int>& flank = mesh.NodeSet(gears::ToothSetName(3, "FLANK_PLUS"));
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "flex/fe_mesh.h"
#include "models/gear_geometry.h"
#include "models/tooth_fault.h"

namespace orrery::gears {

struct GearWebSpec {
  double rim_thickness_m = 0;  // radial, from the root circle down to the web (> root layer depth)
  double web_thickness_m = 0;  // axial, centred on the face width (< b)
  double hub_radius_m = 0;     // outer radius of the hub (bore < hub < r_f - rim thickness)
  int web_radial_divisions = 2;
  int hub_radial_divisions = 2;
  int web_axial_divisions = 2;  // across the web thickness; the rest of face_divisions is split
                                // equally over the two sides (must be even, >= 2)
};

struct GearFeMeshSpec {
  double bore_radius_m = 0;  // 0 < r_bore < r_base (below the root layer)
  flex::ElementType type = flex::ElementType::kHex8;  // kHex8 or kHex20
  int flank_divisions = 8;       // along the involute, form circle to tip
  int fillet_divisions = 4;      // along fillet + half root arc, form circle to space middle
  int tooth_divisions = 6;       // across the tooth (tip arc; base arc, space middle to middle)
  int root_layer_divisions = 3;  // radial, root circle down to r_base
  int rim_divisions = 4;         // radial, r_base to the bore (with a web: r_base to the web)
  int face_divisions = 10;       // axial, over the face width
  double root_layer_depth_coef = 1.0;  // r_base = r_f - coef m_n
  double flank_bias = 2.0;       // across the tooth: middle / flank element size (>= 1)
  double rim_bias = 2.0;         // through the rim: bore / root element size (> 0)
  int smoothing_iterations = 2000;  // Winslow sweeps over the tooth block (0: Coons map only)
  std::optional<GearWebSpec> web;
  std::vector<ToothFaultSpec> faults;  // tooth faults (header), gear-frame tooth indices
  flex::IsotropicMaterial material{.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3,
                                   .density_kg_m3 = 7850};
};

// The mesh described above. Throws std::invalid_argument naming the offending field for an
// internal gear, a bore not inside r_base, divisions < 1, biases <= 0 (flank_bias < 1), an
// element type other than hex8/hex20, an invalid material or inconsistent web dimensions.
flex::FeMesh MakeGearFeMesh(const Gear& gear, const GearFeMeshSpec& spec);

// "TOOTH<k>_<part>", e.g. ToothSetName(3, "FLANK_PLUS") == "TOOTH3_FLANK_PLUS".
std::string ToothSetName(int tooth, std::string_view part);

// ---- Node selection by geometry ------------------------------------------------------------

// Indices of the nodes within `tolerance_m` of the cylinder of radius `radius_m` about the axis
// through `p_axis_m` with direction `axis` (normalized here; throws std::invalid_argument for a
// zero axis or a negative radius / tolerance). Distance: | |(p - p_axis) x a| - r |.
std::vector<int> SelectNodesOnCylinder(const flex::FeMesh& mesh, const Eigen::Vector3d& p_axis_m,
                                       const Eigen::Vector3d& axis, double radius_m, double tolerance_m);
// Indices of the nodes within `tolerance_m` of the plane through `p_plane_m` with normal `normal`
// (normalized here; throws for a zero normal or a negative tolerance).
std::vector<int> SelectNodesOnPlane(const flex::FeMesh& mesh, const Eigen::Vector3d& p_plane_m,
                                    const Eigen::Vector3d& normal, double tolerance_m);

}  // namespace orrery::gears

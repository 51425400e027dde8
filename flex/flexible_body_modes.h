#pragma once
// From a Craig-Bampton model to the multibody engine's flexible-body data
// (orrery::FlexibleBodyModes, mbd/flexible_body.h, whose header defines every quantity below).
//
// Body frame B: origin at the reference interface's master, axes of the mesh; x = p - p_ref.
// Modal coordinates: the elastic Craig-Bampton coordinates (columns 6.. of cb.shapes, the body
// clamped at the reference master, M-normalized), Phi (3N x nf).
// Inertia invariants with the consistent mass. The assembled mass is M = M_s (x) I3 (fe_element.h:
// N^T N times 3 x 3 identity blocks; checked, std::runtime_error otherwise), and for nodal fields
// a, b interpolated by the shape functions int rho a_i b_j dV = a_i^T M_s b_j exactly. With X
// (N x 3) the nodal positions in B, 1 the vector of ones and P (N x 3 nf) the mode shapes
// rearranged per component (column 3 k + i = component i of mode k):
//   mass = 1^T M_s 1, I1 = X^T M_s 1, I3 = X^T M_s X, I2(i, k) = 1^T M_s P_(3k+i),
//   I4_k(i, j) = X_i^T M_s P_(3k+j), I5_kl(i, j) = P_(3k+i)^T M_s P_(3l+j).
// Modal stiffness: the elastic block of cb.K (diagonal w^2); damping left empty.
// Nodes (in this order): one per interface master (position in B, translation shapes = master
// rows 0-2 of cb.master_shapes, rotation shapes = rows 3-5), then the exported FE nodes
// (translation shapes = rows of Phi, rotation shapes zero), in mesh order.
// Node sets: one per interface, named after it, holding its master; every mesh node set restricted
// to the exported FE nodes (non-empty ones), renamed "<name>_NODES" if an interface has its name.
// Surface triangles: the boundary faces of the solid mesh (faces used by exactly one element)
// whose nodes are all exported, outward normals (right-hand rule), see BoundaryTriangles.
// Stress modes (option): nodal averages of D B Phi (stress_recovery.h) at the exported FE nodes.
// Geometric stiffness (option): for the six unit inertial load cases b_c of mbd/flexible_body.h,
// the static response u_c of the body held at the reference master (geometric_stiffness.h), its
// stress sigma_c and G_c = Phi^T K_sigma(sigma_c) Phi.
// Cost (112k-DOF hex20 bar, 8000 elements, nf = 30, Debian's reference BLAS): invariants, nodes
// and surface 0.3 s, stress modes +0.07 s, geometric stiffness +48 s: almost all of it the static
// solve held at the reference (T^T K T and its sparse Cholesky, BLAS-bound, cholmod_factor.h; the
// projection G_c = Phi^T K_sigma Phi takes 1.6 s).
//
// Usage:
//   CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 30});
//   FlexibleBodyModes modes = MakeFlexibleBodyModes(mesh, sys, cb, ifs, {.stress_modes = true});
#include <array>
#include <span>
#include <string>
#include <vector>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_mesh.h"
#include "mbd/flexible_body.h"

namespace orrery::flex {

struct FlexibleBodyModesOptions {
  bool export_surface_nodes = true;           // every node of a boundary face (midside nodes too)
  std::vector<std::string> export_node_sets;  // and the nodes of these mesh node sets
  bool surface_triangles = true;              // boundary triangles among the exported nodes
  bool split_quadratic_faces = true;          // tet10 face: 4 triangles, hex20: 6; false: corners
  std::vector<int> master_ids;                // id per interface; empty: max FE node id + 1 + j
  bool stress_modes = false;                  // stress_modes / stress_nodes at the exported FE nodes
  bool geometric_stiffness = false;           // the six G_c
};

// Fills FlexibleBodyModes (header) from the mesh, its assembled system, the reduction of that
// system with `interfaces` (the same list, in order), and the options. Throws
// std::invalid_argument if the sizes of mesh, system and reduction disagree, a node set is
// unknown or master_ids has the wrong count or clashes with an FE node id; std::runtime_error
// if M is not of the form M_s (x) I3.
FlexibleBodyModes MakeFlexibleBodyModes(const FeMesh& mesh, const FeSystem& system, const CraigBamptonModel& cb,
                                        std::span<const FeInterface> interfaces,
                                        const FlexibleBodyModesOptions& options = {});

// A boundary face of a solid mesh: a face of exactly one element (faces are matched by their
// corner nodes). Nodes are mesh node indices: the corners counter-clockwise seen from outside
// (outward normal by the right-hand rule), the midside nodes between corner k and k + 1 (-1 for
// linear elements). For a hex20 face, corners 0-3 and midsides 0-3 are the 8 nodes of the
// serendipity face of fe_element.h (QuadFaceShape8) in its order.
struct BoundaryFace {
  int element = -1, face = -1;       // element index and its local face
  int corners = 0;                   // 3 or 4
  std::array<int, 4> corner_nodes{-1, -1, -1, -1};
  std::array<int, 4> midside_nodes{-1, -1, -1, -1};
};

// The boundary faces in element order (deterministic).
std::vector<BoundaryFace> BoundaryFaces(const FeMesh& mesh);

// Boundary faces of a solid mesh (BoundaryFaces) as triangles of FE node indices, outward normals by the right-hand rule. Quadrilaterals give
// 2 triangles; with split_quadratic a tet10 face gives 4 (corner and midside nodes) and a hex20
// face 6 (4 corner triangles and the midside quadrilateral), else the corners only.
std::vector<std::array<int, 3>> BoundaryTriangles(const FeMesh& mesh, bool split_quadratic = true);

}  // namespace orrery::flex

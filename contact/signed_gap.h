#pragma once
// Signed gaps by node-to-surface projection (seed 000 eqs. 6-9), one pass per direction: the
// nodes (vertices) of one surface against the faces of the other. For node P:
//   Q = the closest point to P on the candidate faces (eq. 6; ties broken by the lower face
//       index), n = the unit normal of Q's face, pointing out of that surface's material,
//   g = (P - Q) . n                     when Q lies inside the face or on its rim,
//   g = sign((P - Q) . n) |P - Q|       when Q lies on an interior edge or vertex (a ridge or
//                                        valley between faces, where the distance is the gap),
//   g < 0: P penetrates (eq. 8 violated). A node whose Q lies on the open rim of the surface
//   (boundary edge or vertex) lies beyond the surface's edge by s, the part of P - Q across
//   the rim edges at Q (along their outward directions in the face's plane); the rest of
//   P - Q is signed as at an interior edge or vertex (for a rim edge, the plane's gap
//   (P - Q) . n). Its share of contact (its weight w, which scales its area weight in the
//   contact law) fades linearly from 1 at s = 0 to 0 at s = the face's rim fade f
//   (contact_surface.h: a tenth of the face's height across its rim edge; at a gear's axial
//   end a tenth of the axial length of the flank's triangles, at a rim along the profile a
//   tenth of a profile interval):   w = max(0, 1 - s / f),  off the surface when w = 0.
//   The fade makes the contact force continuous where a node slides over a rim, as a node's
//   patch overlapping the face less and less would. A plain cut at the rim made it jump: a
//   flexible planet's edge row of nodes, deformed a nanometre beyond the ring's face width and
//   back, switched some 140 N on and off between Newton iterates, and Newton cycled. A vertex
//   is on the rim when any of its faces has a rim edge there: the face a search picks among
//   ties (the lowest index) may have only interior edges at it.
// The force normal n_W of a gap in contact: Q's face normal n, or, on a face surface with smoothed
// normals (contact_surface.h), the corner normals c_k of Q's face interpolated at Q's
// barycentric coordinates w_k:   n_s = normalize(sum_k w_k c_k); on a deformed surface each
// c_k is made from the deformed normals of its faces (ForceNormal below).
// The gap g keeps the face's normal; n_s turns the force only: continuous where Q passes
// from one facet to the next (the faces share their corner normals there), and within a
// facet's half angle of n. The forces are then no longer exactly minus the gradient of the
// penalty energy (the facets' jump of that gradient is what the smoothing removes).
// Only nodes with |P - Q| <= the search distance are listed: for them the candidate faces hold
// the true closest face (candidate_pairs.h), so the gaps equal a search over all faces.
//
// Two ways to run a pass over the same candidates, with identical results (tested):
//   - ComputeNodeGaps() straight from the triangle pairs (each node-face combination is visited
//     once per pair that contains it, up to 6 times; kept as the oracle),
//   - ListNodeFaceCandidates() once per search, then ComputeNodeGapsFromCandidates() at every
//     evaluation: each node-face combination once, each node transformed once (the step's path).
//
// Usage:
//   GapScratch scratch(nodes_surface);
//   ComputeNodeGaps(surface_a, X_WA, surface_b, X_WB, pairs, /*nodes_are_a=*/true, d,
//                   &scratch, &gaps);
#include <limits>
#include <vector>

#include "contact/candidate_pairs.h"
#include "contact/contact_surface.h"
#include "contact/triangle_geometry.h"

namespace orrery::contact {

struct NodeGap {
  int node = -1;        // vertex of the node surface
  int face = -1;        // triangle of the face surface
  double gap = 0;       // m, signed (< 0: penetration)
  bool on_surface = true;  // false: beyond the face surface's rim (no contact, weight 0)
  double weight = 1;       // share of the node's area weight in contact: 1 inside the rim,
                           // fading to 0 over the face's rim fade beyond it (header)
  double rim_offset_m = 0; // s: distance beyond the rim (0 inside it)
  double rim_fade_m = 0;   // f: the rim's fade (header; 0 for a closest point off the rim)
  Vec3 p_W = Vec3::Zero();  // node position, world
  Vec3 q_W = Vec3::Zero();  // closest point on the face surface, world
  // Unit normal, world (out of the face surface): for a node in contact (InContact) the force
  // normal of the header, for the others (listed, no force) their face's normal: the force
  // normal is made only where a force reads it.
  Vec3 n_W = Vec3::Zero();
};

// Whether a listed node presses (a contact point: penetrating, on the surface).
inline bool InContact(const NodeGap& g) { return g.gap < 0 && g.on_surface; }

// Per-node scratch of one pass, sized once from the node surface (no allocation in a step).
struct GapScratch {
  explicit GapScratch(const ContactSurface& node_surface);
  std::vector<double> best_d2;       // #V: squared distance to the best face so far (inf: none)
  std::vector<int> best_face;        // #V
  std::vector<Vec3> p_F;             // #V: node positions in the face surface's frame
  std::vector<Vec3> q_F;             // #V: closest points, face frame
  std::vector<TriangleFeature> feature;  // #V
  std::vector<int> touched;          // nodes seen in this pass (capacity #V)
};

// One pass: nodes of `node_surface` (pose X_WN) against faces of `face_surface` (pose X_WF),
// over the candidate pairs (pair.a on surface A, pair.b on B; nodes_are_a says which surface
// the nodes belong to). Clears and fills *gaps with every node within search_distance_m of the
// face surface, in increasing node order.
void ComputeNodeGaps(const ContactSurface& node_surface, const Transform& X_WN,
                     const ContactSurface& face_surface, const Transform& X_WF,
                     const std::vector<TrianglePair>& pairs, bool nodes_are_a,
                     double search_distance_m, GapScratch* scratch, std::vector<NodeGap>* gaps);

// A node of one surface and a candidate face of the other.
struct NodeFaceCandidate {
  int node = -1;
  int face = -1;
  bool operator==(const NodeFaceCandidate&) const = default;
  bool operator<(const NodeFaceCandidate& o) const {
    return node != o.node ? node < o.node : face < o.face;
  }
};

// The distinct (node, face) combinations of the pairs for one pass (nodes of A if nodes_are_a),
// sorted by node then face, by a counting sort over the nodes (scratch: of the node surface,
// left as found). Clears *out; allocates only if *out's capacity is below 3 * pairs.size().
void ListNodeFaceCandidates(const ContactSurface& node_surface,
                            const std::vector<TrianglePair>& pairs, bool nodes_are_a,
                            GapScratch* scratch, std::vector<NodeFaceCandidate>* out);

// The pass of ComputeNodeGaps() over a list from ListNodeFaceCandidates(): same gaps, same
// order, same tie-breaking (lowest face index). Clears and fills *gaps.
void ComputeNodeGapsFromCandidates(const ContactSurface& node_surface, const Transform& X_WN,
                                   const ContactSurface& face_surface, const Transform& X_WF,
                                   const std::vector<NodeFaceCandidate>& candidates,
                                   double search_distance_m, std::vector<NodeGap>* gaps);

// The same pass with the vertices given explicitly (flexible surfaces: the deformed positions
// s_P + Phi_P q_f in each body frame, flexible_contact_element.h): node_vertices_N (#V of the
// node surface, its frame N), face_vertices_F and face_normals_F (#V and #T of the face surface,
// its frame F; the unit normals of the deformed faces). The surfaces give the topology, the rim
// flags and nothing else. The call above is this one with the surfaces' own vertices and normals.
void ComputeNodeGapsFromCandidates(const ContactSurface& node_surface,
                                   const std::vector<Vec3>& node_vertices_N, const Transform& X_WN,
                                   const ContactSurface& face_surface,
                                   const std::vector<Vec3>& face_vertices_F,
                                   const std::vector<Vec3>& face_normals_F, const Transform& X_WF,
                                   const std::vector<NodeFaceCandidate>& candidates,
                                   double search_distance_m, std::vector<NodeGap>* gaps);

// The force normal of the header at Q (face frame) on `face`, whose vertices are x0, x1, x2
// (own or deformed, face frame); normal(f): the unit normal of face f as the gaps read it (own
// or deformed). Without smoothed normals: normal(face). With them: on the surface's own
// vertices (deformed false) its corner normals; on deformed ones the corner normals made from
// the deformed normals of each corner's faces (contact_surface.h corner_faces), so that faces
// sharing an edge share them there whatever the deformation.
// corner(face, k): the unit corner normal k of `face` on a deformed surface, that of
// DeformedCornerNormal (or a copy of it made for another corner of its group,
// contact_surface.h corner_group: the same numbers).
// weights (optional): with smoothed normals, set to Q's barycentric coordinates w_k (those the
// normal was interpolated with; tracked_gaps.h face_weights_a); left alone without.
// Always inlined: with the weights' pointer GCC made it a call in the tracked passes, which took
// the rigid scene's first 10 ms from 4 056.5 M to 4 106.3 M instructions (callgrind).
template <class FaceNormal, class CornerNormal>
__attribute__((always_inline)) inline Vec3 ForceNormal(const ContactSurface& face_surface, int face,
                                                       const Vec3& q_F, const Vec3& x0,
                                                       const Vec3& x1, const Vec3& x2,
                                                       bool deformed, const FaceNormal& normal,
                                                       const CornerNormal& corner,
                                                       Vec3* weights = nullptr) {
  if (!face_surface.smooth_normals()) return normal(face);
  const Vec3 w = Barycentric(q_F, x0, x1, x2);
  if (weights) *weights = w;
  if (!deformed) {
    const auto& c = face_surface.face_corner_normals()[face];
    return (w(0) * c[0] + w(1) * c[1] + w(2) * c[2]).normalized();
  }
  Vec3 n = Vec3::Zero();
  for (int k = 0; k < 3; ++k) n += w(k) * corner(face, k);
  return n.normalized();
}

// Corner k of `face` on a deformed surface: its faces' deformed normals, angle-weighted and
// normalized (contact_surface.h corner_faces).
template <class FaceNormal>
Vec3 DeformedCornerNormal(const ContactSurface& face_surface, int face, int k,
                          const FaceNormal& normal) {
  Vec3 c = Vec3::Zero();
  const int end = face_surface.corner_face_start()[3 * face + k + 1];
  for (int i = face_surface.corner_face_start()[3 * face + k]; i < end; ++i)
    c += face_surface.corner_weights()[i] * normal(face_surface.corner_faces()[i]);
  return c.normalized();
}

// The same with each deformed corner normal made anew (no cache).
template <class FaceNormal>
Vec3 ForceNormal(const ContactSurface& face_surface, int face, const Vec3& q_F, const Vec3& x0,
                 const Vec3& x1, const Vec3& x2, bool deformed, const FaceNormal& normal) {
  return ForceNormal(face_surface, face, q_F, x0, x1, x2, deformed, normal, [&](int f, int k) {
    return DeformedCornerNormal(face_surface, f, k, normal);
  });
}

// The gap of one node P (face frame) against its closest face q (feature as found), by the
// rules above; shared by the pass and by tests.
NodeGap NodeGapFromClosest(const ContactSurface& face_surface, int face, const Vec3& p_F,
                           const Vec3& q_F, TriangleFeature feature);
// The same with the face's unit normal n_F given (a deformed face).
NodeGap NodeGapFromClosest(const ContactSurface& face_surface, int face, const Vec3& n_F,
                           const Vec3& p_F, const Vec3& q_F, TriangleFeature feature);

}  // namespace orrery::contact

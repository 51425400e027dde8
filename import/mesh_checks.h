#pragma once
// Checks of an imported triangle mesh, with a report a user can act on, and the orientation
// repair that makes a closed mesh usable for mass properties (mass_properties.h) and contact.
//
// What is checked (edges are unordered vertex pairs; "uses" counts the triangles that have it):
//   degenerate triangles   a repeated vertex, or |(b - a) x (c - a)| <= 1e-12 l_max^2 (l_max: its
//                          longest edge): no area, no normal
//   duplicate triangles    the same three vertices as an earlier triangle, in either orientation
//   boundary edges         used once: the mesh is open there (not watertight)
//   non-manifold edges     used three or more times
//   inconsistent edges     used twice, both times in the same direction: the two triangles face
//                          opposite ways
//   components             triangles connected through manifold edges (used twice)
//   self-intersections     pairs of triangles that share no vertex and intersect (Moller, "A fast
//                          triangle-triangle intersection test", J. Graphics Tools 2(2), 1997:
//                          plane-side rejection, then the overlap of the two intervals on the
//                          planes' intersection line; coplanar pairs by edge crossings and vertex
//                          containment in the common plane), found over a bounding-volume
//                          hierarchy of the triangles (median splits, self-traversal), so the
//                          cost is near n log n. Touching at a point or along a segment without
//                          crossing counts when the overlap has positive length. Pairs that share
//                          a vertex are not tested (a fold between neighbours is not found).
// Watertight: no boundary and no non-manifold edge.
//
// Orientation (re-oriented where unambiguous): within each component the triangles are flipped,
// by a breadth-first walk over manifold edges, to agree with the first triangle (a component where
// the walk meets a contradiction is non-orientable and left as it is). A closed component (no
// boundary edge, no non-manifold edge) is then turned so that its enclosed volume (divergence
// theorem) is positive, or negative when it lies inside an odd number of other closed components
// (a cavity; insideness by the generalized winding number of one of its vertices, Jacobson et al.,
// "Robust inside-outside segmentation using generalized winding numbers", SIGGRAPH 2013, i.e. the
// sum of signed solid angles (Van Oosterom & Strackee 1983) over 4 pi; checked for up to 64 closed
// components). An open component keeps the orientation most of its triangles had.
// `flipped` lists the triangles to flip; OrientMesh applies it.
//
// Usage:
//   MeshCheckReport r = CheckMesh(mesh);
//   if (!r.flipped.empty()) OrientMesh(mesh, r);
//   for (const std::string& line : r.Problems()) std::cerr << line << "\n";
#include <string>
#include <utility>
#include <vector>

#include "mbd/triangle_mesh.h"

namespace orrery {

struct MeshCheckOptions {
  bool self_intersections = true;   // the BVH test (the only part that is not linear in size)
  int max_reported_pairs = 8;       // intersecting pairs kept as examples
};

struct MeshCheckReport {
  int triangles = 0, vertices = 0;
  int degenerate_triangles = 0;
  int duplicate_triangles = 0;
  int boundary_edges = 0;
  int non_manifold_edges = 0;
  int inconsistent_edges = 0;       // before re-orientation
  int components = 0;
  int closed_components = 0;        // no boundary or non-manifold edge
  int non_orientable_components = 0;
  bool nesting_checked = true;      // false when there were more than 64 closed components
  std::vector<int> flipped;         // triangles OrientMesh flips (ascending)
  int self_intersections = -1;      // intersecting pairs; -1: not checked
  std::vector<std::pair<int, int>> intersecting_pairs;  // up to max_reported_pairs examples
  double signed_volume_m3 = 0;      // of the mesh after re-orientation (closed or not)

  bool watertight() const { return boundary_edges == 0 && non_manifold_edges == 0; }
  // Watertight, orientable, without degenerate or duplicate triangles, nor (when checked)
  // self-intersections: a valid solid boundary.
  bool valid_solid() const;
  // One line per problem found ("12 boundary edges: the mesh is open (not watertight)"); empty
  // when there is none.
  std::vector<std::string> Problems() const;
};

MeshCheckReport CheckMesh(const TriangleMesh& mesh, const MeshCheckOptions& options = {});

// Flips report.flipped (reverses their vertex order).
void OrientMesh(TriangleMesh& mesh, const MeshCheckReport& report);

// True if the two triangles (non-degenerate) intersect with positive overlap (Moller 1997).
bool TrianglesIntersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1, const Vec3& b2);

}  // namespace orrery

#pragma once
// Contact search between two rigid surfaces: which triangle pairs can touch. FCL does the
// culling only; the engine computes gaps itself (signed_gap.h).
//
// Definition: with the gap distance d = (margin_A + margin_B) / 2 and the slack
// s = (slack_A + slack_B) / 2, a candidate pair (a, b) is a triangle a of surface A and a
// triangle b of surface B whose distance is at most d + s at the relative pose X_AB of the last
// search. Every node that penetrates the other surface by less than d has its closest face among
// its candidate pairs, so the gaps computed from candidates equal the gaps over all faces
// (checked against a brute-force search in tests/contact/candidate_pairs_test.cpp).
//
// Keeping pairs across small motions: between the search pose X0 = X_AB and a later pose X1, a
// point v of B (body frame) moves in A's frame by (R1 - R0) v + (p1 - p0), at most
//   delta = ||R1 - R0||_F rho_B + ||p1 - p0||,   rho_B = largest |v| over B's vertices.
// Distances between triangles (convex hulls of their vertices) change by at most delta, so a pair
// within d at X1 was within d + delta at X0: the pairs stay valid while delta <= s, and Find()
// searches again only when delta exceeds the slack.
//
// Stages of a search:
//   1. broad phase (the ring zone), no allocation:
//      a. two part rings (both surfaces carry a PartRing, axes parallel): from the rings' current
//         angles and axis distance a, the polar window [phi_min, phi_max] of each ring's band
//         (inner <= r <= outer) whose points lie in the other ring's band grown by d + s
//         (|P - O'|^2 = a^2 + r^2 - 2 a r cos phi, phi from the direction to the other axis);
//         only parts whose angular span (+- half angle + (d + s) / inner) meets the window go on.
//         For two gears this is the overlap of the tip circles around the contact path: 3 to 4
//         teeth per gear for spur gears with contact ratio < 2, whatever the face width;
//      b. a bounding sphere per part, tested pairwise in A's frame with the spheres grown by
//         d + s; only parts that can be within d + s go on.
//   2. triangle pairs: per overlapping part pair, FCL's OBBRSS mesh-mesh traversal
//      (MeshCollisionTraversalNodeOBBRSS, the one collide() runs) with every bounding volume
//      inflated by (margin + slack) / 2 at build time, and a leaf test that records the triangle
//      pair when the exact triangle-triangle distance (triangle_geometry.h) is at most d + s;
//      a sphere around each triangle is tested first (one transform instead of three and the
//      exact distance).
//   Why not collide() with enable_contact = false: it reports intersecting triangle pairs only.
//   A triangle that has sunk wholly below the other surface intersects nothing (a block's bottom
//   face pressed into a plane gives no pair at all), so its nodes would be missed.
//   Why not FCL's DynamicAABBTreeCollisionManager for stage 1: its update() rebuilds the tree
//   (allocating). Spheres alone keep 18 tooth pairs of a 19/27, b = 10 mm mesh (world boxes:
//   22), but they are loose around wide teeth (168 of seed 001's 18/34, b = 30 mm pair): hence
//   the ring-zone test 1a.
//
// Usage:
//   CandidateSearch search(surface_a, surface_b);
//   std::vector<TrianglePair> pairs;  pairs.reserve(search.suggested_capacity());
//   search.Find(X_WA, X_WB, &pairs);   // true if it searched (pairs replaced)
#include <array>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "contact/contact_surface.h"
#include "contact/deformed_vertices.h"
#include "contact/triangle_geometry.h"

namespace orrery::contact {

struct TrianglePair {
  int a = -1;  // triangle of surface A
  int b = -1;  // triangle of surface B
  bool operator==(const TrianglePair&) const = default;
  bool operator<(const TrianglePair& o) const { return a != o.a ? a < o.a : b < o.b; }
};

// FCL bounding-volume hierarchies of a surface's parts (OBBRSS, inflated by margin / 2), built
// once. Opaque outside candidate_pairs.cpp.
std::shared_ptr<const CullingGeometry> BuildCullingGeometry(const ContactSurface& surface);

// Counters of the last search (for benchmarks and tests).
struct CandidateStats {
  int part_pairs = 0;       // overlapping parts after the broad phase
  int zone_parts_a = 0, zone_parts_b = 0;  // parts inside the ring zone (all without rings)
  int leaf_tests = 0;       // triangle pairs whose inflated bounding volumes overlap
  int exact_tests = 0;      // leaf tests past the triangle-sphere pre-check
  int candidate_pairs = 0;  // pairs within the search distance
  long searches = 0;        // searches since construction
  double motion_since_search_m = 0;  // delta (above) at the last Find()
  double max_motion_between_calls_m = 0;  // largest delta between consecutive Find() poses
};

// The closest triangle of a surface to a point, as a search goes.
struct ClosestFace {
  int face = -1;                                      // triangle of the surface
  double d2 = std::numeric_limits<double>::infinity();  // squared distance
  ClosestPoint point;                                 // on that triangle, body frame
};

// Closest triangle of one part to the point p (the surface's body frame): a best-first
// branch-and-bound descent of the part's FCL hierarchy, the point's distance to each (inflated)
// oriented box being a lower bound on its distance to the triangles inside. *best is replaced
// by any triangle of the part strictly closer than best->d2, or as close with a lower index, so
// that several parts (or a first guess from a walk) can be searched in turn and the result is
// the closest over all with ties to the lowest index. No allocation.
void FindClosestFaceInPart(const ContactSurface& surface, int part, const Vec3& p,
                           ClosestFace* best);
// The same over deformed vertices (#V, body frame) that lie within `deformation_m` of the
// surface's own (the boxes' bounds are lowered by it). With `unseen_d2`, *unseen_d2 is lowered
// to the smallest bound (a box's squared distance, or a triangle's) of what the descent passed
// by without taking it: if no triangle of the part was taken, every one of them is at least
// sqrt(*unseen_d2) from p (the far nodes of tracked_gaps.h sleep on it).
void FindClosestFaceInPart(const ContactSurface& surface, int part, const Vec3& p,
                           ClosestFace* best, const std::vector<Vec3>& vertices,
                           double deformation_m, double* unseen_d2 = nullptr);
// The same with vertices made on first read (deformed_vertices.h): only the leaves' are read.
void FindClosestFaceInPart(const ContactSurface& surface, int part, const Vec3& p,
                           ClosestFace* best, const SurfaceVertices& vertices,
                           double deformation_m, double* unseen_d2 = nullptr);

// Whether part `part_a` of surface A and part `part_b` of B can be within `reach_m` of each
// other, B at pose X_AB in A's frame: the oriented boxes at the roots of the two parts' FCL
// hierarchies (as built, before the inflation), A's grown by reach_m on every side, are tested
// for overlap by the separating-axis test (Gottschalk, Lin and Manocha, "OBBTree", SIGGRAPH 1996;
// FCL's obbDisjoint, which pads the rotation terms by 1e-6). False only when every triangle of
// the one part is farther than reach_m from every triangle of the other. No allocation.
bool PartBoxesWithin(const ContactSurface& a, int part_a, const ContactSurface& b, int part_b,
                     const Transform& X_AB, double reach_m);

// The first three axes of PartBoxesWithin's separating-axis test (A's box's face normals,
// with FCL's padding of the rotation terms): true when none of them separates the boxes, so
// false only when PartBoxesWithin is. Along a fixed axis of A the test compares the distance
// of the interval of B's box's projection from A's centre with a bound that does not depend
// on the pose, and that distance changes by at most the largest motion of a point of B's box:
// if B's box moves by at most mu in A's frame, PartBoxesWithin(reach) after the motion implies
// PartBoxesFacesWithin(reach + mu) before it (tracked_gaps.h, the candidate pairs).
bool PartBoxesFacesWithin(const ContactSurface& a, int part_a, const ContactSurface& b, int part_b,
                          const Transform& X_AB, double reach_m);

// The eight corners (body frame) of the oriented box at the root of a part's FCL hierarchy, as
// inflated for the pair search: every vertex of the part lies inside their convex hull.
std::array<Vec3, 8> PartBoxCorners(const ContactSurface& surface, int part);

class CandidateSearch {
 public:
  // Keeps references to both surfaces, which must outlive the search.
  CandidateSearch(const ContactSurface& surface_a, const ContactSurface& surface_b);
  ~CandidateSearch();
  CandidateSearch(const CandidateSearch&) = delete;
  CandidateSearch& operator=(const CandidateSearch&) = delete;

  // d: the gap distance the candidates serve (signed_gap.h); s: the slack; pairs lie within d + s.
  double search_distance_m() const { return search_distance_; }
  double slack_m() const { return slack_; }
  // delta of the header: bound on the motion of B's points in A's frame from X_AB0 to X_AB1.
  double MotionBound(const Transform& X_AB0, const Transform& X_AB1) const;
  // A capacity for the pair list that the step should not outgrow (a vector that does grows).
  int suggested_capacity() const;

  // Stage 1: poses of the bodies of A and B in the world; lists the part pairs whose spheres
  // are within d + s (+ extra_reach_m, and the ring zone grown by as much).
  void UpdateBroadPhase(const Transform& X_WA, const Transform& X_WB, double extra_reach_m = 0);
  // The same, and in one pass over the part pairs *grown (cleared; capacity #parts_A #parts_B):
  // the pairs within d + s + extra_reach_m + grow_m (grow_m >= 0), those of
  // UpdateBroadPhase(X_WA, X_WB, extra_reach_m + grow_m), sorted as part_pairs().
  void UpdateBroadPhase(const Transform& X_WA, const Transform& X_WB, double extra_reach_m,
                        double grow_m, std::vector<std::pair<int, int>>* grown);
  // The same restricted to the pairs `among` (sorted as part_pairs()): the zone flags of both
  // surfaces as above, the sphere tests for those pairs only, with the same arithmetic, so that
  // part_pairs() and *grown are those of UpdateBroadPhase() less the pairs not in `among`
  // (tracked_gaps.h: the pairs its boxes can still reach). Stats count those pairs only.
  void UpdateBroadPhaseAmong(const Transform& X_WA, const Transform& X_WB, double extra_reach_m,
                             double grow_m, const std::vector<std::pair<int, int>>& among,
                             std::vector<std::pair<int, int>>* grown);
  // The part pairs (part of A, part of B) of the last UpdateBroadPhase().
  const std::vector<std::pair<int, int>>& part_pairs() const;
  // Stage 2: triangle pairs of the part pairs of the last UpdateBroadPhase(); clears *pairs.
  void FindPairs(std::vector<TrianglePair>* pairs);
  // Both stages, skipped (returning false, *pairs untouched) while the motion bound since the
  // last search is within the slack (with zero slack: while X_AB is unchanged).
  bool Find(const Transform& X_WA, const Transform& X_WB, std::vector<TrianglePair>* pairs);
  // Forget the last search (the next Find() searches).
  void Invalidate();

  const CandidateStats& stats() const { return stats_; }

 private:
  struct Impl;
  // The ring-zone flags (stage 1a) of both surfaces' parts at this reach (all set without
  // rings) and, with zone_a_grown and zone_b_grown, at reach_grown: the rings' relative pose
  // and angles once for both. With `among`, the parts of those pairs only (the others' flags
  // are left set; UpdateBroadPhaseAmong reads the pairs' parts only).
  void FlagZones(const Transform& X_WA, const Transform& X_WB, double reach,
                 std::vector<char>* zone_a, std::vector<char>* zone_b, double reach_grown = 0,
                 std::vector<char>* zone_a_grown = nullptr,
                 std::vector<char>* zone_b_grown = nullptr,
                 const std::vector<std::pair<int, int>>* among = nullptr);
  std::unique_ptr<Impl> impl_;
  const ContactSurface& a_;
  const ContactSurface& b_;
  double search_distance_ = 0, slack_ = 0;
  CandidateStats stats_;
};

}  // namespace orrery::contact

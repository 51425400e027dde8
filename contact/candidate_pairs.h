#pragma once
// Contact search between two rigid surfaces: which triangle pairs can touch. FCL does the
// culling only; the engine computes gaps itself (signed_gap.h).
//
// Definition: a candidate pair (a, b) is a triangle a of surface A and a triangle b of surface
// B whose distance is at most the search distance d = (margin_A + margin_B) / 2. Every node that
// penetrates the other surface by less than d has its closest face among its candidate pairs, so
// the gaps computed from candidates equal the gaps over all faces (checked against a brute-force
// search in tests/contact/candidate_pairs_test.cpp).
//
// Stages:
//   1. broad phase: FCL DynamicAABBTreeCollisionManager per surface over its parts (teeth),
//      part AABBs inflated by margin / 2; manager-vs-manager collide lists overlapping parts.
//      Only the surfaces whose pose changed are updated.
//   2. triangle pairs: per overlapping part pair, FCL's OBBRSS mesh-mesh traversal
//      (MeshCollisionTraversalNodeOBBRSS, the one collide() runs) with every bounding volume
//      inflated by margin / 2 at build time, and a leaf test that records the triangle pair when
//      the exact triangle-triangle distance (triangle_geometry.h) is at most d.
//   Why not collide() with enable_contact = false: it reports intersecting triangle pairs only.
//   A triangle that has sunk wholly below the other surface intersects nothing (a block's bottom
//   face pressed into a plane gives no pair at all), so its nodes would be missed.
//
// Caching: the pairs depend on the relative pose X_AB only; Find() returns false without work
// when X_AB equals the previous call's.
//
// Usage:
//   CandidateSearch search(surface_a, surface_b);
//   std::vector<TrianglePair> pairs;  pairs.reserve(search.suggested_capacity());
//   search.Find(X_WA, X_WB, &pairs);
#include <memory>
#include <vector>

#include "contact/contact_surface.h"

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
  int leaf_tests = 0;       // triangle pairs whose inflated bounding volumes overlap
  int candidate_pairs = 0;  // pairs within the search distance
};

class CandidateSearch {
 public:
  // Keeps references to both surfaces, which must outlive the search.
  CandidateSearch(const ContactSurface& surface_a, const ContactSurface& surface_b);
  ~CandidateSearch();
  CandidateSearch(const CandidateSearch&) = delete;
  CandidateSearch& operator=(const CandidateSearch&) = delete;

  double search_distance_m() const { return search_distance_; }
  // A capacity for the pair list that the step should not outgrow (a vector that does grows).
  int suggested_capacity() const;

  // Stage 1: poses of the bodies of A and B in the world; refits the broad phase of the surfaces
  // that moved and lists the overlapping part pairs.
  void UpdateBroadPhase(const Transform& X_WA, const Transform& X_WB);
  // Stage 2: triangle pairs of the part pairs of the last UpdateBroadPhase(); clears *pairs.
  void FindPairs(std::vector<TrianglePair>* pairs);
  // Both stages, skipped (returning false, *pairs untouched) when X_AB is unchanged.
  bool Find(const Transform& X_WA, const Transform& X_WB, std::vector<TrianglePair>* pairs);

  const CandidateStats& stats() const { return stats_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const ContactSurface& a_;
  const ContactSurface& b_;
  double search_distance_ = 0;
  CandidateStats stats_;
};

}  // namespace orrery::contact

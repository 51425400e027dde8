#pragma once
// Point-triangle and triangle-triangle proximity, the exact geometry under the contact search
// (candidate_pairs.h) and the signed gap (signed_gap.h).
//
// Closest point on a triangle: Ericson, "Real-Time Collision Detection" (2005) sec. 5.1.5
// (Voronoi regions of the vertices, edges and face, barycentric coordinates). Segment-segment
// closest points: the same book, sec. 5.1.9. Triangle-triangle distance: zero if an edge of one
// triangle crosses the other; otherwise the minimum is attained between a vertex and a face or
// between two edges, so it is the least of the 6 vertex-face and 9 edge-edge distances.
//
// Usage:
//   ClosestPoint c = ClosestPointOnTriangle(p, a, b, c);   // c.point, c.feature
//   double d2 = TriangleDistanceSquared(a0, a1, a2, b0, b1, b2);
#include "mbd/spatial.h"

namespace orrery::contact {

// Which part of the triangle (a, b, c) holds the closest point: the face interior, an edge
// (kEdge0 = ab, kEdge1 = bc, kEdge2 = ca) or a vertex (kVertex0 = a, kVertex1 = b, kVertex2 = c).
enum class TriangleFeature { kFace, kEdge0, kEdge1, kEdge2, kVertex0, kVertex1, kVertex2 };

struct ClosestPoint {
  Vec3 point = Vec3::Zero();
  TriangleFeature feature = TriangleFeature::kFace;
};

// Closest point to p on the (non-degenerate) triangle (a, b, c).
ClosestPoint ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// The vertex (0, 1, 2) of a vertex feature, -1 for the face or an edge.
constexpr int FeatureVertex(TriangleFeature feature) {
  switch (feature) {
    case TriangleFeature::kVertex0: return 0;
    case TriangleFeature::kVertex1: return 1;
    case TriangleFeature::kVertex2: return 2;
    default: return -1;
  }
}

// The edges that hold a feature, as bits (edge k: bit k): none for the face interior, one for an
// edge, the two that meet at a vertex (vertex k lies on edges k and k + 2 mod 3). Masked with a
// triangle's edge flags (boundary or shared-rim edges) it says whether the feature lies on them.
constexpr unsigned FeatureEdges(TriangleFeature feature) {
  switch (feature) {
    case TriangleFeature::kFace: return 0u;
    case TriangleFeature::kEdge0: return 1u;
    case TriangleFeature::kEdge1: return 2u;
    case TriangleFeature::kEdge2: return 4u;
    case TriangleFeature::kVertex0: return 1u | 4u;
    case TriangleFeature::kVertex1: return 1u | 2u;
    case TriangleFeature::kVertex2: return 2u | 4u;
  }
  return 0u;
}

// Barycentric coordinates (w_a, w_b, w_c) of a point q of the triangle's plane.
Vec3 Barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c);

// Squared distance between the segments [p0, p1] and [q0, q1].
double SegmentDistanceSquared(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// Squared distance between the triangles (a0, a1, a2) and (b0, b1, b2); 0 if they intersect.
double TriangleDistanceSquared(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                               const Vec3& b1, const Vec3& b2);

}  // namespace orrery::contact

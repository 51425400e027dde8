#include "contact/triangle_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace orrery::contact {

Vec3 Barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v0 = b - a, v1 = c - a, v2 = q - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const double d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  const double v = (d11 * d20 - d01 * d21) / den;
  const double w = (d00 * d21 - d01 * d20) / den;
  return {1.0 - v - w, v, w};
}

ClosestPoint ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Vertex region of a.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, TriangleFeature::kVertex0};
  // Vertex region of b.
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, TriangleFeature::kVertex1};
  // Edge region of ab.
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + (d1 / (d1 - d3)) * ab, TriangleFeature::kEdge0};
  // Vertex region of c.
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, TriangleFeature::kVertex2};
  // Edge region of ca.
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + (d2 / (d2 - d6)) * ac, TriangleFeature::kEdge2};
  // Edge region of bc.
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), TriangleFeature::kEdge1};
  }
  // Face region.
  const double denom = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), TriangleFeature::kFace};
}

double SegmentDistanceSquared(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  // Degenerate segments.
  if (a <= 0 && e <= 0) return r.squaredNorm();
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      // General case: closest points of the lines, clamped to the segments.
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return (p0 + d1 * s - (q0 + d2 * t)).squaredNorm();
}

namespace {

// True if the segment [p, q] crosses or touches the triangle (a, b, c) (Moller-Trumbore with the
// segment parameter restricted to [0, 1]).
bool SegmentHitsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                         const Vec3& c) {
  const Vec3 d = q - p, e1 = b - a, e2 = c - a;
  const Vec3 h = d.cross(e2);
  const double det = e1.dot(h);
  // Parallel segments never cross the interior; touching is covered by the distance terms.
  if (std::abs(det) <= 1e-300) return false;
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0 || u > 1) return false;
  const Vec3 qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0 || u + v > 1) return false;
  const double t = inv * e2.dot(qv);
  return t >= 0 && t <= 1;
}

}  // namespace

double TriangleDistanceSquared(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                               const Vec3& b1, const Vec3& b2) {
  const Vec3* A[3] = {&a0, &a1, &a2};
  const Vec3* B[3] = {&b0, &b1, &b2};
  // Intersection: an edge of one triangle crosses the other.
  for (int k = 0; k < 3; ++k) {
    if (SegmentHitsTriangle(*A[k], *A[(k + 1) % 3], b0, b1, b2)) return 0;
    if (SegmentHitsTriangle(*B[k], *B[(k + 1) % 3], a0, a1, a2)) return 0;
  }
  // Vertex-face pairs.
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    best = std::min(best, (*A[k] - ClosestPointOnTriangle(*A[k], b0, b1, b2).point).squaredNorm());
    best = std::min(best, (*B[k] - ClosestPointOnTriangle(*B[k], a0, a1, a2).point).squaredNorm());
  }
  // Edge-edge pairs.
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      best = std::min(best, SegmentDistanceSquared(*A[i], *A[(i + 1) % 3], *B[j], *B[(j + 1) % 3]));
  return best;
}

}  // namespace orrery::contact

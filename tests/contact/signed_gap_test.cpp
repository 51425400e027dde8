// The rim rule of signed_gap.h (NodeGapFromClosest): a node beyond the open rim of a surface
// has a weight that fades linearly over the face's rim fade, so the contact force is continuous
// where a node slides over a rim; which of several tied faces reports a rim vertex does not
// matter (a search picks the lowest index, whose own edges at the vertex may all be interior:
// the node was then taken for one under an interior vertex, millimetres deep). Oracles: the
// fade's own formula at known offsets, and the tied faces against each other and the geometry.
#include "contact/signed_gap.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "contact/contact_surface.h"
#include "contact/triangle_geometry.h"

namespace orrery::contact {
namespace {

// The gap of node p against face f (closest point on that face).
NodeGap GapOnFace(const ContactSurface& s, int f, const Vec3& p) {
  const auto& t = s.triangles()[f];
  const ClosestPoint c = ClosestPointOnTriangle(p, s.vertices()[t[0]], s.vertices()[t[1]], s.vertices()[t[2]]);
  return NodeGapFromClosest(s, f, p, c.point, c.feature);
}

// The gap over all faces (closest face, ties to the lower index), as a search gives it.
NodeGap ClosestGap(const ContactSurface& s, const Vec3& p) {
  double best = 1e300;
  int face = -1;
  for (int f = 0; f < s.num_triangles(); ++f) {
    const auto& t = s.triangles()[f];
    const double d = (ClosestPointOnTriangle(p, s.vertices()[t[0]], s.vertices()[t[1]], s.vertices()[t[2]]).point - p).norm();
    if (d < best) best = d, face = f;
  }
  return GapOnFace(s, face, p);
}

// A flat square z = 0, normal +z, 4 x 4 cells of 5 mm (its rim fade: a tenth of 5 mm).
ContactSurface Square() {
  TriangleMesh m;
  const int n = 4;
  const double h = 5e-3;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back(Vec3(i * h, j * h, 0));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      m.triangles.push_back({v, v + 1, v + n + 2});
      m.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  return ContactSurface({m}, 30e-6);
}

TEST(SignedGap, WeightFadesContinuouslyBeyondTheRim) {
  const ContactSurface s = Square();
  const double fade = 0.1 * 5e-3;
  // A node 2 um under the surface slides out over the rim x = 0 (y = 7.5 mm, mid-edge).
  for (double x : {1e-3, 1e-9, 0.0, -1e-9, -1e-6, -0.25 * fade, -0.5 * fade, -0.999 * fade, -fade, -2 * fade}) {
    const NodeGap g = ClosestGap(s, Vec3(x, 7.5e-3, -2e-6));
    const double beyond = std::max(0.0, -x);
    EXPECT_NEAR(g.gap, -2e-6, 1e-15) << "x " << x;
    EXPECT_NEAR(g.weight, std::max(0.0, 1 - beyond / fade), 1e-12) << "x " << x;
    EXPECT_EQ(g.on_surface, beyond < fade) << "x " << x;
  }
}

TEST(SignedGap, ARimVertexIsTheSameFromEveryTiedFace) {
  const ContactSurface s = Square();
  // Beyond the rim vertex (10, 20) mm of the edge y = 20 mm, along +y by 0.2 mm, 1 um under.
  const Vec3 p(10e-3, 20.2e-3, -1e-6);
  // Every face with that vertex: its closest point is the vertex. One of them has only
  // interior edges there (the lowest index, which a search picks among the ties).
  std::vector<NodeGap> gaps;
  bool one_without_rim_edge = false;
  for (int f = 0; f < s.num_triangles(); ++f) {
    const auto& t = s.triangles()[f];
    for (int k = 0; k < 3; ++k) {
      if ((s.vertices()[t[k]] - Vec3(10e-3, 20e-3, 0)).norm() > 1e-12) continue;
      gaps.push_back(GapOnFace(s, f, p));
      one_without_rim_edge |= s.boundary_edges()[f] == 0;
    }
  }
  ASSERT_EQ(gaps.size(), 3u);
  ASSERT_TRUE(one_without_rim_edge);
  for (const NodeGap& g : gaps) {
    EXPECT_NEAR(g.gap, -1e-6, 1e-15);
    EXPECT_NEAR(g.rim_offset_m, 0.2e-3, 1e-12);
    EXPECT_NEAR(g.weight, 1 - 0.2e-3 / (0.1 * 5e-3), 1e-9);
  }
}

}  // namespace
}  // namespace orrery::contact

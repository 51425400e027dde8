// The rim rule of signed_gap.h (NodeGapFromClosest): a node beyond the open rim of a surface
// has a weight that fades linearly over the face's rim fade, so the contact force is continuous
// where a node slides over a rim; which of several tied faces reports a rim vertex does not
// matter (a search picks the lowest index, whose own edges at the vertex may all be interior:
// the node was then taken for one under an interior vertex, millimetres deep). Oracles: the
// fade's own formula at known offsets, and the tied faces against each other and the geometry.
// The smoothed force normal (ForceNormal, contact_surface.h smooth_normals): on a faceted
// cylinder the corner normals interpolated along a chord are the chord point's own radius,
// P / |P| in the cross-section (closed form: (1 - t) e0 + t e1 = P / R for
// P = R ((1 - t) e0 + t e1)), so the force normal is the cylinder's normal through Q on every
// facet, continuous across the facets' edges; a sharp fold keeps each side's facet normal.
#include "contact/signed_gap.h"

#include <algorithm>
#include <cmath>
#include <random>
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

// The closest face over all faces (ties to the lower index), as a search gives it.
int ClosestFace(const ContactSurface& s, const Vec3& p) {
  double best = 1e300;
  int face = -1;
  for (int f = 0; f < s.num_triangles(); ++f) {
    const auto& t = s.triangles()[f];
    const double d = (ClosestPointOnTriangle(p, s.vertices()[t[0]], s.vertices()[t[1]], s.vertices()[t[2]]).point - p).norm();
    if (d < best) best = d, face = f;
  }
  return face;
}

// The gap over all faces, as a search gives it.
NodeGap ClosestGap(const ContactSurface& s, const Vec3& p) {
  return GapOnFace(s, ClosestFace(s, p), p);
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

// A quarter cylinder of radius r about z (material inside, normals outward), n facets around,
// 2 intervals along z (40 mm): rectangles split into two triangles each.
ContactSurface FacetedCylinder(int n, double r, bool smooth) {
  TriangleMesh m;
  const int nz = 2;
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= n; ++i) {
      const double a = 0.5 * M_PI * i / n;
      m.vertices.push_back(Vec3(r * std::cos(a), r * std::sin(a), 20e-3 * j));
    }
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      m.triangles.push_back({v, v + 1, v + n + 2});
      m.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  return ContactSurface({m}, 30e-6, 0, std::nullopt, {}, smooth);
}

// The force normal of the closest point on face f (the surface's own normals).
Vec3 NormalOnFace(const ContactSurface& s, int f, const Vec3& p) {
  const auto& t = s.triangles()[f];
  const auto& x = s.vertices();
  const ClosestPoint c = ClosestPointOnTriangle(p, x[t[0]], x[t[1]], x[t[2]]);
  return ForceNormal(s, f, c.point, x[t[0]], x[t[1]], x[t[2]], /*deformed=*/false,
                     [&](int g) -> const Vec3& { return s.face_normals()[g]; });
}

TEST(ForceNormal, OnAFacetedCylinderIsTheRadiusThroughTheClosestPoint) {
  const int n = 12;  // 7.5 degree facets
  const double r = 20e-3;
  const ContactSurface smooth = FacetedCylinder(n, r, true);
  const ContactSurface facets = FacetedCylinder(n, r, false);
  ASSERT_TRUE(smooth.smooth_normals());
  ASSERT_FALSE(facets.smooth_normals());
  std::mt19937 rng(7);
  // Away from the arc's two end facets, whose outer corners have one side only.
  const double facet = 0.5 * M_PI / n;
  std::uniform_real_distribution<double> angle(1.01 * facet, 0.5 * M_PI - 1.01 * facet),
      z(1e-3, 39e-3), depth(-5e-6, 5e-6);
  double worst = 0, worst_facet = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const double a = angle(rng);
    const Vec3 p((r + depth(rng)) * std::cos(a), (r + depth(rng)) * std::sin(a), z(rng));
    const int face = ClosestFace(smooth, p);
    const auto& t = smooth.triangles()[face];
    const auto& x = smooth.vertices();
    const Vec3 q = ClosestPointOnTriangle(p, x[t[0]], x[t[1]], x[t[2]]).point;
    const Vec3 radius = Vec3(q.x(), q.y(), 0).normalized();
    const Vec3 ns = NormalOnFace(smooth, face, p);
    const Vec3 nf = NormalOnFace(facets, face, p);
    worst = std::max(worst, (ns - radius).norm());
    worst_facet = std::max(worst_facet, (nf - radius).norm());
  }
  EXPECT_LT(worst, 1e-12);
  // The facet normal is off by up to half a facet angle (3.75 degrees).
  EXPECT_GT(worst_facet, 0.5 * (0.5 * M_PI / n) * 0.9);
}

TEST(ForceNormal, IsContinuousAcrossAFacetEdge) {
  const int n = 12;
  const double r = 20e-3;
  const ContactSurface s = FacetedCylinder(n, r, true);
  // A node 3 um inside the cylinder crossing the edge at angle 2 * 7.5 degrees, mid-length:
  // its closest face changes where it passes the bisector, and its closest point jumps from one
  // facet to the other by about 2 depth tan(facet / 2); the force normal turns only with that
  // jump (the radius through each point: |q1 - q2| / r), not by the facet angle.
  const double edge = 2 * 0.5 * M_PI / n;
  Vec3 before = Vec3::Zero(), after = Vec3::Zero(), q_before = Vec3::Zero(), q_after = Vec3::Zero();
  int face_before = -1, face_after = -1;
  for (const double da : {-1e-9, 1e-9}) {
    const double a = edge + da;
    const Vec3 p((r - 3e-6) * std::cos(a), (r - 3e-6) * std::sin(a), 10e-3);
    const int face = ClosestFace(s, p);
    (da < 0 ? before : after) = NormalOnFace(s, face, p);
    const auto& t = s.triangles()[face];
    (da < 0 ? q_before : q_after) =
        ClosestPointOnTriangle(p, s.vertices()[t[0]], s.vertices()[t[1]], s.vertices()[t[2]]).point;
    (da < 0 ? face_before : face_after) = face;
  }
  ASSERT_NE(face_before, face_after);
  // The faces' own normals differ by the facet angle; the force normals by the node's motion.
  EXPECT_GT((s.face_normals()[face_before] - s.face_normals()[face_after]).norm(), 0.1);
  const double jump = (q_before - q_after).norm();
  EXPECT_LT(jump, 2 * 3e-6 * std::tan(0.25 * M_PI / n) * 1.01);
  EXPECT_NEAR((before - after).norm(), jump / r, 1e-3 * jump / r);
}

TEST(ForceNormal, ASharpFoldKeepsEachSidesFacetNormal) {
  // Two flat strips meeting at x = 0 with a 30 degree fold (beyond the 10 degree sharp-edge
  // test): every corner normal is its own face's normal.
  TriangleMesh m;
  const double c = std::cos(M_PI / 6), sn = std::sin(M_PI / 6);
  for (int j = 0; j <= 1; ++j) {
    const double y = 10e-3 * j;
    m.vertices.push_back(Vec3(-10e-3, y, 0));
    m.vertices.push_back(Vec3(0, y, 0));
    m.vertices.push_back(Vec3(10e-3 * c, y, -10e-3 * sn));
  }
  m.triangles = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}};
  const ContactSurface s({m}, 30e-6, 0, std::nullopt, {}, true);
  for (int f = 0; f < s.num_triangles(); ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_LT((s.face_corner_normals()[f][k] - s.face_normals()[f]).norm(), 1e-15);
  EXPECT_LT((NormalOnFace(s, 0, Vec3(-1e-3, 5e-3, -1e-6)) - s.face_normals()[0]).norm(), 1e-15);
}

TEST(ForceNormal, DeformedCornersTurnWithTheirFacesAndStayShared) {
  const ContactSurface s = FacetedCylinder(12, 20e-3, true);
  const auto& x = s.vertices();
  // The deformed path with the surface's own normals is the precomputed corners' path.
  const int f = 5;
  const auto& t = s.triangles()[f];
  const Vec3 q = (0.2 * x[t[0]] + 0.3 * x[t[1]] + 0.5 * x[t[2]]);
  const Vec3 own = ForceNormal(s, f, q, x[t[0]], x[t[1]], x[t[2]], false,
                               [&](int g) -> const Vec3& { return s.face_normals()[g]; });
  const Vec3 made = ForceNormal(s, f, q, x[t[0]], x[t[1]], x[t[2]], true,
                                [&](int g) -> const Vec3& { return s.face_normals()[g]; });
  EXPECT_LT((own - made).norm(), 1e-15);
  // A rigid rotation R of every face (vertices and normals): the force normal turns by R.
  const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  std::vector<Vec3> turned(s.num_triangles());
  for (int g = 0; g < s.num_triangles(); ++g) turned[g] = R * s.face_normals()[g];
  const Vec3 r = ForceNormal(s, f, R * q, R * x[t[0]], R * x[t[1]], R * x[t[2]], true,
                             [&](int g) -> const Vec3& { return turned[g]; });
  EXPECT_LT((r - R * own).norm(), 1e-14);
  // Each face turned by its own small rotation (a deformation whose gradient jumps from face
  // to face, as across an FE element boundary): at a point of an edge the two faces share,
  // both give the same force normal, though their own normals now differ.
  std::mt19937 rng(3);
  std::normal_distribution<double> small(0, 1e-3);
  std::vector<Vec3> bent(s.num_triangles());
  for (int g = 0; g < s.num_triangles(); ++g)
    bent[g] = (s.face_normals()[g] + Vec3(small(rng), small(rng), small(rng))).normalized();
  auto bent_normal = [&](int g) -> const Vec3& { return bent[g]; };
  int shared = 0;
  for (int g = 0; g < s.num_triangles(); ++g)
    for (int e = 0; e < 3; ++e) {
      const int h = s.face_neighbors()[g][e];
      if (h < 0) continue;
      const auto& tg = s.triangles()[g];
      const auto& th = s.triangles()[h];
      const Vec3 p = 0.3 * x[tg[e]] + 0.7 * x[tg[(e + 1) % 3]];
      const Vec3 ng = ForceNormal(s, g, p, x[tg[0]], x[tg[1]], x[tg[2]], true, bent_normal);
      const Vec3 nh = ForceNormal(s, h, p, x[th[0]], x[th[1]], x[th[2]], true, bent_normal);
      EXPECT_LT((ng - nh).norm(), 1e-14) << "faces " << g << ", " << h;
      EXPECT_GT((bent[g] - bent[h]).norm(), 1e-5);
      ++shared;
    }
  EXPECT_GT(shared, 100);
}

// The corner cache of the tracked gaps (contact_surface.h corner_group, tracked_gaps.h
// Geometry::CornerNormal): a deformed corner normal made once per group and read by every
// corner of the group gives each face's force normal to the bit (`==` against the corners made
// anew). The faceted cylinder with each face turned by its own rotation, faces visited in a
// shuffled order at points inside and on their edges, so most corners are read from another
// face's making.
TEST(ForceNormal, CornerNormalsMadeOncePerGroupAreTheSameNumbers) {
  const ContactSurface s = FacetedCylinder(12, 20e-3, true);
  const auto& x = s.vertices();
  std::mt19937 rng(7);
  std::normal_distribution<double> small(0, 1e-3);
  std::vector<Vec3> bent(s.num_triangles());
  for (int g = 0; g < s.num_triangles(); ++g)
    bent[g] = (s.face_normals()[g] + Vec3(small(rng), small(rng), small(rng))).normalized();
  auto normal = [&](int g) -> const Vec3& { return bent[g]; };
  // Every edge is smooth (7.5 degree facets): one group per vertex, shared by its faces' corners
  // (six at a vertex inside the cylinder's side).
  ASSERT_EQ(s.corner_group().size(), 3u * s.num_triangles());
  EXPECT_EQ(s.num_corner_groups(), s.num_vertices());
  std::vector<Vec3> cache(s.num_corner_groups(), Vec3::Zero());
  std::vector<char> made(s.num_corner_groups(), 0);
  int reused = 0;
  auto cached = [&](int f, int k) {
    const int group = s.corner_group()[3 * f + k];
    if (!made[group]) {
      cache[group] = DeformedCornerNormal(s, f, k, normal);
      made[group] = 1;
    } else {
      ++reused;
    }
    return cache[group];
  };
  std::vector<int> order(s.num_triangles());
  for (int g = 0; g < s.num_triangles(); ++g) order[g] = g;
  std::shuffle(order.begin(), order.end(), rng);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const int f : order) {
    const auto& t = s.triangles()[f];
    for (int trial = 0; trial < 3; ++trial) {
      double w0 = unit(rng), w1 = unit(rng);
      if (trial == 2) w1 = 1 - w0;  // on the edge of corners 0 and 1
      if (w0 + w1 > 1) w0 = 1 - w0, w1 = 1 - w1;
      const Vec3 q = w0 * x[t[0]] + w1 * x[t[1]] + (1 - w0 - w1) * x[t[2]];
      const Vec3 anew = ForceNormal(s, f, q, x[t[0]], x[t[1]], x[t[2]], true, normal);
      const Vec3 reread = ForceNormal(s, f, q, x[t[0]], x[t[1]], x[t[2]], true, normal, cached);
      EXPECT_EQ(anew, reread) << "face " << f;
    }
  }
  EXPECT_GT(reused, 6 * s.num_triangles());
}

}  // namespace
}  // namespace orrery::contact

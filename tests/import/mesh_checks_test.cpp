// Mesh checks (import/mesh_checks.h): each defect made on purpose on a closed primitive and found
// with its count; orientation repaired where it is unambiguous (a shuffled cube, a cavity inside a
// box turned inward), left alone where it is not (a Moebius strip); the triangle-triangle test on
// known configurations and the self-intersection search against brute force over all pairs.
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "import/mesh_checks.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

using namespace test_meshes;

TriangleMesh Shifted(TriangleMesh m, const Vec3& d) {
  for (Vec3& v : m.vertices) v += d;
  return m;
}

// Two meshes as one (vertices not shared).
TriangleMesh Union(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh m = a;
  const int n = static_cast<int>(a.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) m.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  return m;
}

TEST(MeshChecksTest, ClosedPrimitivesAreValidSolids) {
  for (const TriangleMesh& m : {Box(1, 2, 3), Prism(1, 1, 17), Sphere(1, 9, 14), Torus(2, 0.5, 20, 9), Tube(0.5, 1, 0.3, 12)}) {
    const MeshCheckReport r = CheckMesh(m);
    EXPECT_TRUE(r.watertight());
    EXPECT_TRUE(r.valid_solid()) << r.Problems().front();
    EXPECT_EQ(r.components, 1);
    EXPECT_EQ(r.closed_components, 1);
    EXPECT_EQ(r.inconsistent_edges, 0);
    EXPECT_TRUE(r.flipped.empty());
    EXPECT_EQ(r.self_intersections, 0);
    EXPECT_TRUE(r.Problems().empty());
    EXPECT_GT(r.signed_volume_m3, 0);
  }
}

TEST(MeshChecksTest, ShuffledOrientationIsRepairedOutward) {
  // Every other triangle of a sphere flipped, then the whole thing inside out
  TriangleMesh m = Sphere(1, 8, 12);
  const double volume = EnclosedVolume(m);
  for (std::size_t t = 0; t < m.triangles.size(); t += 2) std::swap(m.triangles[t][1], m.triangles[t][2]);
  MeshCheckReport r = CheckMesh(m);
  EXPECT_GT(r.inconsistent_edges, 0);
  EXPECT_TRUE(r.watertight());
  OrientMesh(m, r);
  EXPECT_EQ(CountOpenOrInconsistentEdges(m), 0);
  EXPECT_NEAR(EnclosedVolume(m), volume, 1e-14);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  r = CheckMesh(m);
  EXPECT_EQ(r.flipped.size(), m.triangles.size());
  OrientMesh(m, r);
  EXPECT_NEAR(EnclosedVolume(m), volume, 1e-14);
}

TEST(MeshChecksTest, CavityIsTurnedInward) {
  // A box with a spherical cavity, both outward at first: the cavity must point into the hole
  const TriangleMesh box = Shifted(Box(4, 4, 4), Vec3(-2, -2, -2));
  const TriangleMesh ball = Sphere(1, 8, 12);
  TriangleMesh m = Union(box, ball);
  const MeshCheckReport r = CheckMesh(m);
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.closed_components, 2);
  EXPECT_EQ(r.flipped.size(), ball.triangles.size());
  OrientMesh(m, r);
  EXPECT_NEAR(EnclosedVolume(m), EnclosedVolume(box) - EnclosedVolume(ball), 1e-12);
  // Two separate boxes stay outward
  TriangleMesh two = Union(box, Shifted(box, Vec3(10, 0, 0)));
  EXPECT_TRUE(CheckMesh(two).flipped.empty());
}

TEST(MeshChecksTest, DefectsAreCounted) {
  // Open: a box without its top (2 triangles): 4 boundary edges
  TriangleMesh open = Box(1, 1, 1);
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);
  MeshCheckReport r = CheckMesh(open);
  EXPECT_EQ(r.boundary_edges, 4);
  EXPECT_FALSE(r.watertight());
  EXPECT_FALSE(r.valid_solid());
  EXPECT_EQ(r.Problems().front(), "4 boundary edges: the mesh is open (not watertight)");
  // Non-manifold: two boxes sharing one edge (welded): 1 edge used 4 times
  TriangleMesh a = Box(1, 1, 1);
  TriangleMesh b = Shifted(Box(1, 1, 1), Vec3(1, 1, 0));
  TriangleMesh joined = Union(a, b);
  // Weld b's vertices (0,1,*) + shift = (1,1,z) onto a's (1,1,z): a 3 and 7 are (1,1,0), (1,1,1)
  for (auto& t : joined.triangles)
    for (int& i : t) {
      if (i == 8 + 0) i = 3;
      if (i == 8 + 4) i = 7;
    }
  r = CheckMesh(joined);
  EXPECT_EQ(r.non_manifold_edges, 1);
  EXPECT_EQ(r.boundary_edges, 0);
  EXPECT_FALSE(r.watertight());
  // Degenerate and duplicate triangles
  TriangleMesh dup = Box(1, 1, 1);
  dup.triangles.push_back(dup.triangles[0]);
  dup.triangles.push_back({dup.triangles[1][2], dup.triangles[1][1], dup.triangles[1][0]});
  dup.vertices.emplace_back(0.5, 0, 0);  // on the edge 0-1
  dup.triangles.push_back({0, 1, 8});
  dup.triangles.push_back({0, 0, 1});
  r = CheckMesh(dup);
  EXPECT_EQ(r.duplicate_triangles, 2);
  EXPECT_EQ(r.degenerate_triangles, 2);
}

TEST(MeshChecksTest, MoebiusStripIsNonOrientableAndLeftAlone) {
  TriangleMesh m;
  const int n = 24;
  for (int i = 0; i < n; ++i) {
    const double u = 2 * std::numbers::pi * i / n;
    for (int s : {-1, 1}) {
      const double w = 0.2 * s;
      m.vertices.emplace_back((1 + w * std::cos(u / 2)) * std::cos(u), (1 + w * std::cos(u / 2)) * std::sin(u),
                              w * std::sin(u / 2));
    }
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * i + 1;
    // The last quad joins the first with the sides swapped (the half twist)
    const int c = i + 1 < n ? 2 * (i + 1) + 1 : 0, d = i + 1 < n ? 2 * (i + 1) : 1;
    Quad(m, a, d, c, b);
  }
  const MeshCheckReport r = CheckMesh(m);
  EXPECT_EQ(r.non_orientable_components, 1);
  EXPECT_TRUE(r.flipped.empty());
  EXPECT_GT(r.boundary_edges, 0);
}

TEST(MeshChecksTest, TriangleTriangleIntersection) {
  const Vec3 o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  // Crossing: a vertical triangle through the middle of a horizontal one
  EXPECT_TRUE(TrianglesIntersect(o, x, y, Vec3(0.2, 0.2, -1), Vec3(0.3, 0.2, 1), Vec3(0.2, 0.3, 1)));
  // Apart: above; beside in the same plane
  EXPECT_FALSE(TrianglesIntersect(o, x, y, Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(0, 1, 1)));
  EXPECT_FALSE(TrianglesIntersect(o, x, y, Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(2, 1, 0)));
  // Its plane cuts the other's, but the segments on the line miss
  EXPECT_FALSE(TrianglesIntersect(o, x, y, Vec3(2, 2, -1), Vec3(2, 3, 1), Vec3(3, 2, 1)));
  // Coplanar overlap; touching at one point only
  EXPECT_TRUE(TrianglesIntersect(o, x, y, Vec3(0.2, 0.2, 0), Vec3(1.2, 0.2, 0), Vec3(0.2, 1.2, 0)));
  EXPECT_FALSE(TrianglesIntersect(o, x, y, Vec3(1, 0, 0), Vec3(2, 0, 1), Vec3(2, 0, -1)));
}

TEST(MeshChecksTest, SelfIntersectionsMatchBruteForce) {
  // Two tori through each other (chain links whose centre circles are 1 apart, tubes 0.6 thick)
  // plus a box that touches neither
  TriangleMesh m = Union(Torus(1, 0.6, 16, 8), Shifted(Torus(1, 0.6, 16, 8), Vec3(1, 0, 0)));
  for (Vec3& v : m.vertices)
    if (&v - m.vertices.data() >= 128) v = Vec3(v.x(), -v.z(), v.y()) + Vec3(0, 0, 0);  // second link upright
  m = Union(m, Shifted(Box(0.2, 0.2, 0.2), Vec3(5, 5, 5)));
  const MeshCheckReport r = CheckMesh(m, {.max_reported_pairs = 1000});
  int brute = 0;
  for (std::size_t s = 0; s < m.triangles.size(); ++s)
    for (std::size_t t = s + 1; t < m.triangles.size(); ++t) {
      const auto &f = m.triangles[s], &g = m.triangles[t];
      bool shared = false;
      for (int i : f)
        for (int j : g) shared |= i == j;
      if (!shared && TrianglesIntersect(m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]], m.vertices[g[0]],
                                        m.vertices[g[1]], m.vertices[g[2]]))
        ++brute;
    }
  EXPECT_GT(brute, 0);
  EXPECT_EQ(r.self_intersections, brute);
  EXPECT_FALSE(r.valid_solid());
  EXPECT_EQ(CheckMesh(m, {.self_intersections = false}).self_intersections, -1);
}

}  // namespace
}  // namespace orrery

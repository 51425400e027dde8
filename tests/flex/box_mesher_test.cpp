// Structured box meshes (flex/box_mesher.cpp): node and element counts, volume, face sets, and
// conformity of the 6-tet split (every interior triangle shared by exactly two tets, so the
// boundary triangles are exactly 2 per brick face on the surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "flex/box_mesher.h"
#include "flex/fe_element.h"

namespace orrery::flex {
namespace {

TEST(BoxMesherTest, CountsVolumesAndFaces) {
  const int nx = 4, ny = 3, nz = 2;
  const Eigen::Vector3d size(0.4, 0.3, 0.1);
  const int corners = (nx + 1) * (ny + 1) * (nz + 1);
  const int edges = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
  // Kuhn split adds a diagonal on each brick face and through each brick
  const int face_diagonals = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
  const std::map<ElementType, std::pair<int, int>> expected{
      {ElementType::kHex8, {corners, nx * ny * nz}},
      {ElementType::kHex20, {corners + edges, nx * ny * nz}},
      {ElementType::kTet4, {corners, 6 * nx * ny * nz}},
      {ElementType::kTet10, {corners + edges + face_diagonals + nx * ny * nz, 6 * nx * ny * nz}}};
  for (const auto& [t, counts] : expected) {
    const FeMesh m = MakeBoxMesh({.size_m = size, .divisions = {nx, ny, nz}, .type = t});
    EXPECT_EQ(m.num_nodes(), counts.first) << CalculixName(t);
    EXPECT_EQ(m.num_elements(), counts.second) << CalculixName(t);
    double v = 0;
    for (int e = 0; e < m.num_elements(); ++e) {
      const ElementQuality q = CalcElementQuality(t, m.ElementPositions(e));
      EXPECT_GT(q.min_det_J, 0);
      v += q.volume_m3;
    }
    EXPECT_NEAR(v, size.prod(), 1e-15);
    for (int n : m.NodeSet("XMAX")) EXPECT_DOUBLE_EQ(m.positions()[n](0), 0.4);
    for (int n : m.NodeSet("ZMIN")) EXPECT_DOUBLE_EQ(m.positions()[n](2), 0.0);
    const int per_face = t == ElementType::kHex20 ? (2 * ny + 1) * (2 * nz + 1) - ny * nz
                         : t == ElementType::kTet10 ? (2 * ny + 1) * (2 * nz + 1)
                                                    : (ny + 1) * (nz + 1);
    EXPECT_EQ(static_cast<int>(m.NodeSet("XMIN").size()), per_face) << CalculixName(t);
  }
}

TEST(BoxMesherTest, TetSplitIsConforming) {
  const int nx = 3, ny = 2, nz = 2;
  const FeMesh m = MakeBoxMesh({.divisions = {nx, ny, nz}, .type = ElementType::kTet4});
  std::map<std::array<int, 3>, int> faces;
  for (const FeElement& e : m.elements())
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      int k = 0;
      for (int a = 0; a < 4; ++a)
        if (a != skip) f[k++] = e.nodes[a];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  int boundary = 0;
  for (const auto& [f, count] : faces) {
    EXPECT_LE(count, 2);
    if (count == 1) ++boundary;
  }
  EXPECT_EQ(boundary, 2 * 2 * (nx * ny + ny * nz + nz * nx));
}

}  // namespace
}  // namespace orrery::flex

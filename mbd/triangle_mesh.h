#pragma once
// Indexed triangle surface mesh, the exchange type between gear geometry (models/gear_geometry.h),
// the STL writer (models/stl.h), mesh import (import/) and contact surfaces (contact/).
#include <array>
#include <vector>

#include "mbd/spatial.h"

namespace orrery {

// vertices: #V points (m, body frame); triangles: #T index triples into `vertices`, counter-
// clockwise seen from outside the enclosed solid (right-hand normal points outward).
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// Volume enclosed by a closed, consistently oriented mesh (divergence theorem:
// V = sum over triangles of a . (b x c) / 6). Positive for outward-oriented meshes.
double EnclosedVolume(const TriangleMesh& mesh);

// Number of edges not shared by exactly two triangles with opposite orientations (0 for a closed,
// consistently oriented, manifold mesh).
int CountOpenOrInconsistentEdges(const TriangleMesh& mesh);

}  // namespace orrery

#pragma once
// Structured meshes of a box [origin, origin + size] for tests and benchmarks: hex8 / hex20
// bricks, or tet4 / tet10 by splitting each brick into 6 tetrahedra around its main diagonal
// (Kuhn / Freudenthal split: one tet per permutation of the axes; the same split in every brick
// makes the face diagonals of neighbours match, so the mesh is conforming).
//
// Nodes sit on a lattice of (2 nx + 1)(2 ny + 1)(2 nz + 1) points (corners on even lattice
// indices, midside nodes halfway), created in element order with ids 1, 2, ...; only the points
// elements use become nodes. Elements have ids 1, 2, ... and CalculiX node order (fe_mesh.h),
// all with positive Jacobian.
// Sets: element set "EALL"; node sets "NALL" and the faces "XMIN", "XMAX", "YMIN", "YMAX",
// "ZMIN", "ZMAX" (every node on the face, midside nodes included).
//
// Usage:
//   FeMesh beam = MakeBoxMesh({.size_m = {1, 0.1, 0.1}, .divisions = {20, 2, 2},
//                              .type = ElementType::kHex20});
#include <array>

#include <Eigen/Core>

#include "flex/fe_mesh.h"

namespace orrery::flex {

struct BoxMeshSpec {
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d size_m = Eigen::Vector3d::Ones();
  std::array<int, 3> divisions{1, 1, 1};  // bricks along x, y, z (>= 1)
  ElementType type = ElementType::kHex8;
};

// Throws std::invalid_argument for divisions < 1 or a non-positive size.
FeMesh MakeBoxMesh(const BoxMeshSpec& spec);

}  // namespace orrery::flex

#pragma once
// STL export of triangle meshes (binary and ASCII), e.g. gear bodies for CAD, gmsh or FE meshing.
//
// Binary layout (the de-facto standard, little-endian): 80-byte header, uint32 triangle count,
// then per triangle 12 float32 (facet normal, three vertices) and a uint16 attribute (0), i.e.
// 84 + 50 n bytes. ASCII: "solid name / facet normal ... / outer loop / vertex ... / endloop /
// endfacet / endsolid name". STL carries no unit: coordinates are written as mesh value * scale
// (the engine is SI, so scale = 1 writes metres; 1000 writes millimetres).
//
// Usage: WriteStlBinary(MakeGearMesh(gear, {}, 20, 0.01), "planet.stl", {.scale = 1000});
#include <string>

#include "mbd/triangle_mesh.h"

namespace orrery::gears {

struct StlOptions {
  double scale = 1.0;                 // written coordinate = value (m) * scale
  std::string solid_name = "orrery";  // ASCII solid name; binary header text
};

// Facet normals are the unit right-hand normals of the triangles (zero for degenerate ones).
// Throws std::runtime_error when the file cannot be written.
void WriteStlBinary(const TriangleMesh& mesh, const std::string& path, const StlOptions& options = {});
void WriteStlAscii(const TriangleMesh& mesh, const std::string& path, const StlOptions& options = {});

}  // namespace orrery::gears

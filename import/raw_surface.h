#pragma once
// What a surface-mesh file reader returns before welding and unit conversion: triangles over a
// vertex list in the file's own length unit, each triangle tagged with the region (STL solid,
// OBJ group or object, assimp mesh) it came from. surface_mesh.h turns it into a welded
// orrery::TriangleMesh in metres.
#include <array>
#include <string>
#include <vector>

#include "mbd/spatial.h"

namespace orrery {

struct RawSurface {
  std::vector<Vec3> vertices;                 // (#V) file units, not welded
  std::vector<std::array<int, 3>> triangles;  // (#T) indices into vertices, as written
  std::vector<int> triangle_region;           // (#T) index into region_names
  std::vector<std::string> region_names;      // at least one ("" for an unnamed whole)
  std::string format;                         // "STL (binary)", "OBJ", "assimp: glTF2", ...
  std::vector<std::string> notes;             // things skipped ("file:line: 'l' (lines) ignored")
};

}  // namespace orrery

#pragma once
// Wavefront OBJ surface meshes read into a RawSurface (raw_surface.h). The project's own reader
// (bounded, line-numbered errors, fuzzed in tools/fuzz/); assimp reads the other formats.
//
// Statements used (one per line, '#' starts a comment):
//   v x y z [w | r g b]           a vertex (extra values ignored)
//   f a b c [d ...]               a polygon, split into a fan of k - 2 triangles; each corner is
//                                 "i", "i/t", "i//n" or "i/t/n": 1-based vertex indices, negative
//                                 ones counted back from the last vertex defined
//   g name ... / o name           the region of the following faces (group, else object name)
// Every other statement (vt, vn, s, usemtl, mtllib, l, p, curves, ...) is skipped with one note
// per keyword. A face must refer to vertices defined before it.
//
// Errors are std::runtime_error "FILE:LINE: reason": a malformed number, a vertex with fewer than
// three coordinates, a face with fewer than three corners, an index 0 or beyond the vertices
// defined so far, a file without faces.
//
// Usage:
//   RawSurface raw = ParseObj(ReadFileBounded("part.obj"), "part.obj");
#include <string>
#include <string_view>

#include "import/raw_surface.h"

namespace orrery {

RawSurface ParseObj(std::string_view bytes, const std::string& source);

}  // namespace orrery

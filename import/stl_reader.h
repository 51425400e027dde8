#pragma once
// STL files (stereolithography), binary and ASCII, read into a RawSurface (raw_surface.h).
// The project's own reader rather than assimp's: it checks a binary file's triangle count
// against its size before it allocates, names the line of an ASCII error, and is fuzzed
// (tools/fuzz/). models/stl.h writes the same layouts.
//
// Binary (little-endian): 80-byte header, uint32 triangle count n, then n records of 12 float32
// (facet normal, three vertices) and a uint16 attribute count: exactly 84 + 50 n bytes. The
// stored normals are ignored (normals come from the vertex order, right-hand rule).
// ASCII: one or more "solid [name] ... endsolid [name]" blocks of
//   facet normal nx ny nz / outer loop / vertex x y z (3 or more) / endloop / endfacet
// keywords case-insensitive; a loop of k > 3 vertices is split into a fan of k - 2 triangles.
// Each solid is a region named after it.
// Which one: a file whose size is 84 + 50 n for the count n in bytes 80-83 is binary (binary
// headers may begin with "solid" too); otherwise one that begins with "solid" is ASCII; anything
// else is a binary file whose count does not match its size, which is an error.
//
// Errors are std::runtime_error naming the source and, for ASCII, the line:
//   "part.stl: binary STL header says 1000 triangles (50084 bytes) but the file has 684 bytes"
//   "part.stl:12: expected 'vertex', got 'endloop'"
// Coordinates are returned as read (non-finite ones included); surface_mesh.h checks them.
//
// Usage:
//   RawSurface raw = ParseStl(ReadFileBounded("part.stl"), "part.stl");
#include <string>
#include <string_view>

#include "import/raw_surface.h"

namespace orrery {

// True if `bytes` is a binary STL by the size rule above.
bool IsBinaryStl(std::string_view bytes);

// Parses an STL file's bytes. `source` names it in messages.
RawSurface ParseStl(std::string_view bytes, const std::string& source);

}  // namespace orrery

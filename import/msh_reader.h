#pragma once
// gmsh mesh files (.msh), format versions 2.2 and 4.1, ASCII and binary, read into flex's FE
// mesh (flex/fe_mesh.h) and a surface triangle mesh. A file format, so it lives in import/ (the
// Abaqus/CalculiX .inp reader, flex/inp_file.h, predates it); gmsh itself is never linked
// (gmsh_program.h runs it as a program).
//
// Format: gmsh reference manual, section "MSH file format" (versions 4.1 and 2.2): $MeshFormat,
// $PhysicalNames, $Entities (4.1: which physical groups each geometric entity belongs to),
// $Nodes, $Elements; other sections ($Periodic, $NodeData, ...) are skipped. Binary files must be
// little-endian (the check integer after the version line) with 8-byte size_t (4.1) / 4-byte
// int (2.2) as gmsh writes them on every common platform.
//
// Elements:
//   volume: 4 (tet4), 11 (tet10), 5 (hex8), 17 (hex20) become FE elements, node order converted
//     from gmsh's to CalculiX's (fe_mesh.h). 0-based: tet10 midside nodes in gmsh are on edges
//     0-1, 1-2, 2-0, 3-0, 3-2, 3-1, in C3D10 on 0-1, 1-2, 2-0, 0-3, 1-3, 2-3 (the last two
//     swap); hex20 midside nodes in gmsh are on edges 0-1, 0-3, 0-4, 1-2, 1-5, 2-3, 2-6, 3-7,
//     4-5, 4-7, 5-6, 6-7, in C3D20 on 0-1, 1-2, 2-3, 3-0, 4-5, 5-6, 6-7, 7-4, 0-4, 1-5, 2-6, 3-7;
//     corners are in the same order in both;
//   surface: 2 (tri3) and 9 (tri6, corners) become triangles of `surface`, 3 (quad4) and 16
//     (quad8) / 10 (quad9) two triangles each;
//   points and lines (15, 1, 8, 26-28): used only for their physical groups' nodes;
//   any other type (prisms, pyramids, hex27, tet20, ...): an error naming it, since flex has no
//   such element.
// Physical groups: every physical group becomes a node set (the nodes of its elements that the
// FE mesh holds) named after its $PhysicalNames entry, or "PHYSICAL<dim>D_<tag>" when unnamed;
// a volume group also becomes an element set of the same name. Names are upper-cased (fe_mesh.h).
// Only nodes used by the volume elements enter the FE mesh (a geometry point alone would be a
// free, stiffness-less node); the ids are the file's.
// Surface: the tri/quad elements, corner nodes, regions per physical group (region "" for
// elements in none); vertex positions in metres after `scale`.
//
// Bounds: counts in headers are never trusted for allocation (arrays grow as data is parsed, so
// memory is bounded by the file's size); tags must fit in an int.
// Errors are std::runtime_error "FILE[:LINE]: $Section: reason": version 4.0 or unknown versions,
// big-endian files, an unknown element type, an unsupported volume element, an element that
// refers to a node not in $Nodes, a duplicate node or element tag, a truncated section, a
// non-finite or huge coordinate.
//
// Usage:
//   GmshMesh m = ReadGmshMsh("part.msh");           // m.mesh (FE), m.surface, m.notes
//   flex::FeMesh mesh = std::move(m.mesh);
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "flex/fe_mesh.h"
#include "import/bounded_file.h"
#include "import/raw_surface.h"

namespace orrery {

struct GmshMesh {
  flex::FeMesh mesh;          // volume elements, nodes they use, sets from physical groups
  RawSurface surface;         // tri / quad elements (file coordinates times scale)
  std::string version;        // "2.2" or "4.1"
  bool binary = false;
  int volume_entities = 0;    // 4.1: volumes listed in $Entities (-1 for 2.2: not stated)
  std::vector<std::string> notes;  // skipped sections, point / line elements
};

struct GmshReadOptions {
  double scale = 1.0;  // coordinates are multiplied by this (file unit -> m)
  double max_coordinate_m = 1e5;  // |x|, |y|, |z| bound after the scale
  std::uintmax_t max_bytes = kDefaultMaxInputBytes;
};

GmshMesh ReadGmshMsh(const std::filesystem::path& path, const GmshReadOptions& options = {});
// The same from bytes; `source` names them in messages.
GmshMesh ParseGmshMsh(std::string_view bytes, const std::string& source, const GmshReadOptions& options = {});

}  // namespace orrery

#pragma once
// Surface meshes from files: every format of import/ read into one welded orrery::TriangleMesh in
// metres, with face normals and regions. The first stage of mesh import; checks (mesh_checks.h)
// and mass properties (mass_properties.h) follow.
//
// Formats, by extension (case-insensitive):
//   .stl            own reader (stl_reader.h), binary or ASCII
//   .obj            own reader (obj_reader.h)
//   .step .stp .iges .igs   gmsh triangulates the CAD faces (gmsh_mesher.h); the file's own
//                   length unit is used (OpenCASCADE converts to metres); one solid expected
//   .msh            gmsh mesh (msh_reader.h): its tri/quad elements, else the boundary of its
//                   volume elements
//   .inp            Abaqus/CalculiX mesh (flex/inp_file.h): the boundary of its volume elements
//   anything assimp 5.2 imports (.ply .gltf .glb .3mf .off .dae .fbx .3ds .amf ...; assimp_surface.h)
// Units: files other than STEP/IGES carry none that is read; options.unit states it (default
// metres). When it is not stated and the largest extent of the mesh exceeds 10 m, a warning says
// that the coordinates look like millimetres. Stating a unit for a STEP/IGES file is an error
// (its own is used).
// Welding: vertices with bit-identical coordinates (after -0 -> +0) are merged, in order of first
// use; vertices no triangle uses are dropped. Polygons are already triangulated by the readers.
// Face normals: the unit right-hand normals (b - a) x (c - a) / |...|, zero for a degenerate face.
// Coordinates are checked: every one finite and within max_coordinate_m of the origin (after the
// unit), else an error naming the vertex.
//
// Errors (std::runtime_error, one line naming the file): no such file, not a regular file, too
// large, unknown format (the supported extensions listed), empty mesh, a reader's own message,
// a non-finite or huge coordinate.
//
// Usage:
//   SurfaceMesh s = ReadSurfaceMesh("gear.stl", {.unit = LengthUnit::kMillimetre});
//   s.mesh.triangles.size();  s.warnings;
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "import/bounded_file.h"
#include "import/gmsh_mesher.h"
#include "import/length_unit.h"
#include "import/raw_surface.h"
#include "mbd/triangle_mesh.h"

namespace orrery {

enum class MeshFileFormat { kStl, kObj, kCad, kGmsh, kInp, kAssimp, kUnknown };

// The format of a file by its extension (assimp's list for the rest).
MeshFileFormat DetectMeshFileFormat(const std::filesystem::path& path);
// "STL", "OBJ", "STEP/IGES", "gmsh MSH", "Abaqus/CalculiX INP", "assimp", "unknown".
const char* MeshFileFormatName(MeshFileFormat format);
// ".stl .obj .step .stp .iges .igs .msh .inp" and assimp's extensions, for messages.
std::string SupportedMeshExtensions();

struct SurfaceReadOptions {
  std::optional<LengthUnit> unit;        // nullopt: metres (with the millimetre warning)
  std::uintmax_t max_bytes = kDefaultMaxInputBytes;
  double max_coordinate_m = 1e5;         // |x|, |y|, |z| bound after the unit
  GmshMeshOptions cad;                   // STEP/IGES triangulation (curvature_elements 0: 48 per
                                         // 2 pi, chords within 0.2 % of a radius)
};

struct SurfaceMesh {
  TriangleMesh mesh;                       // metres, welded
  std::vector<Vec3> face_normals;          // (#T) unit, zero for degenerate faces
  std::vector<int> triangle_region;        // (#T) index into region_names
  std::vector<std::string> region_names;   // STL solids, OBJ groups, assimp meshes, gmsh groups
  std::string format;                      // "STL (binary)", ...
  std::string unit;                        // "mm", ... (the stated one, the CAD file's, or "m")
  bool unit_stated = false;                // given by the caller or by the file (STEP)
  int file_vertices = 0;                   // before welding
  int unused_vertices = 0;                 // dropped by welding (no triangle used them)
  std::vector<std::string> notes;          // reader notes (skipped statements and sections)
  std::vector<std::string> warnings;       // e.g. the millimetre warning
};

// Reads any supported file. Throws std::runtime_error "FILE: reason".
SurfaceMesh ReadSurfaceMesh(const std::filesystem::path& path, const SurfaceReadOptions& options = {});

// Scales, checks and welds a reader's output (the part of ReadSurfaceMesh after the reader).
// `source` names the file in messages.
SurfaceMesh WeldRawSurface(const RawSurface& raw, double metres_per_unit, const std::string& source,
                           double max_coordinate_m = 1e5);

// Unit right-hand face normals (zero for degenerate faces).
std::vector<Vec3> FaceNormals(const TriangleMesh& mesh);

}  // namespace orrery

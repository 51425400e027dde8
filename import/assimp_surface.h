#pragma once
// Surface meshes through assimp (Open Asset Import Library 5.2): PLY, glTF 2 (.gltf / .glb), 3MF,
// OFF, Collada, FBX, 3DS, AMF and the other formats its importer lists. The only file of the
// project that includes assimp's headers (assimp_surface.cpp). STL and OBJ have their own readers
// (stl_reader.h, obj_reader.h); STEP and IGES go through gmsh (gmsh_program.h), since assimp's
// "STEP" support is the IFC subset, not solids.
//
// Reading: aiProcess_PreTransformVertices (the node transforms applied, so every mesh is in the
// file's root frame), aiProcess_Triangulate, aiProcess_SortByPType with points and lines removed;
// normals, texture coordinates and colours are dropped (normals come from the faces). Vertices
// are welded later (surface_mesh.h). Each aiMesh becomes a region named after it (or after its
// index when unnamed).
// Units: formats that state a unit are not converted by assimp 5.2 (glTF is metres by its
// specification; 3MF's default unit is the millimetre): the caller states the unit.
// Bounds: the file is size-checked (bounded_file.h) and a zip container (3MF, .zae, .pk3) is
// refused when its central directory lists more uncompressed bytes than the limit, so a zip bomb
// is not expanded.
//
// Usage:
//   if (AssimpReadsExtension(".ply")) RawSurface raw = ReadAssimpSurface("part.ply");
//   WriteAssimpSurface(mesh, "part.glb", "glb2");   // e.g. to make test files
#include <cstdint>
#include <filesystem>
#include <string>

#include "import/bounded_file.h"
#include "import/raw_surface.h"
#include "mbd/triangle_mesh.h"

namespace orrery {

// True if assimp has an importer for this extension (".ply", case-insensitive).
bool AssimpReadsExtension(const std::string& extension);
// assimp's import extensions, "*.3d;*.3ds;...".
std::string AssimpExtensionList();

// Reads a file with assimp. Throws std::runtime_error "FILE: reason" (assimp's own message for a
// malformed file, "no triangles" for a file without surface triangles).
RawSurface ReadAssimpSurface(const std::filesystem::path& path, std::uintmax_t max_bytes = kDefaultMaxInputBytes);

// Writes `mesh` (coordinates as they are) with assimp's exporter `format_id` ("stlb", "ply",
// "plyb", "obj", "gltf2", "glb2", "3mf", "collada", ...). Throws std::runtime_error naming the
// path and assimp's message.
void WriteAssimpSurface(const TriangleMesh& mesh, const std::filesystem::path& path, const std::string& format_id);

}  // namespace orrery

#pragma once
// CAD solids (STEP, IGES) and watertight surface meshes to triangle and tetrahedral meshes through
// the gmsh program (Debian package `gmsh`, built on OpenCASCADE). gmsh is GPL: it runs as a
// separate program on a generated .geo script in a scratch directory and is never linked into
// this BSD project. Its .msh output is read by msh_reader.h.
//
// Scripts (gmsh reference manual, "Gmsh scripting language" and the mesh options):
//   CAD:     Geometry.OCCTargetUnit = "M"  (OpenCASCADE converts from the file's own length unit,
//            the STEP LENGTH_UNIT / IGES global unit, to metres); Merge the file; the number of
//            volumes is written out and checked (one solid expected unless stated otherwise);
//            every face a physical surface "FACE<tag>" (node sets, regions), the solid(s) a
//            physical volume "SOLID"; Mesh 2 (triangles) or Mesh 3 (tetrahedra).
//   Surface: a watertight triangle mesh in metres, written as a gmsh 2.2 ASCII mesh (17 digits,
//            where an STL would round to float); ClassifySurfaces
//            (feature angle) and CreateGeometry make parametrizable patches from it so the volume
//            is remeshed to the requested size (remesh_surface, default), or the triangles are
//            kept as the boundary; Surface Loop + Volume; Mesh 3.
//   Sizes:   Mesh.MeshSizeMax / Mesh.MeshSizeMin (m; 0 = gmsh's defaults), Mesh.MeshSizeFromCurvature
//            (elements per 2 pi of curvature; 0 = off); Mesh.ElementOrder 1 (tet4) or 2 (tet10,
//            straight-sided by default, Mesh.SecondOrderLinear: valid whenever the tet4 is; from
//            CAD optionally curved, midside nodes on the geometry with Mesh.HighOrderOptimize 2
//            to untangle them, which is more accurate on curved faces (a 10 mm hole: 300 times
//            less volume error) but slower and can fail on coarse meshes, which is then an
//            error); Mesh.Optimize (and OptimizeNetgen off); General.NumThreads 1
//            so that a mesh is the same from run to run (reduced-body provenance hashes the mesh).
// A run is limited in time (coreutils `timeout`, timeout_s) and its log's tail is quoted when it
// fails.
//
// Errors (std::runtime_error, one line):
//   "gmsh not found on PATH: install Debian's package gmsh (apt-get install gmsh) to read STEP/IGES
//    files and to tetrahedralize surface meshes"
//   "part.step: 3 solids; one is expected", "part.step: no solid (surfaces only?)",
//   "gmsh failed on part.step (status 1): <last lines of its log>".
//
// Usage:
//   GmshMeshing m = MeshCadVolume("planet.step", {.max_size_m = 2e-3});   // m.mesh.mesh: tet10
//   GmshMeshing s = MeshCadSurface("planet.step", {});                    // s.mesh.surface
#include <filesystem>
#include <optional>
#include <string>

#include "import/msh_reader.h"
#include "mbd/triangle_mesh.h"

namespace orrery {

// The gmsh program on PATH; nullopt if none.
std::optional<std::filesystem::path> FindGmsh();
// FindGmsh or the error above.
std::filesystem::path RequireGmsh();
// "4.8.4" (gmsh -version); throws if the program does not answer.
std::string GmshVersion(const std::filesystem::path& gmsh);

struct GmshMeshOptions {
  double max_size_m = 0;        // Mesh.MeshSizeMax (0: gmsh's default, from the model's size)
  double min_size_m = 0;        // Mesh.MeshSizeMin (0: none)
  int curvature_elements = 0;   // Mesh.MeshSizeFromCurvature: elements per 2 pi (0: off)
  int order = 2;                // 1: tet4 / tri3, 2: tet10 / tri6 (3-D meshes; surfaces use 1)
  bool curved = false;          // CAD tet10: midside nodes on the geometry (see above)
  bool one_solid = true;        // CAD: more than one volume is an error
  bool remesh_surface = true;   // surface input: reparametrize and remesh (else keep its triangles)
  double feature_angle_deg = 40;  // surface input: ClassifySurfaces angle
  double timeout_s = 600;
};

// What a gmsh run gave: the mesh read back, the number of solids, and how it was made.
struct GmshMeshing {
  GmshMesh mesh;             // metres; node sets FACE<k> and SOLID (CAD), SOLID (surface input)
  int solids = 0;            // volumes in the model
  std::string description;   // "gmsh 4.8.4: tet10, max size 0.002 m, from part.step (unit mm)"
  std::string file_unit;     // CAD: the length unit the file states ("mm", "m", "in", "?"); else ""
};

// Triangulates the faces of a STEP / IGES solid (tri3). Throws as above.
GmshMeshing MeshCadSurface(const std::filesystem::path& cad, const GmshMeshOptions& options);
// Tetrahedral mesh of a STEP / IGES solid (tet10 unless options.order = 1). Throws as above.
GmshMeshing MeshCadVolume(const std::filesystem::path& cad, const GmshMeshOptions& options);
// Tetrahedral mesh of the solid a closed, consistently oriented triangle mesh (metres) bounds.
// `source` names the mesh in messages and the description.
GmshMeshing MeshSurfaceVolume(const TriangleMesh& surface_m, const std::string& source,
                              const GmshMeshOptions& options);

// The length unit a STEP file declares (its LENGTH_UNIT entity: SI_UNIT with prefix, or a
// CONVERSION_BASED_UNIT such as 'INCH'): "m", "mm", "cm", "um", "in", "ft", or "?" when none is
// found. Reads at most the file (bounded); IGES files give "?" (OpenCASCADE still converts them).
std::string ReadCadLengthUnit(const std::filesystem::path& cad);

// True for .step / .stp / .iges / .igs (case-insensitive).
bool IsCadFile(const std::filesystem::path& path);

}  // namespace orrery

#pragma once
// Volume (FE) meshes from files: a gmsh .msh or Abaqus/CalculiX .inp mesh is read; a STEP/IGES
// solid or a watertight surface mesh (any format of surface_mesh.h) is tetrahedralized by gmsh
// (gmsh_mesher.h, tet10 by default). The result is flex's FE mesh in metres, without material
// (the caller assigns one), with its node and element sets.
//
// Surface inputs are checked first (mesh_checks.h) and re-oriented; one that is not a valid solid
// boundary (open, non-manifold, degenerate or duplicate triangles, self-intersecting) is refused
// with the check's findings, since gmsh would fail on it or mesh something else.
// Units: .msh and surface files take options.unit (default metres, with the millimetre warning for
// surfaces); STEP/IGES their own; .inp files are taken as SI (a unit other than m is an error).
//
// Usage:
//   VolumeMesh v = ReadVolumeMesh("planet.stl", {.unit = LengthUnit::kMillimetre,
//                                                .meshing = {.max_size_m = 2e-3}});
//   v.mesh.AssignMaterialToAll({...});
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "flex/fe_mesh.h"
#include "import/bounded_file.h"
#include "import/gmsh_mesher.h"
#include "import/length_unit.h"

namespace orrery {

struct VolumeMeshOptions {
  std::optional<LengthUnit> unit;
  GmshMeshOptions meshing;   // CAD and surface inputs
  std::uintmax_t max_bytes = kDefaultMaxInputBytes;
};

struct VolumeMesh {
  flex::FeMesh mesh;
  std::string description;            // "mesh file part.inp", "gmsh 4.8.4: tet10 ... from part.stl"
  bool generated = false;             // meshed here by gmsh (CAD or surface input)
  std::vector<std::string> notes;
  std::vector<std::string> warnings;
};

// Throws std::runtime_error "FILE: reason" (unknown format, no volume elements, a surface that is
// not a valid solid, a gmsh failure, a reader's error).
VolumeMesh ReadVolumeMesh(const std::filesystem::path& path, const VolumeMeshOptions& options = {});

}  // namespace orrery

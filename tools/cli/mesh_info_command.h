#pragma once
// `orrery mesh-info FILE [--unit m|cm|mm|in] [--density RHO] [--no-self-intersections] [--json]`:
// reads a mesh file of any format import/ knows (STL, OBJ, STEP/IGES through gmsh, gmsh .msh,
// .inp, and what assimp reads: PLY, glTF/GLB, 3MF, ...; import/surface_mesh.h), checks it
// (import/mesh_checks.h: watertight, non-manifold, degenerate, duplicate, orientation,
// self-intersections), re-orients it where that is unambiguous and, when it is closed, gives its
// volume and centre of mass; with --density, its mass and inertia about the centre of mass
// (import/mass_properties.h, exact for the polyhedron).
//
// Text: format, unit, sizes, bounding box, the check's findings, the mass properties, warnings.
// JSON (--json):
//   {"file", "format", "unit", "unit_stated", "triangles", "vertices", "regions": [...],
//    "bounding_box_m": {"min": [3], "max": [3]}, "watertight", "boundary_edges",
//    "non_manifold_edges", "degenerate_triangles", "duplicate_triangles", "components",
//    "non_orientable_components", "reoriented_triangles", "self_intersections" (null when not
//    checked), "volume_m3", "center_of_mass_m" [3] (null unless closed), "density_kg_m3",
//    "mass_kg", "inertia_kg_m2" [3][3] (about the centre of mass, mesh axes; null without
//    --density), "principal_moments_kg_m2" [3], "warnings": [...], "notes": [...]}
// Failures: an unreadable or malformed file, an unknown format, an empty mesh, and --density on a
// mesh that is not closed ("not watertight (12 boundary edges)") print one line
// "orrery: error: <reason>" and return kExitFailure.
#include <optional>
#include <ostream>
#include <string>

namespace orrery::cli {

struct MeshInfoArgs {
  std::string path;
  std::string unit;                      // "" (not stated), "m", "cm", "mm", "in"
  std::optional<double> density_kg_m3;
  bool self_intersections = true;
  bool json = false;
};

int MeshInfoCommand(const MeshInfoArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

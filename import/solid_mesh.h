#pragma once
// A solid body from a mesh file: the surface read (import/surface_mesh.h: STL, OBJ, STEP, ...),
// checked to bound a solid (import/mesh_checks.h: watertight, orientable, no duplicate or
// self-intersecting triangles), oriented outward and its mass properties computed
// (import/mass_properties.h, exact for the polyhedron). What a scene's `mesh:` body and a gear
// train's imported planet (models/train_dynamics.h TrainImportedGear) are made from.
//
// Usage:
//   SolidMesh s = ReadSolidMesh("planet.stl", {.unit = LengthUnit::kMillimetre}, 7850);
//   options.imported_gears["S.planet1"] =
//       ReadImportedGear("planet.stl", {.unit = LengthUnit::kMillimetre}, 7850);
#include <filesystem>

#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/surface_mesh.h"
#include "models/train_dynamics.h"

namespace orrery {

struct SolidMesh {
  SurfaceMesh surface;     // oriented (outward), degenerate triangles kept
  MeshCheckReport report;  // of the surface as read
  MassProperties mass;
};

// Throws std::runtime_error with one line naming the file: the reader's errors, "FILE: not a
// valid solid for mass properties: <findings>" (re-oriented triangles and degenerate ones are
// not findings), a density that is not finite and > 0.
SolidMesh ReadSolidMesh(const std::filesystem::path& file, const SurfaceReadOptions& options,
                        double density_kg_m3);

// ReadSolidMesh as a train's imported gear (surface and mass properties in the file's frame,
// which must be the gear frame: models/imported_gear.h); source = the file name.
gears::TrainImportedGear ReadImportedGear(const std::filesystem::path& file,
                                          const SurfaceReadOptions& options, double density_kg_m3);

}  // namespace orrery

#include "import/solid_mesh.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orrery {

SolidMesh ReadSolidMesh(const std::filesystem::path& file, const SurfaceReadOptions& options,
                        double density_kg_m3) {
  if (!(density_kg_m3 > 0) || !std::isfinite(density_kg_m3))
    throw std::runtime_error(file.string() + ": density must be > 0 (kg/m^3), got " +
                             std::to_string(density_kg_m3));
  SolidMesh s;
  s.surface = ReadSurfaceMesh(file, options);
  s.report = CheckMesh(s.surface.mesh);
  // A valid solid boundary only (re-orientation is a repair, degenerate faces carry no volume)
  const MeshCheckReport& r = s.report;
  if (!r.watertight() || r.non_orientable_components > 0 || r.duplicate_triangles > 0 ||
      r.self_intersections > 0) {
    std::string problems;
    for (const std::string& p : r.Problems())
      if (p.find("re-oriented") == std::string::npos && p.find("degenerate") == std::string::npos)
        problems += (problems.empty() ? "" : "; ") + p;
    throw std::runtime_error(file.string() +
                             ": not a valid solid for mass properties: " + problems);
  }
  OrientMesh(s.surface.mesh, r);
  s.mass = MassPropertiesOfSolid(s.surface.mesh, density_kg_m3, r, file.string());
  return s;
}

gears::TrainImportedGear ReadImportedGear(const std::filesystem::path& file,
                                          const SurfaceReadOptions& options, double density_kg_m3) {
  SolidMesh s = ReadSolidMesh(file, options, density_kg_m3);
  return {.surface = std::move(s.surface.mesh),
          .mass_kg = s.mass.mass_kg,
          .center_of_mass_m = s.mass.center_of_mass_m,
          .inertia_kg_m2 = s.mass.inertia_kg_m2,
          .source = file.filename().string()};
}

}  // namespace orrery

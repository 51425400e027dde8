#include "import/volume_mesh.h"

#include <stdexcept>

#include "flex/inp_file.h"
#include "import/mesh_checks.h"
#include "import/msh_reader.h"
#include "import/surface_mesh.h"

namespace orrery {

VolumeMesh ReadVolumeMesh(const std::filesystem::path& path, const VolumeMeshOptions& options) {
  const std::string source = path.string();
  const MeshFileFormat format = DetectMeshFileFormat(path);
  CheckedFileSize(path, options.max_bytes);
  VolumeMesh v;
  switch (format) {
    case MeshFileFormat::kGmsh: {
      const double scale = options.unit ? MetresPerUnit(*options.unit) : 1.0;
      GmshMesh m = ReadGmshMsh(path, {.scale = scale, .max_bytes = options.max_bytes});
      v.mesh = std::move(m.mesh);
      v.notes = std::move(m.notes);
      v.description = "mesh file " + source + " (gmsh MSH " + m.version + (m.binary ? ", binary)" : ", ASCII)");
      break;
    }
    case MeshFileFormat::kInp: {
      if (options.unit && *options.unit != LengthUnit::kMetre)
        throw std::runtime_error(source + ": .inp meshes are read in SI units (m); a unit of " +
                                 LengthUnitName(*options.unit) + " is not applied");
      flex::InpReadResult r = flex::ReadInp(path);
      v.mesh = std::move(r.mesh);
      v.notes = std::move(r.notes);
      v.description = "mesh file " + source;
      break;
    }
    case MeshFileFormat::kCad: {
      if (options.unit)
        throw std::runtime_error(source + ": a STEP/IGES file states its own length unit; do not give one (got " +
                                 LengthUnitName(*options.unit) + ")");
      GmshMeshing m = MeshCadVolume(path, options.meshing);
      v.mesh = std::move(m.mesh.mesh);
      v.notes = std::move(m.mesh.notes);
      v.description = m.description;
      v.generated = true;
      break;
    }
    case MeshFileFormat::kUnknown:
      throw std::runtime_error(source + ": unknown mesh format '" + path.extension().string() + "' (supported: " +
                               SupportedMeshExtensions() + ")");
    default: {
      // A surface: checked, oriented, then filled with tetrahedra
      SurfaceMesh s = ReadSurfaceMesh(path, {.unit = options.unit, .max_bytes = options.max_bytes});
      const MeshCheckReport report = CheckMesh(s.mesh);
      if (!report.valid_solid()) {
        std::string problems;
        for (const std::string& p : report.Problems())
          if (p.find("re-oriented") == std::string::npos) problems += (problems.empty() ? "" : "; ") + p;
        throw std::runtime_error(source + ": not a valid solid boundary, cannot fill it with tetrahedra: " + problems);
      }
      OrientMesh(s.mesh, report);
      GmshMeshing m = MeshSurfaceVolume(s.mesh, source + " (" + s.format + ", unit " + s.unit + ")", options.meshing);
      v.mesh = std::move(m.mesh.mesh);
      v.notes = std::move(s.notes);
      v.notes.insert(v.notes.end(), m.mesh.notes.begin(), m.mesh.notes.end());
      v.warnings = std::move(s.warnings);
      v.description = m.description;
      v.generated = true;
      break;
    }
  }
  if (v.mesh.num_elements() == 0)
    throw std::runtime_error(source + ": no volume elements (tet4, tet10, hex8, hex20)" +
                             (format == MeshFileFormat::kGmsh
                                  ? std::string(" (a .msh with physical groups holds only their elements: add the "
                                                "volume to a physical group, or save with Mesh.SaveAll = 1)")
                                  : std::string()));
  return v;
}

}  // namespace orrery

#include "import/surface_mesh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include "flex/flexible_body_modes.h"
#include "flex/inp_file.h"
#include "import/assimp_surface.h"
#include "import/msh_reader.h"
#include "import/obj_reader.h"
#include "import/stl_reader.h"

namespace orrery {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string Num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

// The boundary of a volume mesh as a raw surface (FE node positions, corner triangles).
RawSurface BoundaryOf(const flex::FeMesh& mesh, const std::string& format) {
  RawSurface raw;
  raw.format = format;
  raw.vertices = mesh.positions();
  raw.triangles = flex::BoundaryTriangles(mesh, /*split_quadratic=*/false);
  raw.triangle_region.assign(raw.triangles.size(), 0);
  raw.region_names = {""};
  return raw;
}

// The raw surface of a file and the metres per file unit.
RawSurface ReadRaw(const std::filesystem::path& path, const SurfaceReadOptions& o, SurfaceMesh& out) {
  const std::string source = path.string();
  const MeshFileFormat format = DetectMeshFileFormat(path);
  switch (format) {
    case MeshFileFormat::kStl: return ParseStl(ReadFileBounded(path, o.max_bytes), source);
    case MeshFileFormat::kObj: return ParseObj(ReadFileBounded(path, o.max_bytes), source);
    case MeshFileFormat::kAssimp: return ReadAssimpSurface(path, o.max_bytes);
    case MeshFileFormat::kCad: {
      GmshMeshOptions cad = o.cad;
      if (cad.curvature_elements == 0) cad.curvature_elements = 48;
      GmshMeshing m = MeshCadSurface(path, cad);
      out.unit = m.file_unit;
      out.notes.push_back(m.description);
      m.mesh.surface.format = "STEP/IGES, triangulated by gmsh";
      return std::move(m.mesh.surface);
    }
    case MeshFileFormat::kGmsh: {
      GmshMesh m = ReadGmshMsh(path, {.max_bytes = o.max_bytes});
      out.notes.insert(out.notes.end(), m.notes.begin(), m.notes.end());
      if (m.mesh.num_elements() > 0) return BoundaryOf(m.mesh, m.surface.format + ", boundary of the volume elements");
      return std::move(m.surface);
    }
    case MeshFileFormat::kInp: {
      CheckedFileSize(path, o.max_bytes);
      flex::InpReadResult r = flex::ReadInp(path);
      if (r.mesh.num_elements() == 0) throw std::runtime_error(source + ": no solid elements");
      return BoundaryOf(r.mesh, "Abaqus/CalculiX INP, boundary of the volume elements");
    }
    default:
      throw std::runtime_error(source + ": unknown mesh format '" + path.extension().string() + "' (supported: " +
                               SupportedMeshExtensions() + ")");
  }
}

// Bit pattern of a coordinate with -0 folded into +0 (weld key).
double Key(double x) { return x + 0.0; }

}  // namespace

MeshFileFormat DetectMeshFileFormat(const std::filesystem::path& path) {
  const std::string e = Lower(path.extension().string());
  if (e == ".stl") return MeshFileFormat::kStl;
  if (e == ".obj") return MeshFileFormat::kObj;
  if (IsCadFile(path)) return MeshFileFormat::kCad;
  if (e == ".msh") return MeshFileFormat::kGmsh;
  if (e == ".inp") return MeshFileFormat::kInp;
  if (AssimpReadsExtension(e)) return MeshFileFormat::kAssimp;
  return MeshFileFormat::kUnknown;
}

const char* MeshFileFormatName(MeshFileFormat format) {
  switch (format) {
    case MeshFileFormat::kStl: return "STL";
    case MeshFileFormat::kObj: return "OBJ";
    case MeshFileFormat::kCad: return "STEP/IGES";
    case MeshFileFormat::kGmsh: return "gmsh MSH";
    case MeshFileFormat::kInp: return "Abaqus/CalculiX INP";
    case MeshFileFormat::kAssimp: return "assimp";
    default: return "unknown";
  }
}

std::string SupportedMeshExtensions() {
  std::string list = ".stl .obj .step .stp .iges .igs .msh .inp";
  std::string assimp = AssimpExtensionList();  // "*.3d;*.3ds;..."
  for (std::size_t at = 0; at < assimp.size();) {
    std::size_t end = assimp.find(';', at);
    if (end == std::string::npos) end = assimp.size();
    std::string ext = assimp.substr(at, end - at);
    if (ext.rfind("*", 0) == 0) ext.erase(0, 1);
    if (!ext.empty() && ext != ".stl" && ext != ".obj" && ext != ".step" && ext != ".stp") list += " " + ext;
    at = end + 1;
  }
  return list;
}

std::vector<Vec3> FaceNormals(const TriangleMesh& mesh) {
  std::vector<Vec3> normals(mesh.triangles.size(), Vec3::Zero());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const Vec3 n = (mesh.vertices[f[1]] - mesh.vertices[f[0]]).cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
    const double length = n.norm();
    if (length > 0 && std::isfinite(length)) normals[t] = n / length;
  }
  return normals;
}

SurfaceMesh WeldRawSurface(const RawSurface& raw, double metres_per_unit, const std::string& source,
                           double max_coordinate_m) {
  SurfaceMesh out;
  out.format = raw.format;
  out.notes = raw.notes;
  out.region_names = raw.region_names;
  out.triangle_region = raw.triangle_region;
  out.file_vertices = static_cast<int>(raw.vertices.size());
  if (raw.triangles.empty()) throw std::runtime_error(source + ": the mesh is empty (no triangles)");
  const int nv = static_cast<int>(raw.vertices.size());

  // Used vertices, each checked: finite and within the bound
  std::vector<char> used(nv, 0);
  for (std::size_t t = 0; t < raw.triangles.size(); ++t)
    for (int i : raw.triangles[t]) {
      if (i < 0 || i >= nv)
        throw std::runtime_error(source + ": triangle " + std::to_string(t + 1) + " refers to vertex " +
                                 std::to_string(i + 1) + " of " + std::to_string(nv));
      used[i] = 1;
    }
  for (int i = 0; i < nv; ++i) {
    if (!used[i]) continue;
    const Vec3 p = raw.vertices[i] * metres_per_unit;
    if (!p.allFinite())
      throw std::runtime_error(source + ": vertex " + std::to_string(i + 1) + " has a non-finite coordinate (" +
                               Num(raw.vertices[i].x()) + ", " + Num(raw.vertices[i].y()) + ", " +
                               Num(raw.vertices[i].z()) + ")");
    if (p.cwiseAbs().maxCoeff() > max_coordinate_m)
      throw std::runtime_error(source + ": vertex " + std::to_string(i + 1) + " lies " + Num(p.cwiseAbs().maxCoeff()) +
                               " m from the origin, beyond the " + Num(max_coordinate_m) +
                               " m that a part can plausibly have (wrong unit or a corrupt file?)");
  }

  // Weld: sort used vertices by coordinates, merge equal runs, number them by first use
  std::vector<int> order;
  order.reserve(nv);
  for (int i = 0; i < nv; ++i)
    if (used[i]) order.push_back(i);
  const auto less = [&](int a, int b) {
    const Vec3& p = raw.vertices[a];
    const Vec3& q = raw.vertices[b];
    for (int k = 0; k < 3; ++k)
      if (Key(p[k]) != Key(q[k])) return Key(p[k]) < Key(q[k]);
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> representative(nv, -1);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const bool same = k > 0 && raw.vertices[order[k]].cwiseEqual(raw.vertices[order[k - 1]]).all();
    representative[order[k]] = same ? representative[order[k - 1]] : order[k];
  }
  std::vector<int> welded(nv, -1);
  TriangleMesh& mesh = out.mesh;
  mesh.triangles.resize(raw.triangles.size());
  for (std::size_t t = 0; t < raw.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int r = representative[raw.triangles[t][k]];
      if (welded[r] < 0) {
        welded[r] = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(raw.vertices[r] * metres_per_unit);
      }
      mesh.triangles[t][k] = welded[r];
    }
  out.unused_vertices = nv - static_cast<int>(order.size());
  if (out.triangle_region.size() != mesh.triangles.size()) out.triangle_region.assign(mesh.triangles.size(), 0);
  if (out.region_names.empty()) out.region_names = {""};
  out.face_normals = FaceNormals(mesh);
  return out;
}

SurfaceMesh ReadSurfaceMesh(const std::filesystem::path& path, const SurfaceReadOptions& options) {
  const std::string source = path.string();
  SurfaceMesh head;  // what the reader stage learns (CAD unit, notes)
  const bool cad = DetectMeshFileFormat(path) == MeshFileFormat::kCad;
  if (cad && options.unit)
    throw std::runtime_error(source + ": a STEP/IGES file states its own length unit; do not give one (got " +
                             LengthUnitName(*options.unit) + ")");
  CheckedFileSize(path, options.max_bytes);
  const RawSurface raw = ReadRaw(path, options, head);
  const double scale = cad || !options.unit ? 1.0 : MetresPerUnit(*options.unit);
  SurfaceMesh out = WeldRawSurface(raw, scale, source, options.max_coordinate_m);
  out.notes.insert(out.notes.begin(), head.notes.begin(), head.notes.end());
  if (cad) {
    out.unit = head.unit;
    out.unit_stated = true;
  } else {
    out.unit = options.unit ? LengthUnitName(*options.unit) : "m";
    out.unit_stated = options.unit.has_value();
  }
  // The millimetre warning
  if (!out.unit_stated) {
    Vec3 lo = out.mesh.vertices.front(), hi = lo;
    for (const Vec3& p : out.mesh.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double extent = (hi - lo).maxCoeff();
    if (extent > 10)
      out.warnings.push_back(source + ": read in metres (no unit stated), the mesh is " + Num(extent) +
                             " m across: if its coordinates are millimetres, state the unit (--unit mm, unit: mm)");
  }
  return out;
}

}  // namespace orrery

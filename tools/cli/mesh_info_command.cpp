#include "tools/cli/mesh_info_command.h"

#include <cstdio>
#include <exception>
#include <optional>

#include "import/length_unit.h"
#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/surface_mesh.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {
namespace {

std::string Num(double x, const char* format = "%.6g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

std::string Vector(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v.x(), v.y(), v.z());
  return buf;
}

struct Info {
  SurfaceMesh surface;
  MeshCheckReport report;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  std::optional<MassProperties> mass;  // closed meshes (density 1 without --density)
};

Info Analyse(const MeshInfoArgs& args) {
  Info info;
  SurfaceReadOptions options;
  if (!args.unit.empty()) {
    options.unit = ParseLengthUnit(args.unit);
    if (!options.unit) throw std::runtime_error("--unit " + args.unit + ": expected " + kLengthUnitChoices);
  }
  info.surface = ReadSurfaceMesh(args.path, options);
  info.report = CheckMesh(info.surface.mesh, {.self_intersections = args.self_intersections});
  OrientMesh(info.surface.mesh, info.report);
  info.lo = info.hi = info.surface.mesh.vertices.front();
  for (const Vec3& p : info.surface.mesh.vertices) info.lo = info.lo.cwiseMin(p), info.hi = info.hi.cwiseMax(p);
  const bool closed = info.report.watertight() && info.report.non_orientable_components == 0;
  if (args.density_kg_m3 || closed) {
    // With --density an open mesh is an error; without, volume and centre only when closed
    info.mass = MassPropertiesOfSolid(info.surface.mesh, args.density_kg_m3.value_or(1.0), info.report, args.path);
  }
  return info;
}

void WriteJson(const MeshInfoArgs& args, const Info& info, std::ostream& out) {
  const SurfaceMesh& s = info.surface;
  const MeshCheckReport& r = info.report;
  JsonWriter w(out);
  w.BeginObject().Key("file").String(args.path).Key("format").String(s.format).Key("unit").String(s.unit);
  w.Key("unit_stated").Bool(s.unit_stated);
  w.Key("triangles").Int(r.triangles).Key("vertices").Int(r.vertices);
  w.Key("regions").BeginArray();
  for (const std::string& name : s.region_names) w.String(name);
  w.EndArray();
  w.Key("bounding_box_m").BeginObject().Key("min").BeginArray();
  for (int k = 0; k < 3; ++k) w.Number(info.lo[k]);
  w.EndArray().Key("max").BeginArray();
  for (int k = 0; k < 3; ++k) w.Number(info.hi[k]);
  w.EndArray().EndObject();
  w.Key("watertight").Bool(r.watertight()).Key("boundary_edges").Int(r.boundary_edges);
  w.Key("non_manifold_edges").Int(r.non_manifold_edges).Key("degenerate_triangles").Int(r.degenerate_triangles);
  w.Key("duplicate_triangles").Int(r.duplicate_triangles).Key("components").Int(r.components);
  w.Key("non_orientable_components").Int(r.non_orientable_components);
  w.Key("reoriented_triangles").Int(static_cast<long long>(r.flipped.size()));
  w.Key("self_intersections");
  r.self_intersections < 0 ? w.Null() : w.Int(r.self_intersections);
  const bool with_mass = info.mass && args.density_kg_m3;
  w.Key("volume_m3");
  info.mass ? w.Number(info.mass->volume_m3) : w.Null();
  w.Key("center_of_mass_m");
  if (info.mass) {
    w.BeginArray();
    for (int k = 0; k < 3; ++k) w.Number(info.mass->center_of_mass_m[k]);
    w.EndArray();
  } else {
    w.Null();
  }
  w.Key("density_kg_m3");
  args.density_kg_m3 ? w.Number(*args.density_kg_m3) : w.Null();
  w.Key("mass_kg");
  with_mass ? w.Number(info.mass->mass_kg) : w.Null();
  w.Key("inertia_kg_m2");
  if (with_mass) {
    w.BeginArray();
    for (int i = 0; i < 3; ++i) {
      w.BeginArray();
      for (int j = 0; j < 3; ++j) w.Number(info.mass->inertia_kg_m2(i, j));
      w.EndArray();
    }
    w.EndArray();
  } else {
    w.Null();
  }
  w.Key("principal_moments_kg_m2");
  if (with_mass) {
    w.BeginArray();
    for (int k = 0; k < 3; ++k) w.Number(info.mass->principal_moments_kg_m2[k]);
    w.EndArray();
  } else {
    w.Null();
  }
  w.Key("warnings").BeginArray();
  for (const std::string& x : s.warnings) w.String(x);
  w.EndArray().Key("notes").BeginArray();
  for (const std::string& x : s.notes) w.String(x);
  w.EndArray().EndObject();
}

void WriteText(const MeshInfoArgs& args, const Info& info, std::ostream& out) {
  const SurfaceMesh& s = info.surface;
  const MeshCheckReport& r = info.report;
  out << args.path << ": " << s.format << ", unit " << s.unit << (s.unit_stated ? "" : " (not stated: metres)") << "\n"
      << "triangles " << r.triangles << ", vertices " << r.vertices << " (" << s.file_vertices << " in the file"
      << (s.unused_vertices ? ", " + std::to_string(s.unused_vertices) + " unused" : "") << "), " << r.components
      << " component" << (r.components == 1 ? "" : "s") << ", " << s.region_names.size() << " region"
      << (s.region_names.size() == 1 ? "" : "s") << "\n"
      << "bounding box (m): " << Vector(info.lo) << " to " << Vector(info.hi) << "\n"
      << "watertight: " << (r.watertight() ? "yes" : "no") << "; self-intersections: "
      << (r.self_intersections < 0 ? std::string("not checked") : std::to_string(r.self_intersections)) << "\n";
  for (const std::string& p : r.Problems()) out << "  " << p << "\n";
  if (info.mass) {
    const MassProperties& m = *info.mass;
    out << "volume " << Num(m.volume_m3) << " m^3, centre of mass " << Vector(m.center_of_mass_m) << " m\n";
    if (args.density_kg_m3) {
      out << "density " << Num(*args.density_kg_m3) << " kg/m^3: mass " << Num(m.mass_kg) << " kg\n"
          << "inertia about the centre of mass (kg m^2, mesh axes):\n";
      for (int i = 0; i < 3; ++i)
        out << "  " << Num(m.inertia_kg_m2(i, 0), "%14.6e") << Num(m.inertia_kg_m2(i, 1), "%14.6e")
            << Num(m.inertia_kg_m2(i, 2), "%14.6e") << "\n";
      out << "principal moments (kg m^2): " << Vector(m.principal_moments_kg_m2) << "\n";
    }
  } else {
    out << "no volume: the mesh is not closed\n";
  }
  for (const std::string& x : s.warnings) out << "warning: " << x << "\n";
  for (const std::string& x : s.notes) out << "note: " << x << "\n";
}

}  // namespace

int MeshInfoCommand(const MeshInfoArgs& args, std::ostream& out, std::ostream& err) {
  Info info;
  try {
    info = Analyse(args);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  if (args.json) {
    WriteJson(args, info, out);
  } else {
    WriteText(args, info, out);
  }
  // Warnings also on the error stream when the output is JSON (so a script sees them)
  if (args.json)
    for (const std::string& x : info.surface.warnings) err << "orrery: warning: " << x << "\n";
  return kExitSuccess;
}

}  // namespace orrery::cli

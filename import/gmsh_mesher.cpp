#include "import/gmsh_mesher.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "import/bounded_file.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

std::optional<fs::path> FindOnPath(const std::string& program) {
  const char* path_env = std::getenv("PATH");
  if (!path_env) return std::nullopt;
  std::stringstream dirs(path_env);
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / program;
    std::error_code ec;
    const fs::file_status s = fs::status(candidate, ec);
    if (!ec && fs::is_regular_file(s) && (s.permissions() & fs::perms::others_exec) != fs::perms::none)
      return candidate;
  }
  return std::nullopt;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string Num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// A scratch directory removed with its content when it goes out of scope.
class ScratchDir {
 public:
  ScratchDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("orrery_gmsh_" + std::to_string(::getpid()) + "_" + std::to_string(counter.fetch_add(1)));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// The last `lines` lines of a log file, joined with " | ".
std::string LogTail(const fs::path& log, int lines) {
  std::ifstream in(log);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) all.push_back(line);
  std::string tail;
  for (std::size_t i = all.size() > static_cast<std::size_t>(lines) ? all.size() - lines : 0; i < all.size(); ++i) {
    if (!tail.empty()) tail += " | ";
    tail += all[i].substr(0, 200);
  }
  return tail.empty() ? "(no output)" : tail;
}

// A quoted path for a .geo string (gmsh strings take no escapes for backslash-free paths).
std::string GeoString(const fs::path& p) {
  const std::string s = fs::absolute(p).string();
  if (s.find('"') != std::string::npos) throw std::runtime_error(s + ": a path with a double quote cannot be passed to gmsh");
  return "\"" + s + "\"";
}

std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Mesh size and order options of a script.
std::string SizeOptions(const GmshMeshOptions& o, int order) {
  std::string s = "General.NumThreads = 1;\nMesh.ElementOrder = " + std::to_string(order) + ";\n";
  if (o.max_size_m > 0) s += "Mesh.MeshSizeMax = " + Num(o.max_size_m) + ";\n";
  if (o.min_size_m > 0) s += "Mesh.MeshSizeMin = " + Num(o.min_size_m) + ";\n";
  if (o.curvature_elements > 0) s += "Mesh.MeshSizeFromCurvature = " + std::to_string(o.curvature_elements) + ";\n";
  s += "Mesh.Optimize = 1;\nMesh.MshFileVersion = 4.1;\nMesh.Binary = 1;\n";
  return s;
}

// Runs `gmsh script -` in `dir` (batch: parse, run, exit). Throws with the log's tail.
void RunScript(const fs::path& gmsh, const fs::path& dir, const std::string& script, const std::string& what,
               double timeout_s) {
  {
    std::ofstream out(dir / "orrery.geo");
    out << script;
    if (!out) throw std::runtime_error("cannot write the gmsh script in " + dir.string());
  }
  std::string command = "cd " + ShellQuote(dir.string()) + " && ";
  if (const auto timeout = FindOnPath("timeout"))
    command += ShellQuote(timeout->string()) + " -k 5 " + std::to_string(static_cast<long>(timeout_s) + 1) + " ";
  command += ShellQuote(gmsh.string()) + " orrery.geo - -nopopup > gmsh.log 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0)
    throw std::runtime_error("gmsh failed on " + what + " (status " + std::to_string(status) +
                             (WIFEXITED(status) && WEXITSTATUS(status) == 124 ? ", timed out" : "") +
                             "): " + LogTail(dir / "gmsh.log", 3));
  if (!fs::exists(dir / "mesh.msh"))
    throw std::runtime_error("gmsh wrote no mesh for " + what + ": " + LogTail(dir / "gmsh.log", 3));
}

int ReadCount(const fs::path& file) {
  std::ifstream in(file);
  double n = -1;
  if (!(in >> n)) throw std::runtime_error("gmsh did not report the number of volumes (" + file.string() + ")");
  return static_cast<int>(n);
}

// Meshes a CAD file to `dim` (2 or 3).
GmshMeshing MeshCad(const fs::path& cad, const GmshMeshOptions& o, int dim) {
  CheckedFileSize(cad);
  if (!IsCadFile(cad)) throw std::runtime_error(cad.string() + ": not a STEP or IGES file (.step, .stp, .iges, .igs)");
  const fs::path gmsh = RequireGmsh();
  ScratchDir dir;
  const int order = dim == 3 ? o.order : 1;
  std::string script = "Geometry.OCCTargetUnit = \"M\";\nMerge " + GeoString(cad) + ";\n";
  script += "orrery_v[] = Volume{:};\nPrintf(\"%g\", #orrery_v[]) > " + GeoString(dir.path() / "volumes.txt") + ";\n";
  script += "orrery_s[] = Surface{:};\nFor orrery_i In {0 : #orrery_s[] - 1}\n"
            "  Physical Surface(Sprintf(\"FACE%g\", orrery_s[orrery_i])) = {orrery_s[orrery_i]};\nEndFor\n";
  script += "If (#orrery_v[] > 0)\n  Physical Volume(\"SOLID\") = {orrery_v[]};\nEndIf\n";
  script += SizeOptions(o, order);
  // tet10: straight sides (always valid when the tet4 is), or curved onto the geometry with the
  // high-order elements untangled and optimized (elastic analogy + optimization)
  if (dim == 3 && order == 2)
    script += o.curved ? "Mesh.HighOrderOptimize = 2;\n" : "Mesh.SecondOrderLinear = 1;\n";
  script += "Mesh " + std::to_string(dim) + ";\nSave " + GeoString(dir.path() / "mesh.msh") + ";\n";
  RunScript(gmsh, dir.path(), script, cad.string(), o.timeout_s);

  GmshMeshing m;
  m.solids = ReadCount(dir.path() / "volumes.txt");
  if (m.solids == 0) throw std::runtime_error(cad.string() + ": no solid (the file holds surfaces only?)");
  if (o.one_solid && m.solids > 1)
    throw std::runtime_error(cad.string() + ": " + std::to_string(m.solids) + " solids; one is expected");
  m.mesh = ReadGmshMsh(dir.path() / "mesh.msh");
  m.file_unit = ReadCadLengthUnit(cad);
  std::string what = dim == 2 ? "triangles" : order == 2 ? (o.curved ? "curved tet10" : "tet10") : "tet4";
  m.description = "gmsh " + GmshVersion(gmsh) + ": " + what +
                  (o.max_size_m > 0 ? ", max size " + Num(o.max_size_m) + " m" : "") +
                  (o.curvature_elements > 0 ? ", " + std::to_string(o.curvature_elements) + " per 2 pi" : "") +
                  " from " + cad.string() + " (file unit " + m.file_unit + ")";
  return m;
}

// A triangle surface as a gmsh 2.2 ASCII mesh with 17 significant digits (an STL would round the
// coordinates to float).
void WriteSurfaceMsh(const TriangleMesh& mesh, const fs::path& path) {
  std::ofstream out(path);
  out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << mesh.vertices.size() << "\n";
  char buf[96];
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& p = mesh.vertices[i];
    std::snprintf(buf, sizeof buf, "%zu %.17g %.17g %.17g\n", i + 1, p.x(), p.y(), p.z());
    out << buf;
  }
  out << "$EndNodes\n$Elements\n" << mesh.triangles.size() << "\n";
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    out << t + 1 << " 2 2 0 1 " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
  }
  out << "$EndElements\n";
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

}  // namespace

std::optional<fs::path> FindGmsh() { return FindOnPath("gmsh"); }

fs::path RequireGmsh() {
  if (auto gmsh = FindGmsh()) return *gmsh;
  throw std::runtime_error(
      "gmsh not found on PATH: install Debian's package gmsh (apt-get install gmsh) to read STEP/IGES files and to "
      "tetrahedralize surface meshes");
}

std::string GmshVersion(const fs::path& gmsh) {
  static std::string cached_for, cached;
  if (cached_for == gmsh.string()) return cached;
  ScratchDir dir;
  const std::string command = ShellQuote(gmsh.string()) + " -version > " + ShellQuote((dir.path() / "v").string()) + " 2>&1";
  if (std::system(command.c_str()) != 0) throw std::runtime_error(gmsh.string() + " -version failed");
  std::ifstream in(dir.path() / "v");
  std::string version;
  std::getline(in, version);
  while (!version.empty() && std::isspace(static_cast<unsigned char>(version.back()))) version.pop_back();
  cached_for = gmsh.string();
  cached = version;
  return version;
}

bool IsCadFile(const fs::path& path) {
  const std::string e = Lower(path.extension().string());
  return e == ".step" || e == ".stp" || e == ".iges" || e == ".igs";
}

std::string ReadCadLengthUnit(const fs::path& cad) {
  const std::string e = Lower(cad.extension().string());
  if (e != ".step" && e != ".stp") return "?";
  const std::string text = ReadFileBounded(cad);
  // The entity (up to ';') that holds LENGTH_UNIT
  for (std::size_t at = text.find("LENGTH_UNIT"); at != std::string::npos; at = text.find("LENGTH_UNIT", at + 1)) {
    const std::size_t begin = text.rfind(';', at), end = text.find(';', at);
    const std::string entity = text.substr(begin == std::string::npos ? 0 : begin + 1,
                                           (end == std::string::npos ? text.size() : end) - (begin == std::string::npos ? 0 : begin + 1));
    if (const std::size_t si = entity.find("SI_UNIT("); si != std::string::npos) {
      const std::string args = entity.substr(si + 8, entity.find(')', si) - si - 8);
      if (args.find(".METRE.") == std::string::npos) continue;
      if (args.find(".MILLI.") != std::string::npos) return "mm";
      if (args.find(".CENTI.") != std::string::npos) return "cm";
      if (args.find(".MICRO.") != std::string::npos) return "um";
      if (args.find(".KILO.") != std::string::npos) return "km";
      return "m";
    }
    if (const std::size_t cb = entity.find("CONVERSION_BASED_UNIT("); cb != std::string::npos) {
      const std::string name = Lower(entity.substr(cb + 22, 12));
      if (name.find("inch") != std::string::npos) return "in";
      if (name.find("foot") != std::string::npos || name.find("feet") != std::string::npos) return "ft";
      return "?";
    }
  }
  return "?";
}

GmshMeshing MeshCadSurface(const fs::path& cad, const GmshMeshOptions& options) { return MeshCad(cad, options, 2); }

GmshMeshing MeshCadVolume(const fs::path& cad, const GmshMeshOptions& options) { return MeshCad(cad, options, 3); }

GmshMeshing MeshSurfaceVolume(const TriangleMesh& surface_m, const std::string& source, const GmshMeshOptions& o) {
  const fs::path gmsh = RequireGmsh();
  ScratchDir dir;
  WriteSurfaceMsh(surface_m, dir.path() / "surface.msh");
  std::string script = "Merge " + GeoString(dir.path() / "surface.msh") + ";\n";
  if (o.remesh_surface) {
    script += "ClassifySurfaces{" + Num(o.feature_angle_deg) + " * Pi / 180, 1, 1, Pi};\nCreateGeometry;\n";
  }
  script += "Surface Loop(1) = Surface{:};\nVolume(1) = {1};\nPhysical Volume(\"SOLID\") = {1};\n";
  script += SizeOptions(o, o.order);
  // The surface is flat facets: midside nodes at the straight midpoints (curving them towards a
  // reparametrization of the facets would only invert elements)
  script += "Mesh.SecondOrderLinear = 1;\n";
  script += "Mesh 3;\nSave " + GeoString(dir.path() / "mesh.msh") + ";\n";
  RunScript(gmsh, dir.path(), script, source, o.timeout_s);
  GmshMeshing m;
  m.solids = 1;
  m.mesh = ReadGmshMsh(dir.path() / "mesh.msh");
  m.description = "gmsh " + GmshVersion(gmsh) + ": " + (o.order == 2 ? "tet10" : "tet4") +
                  (o.max_size_m > 0 ? ", max size " + Num(o.max_size_m) + " m" : "") +
                  (o.remesh_surface ? ", surface remeshed (feature angle " + Num(o.feature_angle_deg) + " deg)"
                                    : ", surface triangles kept") +
                  " from " + source;
  return m;
}

}  // namespace orrery

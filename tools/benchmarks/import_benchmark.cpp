// Mesh import benchmarks (issue 14; Google Benchmark, Release build):
//   ImportStl1M      a closed torus of 1,000,000 triangles as a binary STL (50 MB): read and weld
//                    (ReadSurfaceMesh), check (CheckMesh, self-intersections included), orient,
//                    mass properties; and the same without the self-intersection search.
//   StepPlanet       seed 001's planet (18 teeth, m_n 1.5 mm, alpha_n 21.3 deg, b = 30 mm, 7 mm
//                    bore radius) as a STEP solid (written by gmsh from OpenCASCADE splines
//                    through the exact profile, one per profile segment), end to end: tet10 mesh
//                    by gmsh (max size 2 mm), assembly, Craig-Bampton reduction with the bore as
//                    an RBE2 interface and 20 modes, the engine's modes (stress modes and geometric
//                    stiffness), the reduced-body file.
// Each reports the CPU time per stage (the stages run on one thread; the benchmark's own Time
// column is wall time, which on a loaded machine includes waiting for a core) and the peak
// resident memory of the run (VmHWM, reset before each iteration by writing 5 to
// /proc/self/clear_refs). gmsh runs as another process: its CPU time is not in mesh_cpu_s but in
// gmsh_cpu_s (getrusage of the finished children; their ru_maxrss would count the pages a child
// shares with this process at fork, so gmsh's memory is not reported).
//
//   import_benchmark                                  both (skips StepPlanet without gmsh)
//   import_benchmark --benchmark_filter=ImportStl1M
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "flex/reduced_body_file.h"
#include "import/gmsh_mesher.h"
#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/part_reduction.h"
#include "import/reduce_input.h"
#include "import/surface_mesh.h"
#include "import/volume_mesh.h"
#include "models/gear_geometry.h"
#include "models/stl.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

void ResetPeakRss() { std::ofstream("/proc/self/clear_refs") << "5"; }

double PeakRssMb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024;
  return 0;
}

// CPU time of the process (s): the stages are single-threaded, and on a shared machine the wall
// time also counts the waits for a core.
double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// CPU time (s) of the finished child processes (gmsh).
double ChildCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

fs::path ScratchDir() {
  const fs::path dir = fs::temp_directory_path() / ("orrery_import_benchmark_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// A torus of n_u x n_v x 2 triangles, outward.
TriangleMesh Torus(double R, double r, int n_u, int n_v) {
  TriangleMesh m;
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) {
      const double u = 2 * std::numbers::pi * i / n_u, v = 2 * std::numbers::pi * j / n_v;
      m.vertices.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  const auto at = [&](int i, int j) { return (i % n_u) * n_v + (j % n_v); };
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

void ImportStl1M(benchmark::State& state) {
  const bool self_intersections = state.range(0) != 0;
  const fs::path dir = ScratchDir();
  const fs::path stl = dir / "torus.stl";
  gears::WriteStlBinary(Torus(0.1, 0.03, 1000, 500), stl.string());
  double read_s = 0, check_s = 0, mass_s = 0, peak = 0;
  for (auto _ : state) {
    ResetPeakRss();
    double t = CpuSeconds();
    SurfaceMesh s = ReadSurfaceMesh(stl);
    read_s = CpuSeconds() - t;
    t = CpuSeconds();
    const MeshCheckReport r = CheckMesh(s.mesh, {.self_intersections = self_intersections});
    OrientMesh(s.mesh, r);
    check_s = CpuSeconds() - t;
    t = CpuSeconds();
    const MassProperties p = MassPropertiesOfSolid(s.mesh, 7850, r, stl.string());
    mass_s = CpuSeconds() - t;
    benchmark::DoNotOptimize(p.mass_kg);
    peak = PeakRssMb();
    if (r.triangles != 1000000 || !r.watertight()) state.SkipWithError("unexpected mesh");
  }
  state.counters["read_cpu_s"] = read_s;
  state.counters["check_cpu_s"] = check_s;
  state.counters["mass_cpu_s"] = mass_s;
  state.counters["peak_rss_mb"] = peak;
  state.counters["file_mb"] = static_cast<double>(fs::file_size(stl)) / (1 << 20);
  fs::remove_all(dir);
}
BENCHMARK(ImportStl1M)->Arg(1)->Arg(0)->Unit(benchmark::kSecond)->Iterations(1);

// A STEP of the planet: gmsh writes OpenCASCADE splines through the exact profile (one per
// profile segment of each tooth), the bore circle, extruded over the face width (millimetres).
fs::path WritePlanetStep(const fs::path& dir, const gears::Gear& gear, double bore_m) {
  std::ofstream geo(dir / "planet.geo");
  geo << "SetFactory(\"OpenCASCADE\");\n";
  const std::vector<gears::ProfilePoint> outline = gear.SampleGearOutline({.root = 4, .fillet = 8, .involute = 16, .tip = 4});
  const int n = static_cast<int>(outline.size());
  for (int i = 0; i < n; ++i) geo << "Point(" << i + 1 << ") = {" << outline[i].p.x() * 1e3 << ", " << outline[i].p.y() * 1e3 << ", 0};\n";
  // Runs of points of one segment, each a spline from its first point to the next run's first
  std::vector<int> curves;
  for (int i = 0; i < n;) {
    int j = i + 1;
    while (j < n && outline[j].segment == outline[i].segment && outline[j].s > outline[j - 1].s) ++j;
    const int id = static_cast<int>(curves.size()) + 1;
    geo << (j - i == 1 ? "Line(" : "Spline(") << id << ") = {";
    for (int k = i; k <= j; ++k) geo << (k == i ? "" : ", ") << (k % n) + 1;
    geo << "};\n";
    curves.push_back(id);
    i = j;
  }
  geo << "Curve Loop(1) = {";
  for (std::size_t c = 0; c < curves.size(); ++c) geo << (c ? ", " : "") << curves[c];
  geo << "};\nCircle(" << curves.size() + 1 << ") = {0, 0, 0, " << bore_m * 1e3 << "};\nCurve Loop(2) = {" << curves.size() + 1
      << "};\nPlane Surface(1) = {1, 2};\nExtrude {0, 0, " << gear.spec().face_width_m * 1e3 << "} { Surface{1}; }\n";
  geo.close();
  const std::string command = "cd '" + dir.string() + "' && gmsh planet.geo -0 -o planet.step -format step > gmsh.log 2>&1";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("gmsh could not write the planet STEP: " + command);
  return dir / "planet.step";
}

void StepPlanet(benchmark::State& state) {
  if (!FindGmsh()) {
    state.SkipWithError("gmsh not found (Debian package gmsh)");
    return;
  }
  const gears::Gear planet({.teeth = 18, .normal_module_m = 1.5e-3,
                            .normal_pressure_angle_rad = 21.3 * std::numbers::pi / 180, .face_width_m = 0.03});
  const fs::path dir = ScratchDir();
  const fs::path step = WritePlanetStep(dir, planet, 7e-3);
  const double size_m = state.range(0) * 1e-4;
  double mesh_s = 0, mesh_wall_s = 0, gmsh_s = 0, reduce_s = 0, write_s = 0, peak = 0;
  long dofs = 0;
  for (auto _ : state) {
    ResetPeakRss();
    const auto wall = Clock::now();
    double t = CpuSeconds();
    const double children = ChildCpuSeconds();
    PartReduction job = PreparePartReduction(
        {.input = step.string(),
         .material = flex::IsotropicMaterial{.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3,
                                             .density_kg_m3 = 7850},
         .interfaces = {"bore"},
         .modes = 20,
         .meshing = {.max_size_m = size_m}});
    mesh_s = CpuSeconds() - t;
    gmsh_s = ChildCpuSeconds() - children;
    mesh_wall_s = std::chrono::duration<double>(Clock::now() - wall).count();
    t = CpuSeconds();
    Reduction r = ReduceBody(job.mesh, job.interfaces, job.cb_options, job.outputs, job.source);
    reduce_s = CpuSeconds() - t;
    dofs = r.system.K.rows();
    t = CpuSeconds();
    flex::WriteReducedBody((dir / "planet.h5").string(), r.body);
    write_s = CpuSeconds() - t;
    peak = PeakRssMb();
    state.counters["first_hz"] = r.cb.frequencies_hz.at(6);
  }
  state.counters["dofs"] = static_cast<double>(dofs);
  state.counters["mesh_cpu_s"] = mesh_s;       // reading the gmsh output and the interface
  state.counters["mesh_wall_s"] = mesh_wall_s;  // gmsh included
  state.counters["gmsh_cpu_s"] = gmsh_s;
  state.counters["reduce_cpu_s"] = reduce_s;    // assembly, Craig-Bampton, engine modes
  state.counters["write_cpu_s"] = write_s;
  state.counters["peak_rss_mb"] = peak;
  fs::remove_all(dir);
}
// Max element size in 0.1 mm: 2 mm
BENCHMARK(StepPlanet)->Arg(20)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

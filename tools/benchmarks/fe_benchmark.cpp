// The FE rows of issue 15, measured in one run (a runner, not Google Benchmark: each case is one
// long job whose peak memory must be its own, so each runs in a child process and is measured
// by wait4's rusage):
//   (1) `orrery fe-modes` against CalculiX `ccx` on the same mesh: a clamped hex20 block of 10 mm
//       steel bricks, by default 66 x 10 x 10 of them (a 0.66 x 0.1 x 0.1 m cantilever, 30,833
//       nodes, 92,499 DOF, face XMIN held: 91,476 free DOF; --divisions=19,19,19 gives a cube of
//       92,400 DOF, whose factor fills in more), 30 modes. The mesh is written once as an .inp with a
//       *FREQUENCY step; `orrery
//       fe-modes block.inp --fix XMIN --modes 30` and `ccx -i block` then run on that file, one
//       after the other, both single-threaded (OMP_NUM_THREADS=1; the serial OpenBLAS that
//       tools/install_deps.sh installs). Printed: wall time, CPU time (user + system) and peak
//       resident set of each, the ratios, and the largest relative difference of the frequencies
//       (ccx prints 7 significant digits: agreement to ~1e-6 expected).
//   (2) The Craig-Bampton reduction of seed 001's planet at 100k DOF (flex_benchmark's "100k"
//       mesh: hex20, 101,952 DOF, bore as one RBE2 interface), 30 fixed-interface modes, followed
//       by MakeFlexibleBodyModes with stress modes and the six geometric stiffness matrices (what
//       `orrery reduce` writes), in a forked child: wall time per stage and peak resident set.
//
//   fe_benchmark [--only=fe|cb] [--divisions=NX,NY,NZ] [--modes=30] [--work-dir=DIR] [--orrery=PATH]
//                [--keep] [--dump=FILE]
// --dump writes the reduced planet's frequencies, K, M and geometric stiffness matrices (17 digits)
// for a before/after comparison; --keep keeps the work directory (block.inp, the logs, block.dat).
// CPU time is the better measure on a loaded machine (wall time includes waiting for a core);
// both are printed. Without ccx on PATH the comparison is skipped with a message naming the
// Debian package (calculix-ccx).
#include <dlfcn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "flex/box_mesher.h"
#include "flex/calculix.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_modes.h"
#include "flex/flexible_body_modes.h"
#include "flex/inp_file.h"
#include "models/gear_fe_mesh.h"
#include "models/gear_geometry.h"

namespace orrery {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// What a finished child cost.
struct ChildCost {
  int status = -1;      // exit code, or -1 if it did not exit normally
  double wall_s = 0;
  double cpu_s = 0;     // user + system
  double peak_mib = 0;  // ru_maxrss
};

ChildCost Wait(pid_t pid, Clock::time_point start) {
  int status = 0;
  rusage u{};
  if (wait4(pid, &status, 0, &u) < 0) throw std::runtime_error(std::string("wait4: ") + std::strerror(errno));
  ChildCost c;
  c.wall_s = Seconds(start, Clock::now());
  c.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  c.cpu_s = double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  c.peak_mib = double(u.ru_maxrss) / 1024.0;
  return c;
}

// Runs argv in `dir` with stdout and stderr to `log`, one thread for OpenMP and OpenBLAS.
ChildCost Run(const std::vector<std::string>& argv, const std::filesystem::path& dir, const std::filesystem::path& log) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const Clock::time_point start = Clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(126);
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) _exit(126);
    dup2(fd, 1);
    dup2(fd, 2);
    setenv("OMP_NUM_THREADS", "1", 1);
    setenv("OPENBLAS_NUM_THREADS", "1", 1);
    execv(args[0], args.data());
    _exit(127);
  }
  return Wait(pid, start);
}

std::string ReadText(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Frequencies (Hz) from `orrery fe-modes`' table ("mode  frequency (Hz)" then "   1   123.456").
std::vector<double> ParseFeModesTable(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::vector<double> f;
  bool table = false;
  while (std::getline(in, line)) {
    if (!table) {
      table = line.find("frequency (Hz)") != std::string::npos;
      continue;
    }
    std::istringstream row(line);
    int mode = 0;
    double hz = 0;
    if (row >> mode >> hz) f.push_back(hz);
  }
  return f;
}

void PrintCost(const char* name, const ChildCost& c) {
  std::printf("  %-22s wall %8.2f s   cpu %8.2f s   peak %8.1f MiB   exit %d\n", name, c.wall_s, c.cpu_s, c.peak_mib,
              c.status);
  std::fflush(stdout);
}

// The OpenBLAS kernel set this process (and so its children, same library and environment) runs:
// OpenBLAS falls back to generic kernels on a CPU model it does not know (docs/performance.md).
void PrintBlasCore() {
  using CoreName = char* (*)();
  const auto name = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  const char* env = std::getenv("OPENBLAS_CORETYPE");
  std::printf("BLAS: %s%s%s\n", name ? "OpenBLAS, kernels " : "not OpenBLAS (no openblas_get_corename)",
              name ? name() : "", env ? (std::string(" (OPENBLAS_CORETYPE=") + env + ")").c_str() : "");
}

// ---- (1) fe-modes against ccx ------------------------------------------------------------

int FeModesAgainstCcx(const std::array<int, 3>& divisions, int modes, const std::filesystem::path& work,
                      const std::filesystem::path& orrery) {
  const Eigen::Vector3d size_m = 0.01 * Eigen::Vector3d(divisions[0], divisions[1], divisions[2]);
  flex::FeMesh mesh = flex::MakeBoxMesh({.size_m = size_m, .divisions = divisions, .type = flex::ElementType::kHex20});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
  const int ndof = 3 * mesh.num_nodes();
  const int nfree = ndof - 3 * static_cast<int>(mesh.NodeSet("XMIN").size());
  std::filesystem::create_directories(work);
  flex::WriteInpFile(work / "block.inp", mesh,
                     {.heading = "fe_benchmark block", .fixed_node_sets = {"XMIN"}, .num_frequencies = modes});
  std::printf("FE modes: hex20 block of %d x %d x %d bricks, %d nodes, %d DOF (%d free, face XMIN held), %d modes\n",
              divisions[0], divisions[1], divisions[2], mesh.num_nodes(), ndof, nfree, modes);
  std::fflush(stdout);
  mesh = flex::FeMesh();  // the children's memory is measured, keep the parent small

  const ChildCost o = Run({orrery.string(), "fe-modes", "block.inp", "--fix", "XMIN", "--modes", std::to_string(modes)},
                          work, work / "orrery.log");
  PrintCost("orrery fe-modes", o);
  const std::vector<double> f_orrery = ParseFeModesTable(ReadText(work / "orrery.log"));
  if (o.status != 0 || static_cast<int>(f_orrery.size()) != modes) {
    std::printf("  orrery fe-modes failed:\n%s\n", ReadText(work / "orrery.log").c_str());
    return 1;
  }
  const std::optional<std::filesystem::path> ccx = flex::FindCalculix();
  if (!ccx) {
    std::printf("  ccx: not found on PATH (Debian package calculix-ccx): comparison skipped\n");
    std::printf("  f1 %.6f Hz, f%d %.6f Hz\n", f_orrery.front(), modes, f_orrery.back());
    return 0;
  }
  std::filesystem::remove(work / "block.dat");
  const ChildCost c = Run({ccx->string(), "-i", "block"}, work, work / "ccx.log");
  PrintCost("ccx", c);
  if (c.status != 0) {
    std::printf("  ccx failed:\n%s\n", ReadText(work / "ccx.log").c_str());
    return 1;
  }
  const std::vector<double> w2 = flex::ReadCalculixEigenvalues(work / "block.dat");
  double worst = 0;
  for (int i = 0; i < modes && i < static_cast<int>(w2.size()); ++i)
    worst = std::max(worst, std::abs(f_orrery[i] / flex::EigenvalueToHz(w2[i]) - 1));
  std::printf("  f1 %.6f Hz, f%d %.6f Hz; largest relative difference to ccx %.2g over %zu modes\n", f_orrery.front(),
              modes, f_orrery.back(), worst, std::min<std::size_t>(modes, w2.size()));
  std::printf("  ccx / orrery: wall %.2fx, cpu %.2fx; peak memory orrery / ccx %.2f\n", c.wall_s / o.wall_s,
              c.cpu_s / o.cpu_s, o.peak_mib / c.peak_mib);
  return 0;
}

// ---- (2) Craig-Bampton reduction of the 100k-DOF planet --------------------------------------

// flex_benchmark's "100k" planet: seed 001's planet, hex20.
flex::FeMesh Planet100k() {
  const gears::Gear planet({.teeth = 18, .normal_module_m = 1.5e-3,
                            .normal_pressure_angle_rad = 21.3 * std::numbers::pi / 180, .face_width_m = 0.03});
  return gears::MakeGearFeMesh(planet, {.bore_radius_m = 7e-3, .type = flex::ElementType::kHex20, .flank_divisions = 5,
                                        .fillet_divisions = 3, .tooth_divisions = 4, .root_layer_divisions = 2,
                                        .rim_divisions = 3, .face_divisions = 7});
}

// CPU time of this process so far (user + system, all threads), s.
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The reduced body's numbers for a before/after comparison, full precision: frequencies, then
// K, M and the six geometric stiffness matrices row by row.
void DumpReduction(const flex::CraigBamptonModel& cb, const FlexibleBodyModes& body, const std::filesystem::path& file) {
  std::ofstream f(file);
  f.precision(17);
  f << "frequencies_hz";
  for (double hz : cb.frequencies_hz) f << ' ' << hz;
  f << '\n';
  auto matrix = [&](const char* name, const Eigen::MatrixXd& A) {
    f << name << ' ' << A.rows() << ' ' << A.cols();
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      for (Eigen::Index j = 0; j < A.cols(); ++j) f << ' ' << A(i, j);
    f << '\n';
  };
  matrix("K", cb.K);
  matrix("M", cb.M);
  for (const Eigen::MatrixXd& g : body.geometric_stiffness) matrix("G", g);
}

// In the child: the stages, one line each, to `out` (wall and CPU time of each).
void ReducePlanet(int modes, std::FILE* out, const std::filesystem::path& dump) {
  Clock::time_point t = Clock::now();
  double c = ProcessCpuSeconds();
  const flex::FeMesh mesh = Planet100k();
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const double t_setup = Seconds(t, Clock::now()), c_setup = ProcessCpuSeconds() - c;
  const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
  t = Clock::now();
  c = ProcessCpuSeconds();
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = modes});
  const double t_cb = Seconds(t, Clock::now()), c_cb = ProcessCpuSeconds() - c;
  t = Clock::now();
  c = ProcessCpuSeconds();
  const FlexibleBodyModes body =
      flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs, {.stress_modes = true, .geometric_stiffness = true});
  const double t_body = Seconds(t, Clock::now()), c_body = ProcessCpuSeconds() - c;
  double g_norm = 0;
  for (const Eigen::MatrixXd& g : body.geometric_stiffness) g_norm += g.squaredNorm();
  std::fprintf(out, "  %d nodes, %d DOF; first elastic %.6f Hz, last %.6f Hz; |G| %.9g\n", mesh.num_nodes(),
               3 * mesh.num_nodes(), cb.frequencies_hz[cb.num_rigid], cb.frequencies_hz.back(), std::sqrt(g_norm));
  std::fprintf(out, "  mesh + assembly      wall %7.2f s  cpu %7.2f s\n", t_setup, c_setup);
  std::fprintf(
      out, "  ReduceCraigBampton   wall %7.2f s  cpu %7.2f s  (%d Lanczos operator applications)\n",
      t_cb, c_cb, cb.lanczos_operations);
  std::fprintf(out, "  MakeFlexibleBodyModes (stress modes, geometric stiffness) wall %7.2f s  cpu %7.2f s\n", t_body,
               c_body);
  if (!dump.empty()) DumpReduction(cb, body, dump);
}

int CraigBamptonPlanet(int modes, const std::filesystem::path& dump) {
  std::printf("Craig-Bampton: seed 001 planet, hex20 100k DOF, bore RBE2, %d modes\n", modes);
  std::fflush(stdout);
  const Clock::time_point start = Clock::now();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    try {
      ReducePlanet(modes, stdout, dump);
    } catch (const std::exception& e) {
      std::fprintf(stdout, "  failed: %s\n", e.what());
      std::fflush(stdout);
      _exit(1);
    }
    std::fflush(stdout);
    _exit(0);
  }
  const ChildCost c = Wait(pid, start);
  PrintCost("reduction (all stages)", c);
  return c.status == 0 ? 0 : 1;
}

}  // namespace
}  // namespace orrery

int main(int argc, char** argv) {
  std::string only;
  std::array<int, 3> divisions{66, 10, 10};
  int modes = 30;
  bool keep = false;
  std::filesystem::path dump;  // --dump=FILE: the reduction's matrices (DumpReduction)
  std::filesystem::path work = std::filesystem::temp_directory_path() / ("orrery_fe_benchmark_" + std::to_string(getpid()));
  std::filesystem::path orrery = std::filesystem::read_symlink("/proc/self/exe").parent_path() / "orrery";
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a.starts_with("--only=")) only = a.substr(7);
    else if (a.starts_with("--divisions=")) {
      if (std::sscanf(argv[i] + 12, "%d,%d,%d", &divisions[0], &divisions[1], &divisions[2]) != 3) divisions[0] = 0;
    }
    else if (a.starts_with("--modes=")) modes = std::atoi(argv[i] + 8);
    else if (a.starts_with("--work-dir=")) work = a.substr(11);
    else if (a.starts_with("--orrery=")) orrery = a.substr(9);
    else if (a == "--keep") keep = true;
    else if (a.starts_with("--dump=")) dump = a.substr(7);
    else {
      std::fprintf(stderr, "fe_benchmark: unknown argument '%s' (see the top of fe_benchmark.cpp)\n", argv[i]);
      return 2;
    }
  }
  if (!only.empty() && only != "fe" && only != "cb") {
    std::fprintf(stderr, "fe_benchmark: --only takes fe or cb, got '%s'\n", only.c_str());
    return 2;
  }
  if (*std::min_element(divisions.begin(), divisions.end()) < 1 || modes < 1) {
    std::fprintf(stderr, "fe_benchmark: --divisions takes NX,NY,NZ >= 1 and --modes N >= 1\n");
    return 2;
  }
  orrery::PrintBlasCore();
  int rc = 0;
  try {
    if (only.empty() || only == "fe") rc |= orrery::FeModesAgainstCcx(divisions, modes, work, orrery);
    if (only.empty() || only == "cb") rc |= orrery::CraigBamptonPlanet(modes, dump);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fe_benchmark: %s\n", e.what());
    rc = 1;
  }
  if (!keep) std::filesystem::remove_all(work);
  return rc;
}

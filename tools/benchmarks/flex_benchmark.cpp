// Flexible-body benchmarks (issue 4; Google Benchmark, Release build):
//   (a) Craig-Bampton reduction of seed 001's planet (18 teeth, m_n 1.5 mm, alpha_n 21.3 deg,
//       b = 30 mm, spur, 7 mm bore radius, steel; hex20) with the bore as one RBE2 interface, 30
//       fixed-interface modes, by stage: MakeGearFeMesh, AssembleFeSystem, ReduceCraigBampton,
//       MakeFlexibleBodyModes. Mesh sizes (kPlanetSizes): ~10k, ~100k and ~300k DOF.
//   (b) the multibody hot path with one flexible body: the reduced planet on a revolute joint
//       (spinning at 100 rad/s, modes deflected and moving, gravity, 1 % modal damping), cost of
//       EvaluateDynamics, DaeSystem::Residual and DaeSystem::Jacobian vs the number of modes
//       nf = 5, 10, 20, 50, 100. The modes come from one reduction of the 10k-DOF planet to 100
//       modes, truncated to the first nf (the elastic Craig-Bampton coordinates are M-orthonormal
//       and sorted by frequency, so the first nf of them are a consistent smaller body).
//
//   flex_benchmark                                   all (the 100k reduction: 1-2 minutes)
//   flex_benchmark --benchmark_filter='Flex(Eval|Residual|Jacobian)'
//
// Peak memory is a process-wide maximum (getrusage's ru_maxrss, /proc/self/status VmHWM), so
// one process can only tell it for one mesh size. Probe mode reduces one size in a fresh process
// and prints JSON (stage wall times, VmHWM after each stage, the BLAS library actually loaded):
//   flex_benchmark --probe=10k|100k|300k [--modes=30] [--outputs=full]
// --outputs=full adds stress modes and the six geometric-stiffness matrices to
// MakeFlexibleBodyModes (default: surface nodes and triangles only).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "models/gear_fe_mesh.h"
#include "models/gear_geometry.h"

namespace orrery {
namespace {

// ---- The planet and its meshes -----------------------------------------------------------

gears::Gear Planet() {
  return gears::Gear({.teeth = 18, .normal_module_m = 1.5e-3,
                      .normal_pressure_angle_rad = 21.3 * std::numbers::pi / 180, .face_width_m = 0.03});
}

// hex20 meshes of the planet. DOFs (3 per node) counted from MakeGearFeMesh.
struct PlanetSize {
  const char* name;
  int dofs;  // for the label; checked against the mesh
  int flank, fillet, tooth, root_layer, rim, face;
};
constexpr PlanetSize kPlanetSizes[] = {
    {"10k", 11070, 2, 1, 2, 1, 1, 3},
    {"100k", 101952, 5, 3, 4, 2, 3, 7},
    {"300k", 295812, 8, 4, 6, 3, 4, 10},  // MakeGearFeMesh's default divisions
};

gears::GearFeMeshSpec PlanetMeshSpec(const PlanetSize& s) {
  return {.bore_radius_m = 7e-3, .type = flex::ElementType::kHex20, .flank_divisions = s.flank,
          .fillet_divisions = s.fillet, .tooth_divisions = s.tooth, .root_layer_divisions = s.root_layer,
          .rim_divisions = s.rim, .face_divisions = s.face};
}

flex::FeMesh PlanetMesh(const PlanetSize& s) { return gears::MakeGearFeMesh(Planet(), PlanetMeshSpec(s)); }

std::vector<flex::FeInterface> BoreInterface(const flex::FeMesh& mesh) {
  return {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
}

// Only what the engine needs to run: no surface export, stresses or geometric stiffness.
flex::FlexibleBodyModesOptions LeanOutputs() { return {.export_surface_nodes = false, .surface_triangles = false}; }

// ---- Memory ------------------------------------------------------------------------------

// A field of /proc/self/status in KiB (VmHWM: peak resident set, VmRSS: current), -1 if absent.
long ProcStatusKiB(std::string_view field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, field.size(), field) == 0 && line.size() > field.size() && line[field.size()] == ':')
      return std::stol(line.substr(field.size() + 1));
  return -1;
}

// ru_maxrss (KiB on Linux).
long MaxRssKiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

// The BLAS and LAPACK shared objects mapped into this process (what the dynamic linker chose).
std::vector<std::string> LoadedBlas() {
  std::ifstream in("/proc/self/maps");
  std::string line;
  std::vector<std::string> libs;
  while (std::getline(in, line)) {
    const std::size_t slash = line.find('/');
    if (slash == std::string::npos) continue;
    const std::string path = line.substr(slash);
    if (path.find("blas") == std::string::npos && path.find("lapack") == std::string::npos) continue;
    bool seen = false;
    for (const std::string& l : libs) seen |= l == path;
    if (!seen) libs.push_back(path);
  }
  return libs;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// ---- (a) Reduction by stage, in process ---------------------------------------------------

const PlanetSize& SizeArg(const benchmark::State& st) { return kPlanetSizes[st.range(0)]; }

void SetSizeCounters(benchmark::State& st, const flex::FeMesh& mesh) {
  st.SetLabel(std::string(SizeArg(st).name) + " DOF hex20");
  st.counters["dofs"] = 3.0 * mesh.num_nodes();
  st.counters["VmHWM_MiB"] = ProcStatusKiB("VmHWM") / 1024.0;
}

void BM_PlanetMesh(benchmark::State& st) {
  flex::FeMesh mesh;
  for (auto _ : st) mesh = PlanetMesh(SizeArg(st));
  SetSizeCounters(st, mesh);
}
BENCHMARK(BM_PlanetMesh)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

void BM_PlanetAssembly(benchmark::State& st) {
  const flex::FeMesh mesh = PlanetMesh(SizeArg(st));
  for (auto _ : st) {
    flex::FeSystem sys = flex::AssembleFeSystem(mesh);
    benchmark::DoNotOptimize(sys.K.valuePtr());
  }
  SetSizeCounters(st, mesh);
}
BENCHMARK(BM_PlanetAssembly)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// ReduceCraigBampton, 30 modes. 100k: 1-2 minutes and 2 GB; 300k (15 minutes, 8 GB with the
// reference BLAS) only in probe mode.
void BM_PlanetReduction(benchmark::State& st) {
  const flex::FeMesh mesh = PlanetMesh(SizeArg(st));
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const std::vector<flex::FeInterface> ifs = BoreInterface(mesh);
  flex::CraigBamptonModel cb;
  for (auto _ : st) cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 30});
  SetSizeCounters(st, mesh);
  st.counters["f1_Hz"] = cb.frequencies_hz[cb.num_rigid];
  st.counters["f30_Hz"] = cb.frequencies_hz.back();
}
BENCHMARK(BM_PlanetReduction)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->Iterations(1);

// MakeFlexibleBodyModes after a 30-mode reduction, default outputs (surface nodes, triangles);
// 10k only (larger sizes: probe mode, which times this stage without a second reduction).
void BM_PlanetBodyModes(benchmark::State& st) {
  const flex::FeMesh mesh = PlanetMesh(SizeArg(st));
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const std::vector<flex::FeInterface> ifs = BoreInterface(mesh);
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 30});
  FlexibleBodyModes modes;
  for (auto _ : st) modes = flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs);
  SetSizeCounters(st, mesh);
  st.counters["nodes_exported"] = double(modes.nodes.size());
}
BENCHMARK(BM_PlanetBodyModes)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(3);

// ---- (b) One flexible body on a revolute joint ------------------------------------------

constexpr int kMaxModes = 100;

// The 10k-DOF planet reduced to kMaxModes modes, once per process.
const FlexibleBodyModes& PlanetModes100() {
  static const FlexibleBodyModes modes = [] {
    const flex::FeMesh mesh = PlanetMesh(kPlanetSizes[0]);
    const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
    const std::vector<flex::FeInterface> ifs = BoreInterface(mesh);
    const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = kMaxModes});
    return flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs, LeanOutputs());
  }();
  return modes;
}

// The first nf modes of `full`: every per-mode quantity restricted to them.
std::shared_ptr<FlexibleBodyModes> FirstModes(const FlexibleBodyModes& full, int nf) {
  auto m = std::make_shared<FlexibleBodyModes>();
  m->nf = nf;
  m->mass = full.mass;
  m->I1 = full.I1;
  m->I3 = full.I3;
  m->I2 = full.I2.leftCols(nf);
  m->I4.assign(full.I4.begin(), full.I4.begin() + nf);
  m->I5.reserve(std::size_t(nf) * nf);
  for (int k = 0; k < nf; ++k)
    for (int l = 0; l < nf; ++l) m->I5.push_back(full.I5[std::size_t(k) * full.nf + l]);
  m->stiffness = full.stiffness.topLeftCorner(nf, nf);
  if (full.damping.size() > 0) m->damping = full.damping.topLeftCorner(nf, nf);
  for (const Eigen::MatrixXd& g : full.geometric_stiffness) m->geometric_stiffness.push_back(g.topLeftCorner(nf, nf));
  for (const FlexibleBodyModes::Node& n : full.nodes)
    m->nodes.push_back({.id = n.id, .position = n.position, .translation_shapes = n.translation_shapes.leftCols(nf),
                        .rotation_shapes = n.rotation_shapes.leftCols(nf)});
  m->node_sets = full.node_sets;
  m->frequencies_hz.assign(full.frequencies_hz.begin(), full.frequencies_hz.begin() + nf);
  return m;
}

std::shared_ptr<const Model> SpinningPlanet(int nf) {
  ModelBuilder b;
  const BodyIndex planet = b.AddFlexibleBody("planet", FirstModes(PlanetModes100(), nf), {.damping_ratios = {0.01}});
  const JointIndex pin = b.AddJoint({.name = "pin", .type = JointType::kRevolute, .parent = kWorldBody,
                                     .child = planet, .axis = Vec3::UnitZ()});
  b.SetJointVelocity(pin, Eigen::VectorXd::Constant(1, 100.0));  // rad/s
  // Small deflections and modal velocities, all different (no term vanishes).
  const Eigen::VectorXd q_f = Eigen::VectorXd::LinSpaced(nf, 1e-7, 2e-7);
  const Eigen::VectorXd v_f = Eigen::VectorXd::LinSpaced(nf, -1e-4, 1e-4);
  b.SetModalCoordinates(planet, q_f, v_f);
  b.SetGravity(Vec3(0, -9.81, 0));
  return std::move(b).Finalize();
}

struct FlexFixture {
  explicit FlexFixture(int nf) : model(SpinningPlanet(nf)), dae(*model), data(*model) {
    const State s = State::Initial(*model);
    y.setZero(dae.size());
    yp.setZero(dae.size());
    r.setZero(dae.size());
    J.setZero(dae.size(), dae.size());
    dae.ConsistentInitial(s, y, yp);
  }
  std::shared_ptr<const Model> model;
  DaeSystem dae;
  Data data;
  Eigen::VectorXd y, yp, r;
  Eigen::MatrixXd J;
};

void SetModeCounters(benchmark::State& st, const FlexFixture& f) {
  st.counters["nf"] = double(st.range(0));
  st.counters["nv"] = double(f.model->nv);
}

void BM_FlexEvaluateDynamics(benchmark::State& st) {
  FlexFixture f(static_cast<int>(st.range(0)));
  const Model& m = *f.model;
  const Eigen::VectorXd q = f.y.head(m.nq), v = f.y.segment(m.nq, m.nv), vdot = f.yp.segment(m.nq, m.nv);
  for (auto _ : st) {
    EvaluateDynamics(m, 0.0, q, v, vdot, f.data);
    benchmark::DoNotOptimize(f.data.tau_id.data());
  }
  SetModeCounters(st, f);
}
BENCHMARK(BM_FlexEvaluateDynamics)->Arg(5)->Arg(10)->Arg(20)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);

void BM_FlexResidual(benchmark::State& st) {
  FlexFixture f(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    f.dae.Residual(0.0, f.y, f.yp, f.r);
    benchmark::DoNotOptimize(f.r.data());
  }
  SetModeCounters(st, f);
}
BENCHMARK(BM_FlexResidual)->Arg(5)->Arg(10)->Arg(20)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);

void BM_FlexJacobian(benchmark::State& st) {
  FlexFixture f(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    f.dae.Jacobian(0.0, 1e4, f.y, f.yp, f.J);
    benchmark::DoNotOptimize(f.J.data());
  }
  SetModeCounters(st, f);
}
BENCHMARK(BM_FlexJacobian)->Arg(5)->Arg(10)->Arg(20)->Arg(50)->Arg(100)->Unit(benchmark::kMicrosecond);

// ---- Probe mode: one size in this process, JSON on stdout --------------------------------

int Probe(std::string_view size, int num_modes, bool full_outputs) {
  const PlanetSize* s = nullptr;
  for (const PlanetSize& p : kPlanetSizes)
    if (size == p.name) s = &p;
  if (s == nullptr) {
    std::fprintf(stderr, "--probe: unknown size '%.*s' (10k, 100k, 300k)\n", int(size.size()), size.data());
    return 2;
  }
  // Each stage: wall time and the peak resident set so far.
  auto t = std::chrono::steady_clock::now();
  const flex::FeMesh mesh = PlanetMesh(*s);
  const double t_mesh = Seconds(t);
  if (3 * mesh.num_nodes() != s->dofs)
    std::fprintf(stderr, "note: %s mesh has %d DOFs, kPlanetSizes says %d\n", s->name, 3 * mesh.num_nodes(), s->dofs);
  const long hwm_mesh = ProcStatusKiB("VmHWM");
  t = std::chrono::steady_clock::now();
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const double t_assembly = Seconds(t);
  const long hwm_assembly = ProcStatusKiB("VmHWM");
  t = std::chrono::steady_clock::now();
  const std::vector<flex::FeInterface> ifs = BoreInterface(mesh);
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = num_modes});
  const double t_reduction = Seconds(t);
  const long hwm_reduction = ProcStatusKiB("VmHWM");
  t = std::chrono::steady_clock::now();
  flex::FlexibleBodyModesOptions outputs;
  outputs.stress_modes = outputs.geometric_stiffness = full_outputs;
  const FlexibleBodyModes modes = flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs, outputs);
  const double t_modes = Seconds(t);
  const long hwm_modes = ProcStatusKiB("VmHWM");

  std::printf("{\"size\": \"%s\", \"element_type\": \"hex20\", \"nodes\": %d, \"elements\": %d, \"dofs\": %d, "
              "\"bore_nodes\": %zu, \"modes\": %d, \"outputs\": \"%s\",\n",
              s->name, mesh.num_nodes(), mesh.num_elements(), 3 * mesh.num_nodes(), mesh.NodeSet("BORE").size(),
              num_modes, full_outputs ? "surface, stress modes, geometric stiffness" : "surface");
  std::printf(" \"first_elastic_hz\": %.6g, \"last_elastic_hz\": %.6g, \"exported_nodes\": %zu,\n",
              cb.frequencies_hz[cb.num_rigid], cb.frequencies_hz.back(), modes.nodes.size());
  std::printf(" \"wall_s\": {\"mesh\": %.4g, \"assembly\": %.4g, \"reduction\": %.4g, \"flexible_body_modes\": %.4g, "
              "\"total\": %.4g},\n",
              t_mesh, t_assembly, t_reduction, t_modes, t_mesh + t_assembly + t_reduction + t_modes);
  std::printf(" \"vmhwm_mib_after\": {\"mesh\": %.1f, \"assembly\": %.1f, \"reduction\": %.1f, "
              "\"flexible_body_modes\": %.1f}, \"ru_maxrss_mib\": %.1f,\n",
              hwm_mesh / 1024.0, hwm_assembly / 1024.0, hwm_reduction / 1024.0, hwm_modes / 1024.0,
              MaxRssKiB() / 1024.0);
  std::printf(" \"blas\": [");
  const std::vector<std::string> blas = LoadedBlas();
  for (std::size_t i = 0; i < blas.size(); ++i) std::printf("%s\"%s\"", i ? ", " : "", blas[i].c_str());
  std::printf("]}\n");
  return 0;
}

}  // namespace
}  // namespace orrery

int main(int argc, char** argv) {
  // Probe mode (see the top of the file); otherwise Google Benchmark's usual command line.
  std::string_view probe;
  int num_modes = 30;
  bool full_outputs = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a.starts_with("--probe=")) probe = a.substr(8);
    if (a.starts_with("--modes=")) num_modes = std::atoi(argv[i] + 8);
    if (a == "--outputs=full") full_outputs = true;
  }
  if (!probe.empty()) return orrery::Probe(probe, num_modes, full_outputs);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// The tooth-contact rows of the performance table (docs/performance.md, issue 15): seed 003's
// stage run as `orrery run` runs it (generalized-alpha at 5 us, the result recorder and the
// sensors writing to an in-memory result file, the run's health checks) for 20 ms of simulated
// time after a 5 ms start-up (the meshes taking up the load; run once, not timed).
//   ContactScene/0: rigid tooth contact on all 6 meshes (seed003_contact_healthy.yaml);
//   ContactScene/1: planet 1 flexible (24 modes) with contact on its two meshes, planets 2 and 3
//                   on lumped TVMS meshes (seed003_flexible_healthy.yaml; its reduced body is
//                   made on the first run).
// Counters: cpu_per_sim_s and wall_per_sim_s (process CPU and wall seconds per simulated second:
// the table's figures; CPU over all threads), steps, residuals, jacobians (the integrator's
// statistics), newton_failures (steps retried with a halved step), us_per_step, threads (the
// scene's solver.threads, else OMP_NUM_THREADS, else 1: the contacts of an evaluation in parallel).
//   contact_scenes_benchmark --benchmark_filter=ContactScene/0
//   OMP_NUM_THREADS=2 contact_scenes_benchmark
#include <benchmark/benchmark.h>

#include <atomic>
#include <ctime>
#include <map>
#include <memory>
#include <string>

#include "import/scene.h"
#include "mbd/integrator.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

constexpr const char* kFiles[] = {"seed003_contact_healthy.yaml", "seed003_flexible_healthy.yaml"};
constexpr double kStartUpS = 0.005;
constexpr double kSimulatedS = 0.02;

struct Row {
  Scene scene;
  State start;  // the state after the start-up
};

const Row& LoadRow(int i) {
  static std::map<int, std::unique_ptr<Row>> rows;
  auto& r = rows[i];
  if (r) return *r;
  Scene scene = LoadScene(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + kFiles[i],
                          {"solver.end_time=" + std::to_string(kStartUpS)},
                          {.make_reduced_bodies = true});
  const SimulationReport start_up = Simulate(*scene.model, scene.simulation, nullptr);
  scene.simulation.end_time = kStartUpS + kSimulatedS;
  r = std::make_unique<Row>(Row{.scene = std::move(scene), .start = start_up.final_state});
  return *r;
}

double ProcessCpuS() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void BM_ContactScene(benchmark::State& state) {
  const Row& row = LoadRow(int(state.range(0)));
  SimulationReport report;
  double wall_s = 0, cpu_s = 0;
  static std::atomic<long> files{0};
  for (auto _ : state) {
    ResultFile out = ResultFile::CreateInMemory("contact benchmark " + std::to_string(++files));
    const double cpu0 = ProcessCpuS();
    report = Simulate(*row.scene.model, row.scene.simulation, &out, {}, &row.start);
    cpu_s += ProcessCpuS() - cpu0;
    wall_s += report.wall_s;
  }
  const double runs = double(state.iterations());
  state.SetLabel(kFiles[state.range(0)]);
  state.counters["cpu_per_sim_s"] = cpu_s / runs / kSimulatedS;
  state.counters["wall_per_sim_s"] = wall_s / runs / kSimulatedS;
  state.counters["steps"] = double(report.stats.steps);
  state.counters["residuals"] = double(report.stats.residual_evaluations);
  state.counters["jacobians"] = double(report.stats.jacobian_evaluations);
  state.counters["newton_failures"] = double(report.stats.newton_failures);
  state.counters["us_per_step"] = 1e6 * wall_s / runs / double(report.stats.steps);
  state.counters["threads"] = ResolveThreads(row.scene.simulation.integrator.threads);
}

BENCHMARK(BM_ContactScene)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

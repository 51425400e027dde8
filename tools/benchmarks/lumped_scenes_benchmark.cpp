// The lumped rows of the performance table (docs/performance.md, issue 15): each scene run as
// `orrery run` runs it (its own integrator and settings, the result recorder and the sensors
// writing to an in-memory result file, the run's health checks) for a fixed simulated time.
//   LumpedScene/0: seed 002 3-D lumped stage (seed002_alpha1_ramp.yaml, generalized-alpha 0.1 ms),
//                  the scene's whole 0.2 s ramp;
//   LumpedScene/1: seed 001 three-stage torsional train (seed001_three_stage.yaml,
//                  generalized-alpha 50 us), 0.2 s;
//   LumpedScene/2: seed 003 lumped stage with IDA (seed003_lumped_healthy.yaml), 0.1 s.
// LumpedSceneNoOutput/N: the same runs without a result file (integrator and health only), so
// that the recording's share shows as the difference.
// Counters: wall_per_sim_s (wall seconds per simulated second: the table's figure), steps,
// residuals and jacobians (the integrator's statistics), us_per_step.
//   lumped_scenes_benchmark --benchmark_filter=LumpedScene
#include <benchmark/benchmark.h>

#include <atomic>
#include <string>

#include "import/scene.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

struct Row {
  const char* file;
  double simulated_s;
};

constexpr Row kRows[] = {
    {"seed002_alpha1_ramp.yaml", 0.2},
    {"seed001_three_stage.yaml", 0.2},
    {"seed003_lumped_healthy.yaml", 0.1},
};

void RunScene(benchmark::State& state, bool with_output) {
  const Row& row = kRows[state.range(0)];
  const Scene scene = LoadScene(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + row.file,
                                {"solver.end_time=" + std::to_string(row.simulated_s)});
  SimulationReport report;
  double wall_s = 0;
  static std::atomic<long> files{0};
  for (auto _ : state) {
    if (with_output) {
      ResultFile out = ResultFile::CreateInMemory("lumped benchmark " + std::to_string(++files));
      report = Simulate(*scene.model, scene.simulation, &out);
    } else {
      report = Simulate(*scene.model, scene.simulation, nullptr);
    }
    wall_s += report.wall_s;
  }
  const double runs = double(state.iterations());
  state.SetLabel(std::string(row.file) + " (" + report.integrator + ")");
  state.counters["wall_per_sim_s"] = wall_s / runs / row.simulated_s;
  state.counters["steps"] = double(report.stats.steps);
  state.counters["residuals"] = double(report.stats.residual_evaluations);
  state.counters["jacobians"] = double(report.stats.jacobian_evaluations);
  state.counters["us_per_step"] = 1e6 * wall_s / runs / double(report.stats.steps);
}

void BM_LumpedScene(benchmark::State& state) { RunScene(state, true); }
void BM_LumpedSceneNoOutput(benchmark::State& state) { RunScene(state, false); }

BENCHMARK(BM_LumpedScene)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_LumpedSceneNoOutput)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

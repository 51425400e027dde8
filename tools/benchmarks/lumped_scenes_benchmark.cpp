// The lumped rows of the performance table (docs/performance.md, issue 15): each scene run as
// `orrery run` runs it (its own integrator and settings, the result recorder and the sensors
// writing to an in-memory result file, the run's health checks) for a fixed simulated time.
//   LumpedScene/0: seed 002 3-D lumped stage (seed002_alpha1_ramp.yaml, generalized-alpha 0.1 ms),
//                  the scene's whole 0.2 s ramp;
//   LumpedScene/1: seed 001 three-stage torsional train (seed001_three_stage.yaml,
//                  generalized-alpha 50 us), 0.2 s;
//   LumpedScene/2: seed 003 lumped stage with IDA (seed003_lumped_healthy.yaml), 0.1 s.
//   LumpedScene/3: the floor under row 2 (docs/performance.md): a 1-DOF oscillator
//                  (oscillator.yaml) at seed 003's highest mesh mode, 9757.5 Hz (`orrery modes
//                  models/scenes/seed003_lumped_healthy.yaml`), on IDA at seed 003's tolerances
//                  (rtol 1e-6, atol 1e-8), ringing at 1 um, 0.1 s: the steps per second BDF needs
//                  to resolve that mode and IDA's cost per step for the smallest system.
// LumpedSceneNoOutput/N: the same runs without a result file (integrator and health only), so
// that the recording's share shows as the difference.
// Counters: wall_per_sim_s (wall seconds per simulated second: the table's figure), steps,
// residuals and jacobians (the integrator's statistics), us_per_step.
//   lumped_scenes_benchmark --benchmark_filter=LumpedScene
#include <benchmark/benchmark.h>

#include <atomic>
#include <string>
#include <vector>

#include "import/scene.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

struct Row {
  const char* file;
  double simulated_s;
  std::vector<std::string> settings;  // --set overrides besides the end time
};

// k = m (2 pi f)^2 for m = 1 kg and f = 9757.5 Hz.
const Row kRows[] = {
    {"seed002_alpha1_ramp.yaml", 0.2, {}},
    {"seed001_three_stage.yaml", 0.2, {}},
    {"seed003_lumped_healthy.yaml", 0.1, {}},
    {"oscillator.yaml",
     0.1,
     {"force_elements.0.stiffness=3.7587e9", "joints.0.initial_position=1e-6", "solver.rtol=1e-6",
      "solver.atol=1e-8", "output.interval=1e-4"}},
};

void RunScene(benchmark::State& state, bool with_output) {
  const Row& row = kRows[state.range(0)];
  std::vector<std::string> settings = row.settings;
  settings.push_back("solver.end_time=" + std::to_string(row.simulated_s));
  const Scene scene = LoadScene(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + row.file, settings);
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

BENCHMARK(BM_LumpedScene)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_LumpedSceneNoOutput)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

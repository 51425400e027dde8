// What the virtual sensors cost (docs/sensors.md): per internal sample and per run.
//   SensorSignals/*: one internal sample's readings (CalcSensorSignals) on seed 003's lumped
//     stage (models/scenes/seed003_lumped_healthy.yaml) with a diagnostics set of sensors: a 3-axis
//     accelerometer on each member and planet, an angular accelerometer on planet 1, an encoder
//     and a tachometer on each member, the force of every lumped mesh (35 channels);
//   FilterSample/channels: one sample through the anti-alias filter (M = 10, 100 dB: 643 taps)
//     and the row it yields every M samples, per sample;
//   Run/*: the whole run (Simulate with a result file) with no sensor, with the scene's own six
//     channels (seed 003's study set: planet 1, housing, ring, carrier, two mesh forces), with the
//     diagnostics set (M = 10 and M = 4), and the
//     slider crank (models/scenes/slider_crank.yaml) with and without its three sensors: the
//     difference is the sensors' share of a run's wall time.
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>

#include "import/scene.h"
#include "mbd/anti_alias_filter.h"
#include "mbd/data.h"
#include "mbd/result_file.h"
#include "mbd/sensor_signals.h"
#include "mbd/simulation.h"
#include "models/train_dynamics.h"

namespace orrery {
namespace {

// Seed 003's lumped stage rebuilt with the diagnostics sensors (and their frames) and without
// (both at the scene's constant input speed).
struct Stage {
  Scene scene;
  std::shared_ptr<const Model> with_sensors, without_sensors, no_sensors;
};

const Stage& LoadStage() {
  static std::unique_ptr<Stage> s;
  if (s) return *s;
  s = std::make_unique<Stage>();
  s->scene = LoadScene(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/seed003_lumped_healthy.yaml");
  const GearTrainScene& g = *s->scene.gear_train;
  gears::TrainModelOptions o = g.options;
  // The stage's members and planets, and its six mesh branches (models/train_sensors.cpp)
  const std::vector<std::string> bodies{"S.sun", "S.carrier", "S.ring", "S.planet1", "S.planet2", "S.planet3"};
  for (const std::string& body : bodies)
    o.sensors.push_back({.name = "acc_" + body, .kind = SensorKind::kAccelerometer, .body = body,
                         .position_m = Vec3(0.08, 0, 0.01)});
  o.sensors.push_back({.name = "alpha_planet", .kind = SensorKind::kAngularAccelerometer, .body = "S.planet1",
                       .axes = {2}});
  for (const char* member : {"S.sun", "S.carrier", "S.ring"}) {
    o.sensors.push_back({.name = std::string("enc_") + member, .kind = SensorKind::kEncoder, .joint = member});
    o.sensors.push_back({.name = std::string("tach_") + member, .kind = SensorKind::kTachometer, .joint = member});
  }
  for (const std::string mesh : {"S.sun-planet", "S.ring-planet"})
    for (int k = 1; k <= 3; ++k) {
      const std::string branch = mesh + "#" + std::to_string(k);
      o.sensors.push_back({.name = "mesh_" + branch, .kind = SensorKind::kGearMesh, .mesh = branch});
    }
  s->with_sensors = gears::BuildTrainModel(*g.train, g.range, o).model;
  s->without_sensors = gears::BuildTrainModel(*g.train, g.range, g.options).model;
  gears::TrainModelOptions none = g.options;
  none.sensors.clear();
  s->no_sensors = gears::BuildTrainModel(*g.train, g.range, none).model;
  return *s;
}

void SensorSignals(benchmark::State& state) {
  const Stage& s = LoadStage();
  const Model& m = *s.with_sensors;
  Data data(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::LinSpaced(m.nv, -1, 1);
  Eigen::VectorXd v = m.v_initial;
  double t = 0;
  for (auto _ : state) {
    t += 1e-5;
    CalcSensorSignals(m, t, m.q_initial, v, vdot, data);
    benchmark::DoNotOptimize(data.sensor_values.data());
  }
  state.counters["channels"] = m.n_sensor_channels;
}
BENCHMARK(SensorSignals)->Unit(benchmark::kMicrosecond);

void FilterSample(benchmark::State& state) {
  const int channels = static_cast<int>(state.range(0)), M = 10;
  const FirLowPass f = DesignKaiserLowPass(0.04, 0.05, 100);
  DecimatingFilter d(f.taps, channels, static_cast<long>(f.taps.size()) + 4 * M);
  std::vector<double> x(channels, 0.0), y(channels);
  long n = 0;
  for (auto _ : state) {
    for (int c = 0; c < channels; ++c) x[c] = std::sin(1e-3 * n + c);
    d.Push(x.data());
    const long row = n - d.delay();
    if (row >= 0 && row % M == 0) d.Output(row, y.data());
    ++n;
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["taps"] = static_cast<double>(f.taps.size());
}
BENCHMARK(FilterSample)->Arg(1)->Arg(35)->Unit(benchmark::kMicrosecond);

// A whole run into a temporary result file.
void RunModel(benchmark::State& state, const Model& model, SimulationOptions o) {
  const std::string path = "/tmp/orrery_sensors_benchmark_" + std::to_string(::getpid()) + ".h5";
  long rows = 0;
  for (auto _ : state) {
    ResultFile out = ResultFile::Create(path);
    rows = Simulate(model, o, &out).output_rows;
  }
  std::filesystem::remove(path);
  state.counters["rows"] = static_cast<double>(rows);
  state.counters["channels"] = model.n_sensor_channels;
}

// oversampling -2: no sensor at all; -1: the scene's own sensors (6 channels); >= 0: the
// diagnostics set, 0: the default oversampling (10 for IDA).
void RunStage(benchmark::State& state, int oversampling) {
  const Stage& s = LoadStage();
  SimulationOptions o = s.scene.simulation;
  o.end_time = 0.2;
  o.sensors.oversampling = std::max(0, oversampling);
  RunModel(state, oversampling >= 0 ? *s.with_sensors : oversampling == -1 ? *s.without_sensors : *s.no_sensors, o);
}
BENCHMARK_CAPTURE(RunStage, seed003_lumped_no_sensors, -2)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(RunStage, seed003_lumped_without_sensors, -1)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(RunStage, seed003_lumped_with_sensors, 0)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(RunStage, seed003_lumped_with_sensors_M4, 4)->Unit(benchmark::kMillisecond)->Iterations(3);

void RunSliderCrank(benchmark::State& state, bool sensors) {
  const std::string path = std::string(ORRERY_SOURCE_DIR) + "/models/scenes/slider_crank.yaml";
  std::vector<std::string> set{"solver.end_time=1"};
  if (!sensors) set.push_back("sensors=[]");
  const Scene scene = LoadScene(path, set);
  RunModel(state, *scene.model, scene.simulation);
}
BENCHMARK_CAPTURE(RunSliderCrank, without_sensors, false)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK_CAPTURE(RunSliderCrank, with_sensors, true)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

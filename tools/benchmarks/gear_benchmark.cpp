// Geared-drivetrain benchmarks (Google Benchmark, Release build):
//   (a) seed 002 stage, spatial lumped train with TVMS meshes, 1 s simulated at a constant 20 r/min
//       (carrier driven, rated load, from the static equilibrium): wall time, steps, residual
//       evaluations, IDA and generalized-alpha; target faster than real time on one core
//       (counter "realtime_factor" = simulated / wall time > 1);
//   (b) modes of seed 001's three-stage train in 1st gear: BuildTrainModel + CalcTrainModes
//       (target < 50 ms);
//   (c) DAE residual evaluations per second of the seed 002 model;
//   (d) the seed 002 start-up of Fig. 3 (alpha1 = 0.01 .. 0.16, the whole 0.2 s profile), peak
//       forces as counters (tests/models/seed002_test.cpp runs the first 0.06 s).
//
//   gear_benchmark --benchmark_filter=Seed002Run
// The seed 002 scene is the one of tests/models/seed002_test.cpp (values the paper does not give
// are stated there).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "mbd/constraints.h"
#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "models/modal_analysis.h"
#include "models/planetary_scenes.h"
#include "models/planetary_train.h"
#include "models/seed_models.h"
#include "models/train_dynamics.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRpm = 2 * kPi / 60;

TrainModel Seed002Model(const TimeFunction& carrier_speed) {
  return BuildTrainModel(*Seed002ShiftedStage(), 0, Seed002DynamicsOptions(carrier_speed));
}

// (a) 1 s at 20 r/min. Arg 0: IDA (rtol 1e-5, atol 1e-7); arg 1: generalized-alpha (step 2e-5 s,
// rho_inf 0.8; with 5e-5 s or rho_inf 0.5 its Newton iteration stalls at a residual ~5e-6
// somewhere in the second, with 1e-4 s at the first step). Outputs every 1 ms (the integrator's own steps are what is measured).
void BM_Seed002Run(benchmark::State& st) {
  const TrainModel tm = Seed002Model(TimeFunction::Constant(20 * kRpm));
  const Model& m = *tm.model;
  const State x0 = SolveTrainStaticState(tm, State::Initial(m));
  IntegratorOptions io;
  io.kind = st.range(0) == 0 ? IntegratorKind::kIda : IntegratorKind::kGeneralizedAlpha;
  io.rtol = 1e-5;
  io.atol = 1e-7;
  io.step = 1e-6 * double(st.range(1));  // second argument: generalized-alpha step in us
  io.rho_inf = 0.8;
  const double t_end = 1.0;
  IntegratorStats stats;
  for (auto _ : st) {
    auto integ = MakeIntegrator(m, io);
    integ->Initialize(x0);
    for (int i = 1; i <= 1000; ++i) integ->AdvanceTo(i * t_end / 1000);
    stats = integ->stats();
  }
  st.SetLabel(io.kind == IntegratorKind::kIda ? "IDA" : "generalized-alpha");
  st.counters["steps"] = double(stats.steps);
  st.counters["residuals"] = double(stats.residual_evaluations);
  st.counters["jacobians"] = double(stats.jacobian_evaluations);
  st.counters["realtime_factor"] = benchmark::Counter(t_end * double(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Seed002Run)
    ->Args({0, 0})
    ->Args({1, 20})
    ->Args({1, 50})
    ->Args({1, 100})
    ->Args({1, 200})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// (b) Seed 001 modes, 1st gear (Table 2 stiffnesses).
void BM_Seed001Modes(benchmark::State& st) {
  const auto train = MakeSeed001AutomaticTransmission();
  TrainModelOptions o;
  o.face_width_m = 0.030;
  o.input = TrainModelOptions::Input::kNone;
  o.input_torque_n_m = 300;
  int n = 0;
  for (auto _ : st) {
    const TrainModel tm = BuildTrainModel(*train, train->RangeIndex("1st"), o);
    const TrainModes modes = CalcTrainModes(tm);
    n = static_cast<int>(modes.modes.size());
    benchmark::DoNotOptimize(modes.shapes.data());
  }
  st.counters["modes"] = n;
}
BENCHMARK(BM_Seed001Modes)->Unit(benchmark::kMillisecond);

// (c) DAE residuals of the seed 002 model per second.
void BM_Seed002Residual(benchmark::State& st) {
  const TrainModel tm = Seed002Model(TimeFunction::Constant(20 * kRpm));
  const Model& m = *tm.model;
  DaeSystem dae(m);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(dae.size()), yp = y, r = y;
  State s = State::Initial(m);
  Data d(m);
  AssembleState(m, s, d);
  dae.ConsistentInitial(s, y, yp);
  for (auto _ : st) {
    dae.Residual(0.01, y, yp, r);
    benchmark::DoNotOptimize(r.data());
  }
  st.counters["nv"] = m.nv;
  st.counters["residuals/s"] = benchmark::Counter(double(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Seed002Residual);

// (d) Fig. 3 start-up over the whole profile (t4 = 0.2 s), alpha1 = alpha2 = arg / 100; peak
// sun-planet, ring-planet and planet-pin forces over all branches (N), IDA rtol 1e-6.
void BM_Seed002StartUp(benchmark::State& st) {
  const double alpha1 = st.range(0) / 100.0;
  const TrainModel tm = Seed002Model(TimeFunction::Trapezoid(0, 20 * kRpm, 0, 0.2, alpha1, alpha1, 0.6));
  const Model& m = *tm.model;
  const State x0 = SolveTrainStaticState(tm, State::Initial(m));
  IntegratorOptions io;
  io.rtol = 1e-6;
  io.atol = 1e-8;
  double fsp = 0, frp = 0, fpin = 0;
  IntegratorStats stats;
  for (auto _ : st) {
    auto integ = MakeIntegrator(m, io);
    integ->Initialize(x0);
    Data d(m), dk(m);
    for (int i = 0; i <= 10000; ++i) {
      if (i > 0) integ->AdvanceTo(i * 2e-5);
      const State& s = integ->state();
      EvaluateDynamics(m, s.t, s.q, s.v, integ->vdot(), d);
      for (const TrainMeshElement& e : tm.meshes)
        (e.train_mesh == 0 ? fsp : frp) = std::max(e.train_mesh == 0 ? fsp : frp, d.mesh_force[e.model_mesh]);
      for (double f : CalcPlanetPinForces(tm, s, dk)) fpin = std::max(fpin, f);
    }
    stats = integ->stats();
  }
  st.counters["alpha1"] = alpha1;
  st.counters["peak_sp_N"] = fsp;
  st.counters["peak_rp_N"] = frp;
  st.counters["peak_pin_N"] = fpin;
  st.counters["steps"] = double(stats.steps);
}
BENCHMARK(BM_Seed002StartUp)->Arg(1)->Arg(4)->Arg(9)->Arg(16)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace orrery::gears

BENCHMARK_MAIN();

// Signal-processing benchmarks (Google Benchmark, Release build): the analyses of tools/signal on
// a 1 s record at 10 kHz (the fault study's output rate), 20 kHz and 100 kHz (the argument is the
// sample rate in Hz), a synthetic planet vibration (mesh at 224 Hz with two harmonics,
// amplitude-modulated at 16 Hz, plus noise):
//   AmplitudeSpectrum      Hann window, the whole record (10000 = 2^4 5^4, 20000 = 2^5 5^4,
//                          100000 = 2^5 5^5)
//   FindAndLabelPeaks      FindPeaks (20 largest) + LabelPeaks against 6 kinematic lines
//   WelchPsd               default segments (2N/9, 8 at 50 % overlap), Hann
//   TimeSynchronousAverage OrderResample (DefaultSamplesPerRevolution) + averaging over 16
//                          revolutions of the planet's angle
//   ConditionIndicators    RMS .. NA4 of that TSA
//   SidebandEnergyRatio    3 harmonics, 6 sideband pairs, from the amplitude spectrum
//   ThirdOctaveLevels      Hann periodogram integrated over the IEC 61260 bands
//
//   signal_benchmark --benchmark_filter=Spectrum
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/condition_indicators.h"
#include "tools/signal/kinematic_lines.h"
#include "tools/signal/order_resample.h"
#include "tools/signal/peaks.h"
#include "tools/signal/sideband_energy_ratio.h"
#include "tools/signal/third_octave.h"
#include "tools/signal/time_synchronous_average.h"
#include "tools/signal/welch_psd.h"

namespace orrery::signal {
namespace {

constexpr double kPlanetHz = 16.0, kMeshHz = 224.0;

struct Record {
  std::vector<double> x, angle;
  double fs = 0;
};

// 1 s at `fs`: the planet's angle and its vibration
Record MakeRecord(double fs) {
  Record r;
  r.fs = fs;
  const int n = static_cast<int>(fs);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.01);
  r.x.resize(n);
  r.angle.resize(n);
  for (int i = 0; i < n; ++i) {
    const double theta = 2 * std::numbers::pi * kPlanetHz * i / fs;
    r.angle[i] = theta;
    r.x[i] = (1 + 0.3 * std::cos(theta)) * (std::cos(14 * theta) + 0.3 * std::cos(28 * theta)) + noise(rng);
  }
  return r;
}

const std::vector<KinematicLine> kLines = {{"f_m", kMeshHz, LineKind::kMesh},     {"f_c", 8.42, LineKind::kShaft},
                                           {"f_r", 12.83, LineKind::kShaft},      {"f_p^H", kPlanetHz, LineKind::kShaft},
                                           {"f_pp", 13.22, LineKind::kPlanetPass}, {"f_fault S.planet", kPlanetHz, LineKind::kFault}};

void BM_AmplitudeSpectrum(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(AmplitudeSpectrum(r.x, r.fs, WindowKind::kHann));
}

void BM_FindAndLabelPeaks(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  const Spectrum s = AmplitudeSpectrum(r.x, r.fs, WindowKind::kHann);
  for (auto _ : state) {
    std::vector<Peak> peaks = FindPeaks(s);
    LabelPeaks(peaks, kLines, s.resolution);
    benchmark::DoNotOptimize(peaks);
  }
}

void BM_WelchPsd(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(WelchPsd(r.x, r.fs));
}

void BM_TimeSynchronousAverage(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(TimeSynchronousAverage(r.x, r.angle, DefaultSamplesPerRevolution(r.angle)));
}

void BM_ConditionIndicators(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  const SynchronousAverage tsa = TimeSynchronousAverage(r.x, r.angle, DefaultSamplesPerRevolution(r.angle));
  for (auto _ : state) benchmark::DoNotOptimize(CalcConditionIndicators(tsa.values, {.mesh_order = 14}));
  state.counters["samples_per_revolution"] = tsa.samples_per_revolution;
}

void BM_SidebandEnergyRatio(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  const Spectrum s = AmplitudeSpectrum(r.x, r.fs, WindowKind::kHann);
  for (auto _ : state) benchmark::DoNotOptimize(SidebandEnergyRatio(s, kMeshHz, kPlanetHz));
}

void BM_ThirdOctaveLevels(benchmark::State& state) {
  const Record r = MakeRecord(static_cast<double>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(ThirdOctaveLevels(r.x, r.fs));
}

BENCHMARK(BM_AmplitudeSpectrum)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FindAndLabelPeaks)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WelchPsd)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TimeSynchronousAverage)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ConditionIndicators)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SidebandEnergyRatio)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ThirdOctaveLevels)->Arg(10000)->Arg(20000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace orrery::signal

BENCHMARK_MAIN();

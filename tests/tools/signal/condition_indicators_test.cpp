// Condition indicators (tools/signal/condition_indicators.h) of the synthetic AM/FM gear signal
// (synthetic_gear_signal.h), taken through the whole path a user's signal takes: sampled in time
// while the member speeds up, resampled to its angle, averaged over 20 revolutions, then FM0,
// FM4 and NA4. Oracles: the signal's Bessel-series coefficients and the exact moments of a
// cosine series (no FFT, no resampling, no averaging).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tests/tools/signal/synthetic_gear_signal.h"
#include "tools/signal/condition_indicators.h"
#include "tools/signal/time_synchronous_average.h"

namespace orrery::signal {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr int kS = 512;  // samples per revolution of the TSA: above 4 x the highest order (97)

// The gear signal sampled at 100 kHz while the member runs from 8 to 12 rev/s in 2 s
// (θ = 2π (8 t + t^2): 20 revolutions), then resampled and averaged
SynchronousAverage AveragedGearSignal(const test::GearSignal& gear) {
  const double fs = 100000;
  const int n = 200001;
  std::vector<double> angle(n), x(n);
  for (int i = 0; i < n; ++i) {
    const double t = i / fs;
    angle[i] = kTwoPi * (8 * t + t * t);
    x[i] = gear.Value(angle[i]);
  }
  return TimeSynchronousAverage(x, angle, kS);
}

TEST(ConditionIndicators, StatisticsOfASine) {
  // a cos(q θ) on a whole period: RMS a/√2, peak a, crest factor √2, kurtosis 3/2
  // (mean cos^4 = 3/8 over mean cos^2 = 1/2, squared)
  std::vector<double> x(kS);
  for (int j = 0; j < kS; ++j) x[j] = 2.5 * std::cos(5 * kTwoPi * j / kS);
  EXPECT_NEAR(Rms(x), 2.5 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(PeakAbs(x), 2.5, 1e-12);
  EXPECT_NEAR(CrestFactor(x), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(Kurtosis(x), 1.5, 1e-12);
  EXPECT_TRUE(std::isnan(Kurtosis(std::vector<double>(8, 1.0))));
}

TEST(ConditionIndicators, Fm0Fm4Na4OfTheAmFmGearSignal) {
  const test::GearSignal gear;
  const SynchronousAverage tsa = AveragedGearSignal(gear);
  ASSERT_EQ(tsa.revolutions, 20);
  const RegularComponents regular{.mesh_order = gear.teeth, .shaft_harmonics = 2};
  const ConditionIndicators c = CalcConditionIndicators(tsa.values, regular);

  // Closed forms. The difference signal keeps the sidebands |n| >= 2 of each harmonic (the
  // signal has no shaft orders 1, 2: its lowest order is Z - 13 = 15), the residual |n| >= 1;
  // FM4 and NA4 (one run) are their kurtoses
  const test::Moments difference = test::CosineSeriesMoments(gear.Series(2));
  const test::Moments residual = test::CosineSeriesMoments(gear.Series(1));
  // FM0: peak-to-peak of x on the TSA's grid over the sum of the mesh harmonics' amplitudes
  double lo = 1e300, hi = -1e300, harmonics = 0;
  for (int j = 0; j < kS; ++j) {
    lo = std::min(lo, gear.Value(kTwoPi * j / kS));
    hi = std::max(hi, gear.Value(kTwoPi * j / kS));
  }
  for (int k = 1; k <= 3; ++k) harmonics += std::abs(gear.Coefficient(k, 0));
  const test::Moments whole = test::CosineSeriesMoments(gear.Series(0));

  // Tolerance: the cubic resampling error, at most (q h)^4 9/384 of each component with
  // h = 2π 12/1e5 rad and q <= 97 (6.7e-7), summed over components of total amplitude ~2:
  // 1.4e-6 absolute against a difference signal of RMS ~0.1, i.e. ~1e-5 relative; fourth
  // moments amplify it by ~4 x the crest factor: 2e-4. Orders stay below S/4, so the S-sample
  // means are the exact means over the revolution.
  const double tol = 1e-3;
  EXPECT_NEAR(c.fm4, difference.Kurtosis(), tol * difference.Kurtosis());
  EXPECT_NEAR(c.na4, residual.Kurtosis(), tol * residual.Kurtosis());
  EXPECT_NEAR(c.fm0, (hi - lo) / harmonics, tol * (hi - lo) / harmonics);
  EXPECT_NEAR(c.rms, std::sqrt(whole.m2), tol * std::sqrt(whole.m2));
  EXPECT_NEAR(c.kurtosis, whole.Kurtosis(), tol * whole.Kurtosis());
  EXPECT_NEAR(c.residual_variance, residual.m2, 2 * tol * residual.m2);
  // The numbers, for the record: FM4 and NA4 of this signal
  std::printf("FM4 %.6f (closed form %.6f), NA4 %.6f (%.6f), FM0 %.6f (%.6f)\n", c.fm4, difference.Kurtosis(), c.na4,
              residual.Kurtosis(), c.fm0, (hi - lo) / harmonics);
}

TEST(ConditionIndicators, Na4NormalizesByTheTrendsResidualVariance) {
  // A trend of two runs: a mildly modulated gear (m = 0.1, β = 0.2), then the one above.
  // NA4 of the second = its mean fourth power over the mean of the two residual variances, squared
  test::GearSignal healthy;
  healthy.am = 0.1;
  healthy.pm = 0.2;
  const test::GearSignal faulty;
  const RegularComponents regular{.mesh_order = 28};
  const double v_h = ResidualVariance(AveragedGearSignal(healthy).values, regular);
  const SynchronousAverage tsa_f = AveragedGearSignal(faulty);
  const double na4 = Na4(tsa_f.values, regular, std::vector<double>{v_h});
  const test::Moments r_h = test::CosineSeriesMoments(healthy.Series(1));
  const test::Moments r_f = test::CosineSeriesMoments(faulty.Series(1));
  const double expected = r_f.m4 / std::pow(0.5 * (r_h.m2 + r_f.m2), 2);
  EXPECT_NEAR(na4, expected, 1e-3 * expected);
  // The trend's mean variance is below the faulty run's own (the healthy residual is smaller),
  // so NA4 exceeds the faulty residual's kurtosis: it grows with the damage against the baseline
  EXPECT_LT(Na4(tsa_f.values, regular), na4);
}

TEST(ConditionIndicators, PureAmplitudeModulationLeavesNoDifferenceSignal) {
  // (1 + 0.3 cos θ) cos 28θ: only the mesh order and its first-order sidebands, so the difference
  // signal is rounding noise and FM4 undefined; the residual 0.3 cos θ cos 28θ is a product of
  // cosines of unrelated orders, kurtosis (3/8)^2 / (1/2)^4 = 9/4
  std::vector<double> tsa(kS);
  for (int j = 0; j < kS; ++j) {
    const double theta = kTwoPi * j / kS;
    tsa[j] = (1 + 0.3 * std::cos(theta)) * std::cos(28 * theta);
  }
  EXPECT_TRUE(std::isnan(Fm4(tsa, {.mesh_order = 28})));
  EXPECT_NEAR(Na4(tsa, {.mesh_order = 28}), 2.25, 1e-9);
}

TEST(ConditionIndicators, RejectsMeshOrdersTheTsaCannotHold) {
  const std::vector<double> tsa(64, 0.0);
  EXPECT_THROW(Fm4(tsa, {.mesh_order = 32}), std::invalid_argument);
  EXPECT_THROW(Fm0(tsa, 0), std::invalid_argument);
  EXPECT_NO_THROW(Fm0(std::vector<double>(64, 1.0), 31));
}

}  // namespace
}  // namespace orrery::signal

// Welch PSD (tools/signal/welch_psd.h) against Parseval's theorem: exactly for a rectangular
// window and segments that tile the record, statistically for Hann segments of white noise, and
// against the known power of a sine and the known density of white noise.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/welch_psd.h"

namespace orrery::signal {
namespace {

std::vector<double> WhiteNoise(int n, double sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

double Integral(const PowerSpectralDensity& p) {
  double sum = 0;
  for (double s : p.psd) sum += s * p.resolution_hz;
  return sum;
}

TEST(WelchPsd, ParsevalExactWithRectangularTiles) {
  // Discrete Parseval per segment: sum_k |X_k|^2 over all N bins = N sum x^2, and the one-sided
  // scaling folds the two halves: sum_k S_k Δf = mean square of the record
  const std::vector<double> x = WhiteNoise(8192, 0.3, 1);
  double mean_square = 0;
  for (double v : x) mean_square += v * v;
  mean_square /= x.size();
  for (int length : {1024, 2048, 8192, 1000}) {
    if (8192 % length) continue;
    const PowerSpectralDensity p = WelchPsd(x, 5000.0, {.segment_length = length, .overlap = 0, .window = WindowKind::kRectangular});
    EXPECT_EQ(p.segments, 8192 / length);
    EXPECT_NEAR(Integral(p), mean_square, 1e-12 * mean_square) << length;
  }
  // Odd length: no Nyquist bin, same identity
  const std::vector<double> y(x.begin(), x.begin() + 999 * 3);
  double ms = 0;
  for (double v : y) ms += v * v;
  ms /= y.size();
  const PowerSpectralDensity odd = WelchPsd(y, 5000.0, {.segment_length = 999, .overlap = 0, .window = WindowKind::kRectangular});
  EXPECT_NEAR(Integral(odd), ms, 1e-12 * ms);
}

TEST(WelchPsd, ParsevalForWhiteNoiseWithHannSegments) {
  // E[sum S_k Δf] = σ^2 for stationary noise. The estimate averages K segments of L samples
  // (Hann-weighted); its relative standard deviation is about sqrt(2 / (K L / ENBW_bins)) with
  // overlap making segments partly dependent: for K ~ 63, L = 4096 below 0.5 %; 5 % is > 10 sigma
  const double sigma = 2.0;
  const std::vector<double> x = WhiteNoise(131072, sigma, 2);
  const PowerSpectralDensity p = WelchPsd(x, 10000.0, {.segment_length = 4096, .overlap = 0.5});
  EXPECT_EQ(p.segments, 63);
  EXPECT_NEAR(Integral(p), sigma * sigma, 0.05 * sigma * sigma);
  // The density itself: flat at σ^2 / (f_s / 2); the mean over the interior bins has the same
  // relative spread as the integral
  double mean = 0;
  for (std::size_t k = 1; k + 1 < p.psd.size(); ++k) mean += p.psd[k];
  mean /= static_cast<double>(p.psd.size() - 2);
  EXPECT_NEAR(mean, sigma * sigma / 5000.0, 0.05 * sigma * sigma / 5000.0);
}

TEST(WelchPsd, SinePowerIsHalfItsAmplitudeSquared) {
  // A sine a cos(2π f t) on a bin of every segment: its power a^2/2 lies in its main lobe
  const double fs = 8192, a = 3.0;
  std::vector<double> x(8192 * 4);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = a * std::cos(2 * std::numbers::pi * 512.0 * i / fs);
  for (WindowKind kind : {WindowKind::kHann, WindowKind::kFlatTop, WindowKind::kRectangular}) {
    const PowerSpectralDensity p = WelchPsd(x, fs, {.segment_length = 1024, .window = kind});
    EXPECT_NEAR(Integral(p), a * a / 2, 1e-10) << WindowName(kind);
    // Peak density: the sine's power over the window's ENBW
    EXPECT_NEAR(p.psd[64], a * a / 2 / p.enbw_hz, 1e-9) << WindowName(kind);
  }
}

TEST(WelchPsd, DefaultSegmentsAndErrors) {
  const std::vector<double> x = WhiteNoise(20000, 1.0, 3);
  const PowerSpectralDensity p = WelchPsd(x, 20000.0);
  EXPECT_LE(p.segment_length, 2 * 20000 / 9);
  EXPECT_GE(p.segments, 8);
  EXPECT_THROW(WelchPsd(x, 20000.0, {.segment_length = 30000}), std::invalid_argument);
  EXPECT_THROW(WelchPsd(x, 20000.0, {.overlap = 1.0}), std::invalid_argument);
  EXPECT_THROW(WelchPsd(x, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

// Time-synchronous average (tools/signal/time_synchronous_average.h): a periodic signal plus
// white noise keeps its periodic part while the noise falls by sqrt(R) in RMS (R revolutions;
// the averaged noise is Gaussian with variance σ^2/R, so the mean square of S averaged samples,
// times S R / σ^2, is χ^2 with S degrees of freedom), and a component of non-integer order ν
// falls by |sin(π R ν) / (R sin(π ν))| (McFadden 1987).
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/time_synchronous_average.h"

namespace orrery::signal {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

double Periodic(double theta) { return 1.0 * std::cos(7 * theta) + 0.4 * std::sin(21 * theta + 0.5) + 0.1 * std::cos(theta); }

// Mean square of (TSA - periodic part) over the S samples, relative to σ^2 / R
double NoiseRatio(int revolutions, int S, double sigma, unsigned seed) {
  // The angle grid falls on the time samples (S per revolution at constant speed), so the
  // resampling passes samples through unchanged and the noise stays white
  const int n = revolutions * S + 1;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> angle(n), x(n);
  for (int i = 0; i < n; ++i) {
    angle[i] = kTwoPi * i / S;
    x[i] = Periodic(angle[i]) + g(rng);
  }
  const SynchronousAverage tsa = TimeSynchronousAverage(x, angle, S);
  EXPECT_EQ(tsa.revolutions, revolutions);
  double ms = 0;
  for (int j = 0; j < S; ++j) ms += std::pow(tsa.values[j] - Periodic(kTwoPi * j / S), 2);
  return ms / S / (sigma * sigma / revolutions);
}

TEST(TimeSynchronousAverage, NoiseFallsBySqrtOfTheRevolutions) {
  // χ^2_S / S has mean 1 and standard deviation sqrt(2/S) = 0.045 for S = 1000: bounds of +-0.25
  // are more than 5 standard deviations
  const int S = 1000;
  for (int revolutions : {4, 25, 100}) {
    const double ratio = NoiseRatio(revolutions, S, 0.5, 11 + revolutions);
    EXPECT_NEAR(ratio, 1.0, 0.25) << revolutions << " revolutions";
  }
}

TEST(TimeSynchronousAverage, NonIntegerOrderFallsByTheDirichletKernel) {
  // cos(ν θ), ν = 3.25, averaged over R = 10 revolutions: amplitude |sin(π R ν)/(R sin(π ν))|
  // = 1 / (10 sin(0.25 π)) = 0.1414; fitted by least squares to cos and sin of ν θ over one
  // revolution (exact: the average is a cos(ν θ + φ))
  const int S = 256, R = 10;
  const double nu = 3.25;
  const int n = R * S + 1;
  std::vector<double> angle(n), x(n);
  for (int i = 0; i < n; ++i) {
    angle[i] = kTwoPi * i / S;
    x[i] = std::cos(nu * angle[i]);
  }
  const SynchronousAverage tsa = TimeSynchronousAverage(x, angle, S);
  double cc = 0, ss = 0, cs = 0, xc = 0, xs = 0;
  for (int j = 0; j < S; ++j) {
    const double c = std::cos(nu * kTwoPi * j / S), s = std::sin(nu * kTwoPi * j / S);
    cc += c * c, ss += s * s, cs += c * s, xc += tsa.values[j] * c, xs += tsa.values[j] * s;
  }
  const double det = cc * ss - cs * cs;
  const double a = (xc * ss - xs * cs) / det, b = (xs * cc - xc * cs) / det;
  const double expected = std::abs(std::sin(std::numbers::pi * R * nu) / (R * std::sin(std::numbers::pi * nu)));
  EXPECT_NEAR(std::hypot(a, b), expected, 1e-10);
  EXPECT_NEAR(expected, 0.1414, 1e-4);
}

TEST(TimeSynchronousAverage, NeedsOneRevolution) {
  std::vector<double> angle(50), x(50, 1.0);
  for (int i = 0; i < 50; ++i) angle[i] = 0.1 * i;  // 4.9 rad
  EXPECT_THROW(TimeSynchronousAverage(x, angle, 32), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

// Order resampling (tools/signal/order_resample.h) of a chirp: a component locked to a member
// that speeds up from 5 to 25 rev/s is one line in the angle domain. Oracle: the chirp's closed
// form sin(K θ) at the grid angles, and the cubic interpolant's remainder bound.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/order_resample.h"
#include "tools/signal/peaks.h"

namespace orrery::signal {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

TEST(OrderResample, ChirpBecomesOneOrderLine) {
  // θ(t) = 2π (f0 t + a t^2 / 2), f0 = 5 rev/s, a = 10 rev/s^2, 2 s: 30 revolutions, speed
  // 5 -> 25 rev/s; x = sin(K θ) with K = 12 orders, i.e. 60 -> 300 Hz; sampled at 10 kHz
  const double fs = 10000, f0 = 5, a = 10;
  const int K = 12, n = 20001;
  std::vector<double> angle(n), x(n);
  for (int i = 0; i < n; ++i) {
    const double t = i / fs;
    angle[i] = kTwoPi * (f0 * t + 0.5 * a * t * t);
    x[i] = std::sin(K * angle[i]);
  }
  // Samples per revolution: the time grid at the slowest speed, 10000/5 = 2000 (2000 = 2^4 5^3)
  const int S = DefaultSamplesPerRevolution(angle);
  EXPECT_EQ(S, 2000);
  const AngleDomainSignal r = OrderResample(x, angle, S);
  EXPECT_EQ(r.direction, 1.0);
  EXPECT_DOUBLE_EQ(r.first_angle_rad, 0.0);
  EXPECT_EQ(r.values.size(), 30u * 2000 + 1);

  // Against sin(K φ_j): the cubic's remainder is at most (K h)^4 / 24 with h the largest angle
  // step between time samples, 2π 25/10000 rad: (12 · 0.0157)^4 / 24 = 5.2e-5 (9/384 instead
  // of 1/24 away from the record's ends)
  const double h = kTwoPi * 25 / fs;
  const double bound = std::pow(K * h, 4) / 24.0;
  double worst = 0;
  for (std::size_t j = 0; j < r.values.size(); ++j)
    worst = std::max(worst, std::abs(r.values[j] - std::sin(K * (r.first_angle_rad + j * kTwoPi / S))));
  EXPECT_LT(worst, bound);
  EXPECT_GT(worst, 1e-3 * bound);  // the bound is not vacuous: the error is of its order

  // Order spectrum of the 30 whole revolutions: one line at order 12, amplitude 1 (on a bin)
  const std::vector<double> whole(r.values.begin(), r.values.begin() + 30 * S);
  const Spectrum orders = AmplitudeSpectrum(whole, S, WindowKind::kHann);
  EXPECT_NEAR(orders.resolution, 1.0 / 30, 1e-15);
  const std::vector<Peak> peaks = FindPeaks(orders, {.max_peaks = 1});
  ASSERT_EQ(peaks.size(), 1u);
  EXPECT_NEAR(peaks[0].frequency, 12.0, 1e-6);
  EXPECT_NEAR(peaks[0].amplitude, 1.0, 1e-4);
  // The same record in time: smeared over 60..300 Hz, no line near amplitude 1
  const Spectrum time = AmplitudeSpectrum(x, fs, WindowKind::kHann);
  EXPECT_LT(FindPeaks(time, {.max_peaks = 1})[0].amplitude, 0.2);
}

TEST(OrderResample, BackwardsAndWrappedAnglesAndAlignment) {
  // A member turning backwards at 10 rev/s whose angle is wrapped to (-π, π]: unwrapped, read
  // forwards, and the grid starts at the next whole revolution of the forward angle
  const double fs = 1000;
  const int n = 1000;
  std::vector<double> angle(n), x(n);
  for (int i = 0; i < n; ++i) {
    const double theta = -(0.3 + kTwoPi * 10 * i / fs);
    angle[i] = std::remainder(theta, kTwoPi);
    x[i] = std::cos(3 * theta);
  }
  const AngleDomainSignal r = OrderResample(x, angle, 64);
  EXPECT_EQ(r.direction, -1.0);
  // Forward angle starts at 0.3 - wrapped: the first multiple of 2π at or after it
  EXPECT_GE(r.first_angle_rad, std::remainder(0.3, kTwoPi) - 1e-12);
  EXPECT_LT(r.first_angle_rad - std::remainder(0.3, kTwoPi), kTwoPi);
  EXPECT_NEAR(std::remainder(r.first_angle_rad, kTwoPi), 0.0, 1e-12);
  // cos(3θ) is even in θ: at forward angle φ it is cos(3φ), to the cubic's remainder bound
  // (3h)^4 / 24 with h = 2π/100 (1.3e-4; the grid's last points lie in the record's last
  // interval, where the stencil cannot be centred)
  const double bound = std::pow(3 * kTwoPi / 100, 4) / 24.0;
  for (std::size_t j = 0; j < r.values.size(); ++j)
    ASSERT_NEAR(r.values[j], std::cos(3 * (r.first_angle_rad + j * kTwoPi / 64)), bound) << j;
}

TEST(OrderResample, RejectsStandstillAndBadSizes) {
  std::vector<double> angle = {0, 0.1, 0.2, 0.2, 0.3, 0.4};
  std::vector<double> x(6, 1.0);
  try {
    OrderResample(x, angle, 16);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not strictly monotonic at sample 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(OrderResample(std::vector<double>(5, 0.0), angle, 16), std::invalid_argument);
  EXPECT_THROW(OrderResample(x, std::vector<double>{0, 1, 2, 3, 4, 5}, 2), std::invalid_argument);
  // Less than 4 grid samples
  EXPECT_THROW(OrderResample(x, std::vector<double>{0, 1e-3, 2e-3, 3e-3, 4e-3, 5e-3}, 16), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

// Spectrogram (tools/signal/spectrogram.h): a sine whose frequency steps half-way shows each
// frequency at its amplitude in the segments that hold it.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/spectrogram.h"

namespace orrery::signal {
namespace {

TEST(Spectrogram, SteppedSineAtItsAmplitudeInEachHalf) {
  // 2 s at 8192 Hz: 500 Hz at amplitude 2 for 1 s, then 1500 Hz at amplitude 0.5; segments of
  // 1024 samples have 8 Hz bins, so both sines sit half-way between two bins
  const double fs = 8192;
  std::vector<double> x(2 * 8192);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = i / fs;
    x[i] = t < 1.0 ? 2.0 * std::sin(2 * std::numbers::pi * 500 * t) : 0.5 * std::sin(2 * std::numbers::pi * 1500 * t);
  }
  const Spectrogram g = AmplitudeSpectrogram(x, fs, 1024, 0.5, WindowKind::kHann);
  ASSERT_EQ(g.time_s.size(), 31u);  // (16384 - 1024) / 512 + 1
  EXPECT_DOUBLE_EQ(g.resolution_hz, 8.0);
  EXPECT_DOUBLE_EQ(g.time_s.front(), 512 / fs);
  // 500 and 1500 Hz lie half-way between 8 Hz bins: read the largest bin of each row against
  // the Hann scalloping bound and the interpolated value
  for (std::size_t i = 0; i < g.time_s.size(); ++i) {
    const bool first_half = g.time_s[i] + 512 / fs <= 1.0;
    const bool second_half = g.time_s[i] - 512 / fs >= 1.0;
    if (!first_half && !second_half) continue;  // the segment straddles the step
    Eigen::Index k = 0;
    const double largest = g.amplitude.row(static_cast<Eigen::Index>(i)).maxCoeff(&k);
    const double f = first_half ? 500 : 1500, a = first_half ? 2.0 : 0.5;
    EXPECT_NEAR(g.frequency_hz[k], f, 4.0 + 1e-9) << "row " << i;
    // Half a bin off: K(1/2) = 0.8488 of the amplitude (Hann)
    EXPECT_NEAR(largest, a * WindowResponse(WindowKind::kHann, 0.5), 1e-3 * a) << "row " << i;
  }
  EXPECT_THROW(AmplitudeSpectrogram(x, fs, 1, 0.5, WindowKind::kHann), std::invalid_argument);
  EXPECT_THROW(AmplitudeSpectrogram(x, fs, 1024, 1.5, WindowKind::kHann), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

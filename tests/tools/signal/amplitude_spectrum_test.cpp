// Amplitude spectra and peaks (tools/signal/amplitude_spectrum.h, peaks.h) of records of known
// sines: amplitudes exact on the bins, within the window's scalloping loss between them (Harris
// 1978 Table 1: Hann 1.42 dB), and recovered by the peak interpolation to within what leakage
// from the other sines allows.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/peaks.h"

namespace orrery::signal {
namespace {

struct Sine {
  double amplitude, frequency_hz, phase_rad;
};

std::vector<double> Sines(const std::vector<Sine>& sines, double fs, int n, double offset = 0) {
  std::vector<double> x(n, offset);
  for (int i = 0; i < n; ++i)
    for (const Sine& s : sines) x[i] += s.amplitude * std::cos(2 * std::numbers::pi * s.frequency_hz * i / fs + s.phase_rad);
  return x;
}

TEST(AmplitudeSpectrum, SinesOnBinsReadTheirAmplitudes) {
  // 1 s at 20 kHz: bins 1 Hz apart; Hann's response is exactly 0 at whole bins >= 2 away, so
  // sines at least 2 bins apart do not disturb each other's bin
  const double fs = 20000;
  const int n = 20000;
  const std::vector<Sine> sines = {{1.5, 220, 0.3}, {0.25, 236, -1.0}, {0.04, 1000, 2.0}, {3.0, 5000, 0.0}};
  const Spectrum s = AmplitudeSpectrum(Sines(sines, fs, n, 0.7), fs, WindowKind::kHann);
  ASSERT_EQ(s.amplitude.size(), 10001u);
  EXPECT_DOUBLE_EQ(s.resolution, 1.0);
  EXPECT_NEAR(s.enbw, 1.5, 1e-12);
  for (const Sine& sine : sines) {
    const int bin = static_cast<int>(sine.frequency_hz);
    EXPECT_NEAR(s.frequency[bin], sine.frequency_hz, 1e-12);
    EXPECT_NEAR(s.amplitude[bin], sine.amplitude, 1e-10) << sine.frequency_hz;
  }
  // The mean is A_0
  EXPECT_NEAR(s.amplitude[0], 0.7, 1e-10);
  // Bins 2 or more away from every sine and from DC are empty (rounding only)
  EXPECT_LT(s.amplitude[600], 1e-12);
}

TEST(AmplitudeSpectrum, NyquistAndOddLengthsScale) {
  // x_n = a (-1)^n: all at the Nyquist bin, single-sided amplitude a (no doubling there)
  std::vector<double> x(64);
  for (int i = 0; i < 64; ++i) x[i] = (i % 2 ? -0.5 : 0.5);
  const Spectrum s = AmplitudeSpectrum(x, 64.0, WindowKind::kRectangular);
  EXPECT_NEAR(s.amplitude[32], 0.5, 1e-14);
  // Odd length: a bin-centred sine reads its amplitude
  const Spectrum odd = AmplitudeSpectrum(Sines({{2.0, 10, 0.4}}, 99, 99), 99.0, WindowKind::kHann);
  EXPECT_EQ(odd.amplitude.size(), 50u);
  EXPECT_NEAR(odd.amplitude[10], 2.0, 1e-12);
}

TEST(AmplitudeSpectrum, BetweenBinsWithinTheScallopingLoss) {
  // A sine swept across a bin: the largest bin reads a K(δ), δ <= 1/2, so it stays within
  // [a 10^(-L/20), a] with L the scalloping loss (Hann 1.42 dB: 0.849 a; flat-top 0.02 dB)
  const double fs = 1024;
  const int n = 1024;
  for (WindowKind kind : {WindowKind::kHann, WindowKind::kFlatTop, WindowKind::kRectangular}) {
    const double floor = std::pow(10.0, -MaxScallopingLossDb(kind) / 20);
    for (double offset = 0; offset <= 1.0; offset += 0.125) {
      const double f = 100 + offset;
      const Spectrum s = AmplitudeSpectrum(Sines({{1.0, f, 0.2}}, fs, n), fs, kind);
      double largest = 0;
      for (double a : s.amplitude) largest = std::max(largest, a);
      // Leakage of the image at -f adds at most the response 2f bins away (< 1e-3 for these)
      EXPECT_GE(largest, floor - 2e-3) << WindowName(kind) << " at " << f;
      EXPECT_LE(largest, 1.0 + 2e-3) << WindowName(kind) << " at " << f;
    }
  }
  EXPECT_NEAR(std::pow(10.0, -MaxScallopingLossDb(WindowKind::kHann) / 20), 0.8488, 1e-4);
}

TEST(FindPeaks, InterpolationRecoversFrequencyAndAmplitude) {
  // Three sines between bins, far apart (hundreds of bins): the interpolated peaks recover the
  // sines to the leakage of the others (Hann's response ~ 1/ν^3: < 1e-6 at 100 bins)
  const double fs = 20000;
  const int n = 20000;
  const std::vector<Sine> sines = {{1.0, 220.3, 0.0}, {0.3, 661.77, 1.0}, {0.05, 3311.5, -2.0}};
  const Spectrum s = AmplitudeSpectrum(Sines(sines, fs, n), fs, WindowKind::kHann);
  const std::vector<Peak> peaks = FindPeaks(s);
  ASSERT_EQ(peaks.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(peaks[i].frequency, sines[i].frequency_hz, 1e-3 * s.resolution);
    EXPECT_NEAR(peaks[i].amplitude, sines[i].amplitude, 1e-4 * sines[i].amplitude);
  }
  // Hann: Grandke's closed form δ = (2ρ - 1)/(ρ + 1) gives the same frequency
  const int k = peaks[0].bin;
  const double rho = s.amplitude[k + 1] / s.amplitude[k];
  EXPECT_NEAR(peaks[0].frequency, (k + (2 * rho - 1) / (rho + 1)) * s.resolution, 1e-9);
}

TEST(FindPeaks, FlatTopAndRectangularInterpolate) {
  const double fs = 4096;
  const int n = 4096;
  for (WindowKind kind : {WindowKind::kFlatTop, WindowKind::kRectangular}) {
    const Spectrum s = AmplitudeSpectrum(Sines({{2.0, 512.37, 0.5}}, fs, n), fs, kind);
    const std::vector<Peak> peaks = FindPeaks(s, {.max_peaks = 1});
    ASSERT_EQ(peaks.size(), 1u);
    // The rectangular window's slow leakage (1/ν) from the image at -f limits it to ~1e-3
    EXPECT_NEAR(peaks[0].frequency, 512.37, 2e-3) << WindowName(kind);
    EXPECT_NEAR(peaks[0].amplitude, 2.0, 2e-3 * 2.0) << WindowName(kind);
  }
}

TEST(FindPeaks, ThresholdCountAndLowBins) {
  const double fs = 1000;
  const std::vector<double> x = Sines({{1.0, 100, 0}, {1e-4, 300, 0}, {0.01, 400, 0}}, fs, 1000, 5.0);
  const Spectrum s = AmplitudeSpectrum(x, fs, WindowKind::kHann);
  // -60 dB default: the 1e-4 sine is below it; the large mean (bins 0..1) is skipped
  const std::vector<Peak> peaks = FindPeaks(s);
  ASSERT_EQ(peaks.size(), 2u);
  EXPECT_NEAR(peaks[0].frequency, 100, 1e-9);
  EXPECT_NEAR(peaks[1].frequency, 400, 1e-9);
  EXPECT_EQ(FindPeaks(s, {.max_peaks = 1}).size(), 1u);
  EXPECT_EQ(FindPeaks(s, {.min_relative_amplitude = 1e-6}).size(), 3u);
}

TEST(AmplitudeSpectrum, RejectsBadInput) {
  EXPECT_THROW(AmplitudeSpectrum(std::vector<double>{1.0}, 10, WindowKind::kHann), std::invalid_argument);
  EXPECT_THROW(AmplitudeSpectrum(std::vector<double>{1.0, 2.0}, 0, WindowKind::kHann), std::invalid_argument);
  EXPECT_THROW(AmplitudeSpectrum(std::vector<double>{1.0, NAN}, 10, WindowKind::kHann), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

// One-third-octave levels (tools/signal/third_octave.h): the nominal mid-band frequencies of
// IEC 61260-1:2014 Annex E (ISO 266), the base-ten band edges, and pure sines landing in the
// right band at L = 20 log10((a/√2) / 1e-6) dB (seed 000 eq. 27: a the band's RMS value).
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/third_octave.h"

namespace orrery::signal {
namespace {

TEST(ThirdOctave, NominalMidBandFrequenciesOfIec61260) {
  // IEC 61260-1:2014 Annex E, one-third-octave nominal mid-band frequencies 10 Hz .. 20 kHz
  const double nominal[] = {10,   12.5, 16,   20,   25,   31.5, 40,   50,    63,    80,    100,   125,
                            160,  200,  250,  315,  400,  500,  630,  800,   1000,  1250,  1600,  2000,
                            2500, 3150, 4000, 5000, 6300, 8000, 10000, 12500, 16000, 20000};
  for (int i = 0; i < 34; ++i) {
    const int x = i - 20;
    EXPECT_DOUBLE_EQ(NominalThirdOctaveHz(x), nominal[i]) << "band " << x;
    // The exact base-ten mid-band frequency rounds to it within 2 % (IEC's preferred numbers)
    EXPECT_NEAR(1000 * std::pow(10.0, x / 10.0) / nominal[i], 1.0, 0.02) << "band " << x;
  }
}

TEST(ThirdOctave, PureSinesLandInTheirBandAtTheirLevel) {
  // 4 s at 20 kHz (0.25 Hz bins). Sines of amplitude a, each at least 28 bins inside one band
  // (edges at f_m 10^(+-1/20)); Hann's response d bins away is below 1/(π d (d^2 - 1)), 1.5e-5
  // at 28 bins, so the band holds a^2/2 to 1e-9 and the level is exact to 1e-4 dB, and the
  // neighbouring bands sit more than 80 dB lower
  const double fs = 20000;
  const int n = 80000;
  struct Case {
    double frequency_hz, amplitude, nominal_hz;
  };
  for (const Case& c : {Case{1000.0, 0.5, 1000}, Case{1234.5, 2.0, 1250}, Case{63.3, 0.01, 63}, Case{7777.0, 30.0, 8000}}) {
    std::vector<double> x(n);
    for (int i = 0; i < n; ++i) x[i] = c.amplitude * std::sin(2 * std::numbers::pi * c.frequency_hz * i / fs + 0.3) + 0.2;
    const std::vector<OctaveBand> bands = ThirdOctaveLevels(x, fs);
    const OctaveBand* hit = nullptr;
    for (const OctaveBand& b : bands)
      if (b.lower_hz <= c.frequency_hz && c.frequency_hz < b.upper_hz) hit = &b;
    ASSERT_NE(hit, nullptr) << c.frequency_hz;
    EXPECT_DOUBLE_EQ(hit->nominal_hz, c.nominal_hz);
    const double level = 20 * std::log10(c.amplitude / std::sqrt(2.0) / 1e-6);
    EXPECT_NEAR(hit->level_db, level, 1e-4) << c.frequency_hz;
    EXPECT_NEAR(hit->rms, c.amplitude / std::sqrt(2.0), 1e-5 * c.amplitude);
    for (const OctaveBand& b : bands) {
      if (&b == hit) continue;
      EXPECT_LT(b.level_db, level - 80) << c.frequency_hz << " Hz leaks into " << b.nominal_hz;
    }
  }
}

TEST(ThirdOctave, BandsCoverWhatTheRecordResolves) {
  // 0.1 s at 20 kHz: 10 Hz bins; the first band's lower edge lies at least 40 Hz up, the last
  // band's upper edge at or below 10 kHz (the 8 kHz band; 10 kHz's edge is 11.2 kHz)
  std::vector<double> x(2000, 0.0);
  x[3] = 1;
  const std::vector<OctaveBand> bands = ThirdOctaveLevels(x, 20000.0);
  EXPECT_GE(bands.front().lower_hz, 40.0);
  EXPECT_DOUBLE_EQ(bands.front().nominal_hz, 50);
  EXPECT_DOUBLE_EQ(bands.back().nominal_hz, 8000);
  for (std::size_t i = 1; i < bands.size(); ++i) EXPECT_NEAR(bands[i].lower_hz, bands[i - 1].upper_hz, 1e-9);
  EXPECT_THROW(ThirdOctaveLevels(std::vector<double>(8, 0.0), 1000.0), std::invalid_argument);
  EXPECT_THROW(ThirdOctaveLevels(std::vector<double>(16, 0.0), 1000.0, {.reference = 0}), std::invalid_argument);
  // No band in the range asked for
  EXPECT_THROW(ThirdOctaveLevels(std::vector<double>(2000, 0.0), 20000.0, {.max_frequency_hz = 10}), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

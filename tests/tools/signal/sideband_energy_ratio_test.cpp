// Sideband energy ratio (tools/signal/sideband_energy_ratio.h) of the synthetic AM/FM gear signal
// (synthetic_gear_signal.h) against its closed form
//   SER = sum_{k=1}^{3} sum_{n=1}^{N} (c_{k,n}^2 + c_{k,-n}^2) / sum_{k=1}^{3} c_{k,0}^2
// (powers of cosines of amplitude c are c^2/2; the halves cancel), and of pure AM, m^2/2.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tests/tools/signal/synthetic_gear_signal.h"
#include "tools/signal/sideband_energy_ratio.h"

namespace orrery::signal {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// The gear signal at constant speed f_r rev/s, sampled at 20 kHz for 2 s
std::vector<double> Record(const test::GearSignal& gear, double f_r) {
  std::vector<double> x(40000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = gear.Value(kTwoPi * f_r * i / 20000.0);
  return x;
}

double ClosedForm(const test::GearSignal& gear, int sidebands) {
  double side = 0, carrier = 0;
  for (int k = 1; k <= 3; ++k) {
    carrier += std::pow(gear.Coefficient(k, 0), 2);
    for (int n = 1; n <= sidebands; ++n) side += std::pow(gear.Coefficient(k, n), 2) + std::pow(gear.Coefficient(k, -n), 2);
  }
  return side / carrier;
}

TEST(SidebandEnergyRatio, AmFmGearSignalOnBins) {
  // 10 rev/s for 2 s: every order sits on a bin (0.5 Hz) and lines are 20 bins apart; Hann's
  // response is zero at whole bins beyond 1, so each line's power lies whole in its +-2 bins:
  // the ratio is exact to rounding
  const test::GearSignal gear;
  const Spectrum s = AmplitudeSpectrum(Record(gear, 10.0), 20000.0, WindowKind::kHann);
  const SidebandEnergy e = SidebandEnergyRatio(s, 280.0, 10.0);
  EXPECT_EQ(e.harmonics, 3);
  EXPECT_EQ(e.sidebands, 6);
  EXPECT_NEAR(e.ratio, ClosedForm(gear, 6), 1e-9 * ClosedForm(gear, 6));
  // Carrier power of the first harmonic: c_{1,0}^2 / 2
  EXPECT_NEAR(e.carrier_power_per_harmonic[0], 0.5 * std::pow(gear.Coefficient(1, 0), 2), 1e-12);
  std::printf("SER %.9f, closed form %.9f\n", e.ratio, ClosedForm(gear, 6));
  // Two sideband pairs
  EXPECT_NEAR(SidebandEnergyRatio(s, 280.0, 10.0, {.sidebands = 2}).ratio, ClosedForm(gear, 2), 1e-9);
}

TEST(SidebandEnergyRatio, AmFmGearSignalBetweenBins) {
  // 10.137 rev/s: the lines fall between bins. Hann keeps at least 99.91 % of a line's power
  // within +-2 bins (the worst case, half a bin off: K(0.5)^2 + K(1.5)^2 on each side, of 1.5
  // in all), and the neighbours (20 bins away) leak below 1e-4 in amplitude: 0.3 %
  const test::GearSignal gear;
  const Spectrum s = AmplitudeSpectrum(Record(gear, 10.137), 20000.0, WindowKind::kHann);
  const SidebandEnergy e = SidebandEnergyRatio(s, 28 * 10.137, 10.137);
  EXPECT_NEAR(e.ratio, ClosedForm(gear, 6), 3e-3 * ClosedForm(gear, 6));
}

TEST(SidebandEnergyRatio, PureAmplitudeModulationIsHalfTheIndexSquared) {
  // a (1 + m cos 2π f_x t) cos 2π f_m t: sidebands a m/2 each side, SER = 2 (a m/2)^2 / a^2 = m^2/2
  test::GearSignal gear;
  gear.pm = 0;
  gear.am = 0.4;
  const Spectrum s = AmplitudeSpectrum(Record(gear, 10.0), 20000.0, WindowKind::kFlatTop);
  EXPECT_NEAR(SidebandEnergyRatio(s, 280.0, 10.0).ratio, 0.08, 1e-9);
}

TEST(SidebandEnergyRatio, LimitsAndErrors) {
  const test::GearSignal gear;
  const Spectrum s = AmplitudeSpectrum(Record(gear, 10.0), 20000.0, WindowKind::kHann);
  // Sidebands 1.5 Hz apart are 3 bins apart: Hann's +-2-bin bands would share bins
  try {
    SidebandEnergyRatio(s, 280.0, 1.5);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not resolved"), std::string::npos) << e.what();
  }
  // 40 Hz modulation of a 280 Hz mesh: pairs with n f_x + 2 Δf < 140 Hz, i.e. 3
  EXPECT_EQ(SidebandEnergyRatio(s, 280.0, 40.0).sidebands, 3);
  // Harmonics above Nyquist are dropped
  EXPECT_EQ(SidebandEnergyRatio(s, 4000.0, 10.0).harmonics, 2);
  EXPECT_THROW(SidebandEnergyRatio(s, 12000.0, 10.0), std::invalid_argument);
  EXPECT_THROW(SidebandEnergyRatio(s, -1.0, 10.0), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

#include "tools/signal/sideband_energy_ratio.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace orrery::signal {

double LinePower(const Spectrum& s, double frequency, int band_bins) {
  const int b = band_bins >= 0 ? band_bins : MainLobeHalfWidthBins(s.window);
  const double enbw_bins = s.enbw / s.resolution;
  const double centre = frequency / s.resolution;
  const int last = static_cast<int>(s.amplitude.size()) - 1;
  const int lo = std::max(0, static_cast<int>(std::ceil(centre - b - 1e-9)));
  const int hi = std::min(last, static_cast<int>(std::floor(centre + b + 1e-9)));
  double power = 0;
  for (int j = lo; j <= hi; ++j) power += s.amplitude[j] * s.amplitude[j];
  return power / (2.0 * enbw_bins);
}

SidebandEnergy SidebandEnergyRatio(const Spectrum& s, double mesh_frequency, double modulation_frequency,
                                   const SidebandEnergyOptions& options) {
  if (!(mesh_frequency > 0) || !std::isfinite(mesh_frequency) || !(modulation_frequency > 0) ||
      !std::isfinite(modulation_frequency))
    throw std::invalid_argument("SidebandEnergyRatio: mesh and modulation frequencies must be positive");
  const int b = options.band_bins >= 0 ? options.band_bins : MainLobeHalfWidthBins(s.window);
  const double band = b * s.resolution;
  // Sidebands resolved: neighbouring lines share no bin
  if (!(modulation_frequency > 2 * band)) {
    std::ostringstream msg;
    msg << "sidebands " << modulation_frequency << " apart are not resolved: the " << WindowName(s.window)
        << " window's main lobe spans +-" << b << " bins of " << s.resolution << "; a record longer than "
        << 2.0 * b / modulation_frequency << " (1/resolution units) is needed";
    throw std::invalid_argument(msg.str());
  }
  // Sideband pairs that stay on their harmonic's side of the midpoint to the next
  int sidebands = options.sidebands;
  while (sidebands > 0 && !(sidebands * modulation_frequency + band < 0.5 * mesh_frequency)) --sidebands;
  if (sidebands < 1)
    throw std::invalid_argument("SidebandEnergyRatio: no sideband of " + std::to_string(modulation_frequency) +
                                " fits within half the mesh frequency " + std::to_string(mesh_frequency));
  // Harmonics whose outermost sideband band lies below Nyquist
  const double nyquist = s.frequency.back();
  int harmonics = 0;
  while (harmonics < options.harmonics &&
         (harmonics + 1) * mesh_frequency + sidebands * modulation_frequency + band <= nyquist)
    ++harmonics;
  if (harmonics < 1)
    throw std::invalid_argument("SidebandEnergyRatio: the mesh frequency " + std::to_string(mesh_frequency) +
                                " and its sidebands lie above the Nyquist frequency " + std::to_string(nyquist));

  // Powers of carriers and sidebands per harmonic
  SidebandEnergy e;
  e.harmonics = harmonics;
  e.sidebands = sidebands;
  for (int k = 1; k <= harmonics; ++k) {
    const double carrier = LinePower(s, k * mesh_frequency, b);
    double side = 0;
    for (int n = 1; n <= sidebands; ++n)
      side += LinePower(s, k * mesh_frequency + n * modulation_frequency, b) +
              LinePower(s, k * mesh_frequency - n * modulation_frequency, b);
    e.carrier_power_per_harmonic.push_back(carrier);
    e.sideband_power_per_harmonic.push_back(side);
    e.carrier_power += carrier;
    e.sideband_power += side;
  }
  e.ratio = e.sideband_power / e.carrier_power;
  return e;
}

}  // namespace orrery::signal

#include "tools/signal/third_octave.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include "tools/signal/fft.h"
#include "tools/signal/window.h"

namespace orrery::signal {

double NominalThirdOctaveHz(int index) {
  // Preferred numbers of one decade, x = 0 (1 kHz) at the first
  static constexpr double kDecade[10] = {10, 12.5, 16, 20, 25, 31.5, 40, 50, 63, 80};
  const int position = ((index % 10) + 10) % 10;
  const int decade = (index - position) / 10;  // 0 for 1 kHz .. 8 kHz
  return kDecade[position] * std::pow(10.0, decade + 2);
}

std::vector<OctaveBand> ThirdOctaveLevels(std::span<const double> x, double sample_rate_hz,
                                          const ThirdOctaveOptions& options) {
  if (x.size() < 16) throw std::invalid_argument("ThirdOctaveLevels: need at least 16 samples, got " + std::to_string(x.size()));
  const int n = FastFftLength(static_cast<int>(x.size()));
  if (!(sample_rate_hz > 0) || !std::isfinite(sample_rate_hz))
    throw std::invalid_argument("ThirdOctaveLevels: sample rate must be positive, got " + std::to_string(sample_rate_hz));
  if (!(options.reference > 0)) throw std::invalid_argument("ThirdOctaveLevels: the reference value must be positive");

  // One-sided PSD of the mean-free, Hann-windowed record
  double mean = 0;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) throw std::invalid_argument("ThirdOctaveLevels: sample " + std::to_string(i) + " is not finite");
    mean += x[i];
  }
  mean /= n;
  const Window w = MakeWindow(WindowKind::kHann, n);
  std::vector<double> xw(n);
  for (int i = 0; i < n; ++i) xw[i] = w.w[i] * (x[i] - mean);
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins());
  fft.Forward(xw.data(), X.data());
  const double df = sample_rate_hz / n;
  std::vector<double> power(X.size());  // P_j = S_j Δf: mean square per bin
  for (std::size_t j = 0; j < X.size(); ++j) {
    const bool edge = j == 0 || (n % 2 == 0 && static_cast<int>(j) == n / 2);
    power[j] = (edge ? 1.0 : 2.0) * std::norm(X[j]) / (static_cast<double>(n) * w.sum_of_squares);
  }

  // Bands between 4 bins above DC and Nyquist
  const double nyquist = sample_rate_hz / 2;
  const double lowest = std::max(4 * df, 0.0);
  std::vector<OctaveBand> bands;
  for (int index = -30; index <= 80; ++index) {
    OctaveBand b;
    b.index = index;
    b.exact_hz = 1000.0 * std::pow(10.0, index / 10.0);
    b.lower_hz = b.exact_hz * std::pow(10.0, -1.0 / 20.0);
    b.upper_hz = b.exact_hz * std::pow(10.0, 1.0 / 20.0);
    b.nominal_hz = NominalThirdOctaveHz(index);
    if (b.lower_hz < lowest || b.upper_hz > nyquist * (1 + 1e-12)) continue;
    if (b.exact_hz < options.min_frequency_hz || b.exact_hz > options.max_frequency_hz) continue;
    // Bins weighted by the part of [(j - 1/2) Δf, (j + 1/2) Δf] inside the band
    double mean_square = 0;
    const int first = std::max(0, static_cast<int>(std::floor(b.lower_hz / df + 0.5)));
    const int last = std::min(static_cast<int>(power.size()) - 1, static_cast<int>(std::floor(b.upper_hz / df + 0.5)));
    for (int j = first; j <= last; ++j) {
      const double overlap = std::min(b.upper_hz, (j + 0.5) * df) - std::max(b.lower_hz, (j - 0.5) * df);
      if (overlap > 0) mean_square += power[j] * overlap / df;
    }
    b.rms = std::sqrt(mean_square);
    b.level_db = 20.0 * std::log10(b.rms / options.reference);
    bands.push_back(b);
  }
  if (bands.empty())
    throw std::invalid_argument("ThirdOctaveLevels: no one-third-octave band between " +
                                std::to_string(options.min_frequency_hz) + " and " + std::to_string(options.max_frequency_hz) +
                                " Hz fits a record of " + std::to_string(n) + " samples at " + std::to_string(sample_rate_hz) +
                                " Hz (resolution " + std::to_string(df) + " Hz, Nyquist " + std::to_string(nyquist) + " Hz)");
  return bands;
}

}  // namespace orrery::signal

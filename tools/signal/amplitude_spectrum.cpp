#include "tools/signal/amplitude_spectrum.h"

#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include "tools/signal/fft.h"

namespace orrery::signal {

Spectrum AmplitudeSpectrum(std::span<const double> x, double sample_rate, WindowKind window) {
  const int n = static_cast<int>(x.size());
  if (n < 2) throw std::invalid_argument("AmplitudeSpectrum: need at least 2 samples, got " + std::to_string(n));
  if (!(sample_rate > 0) || !std::isfinite(sample_rate))
    throw std::invalid_argument("AmplitudeSpectrum: sample rate must be positive, got " + std::to_string(sample_rate));
  const Window w = MakeWindow(window, n);

  // Windowed record, transformed
  std::vector<double> xw(n);
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]))
      throw std::invalid_argument("AmplitudeSpectrum: sample " + std::to_string(i) + " is not finite");
    xw[i] = w.w[i] * x[i];
  }
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins());
  fft.Forward(xw.data(), X.data());

  // Single-sided peak amplitudes: interior bins carry both halves of the two-sided spectrum
  Spectrum s;
  s.samples = n;
  s.window = window;
  s.resolution = sample_rate / n;
  s.enbw = w.enbw_bins * s.resolution;
  s.frequency.resize(X.size());
  s.amplitude.resize(X.size());
  for (std::size_t k = 0; k < X.size(); ++k) {
    const bool edge = k == 0 || (n % 2 == 0 && static_cast<int>(k) == n / 2);
    s.frequency[k] = static_cast<double>(k) * s.resolution;
    s.amplitude[k] = (edge ? 1.0 : 2.0) * std::abs(X[k]) / w.sum;
  }
  return s;
}

}  // namespace orrery::signal

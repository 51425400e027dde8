#include "tools/signal/welch_psd.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include "tools/signal/fft.h"

namespace orrery::signal {

PowerSpectralDensity WelchPsd(std::span<const double> x, double sample_rate_hz, const WelchOptions& options) {
  const int n = static_cast<int>(x.size());
  if (n < 2) throw std::invalid_argument("WelchPsd: need at least 2 samples, got " + std::to_string(n));
  if (!(sample_rate_hz > 0) || !std::isfinite(sample_rate_hz))
    throw std::invalid_argument("WelchPsd: sample rate must be positive, got " + std::to_string(sample_rate_hz));
  if (!(options.overlap >= 0 && options.overlap < 1))
    throw std::invalid_argument("WelchPsd: overlap must be in [0, 1), got " + std::to_string(options.overlap));
  // Segment length and step
  const int length = options.segment_length > 0 ? options.segment_length : FastFftLength(std::max(2, 2 * n / 9));
  if (length < 2) throw std::invalid_argument("WelchPsd: segment length must be >= 2, got " + std::to_string(length));
  if (length > n)
    throw std::invalid_argument("WelchPsd: record of " + std::to_string(n) + " samples is shorter than one segment (" +
                                std::to_string(length) + ")");
  const int step = std::max(1, length - static_cast<int>(std::lround(options.overlap * length)));
  const Window w = MakeWindow(options.window, length);

  // Average the segments' periodograms
  RealFft fft(length);
  std::vector<double> segment(length);
  std::vector<std::complex<double>> X(fft.bins());
  PowerSpectralDensity p;
  p.segment_length = length;
  p.psd.assign(fft.bins(), 0.0);
  for (int start = 0; start + length <= n; start += step, ++p.segments) {
    for (int i = 0; i < length; ++i) {
      if (!std::isfinite(x[start + i]))
        throw std::invalid_argument("WelchPsd: sample " + std::to_string(start + i) + " is not finite");
      segment[i] = w.w[i] * x[start + i];
    }
    fft.Forward(segment.data(), X.data());
    for (std::size_t k = 0; k < X.size(); ++k) p.psd[k] += std::norm(X[k]);
  }

  // One-sided scaling: interior bins carry both halves
  p.resolution_hz = sample_rate_hz / length;
  p.enbw_hz = w.enbw_bins * p.resolution_hz;
  p.frequency_hz.resize(p.psd.size());
  const double scale = 1.0 / (p.segments * sample_rate_hz * w.sum_of_squares);
  for (std::size_t k = 0; k < p.psd.size(); ++k) {
    const bool edge = k == 0 || (length % 2 == 0 && static_cast<int>(k) == length / 2);
    p.psd[k] *= (edge ? 1.0 : 2.0) * scale;
    p.frequency_hz[k] = static_cast<double>(k) * p.resolution_hz;
  }
  return p;
}

}  // namespace orrery::signal

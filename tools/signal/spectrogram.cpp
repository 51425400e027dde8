#include "tools/signal/spectrogram.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "tools/signal/amplitude_spectrum.h"

namespace orrery::signal {

Spectrogram AmplitudeSpectrogram(std::span<const double> x, double sample_rate_hz, int segment_length,
                                 double overlap, WindowKind window) {
  const int n = static_cast<int>(x.size());
  if (segment_length < 2 || segment_length > n)
    throw std::invalid_argument("AmplitudeSpectrogram: segment length " + std::to_string(segment_length) +
                                " must be in [2, " + std::to_string(n) + "] (the record's samples)");
  if (!(overlap >= 0 && overlap < 1))
    throw std::invalid_argument("AmplitudeSpectrogram: overlap must be in [0, 1), got " + std::to_string(overlap));
  const int step = std::max(1, segment_length - static_cast<int>(std::lround(overlap * segment_length)));
  const int segments = (n - segment_length) / step + 1;

  // One amplitude spectrum per segment
  Spectrogram g;
  for (int i = 0; i < segments; ++i) {
    const int start = i * step;
    const Spectrum s = AmplitudeSpectrum(x.subspan(start, segment_length), sample_rate_hz, window);
    if (i == 0) {
      g.frequency_hz = s.frequency;
      g.resolution_hz = s.resolution;
      g.amplitude.resize(segments, static_cast<Eigen::Index>(s.amplitude.size()));
    }
    g.time_s.push_back((start + 0.5 * segment_length) / sample_rate_hz);
    for (std::size_t k = 0; k < s.amplitude.size(); ++k) g.amplitude(i, static_cast<Eigen::Index>(k)) = s.amplitude[k];
  }
  return g;
}

}  // namespace orrery::signal

#pragma once
// Short-time amplitude spectra (a spectrogram): the record is cut into segments of L samples
// overlapping by a fraction r, and each segment's single-sided amplitude spectrum is computed
// with the scaling of AmplitudeSpectrum (amplitude_spectrum.h), so a steady sine of amplitude a
// reads a (within the window's scalloping loss) in every row.
//
// Usage:
//   Spectrogram g = AmplitudeSpectrogram(x, 20000.0, 2048, 0.75, WindowKind::kHann);
//   // g.amplitude(i, k): segment i (centred at g.time_s[i]), frequency g.frequency_hz[k]
#include <span>
#include <vector>

#include <Eigen/Core>

#include "tools/signal/window.h"

namespace orrery::signal {

struct Spectrogram {
  std::vector<double> time_s;        // centre of each segment, (start + L/2) / f_s, from the first sample
  std::vector<double> frequency_hz;  // floor(L/2)+1 values k f_s / L
  Eigen::MatrixXd amplitude;         // segments x bins, single-sided peak amplitude
  double resolution_hz = 0;          // f_s / L
};

// Throws std::invalid_argument for a segment length below 2 or above the record, an overlap
// outside [0, 1), a sample rate that is not positive and finite, or a non-finite sample.
Spectrogram AmplitudeSpectrogram(std::span<const double> x, double sample_rate_hz, int segment_length,
                                 double overlap, WindowKind window);

}  // namespace orrery::signal

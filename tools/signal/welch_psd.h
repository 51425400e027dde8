#pragma once
// One-sided power spectral density by Welch's method (P. D. Welch, "The use of fast Fourier
// transform for the estimation of power spectra", IEEE Trans. Audio Electroacoust. 15(2), 1967):
// the record is cut into K segments of L samples overlapping by a fraction r, each segment is
// windowed and transformed, and the periodograms are averaged:
//   S_k = c_k / (K f_s sum_n w_n^2) sum_{segments} |X_k|^2,   c_k = 1 at k = 0 and k = L/2 (even
//   L), 2 elsewhere;   f_k = k f_s / L,  k = 0 .. floor(L/2)
// Unit: (signal unit)^2 / Hz. Parseval holds: sum_k S_k Δf (Δf = f_s / L) equals the mean square
// of the windowed segments, sum w_n^2 x_n^2 / sum w_n^2 averaged over segments; with the
// rectangular window and segments that tile the record it is exactly the record's mean square,
// and for stationary signals it is the mean square in expectation for any window.
// Segments start at 0 and step by L - round(r L); samples after the last whole segment are unused.
//
// Usage:
//   PowerSpectralDensity p = WelchPsd(x, 20000.0, {.segment_length = 4096});
#include <span>
#include <vector>

#include "tools/signal/window.h"

namespace orrery::signal {

struct WelchOptions {
  int segment_length = 0;  // L; 0: the largest fast FFT length <= 2N/9 (8 segments at r = 0.5)
  double overlap = 0.5;    // r in [0, 1)
  WindowKind window = WindowKind::kHann;
};

struct PowerSpectralDensity {
  std::vector<double> frequency_hz;  // floor(L/2)+1 values k f_s / L
  std::vector<double> psd;           // S_k, (signal unit)^2 / Hz
  double resolution_hz = 0;          // f_s / L
  double enbw_hz = 0;                // the window's ENBW in Hz
  int segments = 0;                  // K
  int segment_length = 0;            // L
};

// Welch's PSD of `x` sampled at `sample_rate_hz`. Throws std::invalid_argument when the record
// is shorter than one segment (or than 2 samples), the overlap is outside [0, 1), the segment
// length is below 2, the sample rate is not positive and finite, or a sample is not finite.
PowerSpectralDensity WelchPsd(std::span<const double> x, double sample_rate_hz, const WelchOptions& options = {});

}  // namespace orrery::signal

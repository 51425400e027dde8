#pragma once
// Single-sided amplitude spectrum of a windowed record.
//
// For a record x_0 .. x_{N-1} sampled at f_s, window w (window.h) and X_k the DFT of w_n x_n
// (fft.h):
//   A_0 = |X_0| / sum w,   A_k = 2 |X_k| / sum w  (0 < k < N/2),   A_{N/2} = |X_{N/2}| / sum w
// at frequencies f_k = k f_s / N, k = 0 .. floor(N/2). A sine a cos(2 pi f t + phi) whose
// frequency sits on a bin reads A_k = a exactly; off the bins, within the window's scalloping
// loss (window.h: Hann 1.42 dB, flat-top 0.01 dB at worst); FindPeaks (peaks.h) interpolates the
// peak back to a and f. The amplitudes are peak values in the unit of the signal (multiply by
// 1/sqrt(2) for RMS).
//
// The same function serves angle-domain records (order_resample.h): with the sample rate given
// in samples per revolution, the frequencies are orders (cycles per revolution).
//
// Usage:
//   Spectrum s = AmplitudeSpectrum(x, 20000.0, WindowKind::kHann);
//   for (std::size_t k = 0; k < s.amplitude.size(); ++k) use(s.frequency[k], s.amplitude[k]);
#include <span>
#include <vector>

#include "tools/signal/window.h"

namespace orrery::signal {

struct Spectrum {
  std::vector<double> frequency;  // floor(N/2)+1 bin frequencies k f_s / N: Hz (time records) or
                                  // orders (angle records)
  std::vector<double> amplitude;  // single-sided peak amplitude per bin, signal unit
  double resolution = 0;          // bin spacing f_s / N (Hz or orders)
  double enbw = 0;                // equivalent noise bandwidth ENBW_bins * resolution
  int samples = 0;                // N
  WindowKind window = WindowKind::kHann;
};

// The amplitude spectrum of all of `x` (N = x.size() >= 2) at `sample_rate` (> 0, samples per
// second or per revolution). The mean is kept (A_0 is it). Throws std::invalid_argument for
// fewer than 2 samples, a sample rate that is not positive and finite, or a non-finite sample.
Spectrum AmplitudeSpectrum(std::span<const double> x, double sample_rate, WindowKind window);

}  // namespace orrery::signal

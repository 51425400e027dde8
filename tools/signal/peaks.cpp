#include "tools/signal/peaks.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace orrery::signal {

Peak InterpolatePeak(const Spectrum& s, int bin) {
  const std::vector<double>& a = s.amplitude;
  const int last = static_cast<int>(a.size()) - 1;
  Peak p;
  p.bin = bin;
  p.frequency = s.frequency[bin];
  p.amplitude = a[bin];
  if (bin <= 0 || bin >= last || !(a[bin] > 0)) return p;

  // The larger neighbour lies on the sine's side; the ratio fixes the offset δ
  const int side = a[bin + 1] >= a[bin - 1] ? 1 : -1;
  const double ratio = a[bin + side] / a[bin];
  const auto ratio_at = [&](double delta) {
    return std::abs(WindowResponse(s.window, 1.0 - delta)) / std::abs(WindowResponse(s.window, delta));
  };
  double lo = 0.0, hi = 0.5;
  if (ratio <= ratio_at(lo)) {
    hi = 0.0;
  } else if (ratio >= ratio_at(hi)) {
    lo = 0.5;
  } else {
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (ratio_at(mid) < ratio ? lo : hi) = mid;
    }
  }
  const double delta = 0.5 * (lo + hi);
  p.frequency = (bin + side * delta) * s.resolution;
  p.amplitude = a[bin] / std::abs(WindowResponse(s.window, delta));
  return p;
}

std::vector<Peak> FindPeaks(const Spectrum& s, const PeakOptions& options) {
  if (options.max_peaks < 0) throw std::invalid_argument("FindPeaks: max_peaks must be >= 0");
  const std::vector<double>& a = s.amplitude;
  const int size = static_cast<int>(a.size());
  const int skip = options.skip_low_bins >= 0 ? options.skip_low_bins : MainLobeHalfWidthBins(s.window);

  // Threshold from the largest amplitude outside the skipped bins
  double largest = 0;
  for (int k = skip; k < size; ++k) largest = std::max(largest, a[k]);
  const double threshold = std::max(options.min_amplitude, options.min_relative_amplitude * largest);

  // Local maxima above the threshold
  std::vector<int> maxima;
  for (int k = std::max(skip, 1); k < size; ++k) {
    const bool rises = a[k] > a[k - 1];
    const bool falls = k + 1 >= size || a[k] >= a[k + 1];
    if (rises && falls && a[k] >= threshold && a[k] > 0) maxima.push_back(k);
  }
  std::sort(maxima.begin(), maxima.end(), [&](int i, int j) { return a[i] > a[j]; });
  if (static_cast<int>(maxima.size()) > options.max_peaks) maxima.resize(options.max_peaks);

  std::vector<Peak> peaks;
  peaks.reserve(maxima.size());
  for (int k : maxima) peaks.push_back(InterpolatePeak(s, k));
  return peaks;
}

}  // namespace orrery::signal

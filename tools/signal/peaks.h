#pragma once
// Peaks of an amplitude spectrum, with the frequency and amplitude of the sine behind each peak
// interpolated between bins.
//
// A peak is a local maximum A_k > A_{k-1}, A_k >= A_{k+1} at least `min_relative_amplitude` of the
// largest amplitude (and `min_amplitude`), outside the lowest bins (the window's main lobe around
// DC). For a sine between bins the window's response K (window.h) fixes the ratio of the two
// largest bins: with the larger neighbour on the side of the sine, k + δ its frequency in bins,
//   A_{k±1} / A_k = K(1 - δ) / K(δ),  0 <= δ <= 1/2,
// solved for δ by bisection (the ratio rises monotonically with δ for the three windows); then
//   f = (k ± δ) Δf,   a = A_k / K(δ).
// This is the interpolation of Grandke ("Interpolation algorithms for discrete Fourier transforms
// of weighted signals", IEEE Trans. Instrum. Meas. 32(2), 1983), for any cosine-sum window; for
// Hann it reduces to Grandke's closed form δ = (2ρ - 1)/(ρ + 1), ρ = A_{k±1}/A_k. It assumes one
// sine dominates the three bins (others at least a main lobe away).
//
// Usage:
//   Spectrum s = AmplitudeSpectrum(x, fs, WindowKind::kHann);
//   for (const Peak& p : FindPeaks(s)) std::cout << p.frequency << " " << p.amplitude << "\n";
#include <string>
#include <vector>

#include "tools/signal/amplitude_spectrum.h"

namespace orrery::signal {

struct Peak {
  double frequency = 0;  // interpolated, Hz (or orders for angle-domain spectra)
  double amplitude = 0;  // interpolated peak amplitude, signal unit
  int bin = 0;           // the local maximum's bin
  std::string label;     // kinematic label (LabelPeaks, kinematic_lines.h); "" when none
};

struct PeakOptions {
  int max_peaks = 20;                    // the largest this many peaks are kept
  double min_relative_amplitude = 1e-3;  // of the largest amplitude outside the skipped bins (-60 dB)
  double min_amplitude = 0;              // absolute floor, signal unit
  int skip_low_bins = -1;                // bins 0 .. skip-1 are no peaks; -1: the window's
                                         // main-lobe half width (MainLobeHalfWidthBins)
};

// The peaks of `s`, largest amplitude first. Throws std::invalid_argument for max_peaks < 0.
std::vector<Peak> FindPeaks(const Spectrum& s, const PeakOptions& options = {});

// The interpolated peak at local maximum `bin` (0 < bin < last bin; at the ends the bin itself).
Peak InterpolatePeak(const Spectrum& s, int bin);

}  // namespace orrery::signal

#pragma once
// Sideband energy ratio (SER) around the mesh harmonics of an amplitude spectrum.
//
// Definition used throughout Orrery: for mesh frequency f_m and modulation frequency f_x (a
// shaft, planet or fault frequency),
//
//   SER = sum_{k=1}^{K} sum_{n=1}^{N} [ P(k f_m + n f_x) + P(k f_m - n f_x) ]  /  sum_{k=1}^{K} P(k f_m)
//
// with K = 3 mesh harmonics and N sideband pairs (6 by default), where P(f) is the power (mean
// square) of the line at f, summed over the bins of the window's main lobe around it:
//
//   P(f) = sum_{j : |j - f/Δf| <= B} A_j^2 / (2 ENBW_bins)
//
// (A_j the single-sided amplitudes of AmplitudeSpectrum, B the window's main-lobe half width in
// bins, ENBW_bins its equivalent noise bandwidth: a sine of amplitude a gives P = a^2/2 whatever
// its offset from the bins, up to the power outside the main lobe). SER is a ratio of powers:
// a carrier a_k with sidebands s_kn reads SER = sum (s_kn^2) / sum a_k^2. An amplitude-modulated
// carrier a (1 + m cos 2π f_x t) cos 2π k f_m t has SER = m^2/2.
// (GE's "sideband energy ratio" for wind-turbine gearboxes, Hanna et al., "Detection of wind
// turbine gear tooth defects using sideband energy ratio", China Wind Power 2011, sums the
// amplitudes of six sideband pairs over the carrier's amplitude per harmonic; Orrery sums powers,
// as the name says energy, and sums over the first three harmonics.)
//
// Limits, so that no bin is counted twice: lines f_x apart must not share bins (f_x > 2 B Δf,
// else the record is too short: it needs T > 2 B / f_x); N is reduced to the largest n with
// n f_x + B Δf < f_m / 2 (sidebands of neighbouring harmonics do not meet) and K to the harmonics
// whose outermost sideband band lies below the Nyquist frequency. The result says what was used.
//
// Usage:
//   Spectrum s = AmplitudeSpectrum(x, fs, WindowKind::kHann);
//   double ser = SidebandEnergyRatio(s, 220.3, 15.74).ratio;
#include <vector>

#include "tools/signal/amplitude_spectrum.h"

namespace orrery::signal {

struct SidebandEnergyOptions {
  int harmonics = 3;   // K
  int sidebands = 6;   // N, pairs per harmonic
  int band_bins = -1;  // B; -1: MainLobeHalfWidthBins of the spectrum's window
};

struct SidebandEnergy {
  double ratio = 0;           // SER
  double carrier_power = 0;   // sum_k P(k f_m), (signal unit)^2
  double sideband_power = 0;  // sum_k sum_n [P(k f_m + n f_x) + P(k f_m - n f_x)]
  int harmonics = 0;          // K used
  int sidebands = 0;          // N used
  std::vector<double> carrier_power_per_harmonic;   // K values
  std::vector<double> sideband_power_per_harmonic;  // K values
};

// SER of `s` (frequencies in Hz or orders, as mesh_frequency and modulation_frequency). Throws
// std::invalid_argument for frequencies that are not positive and finite, sidebands not resolved
// by the record (see above, naming the length needed), or no mesh harmonic that fits.
SidebandEnergy SidebandEnergyRatio(const Spectrum& s, double mesh_frequency, double modulation_frequency,
                                   const SidebandEnergyOptions& options = {});

// P(f): the power of the line at f (see above), band half width `band_bins` (-1: main lobe).
double LinePower(const Spectrum& s, double frequency, int band_bins = -1);

}  // namespace orrery::signal

#pragma once
// One-third-octave band levels of a record, as seed 000 reports its housing accelerations:
//   L_a = 20 log10(a / a_0) dB,   a the RMS value in the band,   a_0 = 1e-6 m/s^2
// (seed 000, eq. 27; a_0 as there, for accelerations).
//
// Bands: base-ten one-third octaves of IEC 61260-1:2014 (ANSI S1.11-2004 likewise), band number
// x (0 at 1 kHz):
//   exact mid-band frequency  f_m = 1000 · 10^(x/10) Hz
//   band edges                f_1 = f_m · 10^(-1/20),  f_2 = f_m · 10^(1/20)
//   nominal mid-band frequency (the name of the band; IEC 61260-1 Annex E, ISO 266): the
//   preferred numbers 10, 12.5, 16, 20, 25, 31.5, 40, 50, 63, 80 times a power of ten.
//
// Band RMS: of the first FastFftLength(N) samples (fft.h; no record length makes the transform
// slow), the mean is removed, the record is Hann-windowed and transformed, and the one-sided
// power spectral density (the periodogram, welch_psd.h's scaling with one segment) is
// integrated over the band, bins at the edges weighted by the fraction of their width
// [(j - 1/2) Δf, (j + 1/2) Δf] inside the band. This is the ideal (brick-wall) band filter, which
// the IEC 61260 filter classes approximate; a sine inside a band gives a / sqrt(2) in it, up to
// the Hann window's leakage past an edge within 2 bins.
//
// Bands reported: from the first band whose lower edge lies at least 4 bins above 0 Hz (the
// window's main lobe at DC, doubled) up to the last whose upper edge lies at or below the Nyquist
// frequency, and not below `min_frequency_hz` nor above `max_frequency_hz` (mid-band).
//
// Usage:
//   for (const OctaveBand& b : ThirdOctaveLevels(a, 20000.0)) print(b.nominal_hz, b.level_db);
#include <span>
#include <vector>

namespace orrery::signal {

struct OctaveBand {
  int index = 0;            // x: band number, 0 at 1 kHz
  double nominal_hz = 0;    // 1000, 1250, 1600, ...
  double exact_hz = 0;      // 1000 · 10^(x/10)
  double lower_hz = 0;      // f_1
  double upper_hz = 0;      // f_2
  double rms = 0;           // band RMS, signal unit
  double level_db = 0;      // 20 log10(rms / reference); -inf for rms = 0
};

struct ThirdOctaveOptions {
  double reference = 1e-6;         // a_0, signal unit (m/s^2 for accelerations, seed 000 eq. 27)
  double min_frequency_hz = 1.0;   // lowest mid-band frequency considered
  double max_frequency_hz = 1e9;   // highest mid-band frequency considered
};

// The band levels of `x` sampled at `sample_rate_hz`. Throws std::invalid_argument for fewer than
// 16 samples, a sample rate that is not positive and finite, a reference that is not positive, a
// non-finite sample, or no band that fits both the record and the frequency range (naming the
// resolution and the Nyquist frequency).
std::vector<OctaveBand> ThirdOctaveLevels(std::span<const double> x, double sample_rate_hz,
                                          const ThirdOctaveOptions& options = {});

// The nominal mid-band frequency of band x (IEC 61260-1 Annex E).
double NominalThirdOctaveHz(int index);

}  // namespace orrery::signal

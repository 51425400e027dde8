#pragma once
// Data windows for spectral analysis: rectangular, Hann and flat-top, all cosine sums sampled
// periodically (DFT-even, the sampling meant for spectral analysis):
//   w_n = sum_{j=0}^{J} (-1)^j a_j cos(2 pi j n / N),   n = 0 .. N-1
//   rectangular  a = {1}
//   Hann         a = {0.5, 0.5}                                         (Harris 1978, Table 1)
//   flat-top     a = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368}
//                (D'Antona & Ferrero, "Digital Signal Processing for Measurement Systems",
//                 Springer 2006, p. 70; the same coefficients as MATLAB's and SciPy's flattop)
//
// Figures of merit (F. J. Harris, "On the use of windows for harmonic analysis with the discrete
// Fourier transform", Proc. IEEE 66(1), 1978, eqs. 13-15 and Table 1):
//   coherent gain  CG   = (1/N) sum w_n               = a_0 for these windows
//   equivalent noise bandwidth, in bins
//                  ENBW = N sum w_n^2 / (sum w_n)^2   = (a_0^2 + sum_{j>0} a_j^2 / 2) / a_0^2
//   rectangular CG 1, ENBW 1; Hann CG 0.5, ENBW 1.5; flat-top CG 0.2156, ENBW 3.770
//
// Response to a sine ν bins away from a bin centre (the large-N limit of the windowed DFT,
// normalized to 1 at ν = 0; sinc(u) = sin(pi u)/(pi u)):
//   K(ν) = [a_0 sinc(ν) + sum_{j>0} (a_j/2)(sinc(ν - j) + sinc(ν + j))] / a_0
// The worst-case amplitude error of a sine read at its nearest bin (the scalloping loss) is
// -20 log10 K(1/2): rectangular 3.92 dB, Hann 1.42 dB (Harris 1978 Table 1), flat-top 0.01 dB.
#include <string>
#include <string_view>
#include <vector>

namespace orrery::signal {

enum class WindowKind { kRectangular, kHann, kFlatTop };

// A window of one length with the sums that spectrum scalings need.
struct Window {
  WindowKind kind = WindowKind::kHann;
  std::vector<double> w;       // the N coefficients w_n
  double sum = 0;              // sum w_n = N CG
  double sum_of_squares = 0;   // sum w_n^2
  double coherent_gain = 0;    // sum / N
  double enbw_bins = 0;        // N sum_of_squares / sum^2
};

// The window of `kind` and length n. Throws std::invalid_argument for n < 1.
Window MakeWindow(WindowKind kind, int n);

// The cosine-sum coefficients a_0 .. a_J of `kind` (see above).
const std::vector<double>& CosineSumCoefficients(WindowKind kind);

// K(ν): the normalized amplitude response at ν bins from the sine's frequency (see above).
double WindowResponse(WindowKind kind, double nu_bins);

// Half-width of the main lobe in bins (J + 1: rectangular 1, Hann 2, flat-top 5): a sine's
// power lies within this many bins of its frequency, up to the side lobes.
int MainLobeHalfWidthBins(WindowKind kind);

// -20 log10 K(1/2): the largest amplitude error of a sine read at its nearest bin, in dB.
double MaxScallopingLossDb(WindowKind kind);

// "rect" (also "rectangular"), "hann", "flattop" (also "flat-top"). Throws std::invalid_argument
// naming the value and the choices.
WindowKind ParseWindowKind(std::string_view name);
// "rect", "hann", "flattop".
std::string_view WindowName(WindowKind kind);

}  // namespace orrery::signal

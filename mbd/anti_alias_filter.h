#pragma once
// The anti-alias filter of the sensor chain: a linear-phase FIR low-pass designed by the window
// method with a Kaiser window, and a multi-channel decimator that applies it with its group delay
// compensated.
//
// Design (J. F. Kaiser, "Nonrecursive digital filter design using the I0-sinh window function",
// Proc. IEEE ISCAS 1974; A. V. Oppenheim, R. W. Schafer, "Discrete-Time Signal Processing",
// the Kaiser window design method): for a passband edge w_p, a stopband edge w_s (rad/sample)
// and an attenuation A = -20 log10(delta) dB (the window method gives the same delta in the
// passband and the stopband),
//   beta = 0.1102 (A - 8.7)                                     A > 50
//        = 0.5842 (A - 21)^0.4 + 0.07886 (A - 21)                21 <= A <= 50
//        = 0                                                    A < 21
//   order = ceil((A - 8) / (2.285 (w_s - w_p))), made even (type I: integer delay order / 2),
//   h[n] = (w_c / pi) sinc(w_c (n - a) / pi) I0(beta sqrt(1 - ((n - a) / a)^2)) / I0(beta),
// a = order / 2, w_c = (w_p + w_s) / 2 (the -6 dB point), then scaled to unit gain at DC. The
// order formula is an estimate: the design measures its amplitude response on a grid of 16
// points per 2 pi / (order + 1) (the width of a side lobe) and raises the order by 2 until the
// measured stopband attenuation reaches A. The response is that of a type I FIR,
//   H(w) e^{j w a} = h[a] + 2 sum_{k=1..a} h[a - k] cos(k w)   (real: zero phase after the delay).
//
// Usage:
//   FirLowPass f = DesignKaiserLowPass(0.04, 0.05, 100);   // edges in cycles per sample
//   DecimatingFilter d(f.taps, 10, 3, 16);                  // M = 10, 3 channels
//   d.Push(x);  ...  if (d.Ready(k * 10)) d.Output(k * 10, y);
#include <vector>

namespace orrery {

struct FirLowPass {
  std::vector<double> taps;           // odd count, symmetric, sum 1
  double passband_edge = 0;           // cycles per sample
  double stopband_edge = 0;           // cycles per sample
  double design_attenuation_db = 0;   // A asked for
  double kaiser_beta = 0;
  double passband_ripple_db = 0;      // measured: max |20 log10 |H|| over [0, passband_edge]
  double stopband_attenuation_db = 0; // measured: min -20 log10 |H| over [stopband_edge, 0.5]
  int order() const { return static_cast<int>(taps.size()) - 1; }
  double delay_samples() const { return 0.5 * order(); }
};

// Designs the low-pass above. Requires 0 < passband_edge < stopband_edge <= 0.5 (cycles per
// sample) and attenuation_db > 0; throws std::invalid_argument otherwise, and
// std::runtime_error if no order up to 1e6 meets the attenuation.
FirLowPass DesignKaiserLowPass(double passband_edge, double stopband_edge, double attenuation_db);

// Real amplitude response H(w) e^{j w a} of a symmetric FIR at frequency f (cycles per sample),
// by Clenshaw's recurrence over the cosine series above.
double FirAmplitude(const std::vector<double>& taps, double f);

// Filters `channels` signals sampled at a fixed rate with a symmetric FIR and evaluates the
// output at chosen input samples (decimation picks every M-th):
//   y(n) = sum_j h[j] x[n + a - j],   a = (taps - 1) / 2,
// so y(n) lines up with x(n) (the linear-phase delay is compensated). Beyond the first and the
// last sample pushed so far the signal is continued by odd reflection, x[-m] = 2 x[0] - x[m] and
// x[L + m] = 2 x[L] - x[L - m], which a linear trend (an encoder's angle at constant speed)
// passes through unchanged. The history is a ring of `history` samples per channel (at least the
// taps); Output(n) needs samples n - a .. n + a (reflected) still in it. Push and Output do not
// allocate.
class DecimatingFilter {
 public:
  DecimatingFilter(std::vector<double> taps, int channels, long history);

  // Appends one sample (`channels` values).
  void Push(const double* x);
  // Samples pushed so far (the last has index samples() - 1).
  long samples() const { return count_; }
  // y(n) needs no sample beyond the last pushed: n + a <= samples() - 1.
  bool Ready(long n) const { return n + delay_ <= count_ - 1; }
  // y(n) into y (`channels` values), reflecting where the window crosses either end of what has
  // been pushed. Throws std::logic_error if no sample was pushed or the window's samples have left
  // the history.
  void Output(long n, double* y) const;

  int delay() const { return delay_; }
  int channels() const { return channels_; }

 private:
  double Sample(long i, int c) const { return ring_[c * 2 * history_ + i % history_]; }
  double FoldedDot(const double* window) const;  // taps . window (taps long)

  std::vector<double> taps_;
  int channels_ = 0, delay_ = 0;
  long history_ = 0;   // ring length; each channel holds 2 copies (any window is contiguous)
  long count_ = 0;
  std::vector<double> ring_;           // channels x 2 history
  mutable std::vector<double> window_; // taps: a reflected window
};

}  // namespace orrery

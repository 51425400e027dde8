#include "mbd/anti_alias_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace orrery {
namespace {

constexpr double kPi = std::numbers::pi;

// Modified Bessel function of the first kind, order 0: sum_k ((x/2)^k / k!)^2.
double BesselI0(double x) {
  double sum = 1, term = 1;
  const double y = 0.25 * x * x;
  for (int k = 1; k < 500; ++k) {
    term *= y / (double(k) * k);
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

double KaiserBeta(double a) {
  if (a > 50) return 0.1102 * (a - 8.7);
  if (a >= 21) return 0.5842 * std::pow(a - 21, 0.4) + 0.07886 * (a - 21);
  return 0;
}

// Windowed ideal low-pass of `order` (even) with cut-off wc (rad/sample), unit DC gain.
std::vector<double> KaiserTaps(int order, double wc, double beta) {
  std::vector<double> h(order + 1);
  const double a = 0.5 * order, i0 = BesselI0(beta);
  double sum = 0;
  for (int n = 0; n <= order; ++n) {
    const double x = n - a;
    const double ideal = x == 0 ? wc / kPi : std::sin(wc * x) / (kPi * x);
    const double r = a > 0 ? x / a : 0;
    h[n] = ideal * BesselI0(beta * std::sqrt(std::max(0.0, 1 - r * r))) / i0;
    sum += h[n];
  }
  for (double& x : h) x /= sum;
  return h;
}

// Largest |20 log10 |H|| over [f0, f1] (passband: deviation) or smallest -20 log10 |H|
// (stopband), on a grid of `per_lobe` points per side-lobe width 1 / (order + 1).
double Extreme(const std::vector<double>& h, double f0, double f1, bool stopband, int per_lobe) {
  const double step = 1.0 / (per_lobe * static_cast<double>(h.size()));
  const long n = std::max<long>(2, static_cast<long>(std::ceil((f1 - f0) / step)) + 1);
  double worst = stopband ? std::numeric_limits<double>::infinity() : 0;
  for (long i = 0; i < n; ++i) {
    const double f = f0 + (f1 - f0) * double(i) / double(n - 1);
    const double mag = std::abs(FirAmplitude(h, f));
    const double db = 20 * std::log10(std::max(mag, 1e-300));
    worst = stopband ? std::min(worst, -db) : std::max(worst, std::abs(db));
  }
  return worst;
}

// Stopband attenuation: 16 points per lobe over the 16 lobes next to the stopband edge (a Kaiser
// design's highest), 4 per lobe over the rest (its lobes fall off away from the edge); with
// `near_only` the first part alone (while the order is searched).
double StopbandAttenuation(const std::vector<double>& h, double fs, bool near_only) {
  const double near_end = std::min(0.5, fs + 16.0 / static_cast<double>(h.size()));
  double a = Extreme(h, fs, near_end, true, 16);
  if (!near_only && near_end < 0.5) a = std::min(a, Extreme(h, near_end, 0.5, true, 4));
  return a;
}

}  // namespace

double FirAmplitude(const std::vector<double>& h, double f) {
  // H e^{j w a} = h[a] + 2 sum_k h[a - k] cos(k w): Clenshaw, b_k = c_k + 2 cos(w) b_{k+1} - b_{k+2}.
  const int a = static_cast<int>(h.size() - 1) / 2;
  const double c = std::cos(2 * kPi * f);
  double b1 = 0, b2 = 0;
  for (int k = a; k >= 1; --k) {
    const double b0 = 2 * h[a - k] + 2 * c * b1 - b2;
    b2 = b1;
    b1 = b0;
  }
  return h[a] + c * b1 - b2;
}

FirLowPass DesignKaiserLowPass(double fp, double fs, double attenuation_db) {
  if (!(fp > 0 && fp < fs && fs <= 0.5))
    throw std::invalid_argument("anti-alias filter: need 0 < passband edge < stopband edge <= 0.5 "
                                "cycles per sample, got " + std::to_string(fp) + " and " +
                                std::to_string(fs));
  if (!(attenuation_db > 0) || !std::isfinite(attenuation_db))
    throw std::invalid_argument("anti-alias filter: stopband attenuation must be > 0 dB");
  FirLowPass f;
  f.passband_edge = fp, f.stopband_edge = fs, f.design_attenuation_db = attenuation_db;
  f.kaiser_beta = KaiserBeta(attenuation_db);
  const double dw = 2 * kPi * (fs - fp), wc = kPi * (fp + fs);
  int order = static_cast<int>(std::ceil((attenuation_db - 8) / (2.285 * dw)));
  order = std::max(2, order + (order % 2));
  // Raise the order until the measured stopband attenuation meets the design value (searched on
  // the lobes next to the edge, then confirmed over the whole stopband).
  for (bool whole = false; order <= 1000000; order += 2) {
    f.taps = KaiserTaps(order, wc, f.kaiser_beta);
    f.stopband_attenuation_db = StopbandAttenuation(f.taps, fs, true);
    if (f.stopband_attenuation_db < attenuation_db) continue;
    f.stopband_attenuation_db = StopbandAttenuation(f.taps, fs, whole);
    if (!whole) f.stopband_attenuation_db = StopbandAttenuation(f.taps, fs, false);
    whole = true;
    if (f.stopband_attenuation_db >= attenuation_db) break;
  }
  if (f.stopband_attenuation_db < attenuation_db)
    throw std::runtime_error("anti-alias filter: no order up to 1e6 reaches " +
                             std::to_string(attenuation_db) + " dB");
  f.passband_ripple_db = Extreme(f.taps, 0, fp, false, 16);
  return f;
}

DecimatingFilter::DecimatingFilter(std::vector<double> taps, int channels, long history)
    : taps_(std::move(taps)), channels_(channels) {
  if (taps_.empty() || taps_.size() % 2 == 0)
    throw std::invalid_argument("DecimatingFilter: needs an odd number of taps");
  if (channels < 1) throw std::invalid_argument("DecimatingFilter: needs at least one channel");
  delay_ = static_cast<int>(taps_.size() - 1) / 2;
  history_ = std::max<long>(history, static_cast<long>(taps_.size()));
  ring_.assign(static_cast<size_t>(channels_) * 2 * history_, 0.0);
  window_.assign(taps_.size(), 0.0);
}

double DecimatingFilter::FoldedDot(const double* x) const {
  // Symmetric taps: h[a] x[a] + sum_{j < a} h[j] (x[j] + x[2a - j]) (Eigen vectorizes the
  // reversed half).
  const int a = delay_;
  const Eigen::Map<const Eigen::VectorXd> h(taps_.data(), a), lo(x, a), hi(x + a + 1, a);
  return taps_[a] * x[a] + h.dot(lo + hi.reverse());
}

void DecimatingFilter::Push(const double* x) {
  const long slot = count_ % history_;
  for (int c = 0; c < channels_; ++c) {
    double* ring = ring_.data() + c * 2 * history_;
    ring[slot] = ring[slot + history_] = x[c];
  }
  ++count_;
}

void DecimatingFilter::Output(long n, double* y) const {
  const long last = count_ - 1;
  const long first = n - delay_, end = n + delay_;  // window [first, end]
  if (last < 0) throw std::logic_error("DecimatingFilter: no samples");
  // Lowest sample the window reads (reflections included) must still be in the ring.
  long lo = end > last ? std::min(first, 2 * last - end) : first;
  lo = std::max(lo, 0L);
  if (lo <= last - history_)
    throw std::logic_error("DecimatingFilter: the window of sample " + std::to_string(n) +
                           " has left the history");
  const long ntaps = static_cast<long>(taps_.size());
  for (int c = 0; c < channels_; ++c) {
    const double* ring = ring_.data() + c * 2 * history_;
    // Inside the record: one contiguous window of the doubled ring.
    if (first >= 0 && end <= last) {
      y[c] = FoldedDot(ring + first % history_);
      continue;
    }
    // Across an end: odd reflection (clamped for records shorter than the delay).
    for (long j = 0; j < ntaps; ++j) {
      long i = first + j;
      double value;
      if (i < 0) {
        const long m = std::min(-i, last);
        value = 2 * Sample(0, c) - Sample(m, c);
      } else if (i > last) {
        const long m = std::max(2 * last - i, 0L);
        value = 2 * Sample(last, c) - Sample(m, c);
      } else {
        value = Sample(i, c);
      }
      window_[j] = value;
    }
    y[c] = FoldedDot(window_.data());
  }
}

}  // namespace orrery

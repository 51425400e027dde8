// The anti-alias filter against oracles it does not share code with: its frequency response by
// a direct complex sum of the taps (the design measures through Clenshaw's cosine recurrence),
// and its outputs against sines of known amplitude through the LTI closed form
// y = a |H(f)| sin(2 pi f t + phi) (zero phase: the delay is compensated).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <functional>
#include <numbers>
#include <vector>

#include <Eigen/Dense>

#include "mbd/anti_alias_filter.h"

namespace orrery {
namespace {

constexpr double kPi = std::numbers::pi;

// |sum_n h[n] e^{-j 2 pi f n}|: the magnitude response, summed directly.
double Magnitude(const std::vector<double>& h, double f) {
  std::complex<double> sum = 0;
  for (size_t n = 0; n < h.size(); ++n) sum += h[n] * std::polar(1.0, -2 * kPi * f * double(n));
  return std::abs(sum);
}

// Least-squares amplitudes of sines at `freqs` (cycles per unit of t) in (t, y).
std::vector<double> SineAmplitudes(const std::vector<double>& t, const std::vector<double>& y,
                                   const std::vector<double>& freqs) {
  const int n = static_cast<int>(t.size()), m = static_cast<int>(freqs.size());
  Eigen::MatrixXd A(n, 2 * m);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < m; ++k) {
      A(i, 2 * k) = std::cos(2 * kPi * freqs[k] * t[i]);
      A(i, 2 * k + 1) = std::sin(2 * kPi * freqs[k] * t[i]);
    }
    b(i) = y[i];
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b);
  std::vector<double> amp;
  for (int k = 0; k < m; ++k) amp.push_back(std::hypot(x(2 * k), x(2 * k + 1)));
  return amp;
}

// The sampler's design for decimation M: passband to 0.8 of the output Nyquist frequency,
// stopband from it, 100 dB.
FirLowPass Design(int M, double attenuation_db = 100) {
  const double nyquist = 0.5 / M;
  return DesignKaiserLowPass(0.8 * nyquist, nyquist, attenuation_db);
}

TEST(AntiAliasFilter, DesignMeetsItsStatedResponse) {
  for (const int M : {4, 10, 20}) {
    const FirLowPass f = Design(M);
    SCOPED_TRACE("M = " + std::to_string(M) + ", order " + std::to_string(f.order()));
    ASSERT_EQ(f.taps.size() % 2, 1u);
    for (size_t n = 0; n < f.taps.size(); ++n) EXPECT_EQ(f.taps[n], f.taps[f.taps.size() - 1 - n]);
    EXPECT_GE(f.stopband_attenuation_db, 100.0);
    // Stopband, on a grid 4 times finer than the design's (64 points per side lobe), summed
    // directly: at least the stated attenuation, less the 0.05 dB the design's grid may miss a
    // lobe's peak by (a lobe sampled 16 times is within cos(pi/32) of its peak).
    const double step = 1.0 / (64.0 * f.taps.size());
    double worst_stop = 1e9, worst_pass = 0;
    for (double x = f.stopband_edge; x <= 0.5; x += step)
      worst_stop = std::min(worst_stop, -20 * std::log10(Magnitude(f.taps, x)));
    for (double x = 0; x <= f.passband_edge; x += step)
      worst_pass = std::max(worst_pass, std::abs(20 * std::log10(Magnitude(f.taps, x))));
    EXPECT_GE(worst_stop, 100.0 - 0.05);
    // Passband ripple: as stated (within the same grid margin), and of the order of the
    // stopband's delta = 1e-5 as the window method gives (20 log10(1 + 1e-5) = 8.7e-5 dB).
    EXPECT_LE(worst_pass, f.passband_ripple_db * 1.01 + 1e-9);
    EXPECT_LT(f.passband_ripple_db, 20 * std::log10(1 + 2e-5));
    // The Clenshaw amplitude agrees with the direct sum.
    for (double x : {0.0, 0.3 * f.passband_edge, f.stopband_edge, 0.37})
      EXPECT_NEAR(std::abs(FirAmplitude(f.taps, x)), Magnitude(f.taps, x), 1e-13);
  }
  EXPECT_THROW(DesignKaiserLowPass(0.05, 0.04, 100), std::invalid_argument);
  EXPECT_THROW(DesignKaiserLowPass(0.01, 0.6, 100), std::invalid_argument);
  EXPECT_THROW(DesignKaiserLowPass(0.01, 0.05, 0), std::invalid_argument);
}

// Runs x(n) through the filter and decimates by M: rows k at samples k M (interior rows only,
// those whose windows lie inside the record).
struct Decimated {
  std::vector<double> t, y;
};
Decimated Decimate(const std::vector<double>& taps, int M, long length, const std::function<double(long)>& x) {
  DecimatingFilter d(taps, 1, static_cast<long>(taps.size()) + 4 * M);
  Decimated out;
  for (long n = 0; n < length; ++n) {
    const double v = x(n);
    d.Push(&v);
    // The newest row ready: k M + a = n.
    const long m = n - d.delay();
    if (m >= d.delay() && m % M == 0) {
      double y = 0;
      d.Output(m, &y);
      out.t.push_back(double(m / M));  // in output samples
      out.y.push_back(y);
    }
  }
  return out;
}

TEST(AntiAliasFilter, AboveNyquistDoesNotFoldWhilePointSamplingFoldsIt) {
  // Output rate 1, internal rate 10: tones from just above the recorded Nyquist frequency (0.5)
  // to the internal Nyquist frequency (5), each with an in-band tone at 0.1.
  const int M = 10;
  const FirLowPass f = Design(M);
  const double bound = std::pow(10.0, -f.design_attenuation_db / 20);
  const long length = 4000 * M;
  for (double f2 = 0.5005; f2 < 5; f2 += 0.1237) {
    // Where f2 folds in the record sampled at rate 1.
    double alias = f2 - std::floor(f2);
    if (alias > 0.5) alias = 1 - alias;
    if (std::abs(alias - 0.1) < 0.01) continue;  // on the in-band tone
    auto x = [&](long n) {
      const double t = double(n) / M;
      return std::sin(2 * kPi * 0.1 * t + 0.3) + std::sin(2 * kPi * f2 * t + 1.1);
    };
    const Decimated filtered = Decimate(f.taps, M, length, x);
    const Decimated point = Decimate({1.0}, M, length, x);
    const std::vector<double> a_filtered = SineAmplitudes(filtered.t, filtered.y, {0.1, alias});
    const std::vector<double> a_point = SineAmplitudes(point.t, point.y, {0.1, alias});
    SCOPED_TRACE("f2 = " + std::to_string(f2) + ", alias at " + std::to_string(alias));
    // Point sampling: the tone appears at its alias with its full amplitude.
    EXPECT_NEAR(a_point[1], 1.0, 1e-9);
    // Filtered: at most the stated stopband attenuation (plus the rounding of the sums).
    EXPECT_LE(a_filtered[1], bound + 1e-12);
    // The in-band tone passes within the ripple.
    EXPECT_NEAR(a_filtered[0], 1.0, std::pow(10.0, f.passband_ripple_db / 20) - 1 + bound + 1e-12);
  }
}

TEST(AntiAliasFilter, InBandSinePassesWithoutDelay) {
  // The recorded rows line up with the input's time: y(k M) = a |H(f)| sin(2 pi f t_k + phi) with
  // |H| within the ripple, for tones across the passband.
  const int M = 10;
  const FirLowPass f = Design(M);
  const double ripple = std::pow(10.0, f.passband_ripple_db / 20) - 1;
  for (const double fr : {0.01, 0.13, 0.27, 0.39}) {  // up to 0.78 of the Nyquist frequency 0.5
    auto x = [&](long n) { return 3.0 * std::sin(2 * kPi * fr * double(n) / M + 0.7); };
    const Decimated out = Decimate(f.taps, M, 3000 * M, x);
    double worst = 0;
    for (size_t i = 0; i < out.t.size(); ++i)
      worst = std::max(worst, std::abs(out.y[i] - 3.0 * std::sin(2 * kPi * fr * out.t[i] + 0.7)));
    EXPECT_LE(worst, 3.0 * ripple + 1e-12) << "f = " << fr;
  }
}

TEST(AntiAliasFilter, OddReflectionPassesALineAtBothEnds) {
  // An encoder's angle at constant speed: the rows next to both ends equal the line.
  const FirLowPass f = Design(10);
  DecimatingFilter d(f.taps, 2, static_cast<long>(f.taps.size()) + 40);
  const long length = 2000;
  auto line = [](long n, int c) { return c == 0 ? 0.5 + 0.01 * n : -3.0 - 2e-3 * n; };
  auto check = [&](long n) {
    double y[2];
    d.Output(n, y);
    EXPECT_NEAR(y[0], line(n, 0), 1e-12) << n;
    EXPECT_NEAR(y[1], line(n, 1), 1e-12) << n;
  };
  for (long n = 0; n < length; ++n) {
    const double x[2] = {line(n, 0), line(n, 1)};
    d.Push(x);
    // Near the start, once the window's samples have arrived (reflected before sample 0).
    if (n == d.delay() + 5) {
      check(0);
      check(5);
    }
  }
  // Near the end (reflected beyond the last sample).
  check(length - 300);
  check(length - 1);
  // Samples that have left the ring cannot be filtered.
  double y[2];
  EXPECT_THROW(d.Output(10, y), std::logic_error);
}

}  // namespace
}  // namespace orrery

#include "tools/signal/condition_indicators.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>

#include "tools/signal/fft.h"

namespace orrery::signal {
namespace {

double Mean(std::span<const double> x) {
  double sum = 0;
  for (double v : x) sum += v;
  return sum / static_cast<double>(x.size());
}

// (1/N) sum (x - x̄)^k for k = 2 and 4
std::pair<double, double> CentralMoments(std::span<const double> x) {
  const double mean = Mean(x);
  double m2 = 0, m4 = 0;
  for (double v : x) {
    const double d2 = (v - mean) * (v - mean);
    m2 += d2;
    m4 += d2 * d2;
  }
  const double n = static_cast<double>(x.size());
  return {m2 / n, m4 / n};
}

// A difference or residual signal at rounding level: nothing but regular components
bool Negligible(std::span<const double> part, std::span<const double> tsa) {
  double part_ms = 0, tsa_ms = 0;
  for (double v : part) part_ms += v * v;
  for (double v : tsa) tsa_ms += v * v;
  return !(part_ms > 1e-20 * tsa_ms);
}

void CheckOrders(std::span<const double> tsa, int mesh_order) {
  if (tsa.size() < 4) throw std::invalid_argument("condition indicators: the TSA needs at least 4 samples");
  if (mesh_order < 1)
    throw std::invalid_argument("condition indicators: mesh order must be >= 1, got " + std::to_string(mesh_order));
  if (mesh_order + 1 > static_cast<int>(tsa.size()) / 2)
    throw std::invalid_argument("condition indicators: " + std::to_string(tsa.size()) +
                                " samples per revolution cannot hold mesh order " + std::to_string(mesh_order) +
                                " and its sidebands (need more than " + std::to_string(2 * (mesh_order + 1)) + ")");
}

// The TSA with the mean, shaft orders 1..H, mesh harmonics kZ and, if asked, kZ ± 1 removed
std::vector<double> RemoveRegular(std::span<const double> tsa, const RegularComponents& regular, bool sidebands) {
  CheckOrders(tsa, regular.mesh_order);
  if (regular.shaft_harmonics < 0) throw std::invalid_argument("condition indicators: shaft_harmonics must be >= 0");
  const int n = static_cast<int>(tsa.size());
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins());
  fft.Forward(tsa.data(), X.data());
  const int last = fft.bins() - 1;
  const auto zero = [&](int q) {
    if (q >= 0 && q <= last) X[q] = 0.0;
  };
  zero(0);
  for (int q = 1; q <= regular.shaft_harmonics; ++q) zero(q);
  for (int q = regular.mesh_order; q <= last + 1; q += regular.mesh_order) {
    zero(q);
    if (sidebands) {
      zero(q - 1);
      zero(q + 1);
    }
  }
  std::vector<double> out(n);
  fft.Inverse(X.data(), out.data());
  return out;
}

}  // namespace

double Rms(std::span<const double> x) {
  if (x.empty()) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0;
  for (double v : x) sum += v * v;
  return std::sqrt(sum / static_cast<double>(x.size()));
}

double PeakAbs(std::span<const double> x) {
  double peak = 0;
  for (double v : x) peak = std::max(peak, std::abs(v));
  return peak;
}

double CrestFactor(std::span<const double> x) { return PeakAbs(x) / Rms(x); }

double Kurtosis(std::span<const double> x) {
  const auto [m2, m4] = CentralMoments(x);
  if (!(m2 > 0)) return std::numeric_limits<double>::quiet_NaN();
  return m4 / (m2 * m2);
}

std::vector<double> ResidualSignal(std::span<const double> tsa, const RegularComponents& regular) {
  return RemoveRegular(tsa, regular, false);
}

std::vector<double> DifferenceSignal(std::span<const double> tsa, const RegularComponents& regular) {
  return RemoveRegular(tsa, regular, true);
}

double ResidualVariance(std::span<const double> tsa, const RegularComponents& regular) {
  return CentralMoments(ResidualSignal(tsa, regular)).first;
}

double Fm0(std::span<const double> tsa, int mesh_order) {
  CheckOrders(tsa, mesh_order);
  const int n = static_cast<int>(tsa.size());
  RealFft fft(n);
  std::vector<std::complex<double>> X(fft.bins());
  fft.Forward(tsa.data(), X.data());
  // Sum of the mesh harmonics' single-sided amplitudes
  double harmonics = 0;
  for (int q = mesh_order; q < fft.bins(); q += mesh_order)
    harmonics += (2 * q == n ? 1.0 : 2.0) * std::abs(X[q]) / n;
  const auto [lo, hi] = std::minmax_element(tsa.begin(), tsa.end());
  return (*hi - *lo) / harmonics;
}

double Fm4(std::span<const double> tsa, const RegularComponents& regular) {
  const std::vector<double> d = DifferenceSignal(tsa, regular);
  if (Negligible(d, tsa)) return std::numeric_limits<double>::quiet_NaN();
  return Kurtosis(d);
}

double Na4(std::span<const double> tsa, const RegularComponents& regular,
           std::span<const double> earlier_residual_variances) {
  const std::vector<double> r = ResidualSignal(tsa, regular);
  if (Negligible(r, tsa)) return std::numeric_limits<double>::quiet_NaN();
  const auto [m2, m4] = CentralMoments(r);
  // Residual variance averaged over the trend's runs, this one included
  double variance = m2;
  for (double v : earlier_residual_variances) variance += v;
  variance /= static_cast<double>(earlier_residual_variances.size() + 1);
  if (!(variance > 0)) return std::numeric_limits<double>::quiet_NaN();
  return m4 / (variance * variance);
}

ConditionIndicators CalcConditionIndicators(std::span<const double> tsa, const RegularComponents& regular,
                                            std::span<const double> earlier_residual_variances) {
  ConditionIndicators c;
  c.rms = Rms(tsa);
  c.peak = PeakAbs(tsa);
  c.crest_factor = CrestFactor(tsa);
  c.kurtosis = Kurtosis(tsa);
  c.fm0 = Fm0(tsa, regular.mesh_order);
  c.fm4 = Fm4(tsa, regular);
  c.na4 = Na4(tsa, regular, earlier_residual_variances);
  c.residual_variance = ResidualVariance(tsa, regular);
  return c;
}

}  // namespace orrery::signal

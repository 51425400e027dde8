#include "tools/signal/window.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace orrery::signal {
namespace {

double Sinc(double u) {
  if (std::abs(u) < 1e-12) return 1.0;
  const double x = std::numbers::pi * u;
  return std::sin(x) / x;
}

}  // namespace

const std::vector<double>& CosineSumCoefficients(WindowKind kind) {
  static const std::vector<double> kRectangular = {1.0};
  static const std::vector<double> kHann = {0.5, 0.5};
  static const std::vector<double> kFlatTop = {0.21557895, 0.41663158, 0.277263158, 0.083578947,
                                               0.006947368};
  switch (kind) {
    case WindowKind::kRectangular: return kRectangular;
    case WindowKind::kHann: return kHann;
    case WindowKind::kFlatTop: return kFlatTop;
  }
  throw std::logic_error("CosineSumCoefficients: unknown window kind");
}

Window MakeWindow(WindowKind kind, int n) {
  if (n < 1) throw std::invalid_argument("MakeWindow: length must be >= 1, got " + std::to_string(n));
  const std::vector<double>& a = CosineSumCoefficients(kind);
  Window window;
  window.kind = kind;
  window.w.resize(n);
  // w_n = sum_j (-1)^j a_j cos(2 pi j n / N), periodic sampling
  for (int i = 0; i < n; ++i) {
    double value = 0, sign = 1;
    for (std::size_t j = 0; j < a.size(); ++j, sign = -sign)
      value += sign * a[j] * std::cos(2.0 * std::numbers::pi * static_cast<double>(j) * i / n);
    window.w[i] = value;
    window.sum += value;
    window.sum_of_squares += value * value;
  }
  window.coherent_gain = window.sum / n;
  window.enbw_bins = n * window.sum_of_squares / (window.sum * window.sum);
  return window;
}

double WindowResponse(WindowKind kind, double nu_bins) {
  const std::vector<double>& a = CosineSumCoefficients(kind);
  double g = a[0] * Sinc(nu_bins);
  for (std::size_t j = 1; j < a.size(); ++j) {
    const double shift = static_cast<double>(j);
    g += 0.5 * a[j] * (Sinc(nu_bins - shift) + Sinc(nu_bins + shift));
  }
  return g / a[0];
}

int MainLobeHalfWidthBins(WindowKind kind) { return static_cast<int>(CosineSumCoefficients(kind).size()); }

double MaxScallopingLossDb(WindowKind kind) { return -20.0 * std::log10(std::abs(WindowResponse(kind, 0.5))); }

WindowKind ParseWindowKind(std::string_view name) {
  if (name == "hann") return WindowKind::kHann;
  if (name == "flattop" || name == "flat-top") return WindowKind::kFlatTop;
  if (name == "rect" || name == "rectangular") return WindowKind::kRectangular;
  throw std::invalid_argument("unknown window '" + std::string(name) + "' (expected hann, flattop or rect)");
}

std::string_view WindowName(WindowKind kind) {
  switch (kind) {
    case WindowKind::kRectangular: return "rect";
    case WindowKind::kHann: return "hann";
    case WindowKind::kFlatTop: return "flattop";
  }
  return "unknown";
}

}  // namespace orrery::signal

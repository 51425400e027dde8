#include "tools/signal/order_resample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "tools/signal/fft.h"

namespace orrery::signal {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Cubic Lagrange interpolant through (xs[i], ys[i]), i = 0..3, at x
double Lagrange4(const double* xs, const double* ys, double x) {
  double sum = 0;
  for (int i = 0; i < 4; ++i) {
    double term = ys[i];
    for (int j = 0; j < 4; ++j)
      if (j != i) term *= (x - xs[j]) / (xs[i] - xs[j]);
    sum += term;
  }
  return sum;
}

}  // namespace

std::vector<double> RisingAngle(std::span<const double> angle_rad, double* direction) {
  const std::size_t n = angle_rad.size();
  if (n < 4) throw std::invalid_argument("reference angle: need at least 4 samples, got " + std::to_string(n));
  // Unwrap: a step beyond pi is a wrap of the angle
  std::vector<double> theta(n);
  double offset = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(angle_rad[i]))
      throw std::invalid_argument("reference angle: sample " + std::to_string(i) + " is not finite");
    if (i > 0) {
      const double step = angle_rad[i] - angle_rad[i - 1];
      if (std::abs(step) > std::numbers::pi) offset -= kTwoPi * std::round(step / kTwoPi);
    }
    theta[i] = angle_rad[i] + offset;
  }
  // Rising: the sign of the overall rotation, then strict monotonicity
  const double sign = theta[n - 1] >= theta[0] ? 1.0 : -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    theta[i] *= sign;
    if (i > 0 && !(theta[i] > theta[i - 1]))
      throw std::invalid_argument("reference angle: not strictly monotonic at sample " + std::to_string(i) +
                                  " (the member stops or reverses)");
  }
  if (direction) *direction = sign;
  return theta;
}

AngleDomainSignal OrderResample(std::span<const double> x, std::span<const double> angle_rad,
                                int samples_per_revolution, bool align) {
  if (x.size() != angle_rad.size())
    throw std::invalid_argument("OrderResample: signal has " + std::to_string(x.size()) + " samples, angle " +
                                std::to_string(angle_rad.size()));
  if (samples_per_revolution < 4)
    throw std::invalid_argument("OrderResample: samples per revolution must be >= 4, got " +
                                std::to_string(samples_per_revolution));
  AngleDomainSignal out;
  const std::vector<double> theta = RisingAngle(angle_rad, &out.direction);
  const int n = static_cast<int>(theta.size());
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) throw std::invalid_argument("OrderResample: sample " + std::to_string(i) + " is not finite");

  // Uniform angle grid, starting at a whole revolution when aligned
  const double step = kTwoPi / samples_per_revolution;
  const double first = align ? kTwoPi * std::ceil(theta.front() / kTwoPi - 1e-12) : theta.front();
  const double span = theta.back() - std::max(first, theta.front());
  const long count = span >= 0 ? static_cast<long>(std::floor(span / step + 1e-9)) + 1 : 0;
  if (count < 4)
    throw std::invalid_argument("OrderResample: the reference turns through " + std::to_string(theta.back() - theta.front()) +
                                " rad, fewer than 4 angle samples");
  out.first_angle_rad = first;
  out.samples_per_revolution = samples_per_revolution;
  out.values.resize(count);

  // Cubic Lagrange on the four samples around each grid angle
  int i = 0;
  for (long j = 0; j < count; ++j) {
    const double phi = first + j * step;
    while (i + 1 < n - 1 && theta[i + 1] <= phi) ++i;
    const int s = std::clamp(i - 1, 0, n - 4);
    out.values[j] = Lagrange4(&theta[s], &x[s], phi);
  }
  return out;
}

int DefaultSamplesPerRevolution(std::span<const double> angle_rad) {
  const std::vector<double> theta = RisingAngle(angle_rad);
  const int n = static_cast<int>(theta.size());
  // Smallest mean angle step over blocks of 16 samples (the slowest speed)
  const int block = std::min(16, n - 1);
  double min_step = std::numeric_limits<double>::infinity();
  for (int i = 0; i + block < n; i += block) min_step = std::min(min_step, (theta[i + block] - theta[i]) / block);
  // (a relative 1e-9 below, so that an exact 2π / step is not rounded up by its last bit)
  const double needed = std::ceil(kTwoPi / min_step * (1 - 1e-9));
  constexpr double kMax = 1 << 20;
  if (!(needed <= kMax))
    throw std::invalid_argument("reference angle: the member turns too slowly for order analysis (" +
                                std::to_string(min_step) + " rad per sample)");
  // Smallest even 2-3-5 length at or above the need
  int s = std::max(4, static_cast<int>(needed));
  while (FastFftLength(s) != s) ++s;
  return s;
}

}  // namespace orrery::signal

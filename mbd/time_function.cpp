#include "mbd/time_function.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace orrery {
namespace {
constexpr double kPi = 3.14159265358979323846;
}

TimeFunction TimeFunction::Constant(double c) {
  TimeFunction f;
  f.kind_ = Kind::kConstant;
  f.a_ = c;
  return f;
}

TimeFunction TimeFunction::Ramp(double t0, double t1, double v0, double v1) {
  if (!(t1 > t0)) throw std::invalid_argument("ramp: end time must be after start time");
  TimeFunction f = Table({t0, t1}, {v0, v1});
  f.kind_ = Kind::kRamp;
  return f;
}

TimeFunction TimeFunction::SmoothStep(double t0, double t1, double v0, double v1) {
  if (!(t1 > t0)) throw std::invalid_argument("smooth step: end time must be after start time");
  TimeFunction f;
  f.kind_ = Kind::kSmoothStep;
  f.a_ = t0, f.b_ = t1, f.c_ = v0, f.d_ = v1;
  return f;
}

TimeFunction TimeFunction::Table(std::vector<double> times, std::vector<double> values) {
  if (times.empty() || times.size() != values.size())
    throw std::invalid_argument("table: times and values must be non-empty and of equal length");
  for (size_t i = 1; i < times.size(); ++i)
    if (!(times[i] > times[i - 1]))
      throw std::invalid_argument("table: times must be strictly increasing");
  TimeFunction f;
  f.kind_ = Kind::kTable;
  f.knots_ = std::move(times);
  f.values_ = std::move(values);
  return f;
}

TimeFunction TimeFunction::Sine(double amplitude, double frequency_hz, double phase_rad,
                                double offset) {
  TimeFunction f;
  f.kind_ = Kind::kSine;
  f.a_ = amplitude, f.b_ = 2 * kPi * frequency_hz, f.c_ = phase_rad, f.d_ = offset;
  return f;
}

TimeFunction TimeFunction::Trapezoid(double w0, double w1, double w2, double t4, double alpha1,
                                     double alpha2, double alpha3) {
  const double t1 = alpha1 * t4, t3 = alpha3 * t4, t2 = t3 - alpha2 * t4;
  if (!(t4 > 0) || !(t1 >= 0) || !(t2 >= t1) || !(t3 >= t2) || !(t4 >= t3))
    throw std::invalid_argument(
        "trapezoid: need t4 > 0 and 0 <= t1 <= t2 <= t3 <= t4 (t1 = alpha1 t4, t3 = alpha3 t4, "
        "t2 = t3 - alpha2 t4)");
  // Knots with zero-length segments dropped (alpha1 = 0 is a step).
  std::vector<double> k{0.0}, v{w0};
  auto add = [&](double t, double w) {
    if (t > k.back()) {
      k.push_back(t);
      v.push_back(w);
    } else {
      v.back() = w;  // a step at this instant: keep the later value
    }
  };
  add(t1, w1);
  add(t2, w1);
  add(t3, w2);
  add(t4, w2);
  TimeFunction f;
  f.kind_ = Kind::kTrapezoid;
  f.knots_ = std::move(k);
  f.values_ = std::move(v);
  f.a_ = w0;
  return f;
}

double TimeFunction::LinearValue(double t) const {
  if (t <= knots_.front()) return values_.front();
  if (t >= knots_.back()) return values_.back();
  const size_t i = std::upper_bound(knots_.begin(), knots_.end(), t) - knots_.begin() - 1;
  const double s = (t - knots_[i]) / (knots_[i + 1] - knots_[i]);
  return values_[i] + s * (values_[i + 1] - values_[i]);
}

double TimeFunction::LinearSlope(double t) const {
  if (t < knots_.front() || t >= knots_.back()) return 0.0;
  const size_t i = std::upper_bound(knots_.begin(), knots_.end(), t) - knots_.begin() - 1;
  return (values_[i + 1] - values_[i]) / (knots_[i + 1] - knots_[i]);
}

double TimeFunction::LinearIntegral(double t) const {
  // Integral from 0 to t of the piecewise-linear function held constant outside the knots.
  auto primitive = [&](double x) {  // integral from knots_.front() to x
    if (x <= knots_.front()) return values_.front() * (x - knots_.front());
    double sum = 0;
    for (size_t i = 0; i + 1 < knots_.size(); ++i) {
      const double x0 = knots_[i], x1 = std::min(knots_[i + 1], x);
      if (x1 <= x0) break;
      const double slope = (values_[i + 1] - values_[i]) / (knots_[i + 1] - knots_[i]);
      sum += (x1 - x0) * (values_[i] + 0.5 * slope * (x1 - x0));
    }
    if (x > knots_.back()) sum += values_.back() * (x - knots_.back());
    return sum;
  };
  return primitive(t) - primitive(0.0);
}

double TimeFunction::Value(double t) const {
  switch (kind_) {
    case Kind::kConstant: return a_;
    case Kind::kSine: return a_ * std::sin(b_ * t + c_) + d_;
    case Kind::kSmoothStep: {
      if (t <= a_) return c_;
      if (t >= b_) return d_;
      const double s = (t - a_) / (b_ - a_);
      return c_ + (d_ - c_) * s * s * s * (10 + s * (-15 + 6 * s));
    }
    default: return LinearValue(t);
  }
}

double TimeFunction::Derivative(double t) const {
  switch (kind_) {
    case Kind::kConstant: return 0.0;
    case Kind::kSine: return a_ * b_ * std::cos(b_ * t + c_);
    case Kind::kSmoothStep: {
      if (t <= a_ || t >= b_) return 0.0;
      const double h = b_ - a_, s = (t - a_) / h;
      return (d_ - c_) / h * 30 * s * s * (1 - s) * (1 - s);
    }
    default: return LinearSlope(t);
  }
}

double TimeFunction::SecondDerivative(double t) const {
  switch (kind_) {
    case Kind::kSine: return -a_ * b_ * b_ * std::sin(b_ * t + c_);
    case Kind::kSmoothStep: {
      if (t <= a_ || t >= b_) return 0.0;
      const double h = b_ - a_, s = (t - a_) / h;
      return (d_ - c_) / (h * h) * 60 * s * (1 - s) * (1 - 2 * s);
    }
    default: return 0.0;  // constant, and piecewise linear between knots
  }
}

double TimeFunction::Integral(double t) const {
  switch (kind_) {
    case Kind::kConstant: return a_ * t;
    case Kind::kSine:
      return b_ == 0 ? (a_ * std::sin(c_) + d_) * t
                     : -a_ / b_ * (std::cos(b_ * t + c_) - std::cos(c_)) + d_ * t;
    case Kind::kSmoothStep: {
      // Primitive of the quintic step, piecewise.
      auto primitive = [&](double x) {
        if (x <= a_) return c_ * (x - a_);
        const double h = b_ - a_;
        const double s = std::min((x - a_) / h, 1.0);
        // integral_0^s (10u^3 - 15u^4 + 6u^5) du = 2.5 s^4 - 3 s^5 + s^6
        double p = h * (c_ * s + (d_ - c_) * s * s * s * s * (2.5 + s * (-3 + s)));
        if (x > b_) p += d_ * (x - b_);
        return p;
      };
      return primitive(t) - primitive(0.0);
    }
    default: return LinearIntegral(t);
  }
}

std::string TimeFunction::Describe() const {
  std::ostringstream s;
  switch (kind_) {
    case Kind::kConstant: s << "constant " << a_; break;
    case Kind::kRamp: s << "ramp"; break;
    case Kind::kSmoothStep: s << "smooth step " << c_ << " -> " << d_ << " over [" << a_ << ", " << b_ << "] s"; break;
    case Kind::kTable: s << "table of " << knots_.size() << " points"; break;
    case Kind::kSine: s << "sine"; break;
    case Kind::kTrapezoid: s << "trapezoid"; break;
  }
  return s.str();
}

}  // namespace orrery

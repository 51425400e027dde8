#pragma once
// Scalar functions of time for drivers and applied loads.
//
// Each kind gives its value f(t), first and second derivatives, and the integral from 0 to t
// (a speed driver's position is the integral of its speed). Kinds:
// - Constant(c)
// - Ramp(t0, t1, v0, v1): v0 before t0, linear to v1 at t1, v1 after.
// - SmoothStep(t0, t1, v0, v1): quintic, C2 (zero slope and curvature at both ends).
// - Table(times, values): piecewise linear, held constant outside the table.
// - Sine(amplitude, frequency_hz, phase_rad, offset).
// - Trapezoid(w0, w1, w2, t4, alpha1, alpha2, alpha3): the speed profile of seed 002 Fig. 3:
//   w0 -> w1 linearly over [0, t1], w1 until t2, down to w2 at t3, w2 until t4 and after, with
//   t1 = alpha1 t4, t3 = alpha3 t4, t2 = t3 - alpha2 t4 (so alpha4 = 1 - alpha3).
//
// Usage:  TimeFunction w = TimeFunction::Trapezoid(0, 2.094, 0, 0.2, 0.05, 0.05, 0.6);
//         double speed = w.Value(0.01), angle = w.Integral(0.01);
#include <string>
#include <vector>

namespace orrery {

class TimeFunction {
 public:
  enum class Kind { kConstant, kRamp, kSmoothStep, kTable, kSine, kTrapezoid };

  TimeFunction() = default;  // constant 0
  static TimeFunction Constant(double c);
  static TimeFunction Ramp(double t0, double t1, double v0, double v1);
  static TimeFunction SmoothStep(double t0, double t1, double v0, double v1);
  // Throws std::invalid_argument unless times are strictly increasing and sizes match (>= 1).
  static TimeFunction Table(std::vector<double> times, std::vector<double> values);
  static TimeFunction Sine(double amplitude, double frequency_hz, double phase_rad, double offset);
  // Throws std::invalid_argument unless 0 <= t1 <= t2 <= t3 <= t4, t4 > 0.
  static TimeFunction Trapezoid(double w0, double w1, double w2, double t4, double alpha1,
                                double alpha2, double alpha3);

  double Value(double t) const;
  double Derivative(double t) const;
  double SecondDerivative(double t) const;
  double Integral(double t) const;  // integral of f from 0 to t

  Kind kind() const { return kind_; }
  std::string Describe() const;

 private:
  // Piecewise-linear form shared by Ramp, Table and Trapezoid: breakpoints (knots) and values.
  double LinearValue(double t) const;
  double LinearSlope(double t) const;
  double LinearIntegral(double t) const;

  Kind kind_ = Kind::kConstant;
  double a_ = 0, b_ = 0, c_ = 0, d_ = 0;  // kind-specific scalars (see time_function.cpp)
  std::vector<double> knots_, values_;    // piecewise-linear kinds
};

}  // namespace orrery

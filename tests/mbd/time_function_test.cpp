// TimeFunction: derivatives against central differences, integrals against composite Simpson
// quadrature (split at the kinks, where Simpson is exact for the piecewise-linear kinds), the
// seed 002 trapezoid's knots from the definition in time_function.h, continuity of Table and
// SmoothStep.
#include "mbd/time_function.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace orrery {
namespace {

constexpr double kEps = 2.220446049250313e-16;
constexpr double kPi = 3.14159265358979323846;

// Composite Simpson on [a, b] with n (even) intervals.
template <class F>
double Simpson(F f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * f(a + i * h);
  return s * h / 3;
}

// Simpson over [0, t] split at `breaks` (kinks of f or its derivatives).
double SimpsonSplit(const TimeFunction& f, double t, std::vector<double> breaks, int n) {
  auto value = [&](double x) { return f.Value(x); };
  double sum = 0, a = 0;
  breaks.push_back(t);
  for (double b : breaks) {
    if (b <= a) continue;
    const double e = std::min(b, t);
    sum += Simpson(value, a, e, n);
    a = e;
    if (a >= t) break;
  }
  return sum;
}

TEST(TimeFunction, DerivativesMatchCentralDifferences) {
  // Central difference with step d: truncation d^2/6 max|f'''| plus rounding eps max|f| / d.
  const double d = 1e-5;
  struct Case {
    TimeFunction f;
    double third_max;   // bound on |f'''| (for the first derivative check)
    double fourth_max;  // bound on |f''''| (for the second derivative check)
    double value_max;
  };
  const double A = 0.7, w = 2 * kPi * 3.0;
  const double dv = 2.0, T = 0.5;  // smooth step 1 -> 3 over [0.2, 0.7]
  const std::vector<Case> cases = {
      {TimeFunction::Sine(A, 3.0, 0.4, 0.1), A * w * w * w, A * w * w * w * w, 1.0},
      // Quintic: f''' = dv/T^3 (60 - 360 s + 360 s^2), |.| <= 60 dv/T^3; f'''' <= 360 dv / T^4.
      {TimeFunction::SmoothStep(0.2, 0.7, 1.0, 3.0), 60 * dv / (T * T * T), 360 * dv / (T * T * T * T), 3.0},
      {TimeFunction::Ramp(0.1, 0.4, -1.0, 2.0), 0.0, 0.0, 2.0},
      {TimeFunction::Table({0, 0.3, 0.5, 0.9}, {0, 1, -2, 4}), 0.0, 0.0, 4.0},
  };
  // Points away from kinks by more than d.
  const std::vector<double> ts = {0.05, 0.15, 0.25, 0.33, 0.45, 0.61, 0.68, 0.8, 0.95};
  for (const Case& c : cases) {
    const double tol1 = d * d / 6 * c.third_max + 4 * kEps * c.value_max / d;
    for (double t : ts) {
      const double fd = (c.f.Value(t + d) - c.f.Value(t - d)) / (2 * d);
      EXPECT_NEAR(c.f.Derivative(t), fd, tol1) << c.f.Describe() << " at t = " << t;
      const double dmax = std::abs(c.f.Derivative(t)) + c.value_max * w;  // derivative scale
      const double tol2 = d * d / 6 * c.fourth_max + 4 * kEps * dmax / d;
      const double fd2 = (c.f.Derivative(t + d) - c.f.Derivative(t - d)) / (2 * d);
      EXPECT_NEAR(c.f.SecondDerivative(t), fd2, tol2) << c.f.Describe() << " at t = " << t;
    }
  }
}

TEST(TimeFunction, IntegralsMatchSimpson) {
  // Simpson error (b - a)/180 h^4 max|f''''| (zero for the piecewise-linear kinds split at their
  // knots) plus rounding ~ n eps |integral|.
  const int n = 200;
  const double A = 0.7, w = 2 * kPi * 3.0;
  for (double t : {0.0, 0.13, 0.5, 0.77, 1.4}) {
    const TimeFunction sine = TimeFunction::Sine(A, 3.0, 0.4, 0.1);
    const double hs = t / n;
    EXPECT_NEAR(sine.Integral(t), SimpsonSplit(sine, t, {}, n), t / 180 * std::pow(hs, 4) * A * std::pow(w, 4) + 1e3 * kEps)
        << "t = " << t;
    const TimeFunction step = TimeFunction::SmoothStep(0.2, 0.7, 1.0, 3.0);
    const double f4 = 360 * 2.0 / std::pow(0.5, 4);
    EXPECT_NEAR(step.Integral(t), SimpsonSplit(step, t, {0.2, 0.7}, n), t / 180 * std::pow(0.5 / n, 4) * f4 + 1e3 * kEps)
        << "t = " << t;
    const TimeFunction table = TimeFunction::Table({0, 0.3, 0.5, 0.9}, {0, 1, -2, 4});
    EXPECT_NEAR(table.Integral(t), SimpsonSplit(table, t, {0.3, 0.5, 0.9}, n), 1e3 * kEps) << "t = " << t;
    const TimeFunction trap = TimeFunction::Trapezoid(1.0, 3.0, 0.5, 1.0, 0.1, 0.2, 0.6);
    EXPECT_NEAR(trap.Integral(t), SimpsonSplit(trap, t, {0.1, 0.4, 0.6, 1.0}, n), 1e3 * kEps) << "t = " << t;
    const TimeFunction c = TimeFunction::Constant(2.5);
    EXPECT_NEAR(c.Integral(t), 2.5 * t, 4 * kEps * t);
  }
  // A table starting after 0 holds its first value back to 0.
  const TimeFunction late = TimeFunction::Table({0.2, 0.4}, {1.0, 3.0});
  EXPECT_NEAR(late.Integral(0.5), 0.2 * 1.0 + 0.2 * 2.0 + 0.1 * 3.0, 1e3 * kEps);
}

TEST(TimeFunction, TrapezoidKnotsFollowTheSeed002Definition) {
  // w0 = 0, w1 = 20 rpm, w2 = 0, t4 = 0.2, alpha1 = alpha2 = 0.1, alpha3 = 0.6:
  // t1 = alpha1 t4 = 0.02, t3 = alpha3 t4 = 0.12, t2 = t3 - alpha2 t4 = 0.10.
  const double w1 = 20 * 2 * kPi / 60;
  const TimeFunction f = TimeFunction::Trapezoid(0, w1, 0, 0.2, 0.1, 0.1, 0.6);
  const double tol = 10 * kEps * w1;
  EXPECT_NEAR(f.Value(0.0), 0.0, tol);
  EXPECT_NEAR(f.Value(0.01), w1 / 2, tol);
  EXPECT_NEAR(f.Value(0.02), w1, tol);
  EXPECT_NEAR(f.Value(0.06), w1, tol);
  EXPECT_NEAR(f.Value(0.10), w1, tol);
  EXPECT_NEAR(f.Value(0.11), w1 / 2, tol);
  EXPECT_NEAR(f.Value(0.12), 0.0, tol);
  EXPECT_NEAR(f.Value(0.2), 0.0, tol);
  EXPECT_NEAR(f.Value(5.0), 0.0, tol);
  EXPECT_NEAR(f.Derivative(0.01), w1 / 0.02, 1e3 * kEps * w1 / 0.02);
  EXPECT_NEAR(f.Derivative(0.05), 0.0, tol);
  EXPECT_NEAR(f.Derivative(0.11), -w1 / 0.02, 1e3 * kEps * w1 / 0.02);
  // Area: two ramps of 0.01 w1 and a plateau of 0.08 w1.
  EXPECT_NEAR(f.Integral(0.2), 0.1 * w1, 10 * kEps);
  EXPECT_NEAR(f.Integral(0.02), 0.01 * w1, 10 * kEps);
  // Nonzero end speed w2 holds after t4.
  const TimeFunction g = TimeFunction::Trapezoid(1, 3, 2, 1.0, 0.25, 0.25, 0.75);
  EXPECT_NEAR(g.Value(0.125), 2.0, 10 * kEps);  // halfway up the first ramp
  EXPECT_NEAR(g.Value(0.5), 3.0, 10 * kEps);    // t2 = 0.5
  EXPECT_NEAR(g.Value(0.625), 2.5, 10 * kEps);  // halfway down
  EXPECT_NEAR(g.Value(2.0), 2.0, 10 * kEps);
  EXPECT_THROW(TimeFunction::Trapezoid(0, 1, 0, 1.0, 0.5, 0.3, 0.6), std::invalid_argument);  // t2 < t1
  EXPECT_THROW(TimeFunction::Trapezoid(0, 1, 0, 0.0, 0.1, 0.1, 0.6), std::invalid_argument);
}

TEST(TimeFunction, TableAndSmoothStepAreContinuous) {
  // Values approach the knot value from both sides at the slope (|f(t +- e) - f(t)| <= slope e).
  const TimeFunction table = TimeFunction::Table({0, 0.3, 0.5, 0.9}, {0, 1, -2, 4});
  const double e = 1e-9, max_slope = 15.0;  // |-3/0.2| = 15
  for (double tk : {0.3, 0.5, 0.9}) {
    EXPECT_NEAR(table.Value(tk - e), table.Value(tk), max_slope * e + 4 * kEps);
    EXPECT_NEAR(table.Value(tk + e), table.Value(tk), max_slope * e + 4 * kEps);
  }
  EXPECT_EQ(table.Value(-1.0), 0.0);  // held outside
  EXPECT_EQ(table.Value(2.0), 4.0);
  EXPECT_THROW(TimeFunction::Table({0, 0.3, 0.3}, {0, 1, 2}), std::invalid_argument);
  EXPECT_THROW(TimeFunction::Table({0, 0.3}, {0}), std::invalid_argument);
  // Smooth step: C2 at both ends. Near an end at distance e, the value differs by <= 10 dv (e/T)^3,
  // the slope by <= 30 dv/T (e/T)^2, the curvature by <= 60 dv/T^2 (e/T).
  const double dv = 2.0, T = 0.5, es = 1e-4;
  const TimeFunction s = TimeFunction::SmoothStep(0.2, 0.7, 1.0, 3.0);
  for (double tk : {0.2, 0.7}) {
    for (double t : {tk - es, tk + es}) {
      const double r = es / T;
      EXPECT_NEAR(s.Value(t), s.Value(tk), 10 * dv * r * r * r + 4 * kEps);
      EXPECT_NEAR(s.Derivative(t), 0.0, 30 * dv / T * r * r + 4 * kEps);
      EXPECT_NEAR(s.SecondDerivative(t), 0.0, 60 * dv / (T * T) * r + 4 * kEps);
    }
  }
  EXPECT_EQ(s.Value(0.2), 1.0);
  EXPECT_EQ(s.Value(0.7), 3.0);
  EXPECT_NEAR(s.Value(0.45), 2.0, 4 * kEps);  // symmetric about the middle
}

}  // namespace
}  // namespace orrery

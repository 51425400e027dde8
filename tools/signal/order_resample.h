#pragma once
// Computed order tracking: a signal sampled uniformly (or not) in time, resampled to uniform
// angle of a reference member whose angle is known at the same instants (an encoder: a joint's
// coordinate, e.g. /joints/S.carrier/q). In the angle domain a component locked to the member's
// speed is one line at its order (cycles per revolution), whatever the speed does
// (K. R. Fyfe & E. D. S. Munck, "Analysis of computed order tracking", Mech. Syst. Signal
// Process. 11(2), 1997, 187-205).
//
// Method: the angle θ_i is unwrapped (steps beyond pi are taken as wraps) and its sign made
// positive (a member turning backwards is read forwards); it must then rise strictly. The grid is
//   φ_j = φ_0 + j 2π / S,   j = 0, 1, ...,   φ_j <= θ_{n-1}
// with S samples per revolution and φ_0 the first multiple of 2π at or after θ_0 (`align`,
// so revolutions start at the member's absolute angle 0 and two runs compare sample by sample),
// or θ_0 itself. x(φ_j) is the cubic Lagrange interpolant of (θ_i, x_i) on the four samples around
// φ_j (the first or last four at the record's ends): error O(h^4) for a smooth signal; for a sine
// of k cycles per revolution and an angle step h between samples, at most (k h)^4 · 9/384 of its
// amplitude (the cubic's remainder, |prod (φ - θ_i)| <= 9 h^4 / 16 on the middle interval,
// divided by 4!), and (k h)^4 / 24 in the first and last intervals (|prod| <= h^4 there).
// Components above S/2 orders fold in the angle domain: S must cover the highest order present
// at the slowest speed; DefaultSamplesPerRevolution chooses such an S.
//
// Usage:
//   AngleDomainSignal a = OrderResample(x, carrier_angle, DefaultSamplesPerRevolution(carrier_angle));
//   Spectrum orders = AmplitudeSpectrum(a.values, a.samples_per_revolution, WindowKind::kHann);
#include <span>
#include <vector>

namespace orrery::signal {

struct AngleDomainSignal {
  std::vector<double> values;     // x(φ_j), j = 0 .. count-1
  double first_angle_rad = 0;     // φ_0, in the positive (sign-corrected) sense of rotation
  int samples_per_revolution = 0; // S
  double direction = 1;           // +1 or -1: the sign of the reference's rotation
  double revolutions() const { return static_cast<double>(values.size()) / samples_per_revolution; }
};

// Resamples `x` (n values) to S = `samples_per_revolution` per revolution of the reference whose
// angle at the same instants is `angle_rad` (n values, rad). Throws std::invalid_argument when
// the sizes differ or are below 4, S < 4, a value is not finite, the angle is not strictly
// monotonic (naming the sample), or the angle range holds fewer than 4 grid points.
AngleDomainSignal OrderResample(std::span<const double> x, std::span<const double> angle_rad,
                                int samples_per_revolution, bool align = true);

// The smallest even S with prime factors 2, 3, 5 for which the angle grid is at least as fine as
// the time samples at the slowest speed of the record (S >= 2π / min Δθ, the smallest angle step
// over blocks of 16 samples), so no component below the time record's Nyquist frequency folds.
// Throws std::invalid_argument like OrderResample, and when S would exceed 2^20 (a reference that
// all but stops).
int DefaultSamplesPerRevolution(std::span<const double> angle_rad);

// The angle unwrapped and made rising (direction sign applied); throws as OrderResample does.
// `direction` receives +1 or -1.
std::vector<double> RisingAngle(std::span<const double> angle_rad, double* direction = nullptr);

}  // namespace orrery::signal

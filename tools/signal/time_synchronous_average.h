#pragma once
// Time-synchronous average (TSA) over revolutions of a member: the angle-domain record
// (order_resample.h) cut into whole revolutions r = 0 .. R-1 of S samples and averaged,
//   y_j = (1/R) sum_{r=0}^{R-1} x(φ_0 + 2π r + 2π j / S),   j = 0 .. S-1.
// Components locked to the member (its orders, the meshes of its teeth) pass unchanged; anything
// else is attenuated, noise uncorrelated between revolutions by sqrt(R) in RMS, a component of
// non-integer order ν by |sin(π R ν) / (R sin(π ν))| (P. D. McFadden, "A revised model for the
// extraction of periodic waveforms by time domain averaging", Mech. Syst. Signal Process. 1(1),
// 1987, 83-95).
// With the grid aligned to whole revolutions (OrderResample's default), sample j sits at the
// member's absolute angle 2π j / S: averages of two runs compare tooth by tooth.
//
// Usage:
//   AngleDomainSignal a = OrderResample(x, planet_angle, 512);
//   SynchronousAverage tsa = TimeSynchronousAverage(a);   // tsa.values: one revolution
#include <span>
#include <vector>

#include "tools/signal/order_resample.h"

namespace orrery::signal {

struct SynchronousAverage {
  std::vector<double> values;      // S samples of one revolution
  int revolutions = 0;             // R, whole revolutions averaged
  int samples_per_revolution = 0;  // S
};

// The TSA of the whole revolutions of `a`. Throws std::invalid_argument when `a` holds less than
// one revolution.
SynchronousAverage TimeSynchronousAverage(const AngleDomainSignal& a);

// Resamples `x` to `samples_per_revolution` per revolution of the reference at `angle_rad`
// (OrderResample, aligned) and averages. Throws as both do.
SynchronousAverage TimeSynchronousAverage(std::span<const double> x, std::span<const double> angle_rad,
                                          int samples_per_revolution);

}  // namespace orrery::signal

#pragma once
// The output times of a run and the checks that keep its time bookkeeping sound: times that are
// distinct in double precision (an end time of 1e20 s at a 1 ms interval is 1e23 rows, which
// overflowed the row count, and its times are 16384 s apart in double), row counts in 64-bit
// integers that this bounds, and a bound on the result file's size estimated before anything
// runs.
//
// Output k (k = 0 .. rows - 1) is at t0 + k * interval, the last one at the end time.
//
// Usage:
//   const OutputSchedule rows = MakeOutputSchedule(t0, options);   // throws on absurd settings
//   CheckOutputSize(rows, out.bytes_per_row(), options.max_output_bytes);
//   for (std::int64_t k = 1; k < rows.rows; ++k) integrator->AdvanceTo(rows.Time(k));
#include <cstdint>

#include "mbd/simulation.h"

namespace orrery {

struct OutputSchedule {
  double t0 = 0, end_time = 0, interval = 0;  // s
  std::int64_t rows = 0;                      // output rows, the initial state included
  // Time of row k: t0 + k interval, the last row at the end time exactly.
  double Time(std::int64_t k) const;
};

// Checks the time settings of `options` from t0 and counts the rows. Throws std::invalid_argument
// with the numbers when the end time is not after t0 or not finite, or the interval (or the
// generalized-alpha step) is below the resolution of time over the run (1000 ulp of the larger of
// |t0| and |end time|), which also bounds the rows by 2 / (1000 eps) = 9e12.
OutputSchedule MakeOutputSchedule(double t0, const SimulationOptions& options);

// Throws std::invalid_argument when rows x bytes_per_row exceeds max_bytes (0: no bound), naming
// the estimate, the limit and what to change.
void CheckOutputSize(const OutputSchedule& schedule, std::int64_t bytes_per_row, double max_bytes);

}  // namespace orrery

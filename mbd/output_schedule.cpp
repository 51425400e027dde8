#include "mbd/output_schedule.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace orrery {
namespace {

// printf-style text for messages.
template <class... Args>
std::string Text(const char* format, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}

// Smallest interval told apart from 0 at time t with room to spare: 1000 ulp of t.
double TimeResolution(double t) { return 1000 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)); }

}  // namespace

double OutputSchedule::Time(std::int64_t k) const {
  if (k >= rows - 1) return end_time;
  return std::min(t0 + static_cast<double>(k) * interval, end_time);
}

OutputSchedule MakeOutputSchedule(double t0, const SimulationOptions& options) {
  OutputSchedule s;
  s.t0 = t0, s.end_time = options.end_time, s.interval = options.output_interval;
  if (!std::isfinite(s.end_time) || !(s.end_time > t0))
    throw std::invalid_argument(Text("end time %g s must be finite and after the start (%g s)", s.end_time, t0));
  if (!std::isfinite(s.interval) || !(s.interval > 0))
    throw std::invalid_argument(Text("output interval %g s must be finite and > 0", s.interval));
  // Times must stay distinct in double precision over the run
  const double resolution = TimeResolution(std::max(std::abs(t0), std::abs(s.end_time)));
  if (s.interval < resolution)
    throw std::invalid_argument(Text("output interval %g s is below the resolution of time at %g s (%.3g s): "
                                     "output times would not be distinct; raise output.interval or lower the end time",
                                     s.interval, s.end_time, resolution));
  if (options.integrator.kind == IntegratorKind::kGeneralizedAlpha && options.integrator.step < resolution)
    throw std::invalid_argument(Text("generalized-alpha step %g s is below the resolution of time at %g s (%.3g s): "
                                     "steps would not advance the time",
                                     options.integrator.step, s.end_time, resolution));
  // Rows counted in floating point; by the resolution bound at most 2 / (1000 eps) = 9e12, so the
  // integer holds them
  s.rows = static_cast<std::int64_t>(std::ceil((s.end_time - t0) / s.interval - 1e-9)) + 1;
  return s;
}

void CheckOutputSize(const OutputSchedule& schedule, std::int64_t bytes_per_row, double max_bytes) {
  if (!(max_bytes > 0)) return;
  const double bytes = static_cast<double>(schedule.rows) * static_cast<double>(bytes_per_row);
  if (bytes <= max_bytes) return;
  throw std::invalid_argument(Text("the result file would hold %.4g rows of %lld bytes, %.3g GB (end time %g s at "
                                   "output.interval %g s), more than the limit of %.3g GB; raise output.interval, "
                                   "lower the end time, or allow it with --max-output-gb",
                                   static_cast<double>(schedule.rows), static_cast<long long>(bytes_per_row),
                                   bytes * 1e-9, schedule.end_time, schedule.interval, max_bytes * 1e-9));
}

}  // namespace orrery

#include "tools/signal/time_synchronous_average.h"

#include <stdexcept>
#include <string>

namespace orrery::signal {

SynchronousAverage TimeSynchronousAverage(const AngleDomainSignal& a) {
  const int s = a.samples_per_revolution;
  const int revolutions = s > 0 ? static_cast<int>(a.values.size() / s) : 0;
  if (revolutions < 1)
    throw std::invalid_argument("TimeSynchronousAverage: the record holds " + std::to_string(a.revolutions()) +
                                " revolutions of the reference, fewer than one");
  SynchronousAverage tsa;
  tsa.samples_per_revolution = s;
  tsa.revolutions = revolutions;
  tsa.values.assign(s, 0.0);
  // Sum revolution by revolution, then divide
  for (int r = 0; r < revolutions; ++r)
    for (int j = 0; j < s; ++j) tsa.values[j] += a.values[static_cast<std::size_t>(r) * s + j];
  for (double& v : tsa.values) v /= revolutions;
  return tsa;
}

SynchronousAverage TimeSynchronousAverage(std::span<const double> x, std::span<const double> angle_rad,
                                          int samples_per_revolution) {
  return TimeSynchronousAverage(OrderResample(x, angle_rad, samples_per_revolution, true));
}

}  // namespace orrery::signal

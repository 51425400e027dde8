#include "contact/contact_outputs.h"

#include <algorithm>
#include <limits>

namespace orrery::contact {

std::vector<OutputDescription> ContactOutputs(std::vector<OutputDescription> own,
                                              const ContactMonitor* monitor, int record_points) {
  if (monitor) own.insert(own.end(), monitor->outputs().begin(), monitor->outputs().end());
  if (record_points > 0) {
    own.push_back({.name = "point_positions", .unit = "m", .columns = 3 * record_points});
    own.push_back({.name = "point_normal_forces", .unit = "N", .columns = record_points});
  }
  return own;
}

void WriteContactOutputs(const ContactMonitor* monitor, const ContactMonitorState* state,
                         const ContactPointRecord& points, int record_points, double* values) {
  if (monitor) {
    // A workspace made without the monitor's state (not by MakeWorkspace()) has no values.
    const int n = OutputValueCount(monitor->outputs());
    if (state) monitor->Write(*state, values);
    else std::fill(values, values + n, std::numeric_limits<double>::quiet_NaN());
    values += n;
  }
  if (record_points > 0) points.Write(record_points, values, values + 3 * record_points);
}

ElementHealthCheck PenetrationCheck(double gap_distance_m) {
  return {.name = "penetration", .unit = "m", .limit = gap_distance_m, .stops = false,
          .cause = "penetration beyond the contact margin (the penalty law is calibrated for far less; "
                   "a step or a load that drove the surfaces through each other)"};
}

}  // namespace orrery::contact

#include "contact/contact_outputs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
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

std::vector<ElementHealthCheck> PenetrationChecks(double gap_distance_m, double slack_m,
                                                  const PenetrationLimit& limit) {
  if (!(limit.depth_m >= 0) || !std::isfinite(limit.depth_m))
    throw std::invalid_argument("penetration limit " + std::to_string(limit.depth_m) +
                                " m must be a finite number >= 0");
  ElementHealthCheck warn{.name = "penetration", .unit = "m", .limit = gap_distance_m, .stops = false,
                          .cause = "penetration beyond the contact margin (the penalty law is calibrated for far "
                                   "less; a step or a load that drove the surfaces through each other)"};
  // The stop: the element's own bound, or where the search stops listing the nodes
  ElementHealthCheck stop{.name = "penetration_limit", .unit = "m", .stops = true};
  if (limit.depth_m > 0) {
    stop.limit = limit.depth_m;
    stop.cause = limit.reason;
  } else {
    stop.limit = gap_distance_m + slack_m;
    stop.cause = "the penetration is beyond the contact's search distance plus its slack, where the gaps no "
                 "longer stand for the surfaces (the contact is too soft for its load, or the step too large)";
  }
  return {warn, stop};
}

}  // namespace orrery::contact

#pragma once
// What a contact element (contact_element.h, flexible_contact_element.h) reports after its own
// outputs: its monitor's (contact_monitor.h) when it has one, then its recorded contact points
// (contact_point_record.h) when asked for n > 0 of them. Both elements list and write them
// through these, in this order.
#include <vector>

#include "contact/contact_monitor.h"
#include "contact/contact_point_record.h"
#include "mbd/element_health.h"
#include "mbd/external_force.h"

namespace orrery::contact {

// `own` followed by the monitor's outputs and, for record_points = n > 0, point_positions
// (3 n columns, m) and point_normal_forces (n columns, N).
std::vector<OutputDescription> ContactOutputs(std::vector<OutputDescription> own,
                                              const ContactMonitor* monitor, int record_points);

// Writes the optional outputs' values from `values` on (after the element's own); the monitor's
// are NaN when `state` is null (a workspace made without it).
void WriteContactOutputs(const ContactMonitor* monitor, const ContactMonitorState* state,
                         const ContactPointRecord& points, int record_points, double* values);

// The health check both elements report (mbd/element_health.h): the largest penetration of the
// last evaluation against the gap distance d (m) of their search, a warning.
ElementHealthCheck PenetrationCheck(double gap_distance_m);

}  // namespace orrery::contact

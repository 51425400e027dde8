#pragma once
// What a contact element (contact_element.h, flexible_contact_element.h) reports after its own
// outputs: its monitor's (contact_monitor.h) when it has one, then its recorded contact points
// (contact_point_record.h) when asked for n > 0 of them. Both elements list and write them
// through these, in this order.
#include <string>
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

// How deep the gaps of an element still stand for its surfaces, and why (ContactElementSpec,
// FlexibleContactElementSpec: penetration_limit).
struct PenetrationLimit {
  // > 0: the depth (m); 0: the element's search distance plus its slack, d + s (below).
  double depth_m = 0;
  // What lies beyond, for the stop's message ("the nodes have crossed half the tooth ...").
  std::string reason;
};

// The health checks both elements report (mbd/element_health.h), both on the largest
// penetration of the last evaluation:
//   "penetration"        against the gap distance d (m) of their search: a warning (the penalty
//                        law is calibrated for far less);
//   "penetration_limit"  against limit.depth_m (0: d + s, s the search slack): the run stops.
//                        Beyond d + s the candidate-pair search (candidate_pairs.h) no longer
//                        lists the surfaces' deepest nodes, so the contact loses what it should
//                        push back; the tracked gaps (tracked_gaps.h) stay exact at any depth,
//                        and what bounds them is the surfaces' own shape (a gear pair: half the
//                        thinner tooth, models/gear_contact.h), given as limit.depth_m.
// Throws std::invalid_argument for a negative or non-finite depth.
std::vector<ElementHealthCheck> PenetrationChecks(double gap_distance_m, double slack_m,
                                                  const PenetrationLimit& limit);

}  // namespace orrery::contact

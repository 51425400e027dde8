#pragma once
// A force element's own plausibility checks, reported to the run-health monitor (run_health.h):
// the hook through which an element implemented outside mbd/ (tooth contact in contact/) says
// what in its state makes a result doubtful, without mbd/ knowing what the element is.
//
// An element that has such checks also derives from ElementHealthReporter; the monitor finds it
// with a dynamic_cast on each of Model::external_forces. At every output row the monitor asks for
// the values (one per check, from the element's workspace of the last Apply(), which the
// recorder's evaluation at the output state made) and compares each with its limit: above it, a
// warning (or, for a check that `stops`, the end of the run) naming the time, the element and
// the check's cause, as for the engine's own checks. Values are recorded under
// /health/elements/<element>/<check> (largest value, its time, the limit).
//
// Reporters: the contact elements (contact/contact_element.h, flexible_contact_element.h):
//   HealthChecks():   {{"penetration", "m", d, false, "penetration beyond the contact margin ..."},
//                      {"penetration_limit", "m", limit, true, ...}} with d = (margin_A +
//                     margin_B) / 2 the gap distance of their search and limit the depth their
//                     gaps can stand for (contact/contact_outputs.h PenetrationChecks);
//   GetHealthValues(ws, v): v[0] = v[1] = ws.max_penetration of the last evaluation.
#include <string>
#include <vector>

#include "mbd/external_force.h"

namespace orrery {

struct ElementHealthCheck {
  std::string name;   // identifier, recorded as /health/elements/<element>/<name>
  std::string unit;   // SI unit of the value and the limit
  double limit = 0;   // the value should stay at or below it
  bool stops = false; // beyond the limit the result is meaningless: the run stops
  std::string cause;  // what exceeding the limit means, for the warning
};

class ElementHealthReporter {
 public:
  virtual ~ElementHealthReporter() = default;
  // The element's checks; the same list for the life of the element.
  virtual std::vector<ElementHealthCheck> HealthChecks() const = 0;
  // One value per check (in the order of HealthChecks()) from the workspace of the last
  // Apply(). Must not allocate.
  virtual void GetHealthValues(const ExternalForceWorkspace& workspace, double* values) const = 0;
};

}  // namespace orrery

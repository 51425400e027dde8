#pragma once
// An observer of a contact element's evaluations that reports outputs of its own: a layer above
// contact/ reads meaning into the contact points that the general engine does not have (the
// gear layer's transmission error, mesh stiffness and contact pattern:
// models/gear_mesh_monitor.h). Per evaluation the element calls Start with the poses of its two
// bodies, Add for every penetrating node, and Finish with the contact's spatial force on side a;
// the monitor's outputs follow the element's own (contact_outputs.h). The per-Data state lives in
// a ContactMonitorState that the element's workspace owns; no call may allocate.
//
// Usage (the element's side):
//   spec.monitor = std::make_shared<const MyMonitor>(...);       // outputs() fixed from here on
//   ws.monitor = spec.monitor->MakeState();                       // per workspace
//   monitor.Start(X_WA, X_WB, *ws.monitor);
//   for each penetrating node: monitor.Add(p_on_a_W, n_W, k, *ws.monitor);
//   monitor.Finish(f_A_W, *ws.monitor);
//   monitor.Write(*ws.monitor, values);                           // OutputValueCount values
#include <memory>
#include <vector>

#include "mbd/external_force.h"
#include "mbd/spatial.h"

namespace orrery::contact {

class ContactMonitorState {
 public:
  virtual ~ContactMonitorState() = default;
};

class ContactMonitor {
 public:
  virtual ~ContactMonitor() = default;

  virtual const std::vector<OutputDescription>& outputs() const = 0;
  virtual std::unique_ptr<ContactMonitorState> MakeState() const = 0;
  // X_WA, X_WB: poses of the bodies of sides a and b (world).
  virtual void Start(const Transform& X_WA, const Transform& X_WB,
                     ContactMonitorState& state) const = 0;
  // A penetrating node: p_a_W, its point on side a (the node itself when it is a's, else its
  // closest point on a's face; world), n_W the unit contact normal (world: the outward normal
  // of the face the node was measured against, on either side), k the law's normal stiffness
  // dF_N/d(depth) (N/m).
  virtual void Add(const Vec3& p_a_W, const Vec3& n_W, double k, ContactMonitorState& state) const = 0;
  // f_A_W: the contact's spatial force on side a's body (world origin).
  virtual void Finish(const Vec6& f_A_W, ContactMonitorState& state) const = 0;
  // The outputs of the last Finish, in the order of outputs().
  virtual void Write(const ContactMonitorState& state, double* values) const = 0;
};

}  // namespace orrery::contact

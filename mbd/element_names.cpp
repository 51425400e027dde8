#include "mbd/element_names.h"

#include "mbd/constraints.h"

namespace orrery {

std::string CoordinateName(const Model& model, int k) {
  if (k >= 0 && k < static_cast<int>(model.joint_of_v.size()) && model.joint_of_v[k] >= 0) {
    const Joint& j = model.joints[model.joint_of_v[k]];
    return "joint '" + j.spec.name + "' coordinate " + std::to_string(k - j.v_start) + " (body '" +
           model.bodies[j.spec.child].name + "')";
  }
  for (const FlexibleBody& fb : model.flexible_bodies)
    if (k >= fb.v_start && k < fb.v_start + fb.nf)
      return "flexible body '" + model.bodies[fb.body].name + "' mode " + std::to_string(k - fb.v_start);
  return "coordinate " + std::to_string(k);
}

std::string PositionName(const Model& model, int i) {
  for (const Joint& j : model.joints)
    if (i >= j.q_start && i < j.q_start + j.nq)
      return "joint '" + j.spec.name + "' position " + std::to_string(i - j.q_start) + " (body '" +
             model.bodies[j.spec.child].name + "')";
  for (const FlexibleBody& fb : model.flexible_bodies)
    if (i >= fb.q_start && i < fb.q_start + fb.nf)
      return "flexible body '" + model.bodies[fb.body].name + "' mode " + std::to_string(i - fb.q_start);
  return "position " + std::to_string(i);
}

std::string DaeUnknownName(const Model& model, int i) {
  const int nq = model.nq, nv = model.nv, nc = model.n_constraints;
  if (i < nq) return "position of " + PositionName(model, i);
  if (i < nq + nv) return "velocity of " + CoordinateName(model, i - nq);
  if (i < nq + nv + nc) return "multiplier of " + ConstraintRowName(model, i - nq - nv);
  return "position multiplier of " + ConstraintRowName(model, i - nq - nv - nc);
}

}  // namespace orrery

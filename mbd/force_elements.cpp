#include "mbd/force_elements.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mbd/flexible_dynamics.h"
#include "mbd/gear_mesh.h"

namespace orrery {
namespace {

// Motion of frame B relative to frame A, in A's axes: translation of B's origin and its rate
// (as seen from A), B's orientation, and the relative angular velocity. Shared by the bushing
// and the bearing.
struct RelativeMotion {
  const Transform& Xa;
  const Transform& Xb;
  Vec3 d, d_dot, w_rel;  // A axes
  Mat3 R_AB;
};
RelativeMotion CalcRelativeMotion(const Data& data, FrameIndex fa, FrameIndex fb) {
  const Transform& Xa = data.X_WFrame[fa];
  const Transform& Xb = data.X_WFrame[fb];
  const Vec6& Va = data.V_WFrame[fa];
  const Vec6& Vb = data.V_WFrame[fb];
  const Vec3 delta = Xb.p - Xa.p;
  const Vec3 delta_dot = PointVelocity(Vb, Xb.p) - PointVelocity(Va, Xa.p);
  const Mat3 RaT = Xa.R.transpose();
  return {Xa, Xb, RaT * delta, RaT * (delta_dot - Va.head<3>().cross(delta)),
          RaT * (Vb.head<3>() - Va.head<3>()), RaT * Xb.R};
}

// The same numbers, bit for bit (a key: -0 and +0 differ).
bool SameBits(const Eigen::Ref<const Eigen::VectorXd>& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() &&
         (a.size() == 0 ||
          std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0);
}

}  // namespace

void CalcForceElements(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& v,
                       Data& data) {
  // An element kind added here that couples two bodies must also join their subtrees in
  // DaeSystem::GroupDifferences (mbd/dae.cpp), or the grouped tangents would miss its coupling;
  // one that can read a frame on a flexible body's node must be checked in ModalColumnsAreLocal
  // (mbd/flexible_dynamics.cpp), or the analytic modal tangents would miss it.
  for (auto& f : data.f_ext) f.setZero();
  data.tau_applied.setZero();
  double energy = 0, applied = 0, dissipated = 0;
  const Eigen::VectorXd& q = data.q_normalized;

  // Applied forces and torques on frames.
  for (const AppliedLoadSpec& l : model.applied_loads) {
    const Transform& X = data.X_WFrame[l.frame];
    const double s = l.scale.Value(t);
    const Vec3 f = s * (l.in_frame_axes ? Vec3(X.R * l.force) : l.force);
    const Vec3 n = s * (l.in_frame_axes ? Vec3(X.R * l.torque) : l.torque);
    AddFrameForce(model, data, l.frame, ForceAtPoint(X.p, f, n));
    const Vec6& V = data.V_WFrame[l.frame];
    applied += f.dot(PointVelocity(V, X.p)) + n.dot(V.head<3>());
  }

  // Generalized forces on joint coordinates.
  for (size_t i = 0; i < model.joint_loads.size(); ++i)
  {
    const double tau = model.joint_loads[i].function.Value(t);
    data.tau_applied(model.joint_load_v_index[i]) += tau;
    applied += tau * v(model.joint_load_v_index[i]);
  }

  // Point-to-point spring-dampers.
  for (const TranslationalSpringSpec& s : model.translational_springs) {
    const Vec3& pa = data.X_WFrame[s.frame_a].p;
    const Vec3& pb = data.X_WFrame[s.frame_b].p;
    const Vec3 d = pb - pa;
    const double L = d.norm();
    energy += 0.5 * s.stiffness * (L - s.free_length) * (L - s.free_length) + s.preload * L;
    if (L < 1e-12) continue;  // coincident ends: no direction to pull along
    const Vec3 u = d / L;
    const double Ldot =
        u.dot(PointVelocity(data.V_WFrame[s.frame_b], pb) - PointVelocity(data.V_WFrame[s.frame_a], pa));
    const double tension = s.stiffness * (L - s.free_length) + s.damping * Ldot + s.preload;
    dissipated += s.damping * Ldot * Ldot;
    AddFrameForce(model, data, s.frame_b, ForceAtPoint(pb, -tension * u));
    AddFrameForce(model, data, s.frame_a, ForceAtPoint(pa, tension * u));
  }

  // Rotational spring-dampers about z_A.
  for (const RotationalSpringSpec& s : model.rotational_springs) {
    const Transform& Xa = data.X_WFrame[s.frame_a];
    const Mat3 R_AB = Xa.R.transpose() * data.X_WFrame[s.frame_b].R;
    const Vec3 z = Xa.R.col(2);
    const double angle = std::atan2(R_AB(1, 0), R_AB(0, 0));
    const double rate = z.dot(data.V_WFrame[s.frame_b].head<3>() - data.V_WFrame[s.frame_a].head<3>());
    const double torque = -s.stiffness * (angle - s.angle0) - s.damping * rate;
    dissipated += s.damping * rate * rate;
    energy += 0.5 * s.stiffness * (angle - s.angle0) * (angle - s.angle0);
    Vec6 couple;
    couple << torque * z, Vec3::Zero();
    AddFrameForce(model, data, s.frame_b, couple);
    AddFrameForce(model, data, s.frame_a, -couple);
  }

  // Spring-dampers on joint coordinates.
  for (size_t i = 0; i < model.coordinate_springs.size(); ++i) {
    const CoordinateSpringSpec& s = model.coordinate_springs[i];
    const double dq = q(model.coordinate_spring_q_index[i]) - s.q0;
    const double dv = v(model.coordinate_spring_v_index[i]);
    data.tau_applied(model.coordinate_spring_v_index[i]) -= s.stiffness * dq + s.damping * dv;
    dissipated += s.damping * dv * dv;
    energy += 0.5 * s.stiffness * dq * dq;
  }

  // 6-DOF bushings: deflection of B relative to A in A's axes.
  for (const BushingSpec& s : model.bushings) {
    const RelativeMotion r = CalcRelativeMotion(data, s.frame_a, s.frame_b);
    Vec6 d, d_dot;
    d << r.d, RotationVector(r.R_AB);
    d_dot << r.d_dot, r.w_rel;
    const Vec6 w_A = -s.stiffness * d - s.damping * d_dot;  // (force, torque) in A axes
    energy += 0.5 * d.dot(s.stiffness * d);
    dissipated += d_dot.dot(s.damping * d_dot);
    const Mat3& Ra = r.Xa.R;
    const Vec6 f = ForceAtPoint(r.Xb.p, Ra * w_A.head<3>(), Ra * w_A.tail<3>());
    AddFrameForce(model, data, s.frame_b, f);
    AddFrameForce(model, data, s.frame_a, -f);
  }
  // Bearings: radial/axial springs on B's displacement in A's axes, tilt springs on z_A x z_B.
  for (const BearingSpec& s : model.bearings) {
    const RelativeMotion r = CalcRelativeMotion(data, s.frame_a, s.frame_b);
    const Vec3& d = r.d;
    const Vec3& d_dot = r.d_dot;
    const Vec3 zb_A = r.R_AB.col(2);
    const Vec3 tilt(-zb_A.y(), zb_A.x(), 0.0);  // e_z x z_B in A's axes
    Vec3 tilt_rate = r.w_rel;
    tilt_rate.z() = 0;
    const Vec3 k(s.radial_stiffness, s.radial_stiffness, s.axial_stiffness);
    const Vec3 c(s.radial_damping, s.radial_damping, s.axial_damping);
    const Vec3 f_A = -(k.cwiseProduct(d) + c.cwiseProduct(d_dot));
    const Vec3 m_A = -(s.tilt_stiffness * tilt + s.tilt_damping * tilt_rate);
    energy += 0.5 * d.dot(k.cwiseProduct(d)) + 0.5 * s.tilt_stiffness * tilt.squaredNorm();
    dissipated += d_dot.dot(c.cwiseProduct(d_dot)) + s.tilt_damping * tilt_rate.squaredNorm();
    const Vec6 f = ForceAtPoint(r.Xb.p, r.Xa.R * f_A, r.Xa.R * m_A);
    AddFrameForce(model, data, s.frame_b, f);
    AddFrameForce(model, data, s.frame_a, -f);
  }

  // Lumped gear meshes: spring-damper on the engaged flank's line of action (left out, with
  // their outputs as they were, while DaeSystem::Tangents takes differences: they have analytic
  // tangents, AddGearMeshTangents).
  const size_t n_meshes = data.skip_elements_with_tangents ? 0 : model.gear_meshes.size();
  if (n_meshes > 0) CalcGearAngles(model, data);  // once per gear, for all its meshes
  for (size_t i = 0; i < n_meshes; ++i) {
    const GearMesh& mesh = model.gear_meshes[i];
    const GearMeshSpec& s = mesh.spec;
    const MeshEvaluation e = EvaluateGearMeshAtAngles(model, mesh, data);
    if (e.side != 0) {
      const MeshState& st = e.state;
      const Vec3& n = e.side > 0 ? st.n_drive_W : st.n_coast_W;
      const Vec3 f_b = (e.side * e.force) * n;
      AddFrameForce(model, data, s.gear_b, ForceAtPoint(st.p_b_W, f_b));
      AddFrameForce(model, data, s.gear_a, ForceAtPoint(st.p_a_W, -f_b));
      // Reaction moment on the reference body (zero for consistent, undisplaced geometry).
      Vec6 moment_c;
      moment_c << (e.side * e.force * st.KSpin(n)) * st.z_W, Vec3::Zero();
      AddFrameForce(model, data, s.reference, moment_c);
      energy += 0.5 * e.k * (e.delta - e.ste) * (e.delta - e.ste);
      // Damping power; a clamped (releasing) contact dissipates only what its force does.
      const bool two_sided = s.contact == GearMeshSpec::Contact::kTwoSided;
      dissipated += e.force > 0 || !two_sided ? mesh.c * e.rate * e.rate : 0.0;
    }
    data.mesh_force[i] = e.force;
    data.mesh_deflection[i] = e.delta;
    data.mesh_stiffness[i] = e.k;
    data.mesh_phase[i] = e.psi;
    data.mesh_contact[i] = e.side;
  }
  // Flexible bodies: elastic, damping and geometric-stiffening forces on the modal coordinates.
  const auto [elastic, modal_dissipated] = CalcFlexibleInternalForces(model, data);
  data.potential_energy = energy + elastic;
  data.power_applied = applied;
  data.power_dissipated = dissipated + modal_dissipated;
  CalcExternalForces(model, t, v, data);
}

void CalcExternalForces(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& v,
                        Data& data) {
  // Elements defined outside mbd/ (contact/) add to the same accumulators (those with analytic
  // tangents not while DaeSystem::Tangents takes differences).
  const int n = static_cast<int>(model.external_forces.size());
  if (n == 0) return;  // nothing to apply, and no state to key (the lumped scenes)
  const bool skipping = data.skip_elements_with_tangents;
  auto skipped = [&](int i) { return skipping && model.external_forces[i]->HasTangents(); };
  // The elements with tangents whose workspaces hold this state: their results are added again.
  const bool same_state = !skipping && data.tangent_elements_t == t &&
                          SameBits(data.q_normalized, data.tangent_elements_q) &&
                          SameBits(v, data.tangent_elements_v);
  auto reused = [&](int i) {
    const ExternalForceElement& element = *model.external_forces[i];
    return same_state && element.HasTangents() && element.SplitsApply();
  };
  if (!skipping) data.tangent_elements_t = std::numeric_limits<double>::quiet_NaN();
  // With threads: the elements that split their Apply() compute into their own workspaces in
  // parallel (dynamic schedule: a flexible contact costs several rigid ones).
  const int threads = std::min(data.threads, n);
  if (threads > 1) {
    const Data& input = data;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int i = 0; i < n; ++i) {
      const ExternalForceElement& element = *model.external_forces[i];
      if (skipped(i) || reused(i) || !element.SplitsApply()) continue;
      try {
        element.Compute(model, t, input, *data.external[i]);
      } catch (...) {
        data.external_errors[i] = std::current_exception();
      }
    }
    // The first failure in element order; every slot is cleared, so that none is thrown
    // again by a later evaluation.
    std::exception_ptr first;
    for (std::exception_ptr& error : data.external_errors)
      if (std::exception_ptr e = std::exchange(error, nullptr); e && !first) first = e;
    if (first) std::rethrow_exception(first);
  }
  // Then, in element order on this thread, the results are added (or the element applied).
  for (int i = 0; i < n; ++i) {
    if (skipped(i)) continue;
    const ExternalForceElement& element = *model.external_forces[i];
    if (reused(i) || (threads > 1 && element.SplitsApply()))
      element.AddTo(model, *data.external[i], data);
    else
      element.Apply(model, t, data, *data.external[i]);
  }
  if (!skipping) {
    data.tangent_elements_t = t;
    data.tangent_elements_q = data.q_normalized;
    data.tangent_elements_v = v;
  }
}

void WarmStartExternalWorkspaces(const Model& model, const Data& source, Data& target) {
  target.tangent_elements_t = std::numeric_limits<double>::quiet_NaN();
  for (size_t e = 0; e < model.external_forces.size(); ++e)
    model.external_forces[e]->WarmStart(*source.external[e], *target.external[e]);
}

}  // namespace orrery

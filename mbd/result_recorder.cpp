#include "mbd/result_recorder.h"

#include "mbd/constraints.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"

namespace orrery {
namespace {

std::string JointUnit(JointType type) {
  switch (type) {
    case JointType::kRevolute: case JointType::kUniversal: return "rad";
    case JointType::kPrismatic: return "m";
    case JointType::kCylindrical: return "rad, m";
    case JointType::kSpherical: return "1";
    case JointType::kPlanar: return "m, m, rad";
    case JointType::kFree: return "m, m, m, 1, 1, 1, 1";
    case JointType::kFixed: return "1";
  }
  return "1";
}

std::string JointRateUnit(JointType type) {
  switch (type) {
    case JointType::kRevolute: case JointType::kUniversal: case JointType::kSpherical: return "rad/s";
    case JointType::kPrismatic: return "m/s";
    case JointType::kCylindrical: return "rad/s, m/s";
    case JointType::kPlanar: return "m/s, m/s, rad/s";
    case JointType::kFree: return "m/s, m/s, m/s, rad/s, rad/s, rad/s";
    case JointType::kFixed: return "1";
  }
  return "1";
}

const std::vector<std::string> kXYZ{"x", "y", "z"};
const std::vector<std::string> kWrench{"fx", "fy", "fz", "mx", "my", "mz"};

}  // namespace

ResultRecorder::ResultRecorder(const Model& model, ResultFile& out)
    : model_(model), out_(out), data_(model) {
  time_ = out.AddSeries("/time", 1, "s");
  bodies_.resize(model.nbodies);
  for (BodyIndex b = 1; b < model.nbodies; ++b) {
    const std::string g = "/bodies/" + model.bodies[b].name + "/";
    bodies_[b] = {out.AddSeries(g + "position", 3, "m", kXYZ),
                  out.AddSeries(g + "orientation", 4, "1", {"w", "x", "y", "z"}),
                  out.AddSeries(g + "linear_velocity", 3, "m/s", kXYZ),
                  out.AddSeries(g + "angular_velocity", 3, "rad/s", kXYZ),
                  out.AddSeries(g + "linear_acceleration", 3, "m/s^2", kXYZ),
                  out.AddSeries(g + "angular_acceleration", 3, "rad/s^2", kXYZ)};
  }
  for (const Joint& j : model.joints) {
    const std::string g = "/joints/" + j.spec.name + "/";
    joint_q_.push_back(j.nq > 0 ? out.AddSeries(g + "q", j.nq, JointUnit(j.spec.type)) : -1);
    joint_v_.push_back(j.nv > 0 ? out.AddSeries(g + "v", j.nv, JointRateUnit(j.spec.type)) : -1);
    joint_reaction_.push_back(out.AddSeries(g + "reaction", 6, "N, N m", kWrench));
    out.SetAttribute("/joints/" + j.spec.name, "type", std::string(JointTypeName(j.spec.type)));
  }
  for (const LoopClosureSpec& l : model.loop_closures)
    loop_reaction_.push_back(out.AddSeries("/loop_closures/" + l.name + "/reaction", 6, "N, N m", kWrench));
  for (const Driver& d : model.drivers) {
    const JointType type = model.joints[d.spec.joint].spec.type;
    const bool linear = type == JointType::kPrismatic ||
                        (type == JointType::kCylindrical && d.spec.coordinate == 1) ||
                        (type == JointType::kPlanar && d.spec.coordinate < 2) ||
                        (type == JointType::kFree && d.spec.coordinate < 3);
    driver_effort_.push_back(out.AddSeries("/drivers/" + d.spec.name + "/effort", 1, linear ? "N" : "N m"));
  }
  for (const GearMesh& m : model.gear_meshes) {
    const std::string g = "/gear_meshes/" + m.spec.name + "/";
    meshes_.push_back({out.AddSeries(g + "force", 1, "N"), out.AddSeries(g + "deflection", 1, "m"),
                       out.AddSeries(g + "stiffness", 1, "N/m"), out.AddSeries(g + "contact", 1, "1"),
                       out.AddSeries(g + "phase", 1, "1")});
  }
  for (const GearConstraint& c : model.gear_constraints)
    gear_constraint_force_.push_back(out.AddSeries("/gear_constraints/" + c.spec.name + "/force", 1, "N"));
  energy_ = out.AddSeries("/energy", 3, "J", {"kinetic", "gravity_potential", "elastic_potential"});
  power_ = out.AddSeries("/power", 3, "W", {"applied", "drivers", "dissipated"});
  drift_ = out.AddSeries("/constraints/drift", 2, "m, m/s (rad, rad/s for angular rows)",
                         {"max_abs_phi", "max_abs_phidot"});
  row_.setZero(8);
}

void ResultRecorder::Record(const State& s, const Eigen::VectorXd& vdot,
                            const Eigen::VectorXd& lambda) {
  Data& d = data_;
  EvaluateDynamics(model_, s.t, s.q, s.v, vdot, d);
  out_.Append(time_, &s.t);
  // Energy and drift.
  row_(0) = CalcKineticEnergy(model_, d);
  row_(1) = CalcGravityPotential(model_, d);
  row_(2) = d.potential_energy;
  out_.Append(energy_, row_.data());
  row_(0) = d.power_applied;
  row_(1) = 0;
  for (size_t k = 0; k < model_.drivers.size(); ++k)
    row_(1) += -lambda(model_.driver_row[k]) * s.v(model_.drivers[k].v_index);
  row_(2) = d.power_dissipated;
  out_.Append(power_, row_.data());
  row_(0) = model_.n_holonomic > 0 ? d.phi.lpNorm<Eigen::Infinity>() : 0.0;
  row_(1) = 0;
  if (model_.n_constraints > 0) {
    for (int r = 0; r < model_.n_constraints; ++r)
      row_(1) = std::max(row_(1), std::abs(d.G.row(r).dot(s.v) + d.g_t(r)));
  }
  out_.Append(drift_, row_.data());
  // Reactions: rerun inverse dynamics with the loop closures' forces on the bodies.
  AddConstraintBodyForces(model_, d, lambda, d.f_ext);
  CalcInverseDynamics(model_, vdot, d);
  // Bodies: the world-frame spatial acceleration without the base offset -g.
  Vec6 A0;
  A0 << Vec3::Zero(), -model_.gravity;
  for (BodyIndex b = 1; b < model_.nbodies; ++b) {
    const Transform& X = d.X_WB[b];
    const Vec6& V = d.V_WB[b];
    const Vec6 A = d.A_WB[b] - A0;
    const Vec3 v = PointVelocity(V, X.p);
    const Vec3 a = A.tail<3>() + A.head<3>().cross(X.p) + V.head<3>().cross(v);
    const Quat quat(X.R);
    row_.head<4>() << quat.w(), quat.x(), quat.y(), quat.z();
    out_.Append(bodies_[b].p, X.p.data());
    out_.Append(bodies_[b].quat, row_.data());
    out_.Append(bodies_[b].v, v.data());
    out_.Append(bodies_[b].w, V.data());
    out_.Append(bodies_[b].a, a.data());
    out_.Append(bodies_[b].alpha, A.data());
  }
  // Joints.
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& jt = model_.joints[j];
    if (joint_q_[j] >= 0) out_.Append(joint_q_[j], s.q.data() + jt.q_start);
    if (joint_v_[j] >= 0) out_.Append(joint_v_[j], s.v.data() + jt.v_start);
    const Vec3 p_M = (d.X_WF[j] * d.X_FM[j]).p;
    const Vec6 f = ForceAboutPoint(d.f_joint[jt.spec.child], p_M);
    row_.head<3>() = f.tail<3>();
    row_.segment<3>(3) = f.head<3>();
    out_.Append(joint_reaction_[j], row_.data());
  }
  // Loop closures: wrench on B's body from the multipliers, at B's origin.
  int loop_row = 0;
  for (size_t l = 0; l < model_.loop_closures.size(); ++l) {
    Vec6 f = Vec6::Zero();
    for (int r = 0; r < model_.loop_rows[l]; ++r, ++loop_row)
      f -= lambda(model_.loop_row_start[l] + r) * d.c_rows_b[loop_row];
    const Vec6 fB = ForceAboutPoint(f, d.X_WFrame[model_.loop_closures[l].frame_b].p);
    row_.head<3>() = fB.tail<3>();
    row_.segment<3>(3) = fB.head<3>();
    out_.Append(loop_reaction_[l], row_.data());
  }
  // Gear meshes (filled by CalcForceElements above) and ideal meshes.
  for (size_t i = 0; i < meshes_.size(); ++i) {
    const double contact = d.mesh_contact[i];
    out_.Append(meshes_[i].force, &d.mesh_force[i]);
    out_.Append(meshes_[i].deflection, &d.mesh_deflection[i]);
    out_.Append(meshes_[i].stiffness, &d.mesh_stiffness[i]);
    out_.Append(meshes_[i].contact, &contact);
    out_.Append(meshes_[i].phase, &d.mesh_phase[i]);
  }
  for (size_t k = 0; k < gear_constraint_force_.size(); ++k)
    out_.Append(gear_constraint_force_[k], lambda.data() + model_.gear_constraint_row[k]);
  // Drivers: effort = -lambda of the driver's row.
  for (size_t k = 0; k < model_.drivers.size(); ++k) {
    const double effort = -lambda(model_.driver_row[k]);
    out_.Append(driver_effort_[k], &effort);
  }
}

}  // namespace orrery

#include "mbd/result_recorder.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "mbd/constraints.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/flexible_dynamics.h"
#include "mbd/force_elements.h"
#include "mbd/stress_hot_spot.h"

namespace orrery {
namespace {

// Column names of a joint's q (rate == false) or v series.
std::vector<std::string> JointColumns(JointType type, bool rate) {
  const JointTypeInfo& info = JointInfo(type);
  const int n = rate ? info.nv : info.nq;
  std::vector<std::string> names;
  for (int k = 0; k < n; ++k) names.emplace_back(rate ? info.v_names[k] : info.q_names[k]);
  return names;
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
    joint_q_.push_back(j.nq > 0
                           ? out.AddSeries(g + "q", j.nq, JointCoordinateUnits(j.spec.type, false),
                                           JointColumns(j.spec.type, false))
                           : -1);
    joint_v_.push_back(j.nv > 0
                           ? out.AddSeries(g + "v", j.nv, JointCoordinateUnits(j.spec.type, true),
                                           JointColumns(j.spec.type, true))
                           : -1);
    joint_reaction_.push_back(out.AddSeries(g + "reaction", 6, "N, N m", kWrench));
    out.SetAttribute("/joints/" + j.spec.name, "type", std::string(JointTypeName(j.spec.type)));
  }
  for (const LoopClosureSpec& l : model.loop_closures)
    loop_reaction_.push_back(out.AddSeries("/loop_closures/" + l.name + "/reaction", 6, "N, N m", kWrench));
  for (const Driver& d : model.drivers) {
    const JointType type = model.joints[d.spec.joint].spec.type;
    const bool linear = JointInfo(type).v_kind[d.spec.coordinate] == CoordinateKind::kLength;
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
  int max_surface = 0;
  for (const FlexibleBody& fb : model.flexible_bodies) {
    const FlexibleBodyModes& m = *fb.modes;
    const std::string name = model.bodies[fb.body].name;
    const std::string g = "/flexible_bodies/" + name + "/";
    FlexSeries fs;
    if (fb.nf > 0) {
      fs.q = out.AddSeries(g + "modal_q", fb.nf, "kg^0.5 m");
      fs.v = out.AddSeries(g + "modal_v", fb.nf, "kg^0.5 m/s");
    }
    if (!m.stress_nodes.empty() && fb.nf > 0) {
      fs.von_mises = out.AddSeries(g + "von_mises_max", 5, "Pa, 1, m, m, m", {"stress", "node", "x", "y", "z"});
      fs.hot_spot = std::make_unique<StressHotSpot>(m.stress_modes, fb.nf);
    }
    if (fb.options.record_surface && !m.surface_triangles.empty()) {
      // Compact numbering of the nodes the triangles use.
      std::map<int, int> compact;
      for (const auto& t : m.surface_triangles)
        for (int i : t) compact.emplace(i, 0);
      for (auto& [node, index] : compact) {
        index = static_cast<int>(fs.surface_nodes.size());
        fs.surface_nodes.push_back(node);
      }
      const int n = static_cast<int>(fs.surface_nodes.size());
      Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic> tri(m.surface_triangles.size(), 3);
      for (size_t k = 0; k < m.surface_triangles.size(); ++k)
        for (int c = 0; c < 3; ++c) tri(k, c) = compact[m.surface_triangles[k][c]];
      Eigen::MatrixXd ref(n, 3);
      for (int i = 0; i < n; ++i) ref.row(i) = m.nodes[fs.surface_nodes[i]].position.transpose();
      out.WriteIntMatrix(g + "surface/triangles", tri);
      out.WriteMatrix(g + "surface/reference_positions", ref, "m");
      fs.surface = out.AddSeries(g + "surface/positions", 3 * n, "m");
      max_surface = std::max(max_surface, 3 * n);
    }
    for (const std::string& set : fb.options.record_node_sets) {
      fs.node_set_nodes.push_back(&m.node_sets.at(set));
      const int n = static_cast<int>(fs.node_set_nodes.back()->size());
      fs.node_sets.push_back(out.AddSeries(g + "node_sets/" + set + "/displacement", 3 * n, "m"));
      max_surface = std::max(max_surface, 3 * n);
    }
    flex_.push_back(std::move(fs));
    if (!m.frequencies_hz.empty()) out.WriteVector(g + "frequencies_hz", m.frequencies_hz, "Hz");
  }
  surface_row_.setZero(max_surface);
  size_t max_external = 8;
  for (const auto& e : model.external_forces) {
    std::vector<ResultFile::SeriesId> ids;
    std::vector<int> offsets;
    int offset = 0;
    for (const OutputDescription& o : e->outputs()) {
      ids.push_back(out.AddSeries("/external/" + e->name() + "/" + o.name, o.columns, o.unit));
      offsets.push_back(offset);
      offset += o.columns;
    }
    external_.push_back(std::move(ids));
    external_offsets_.push_back(std::move(offsets));
    max_external = std::max(max_external, static_cast<size_t>(offset));
  }
  energy_ = out.AddSeries("/energy", 3, "J", {"kinetic", "gravity_potential", "elastic_potential"});
  power_ = out.AddSeries("/power", 3, "W", {"applied", "drivers", "dissipated"});
  drift_ = out.AddSeries("/constraints/drift", 2, "m, m/s (rad, rad/s for angular rows)",
                         {"max_abs_phi", "max_abs_phidot"});
  row_.setZero(static_cast<Eigen::Index>(max_external));
  // The staged row: the series above have consecutive ids (each AddSeries returns the next one
  // and nothing else adds series while the constructor runs), time_ the first, drift_ the last.
  first_ = time_;
  count_ = drift_ - time_ + 1;
  offset_.resize(count_);
  int cols = 0;
  for (int k = 0; k < count_; ++k) {
    offset_[k] = cols;
    cols += out.cols(first_ + k);
  }
  staged_.setZero(cols);
}

void ResultRecorder::Record(const State& s, const Eigen::VectorXd& vdot,
                            const Eigen::VectorXd& lambda, const Data* warm, const Data* at_state) {
  if (model_.n_constraints > 0) at_state = nullptr;
  if (!at_state) {
    if (warm) WarmStartExternalWorkspaces(model_, *warm, data_);
    EvaluateDynamics(model_, s.t, s.q, s.v, vdot, data_);
    // Reactions: inverse dynamics again with the constraints' forces on the bodies (without
    // constraints the evaluation's own f_joint are the reactions).
    if (model_.n_constraints > 0) {
      AddConstraintBodyForces(model_, data_, lambda, data_.f_ext);
      CalcInverseDynamics(model_, vdot, data_);
    }
  }
  const Data& d = at_state ? *at_state : data_;
  row_data_ = &d;
  // Each series' columns go to its place in the staged row; one AppendRow at the end (the appends
  // one call per series cost about 108 instructions each, 30k per row of seed 001's 275 series).
  Put<1>(time_, &s.t);
  // Energy and drift.
  row_(0) = CalcKineticEnergy(model_, d);
  row_(1) = CalcGravityPotential(model_, d);
  row_(2) = d.potential_energy;
  Put<3>(energy_, row_.data());
  row_(0) = d.power_applied;
  row_(1) = 0;
  for (size_t k = 0; k < model_.drivers.size(); ++k)
    row_(1) += -lambda(model_.driver_row[k]) * s.v(model_.drivers[k].v_index);
  row_(2) = d.power_dissipated;
  Put<3>(power_, row_.data());
  row_(0) = model_.n_holonomic > 0 ? d.phi.lpNorm<Eigen::Infinity>() : 0.0;
  row_(1) = 0;
  if (model_.n_constraints > 0) {
    for (int r = 0; r < model_.n_constraints; ++r)
      row_(1) = std::max(row_(1), std::abs(d.G.row(r).dot(s.v) + d.g_t(r)));
  }
  Put<2>(drift_, row_.data());
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
    Put<3>(bodies_[b].p, X.p.data());
    Put<4>(bodies_[b].quat, row_.data());
    Put<3>(bodies_[b].v, v.data());
    Put<3>(bodies_[b].w, V.data());
    Put<3>(bodies_[b].a, a.data());
    Put<3>(bodies_[b].alpha, A.data());
  }
  // Joints.
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& jt = model_.joints[j];
    if (joint_q_[j] >= 0) std::copy_n(s.q.data() + jt.q_start, jt.nq, Slot(joint_q_[j]));
    if (joint_v_[j] >= 0) std::copy_n(s.v.data() + jt.v_start, jt.nv, Slot(joint_v_[j]));
    const Vec3 p_M = (d.X_WF[j] * d.X_FM[j]).p;
    const Vec6 f = ForceAboutPoint(d.f_joint[jt.spec.child], p_M);
    row_.head<3>() = f.tail<3>();
    row_.segment<3>(3) = f.head<3>();
    Put<6>(joint_reaction_[j], row_.data());
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
    Put<6>(loop_reaction_[l], row_.data());
  }
  // Gear meshes (filled by CalcForceElements above) and ideal meshes.
  for (size_t i = 0; i < meshes_.size(); ++i) {
    const double contact = d.mesh_contact[i];
    Put<1>(meshes_[i].force, &d.mesh_force[i]);
    Put<1>(meshes_[i].deflection, &d.mesh_deflection[i]);
    Put<1>(meshes_[i].stiffness, &d.mesh_stiffness[i]);
    Put<1>(meshes_[i].contact, &contact);
    Put<1>(meshes_[i].phase, &d.mesh_phase[i]);
  }
  for (size_t k = 0; k < gear_constraint_force_.size(); ++k)
    Put<1>(gear_constraint_force_[k], lambda.data() + model_.gear_constraint_row[k]);
  // Flexible bodies: modal coordinates, the von Mises hot spot, deformed surfaces.
  for (size_t i = 0; i < flex_.size(); ++i) {
    const FlexibleBody& fb = model_.flexible_bodies[i];
    const FlexibleBodyModes& m = *fb.modes;
    const FlexSeries& fs = flex_[i];
    const Eigen::VectorXd& qf = d.flex[i].qf;
    if (fs.q >= 0) {
      std::copy_n(s.q.data() + fb.q_start, fb.nf, Slot(fs.q));
      std::copy_n(s.v.data() + fb.v_start, fb.nf, Slot(fs.v));
    }
    if (fs.von_mises >= 0) {
      // The point of the largest von Mises stress, by bounds (stress_hot_spot.h): the value
      // and point of a scan of every point's stress.
      const StressHotSpot::Result hot = fs.hot_spot->Find(qf.data());
      const FlexibleBodyModes::Node& node = m.nodes[m.stress_nodes[hot.point]];
      row_.head<5>() << hot.von_mises, double(node.id), node.position.x(), node.position.y(),
          node.position.z();
      Put<5>(fs.von_mises, row_.data());
    }
    if (fs.surface >= 0) {
      const Transform& X = d.X_WB[fb.body];
      const int n = static_cast<int>(fs.surface_nodes.size());
      for (int k = 0; k < n; ++k) {
        const FlexibleBodyModes::Node& node = m.nodes[fs.surface_nodes[k]];
        surface_row_.segment<3>(3 * k) = X * Vec3(node.position + node.translation_shapes.leftCols(fb.nf) * qf);
      }
      std::copy_n(surface_row_.data(), 3 * n, Slot(fs.surface));
    }
    for (size_t k = 0; k < fs.node_sets.size(); ++k) {
      const std::vector<int>& nodes = *fs.node_set_nodes[k];
      for (size_t j = 0; j < nodes.size(); ++j)
        surface_row_.segment<3>(3 * j) = m.nodes[nodes[j]].translation_shapes.leftCols(fb.nf) * qf;
      std::copy_n(surface_row_.data(), 3 * nodes.size(), Slot(fs.node_sets[k]));
    }
  }
  for (size_t e = 0; e < external_.size(); ++e) {
    if (external_[e].empty()) continue;
    model_.external_forces[e]->GetOutputs(*d.external[e], row_.data());
    // The element's outputs are consecutive series, so their columns are one block of the row.
    const int n = external_offsets_[e].back() + out_.cols(external_[e].back());
    std::copy_n(row_.data(), n, Slot(external_[e][0]));
  }
  // Drivers: effort = -lambda of the driver's row.
  for (size_t k = 0; k < model_.drivers.size(); ++k) {
    const double effort = -lambda(model_.driver_row[k]);
    Put<1>(driver_effort_[k], &effort);
  }
  out_.AppendRow(first_, count_, staged_.data());
}

}  // namespace orrery

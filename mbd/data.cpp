#include "mbd/data.h"

#include <algorithm>

namespace orrery {

Data::Data(const Model& model) {
  const int nb = model.nbodies, nj = static_cast<int>(model.joints.size());
  const int nf = static_cast<int>(model.frames.size());
  int loop_rows = 0;
  for (int r : model.loop_rows) loop_rows += r;
  X_WB.assign(nb, Transform::Identity());
  X_WF.assign(nj, Transform::Identity());
  X_FM.assign(nj, Transform::Identity());
  X_WFrame.assign(nf, Transform::Identity());
  S = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, model.nv);
  I_W.assign(nb, SpatialInertia{});
  q_normalized = Eigen::VectorXd::Zero(model.nq);
  V_WB.assign(nb, Vec6::Zero());
  // Body Jacobians only where analytic tangents need them (lumped meshes, external elements).
  bool tangents = !model.gear_meshes.empty();
  for (const auto& element : model.external_forces) tangents |= element->HasTangents();
  if (tangents) J_WB.assign(nb, Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, model.nv));
  c_J.assign(nj, Vec6::Zero());
  f_ext.assign(nb, Vec6::Zero());
  tau_applied = Eigen::VectorXd::Zero(model.nv);
  A_WB.assign(nb, Vec6::Zero());
  f_joint.assign(nb, Vec6::Zero());
  tau_id = Eigen::VectorXd::Zero(model.nv);
  I_c.assign(nb, SpatialInertia{});
  M = Eigen::MatrixXd::Zero(model.nv, model.nv);
  phi = Eigen::VectorXd::Zero(model.n_holonomic);
  G = Eigen::MatrixXd::Zero(model.n_constraints, model.nv);
  g_t = Eigen::VectorXd::Zero(model.n_constraints);
  c_rows_a.assign(loop_rows, Vec6::Zero());
  c_rows_b.assign(loop_rows, Vec6::Zero());
  scratch_nv = Eigen::VectorXd::Zero(model.nv);
  const size_t nm = model.gear_meshes.size();
  mesh_force.assign(nm, 0.0);
  mesh_deflection.assign(nm, 0.0);
  mesh_stiffness.assign(nm, 0.0);
  mesh_phase.assign(nm, 0.0);
  gear_angle.assign(model.gear_angles.size(), 0.0);
  mesh_contact.assign(nm, 0);
  c_gear_a.assign(model.gear_constraints.size(), Vec6::Zero());
  c_gear_b.assign(model.gear_constraints.size(), Vec6::Zero());
  c_gear_c.assign(model.gear_constraints.size(), Vec6::Zero());
  V_WFrame.assign(nf, Vec6::Zero());
  J_frame_modal.resize(nf);
  for (int f = 0; f < nf; ++f) {
    const Frame& frame = model.frames[f];
    const int fb = model.bodies[frame.body].flexible;
    if (frame.node >= 0 && fb >= 0)
      J_frame_modal[f] = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, model.flexible_bodies[fb].nf);
  }
  flex.resize(model.flexible_bodies.size());
  for (size_t i = 0; i < flex.size(); ++i) {
    const int n = model.flexible_bodies[i].nf;
    flex[i].D = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, 3 * n);
    flex[i].L = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    flex[i].F_W = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, n);
    flex[i].K_geo = Eigen::MatrixXd::Zero(n, n);
    flex[i].scratch = Eigen::VectorXd::Zero(n);
    flex[i].qf = Eigen::VectorXd::Zero(n);
    flex[i].qf_dot = Eigen::VectorXd::Zero(n);
    flex[i].G = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    flex[i].qf_of_D = Eigen::VectorXd::Zero(n);
    flex[i].qf_dot_of_G = Eigen::VectorXd::Zero(n);
  }
  for (const auto& element : model.external_forces) external.push_back(element->MakeWorkspace(model));
  external_errors.resize(model.external_forces.size());
  tangent_elements_q = Eigen::VectorXd::Zero(model.nq);
  tangent_elements_v = Eigen::VectorXd::Zero(model.nv);
  sensor_values = Eigen::VectorXd::Zero(model.n_sensor_channels);
  int element_values = 0;
  for (const Sensor& s : model.sensors) element_values = std::max(element_values, s.element_values);
  element_outputs = Eigen::VectorXd::Zero(element_values);
}

void AddFrameForce(const Model& model, Data& data, FrameIndex frame, const Vec6& f) {
  const BodyIndex b = model.frames[frame].body;
  if (b == kWorldBody) return;
  data.f_ext[b] += f;
  const auto& J = data.J_frame_modal[frame];
  if (J.cols() > 0) {
    const FlexibleBody& fb = model.flexible_bodies[model.bodies[b].flexible];
    data.tau_applied.segment(fb.v_start, fb.nf).noalias() += J.transpose() * f;
  }
}

}  // namespace orrery

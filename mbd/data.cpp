#include "mbd/data.h"

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
  mesh_contact.assign(nm, 0);
  c_gear_a.assign(model.gear_constraints.size(), Vec6::Zero());
  c_gear_b.assign(model.gear_constraints.size(), Vec6::Zero());
  c_gear_c.assign(model.gear_constraints.size(), Vec6::Zero());
}

}  // namespace orrery

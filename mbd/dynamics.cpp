#include "mbd/dynamics.h"

#include "mbd/flexible_dynamics.h"

namespace orrery {

void CalcInverseDynamics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& vdot,
                         Data& data) {
  // Forward pass: accelerations (the world accelerates at -g) and body forces.
  data.A_WB[kWorldBody] << Vec3::Zero(), -model.gravity;
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    const BodyIndex b = jt.spec.child;
    data.A_WB[b] = data.A_WB[jt.spec.parent] + JointMotion(data, jt.v_start, jt.nv, vdot) + data.c_J[j];
    if (model.bodies[b].flexible >= 0) {
      data.f_joint[b] =
          CalcFlexibleBodyForce(model, model.flexible_bodies[model.bodies[b].flexible], vdot, data);
      continue;
    }
    const SpatialInertia& I = data.I_W[b];
    const Vec6& V = data.V_WB[b];
    data.f_joint[b] = I * data.A_WB[b] + CrossForce(V, I * V) - data.f_ext[b];
  }
  // Backward pass: joint forces, subtree forces handed to the parents.
  for (auto it = model.tree_order.rbegin(); it != model.tree_order.rend(); ++it) {
    const Joint& jt = model.joints[*it];
    const BodyIndex b = jt.spec.child;
    for (int k = 0; k < jt.nv; ++k)
      data.tau_id(jt.v_start + k) = data.S.col(jt.v_start + k).dot(data.f_joint[b]);
    if (jt.spec.parent != kWorldBody) data.f_joint[jt.spec.parent] += data.f_joint[b];
  }
  data.tau_id -= data.tau_applied;
}

void CalcMassMatrix(const Model& model, Data& data) {
  // Composite inertias, leaves to root.
  for (BodyIndex b = 0; b < model.nbodies; ++b) data.I_c[b] = data.I_W[b];
  for (auto it = model.tree_order.rbegin(); it != model.tree_order.rend(); ++it) {
    const Joint& jt = model.joints[*it];
    if (jt.spec.parent != kWorldBody) data.I_c[jt.spec.parent] += data.I_c[jt.spec.child];
  }
  // For each joint, F = I_c S_j and its projection on every ancestor joint.
  data.M.setZero();
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    const SpatialInertia& Ic = data.I_c[jt.spec.child];
    for (int k = 0; k < jt.nv; ++k) {
      const Vec6 F = Ic * data.S.col(jt.v_start + k).eval();
      const int col = jt.v_start + k;
      for (int r = 0; r <= k; ++r) {
        const double m = data.S.col(jt.v_start + r).dot(F);
        data.M(jt.v_start + r, col) = m;
        data.M(col, jt.v_start + r) = m;
      }
      for (JointIndex a = model.bodies[jt.spec.parent].parent_joint; a >= 0;
           a = model.bodies[model.joints[a].spec.parent].parent_joint) {
        const Joint& ja = model.joints[a];
        for (int r = 0; r < ja.nv; ++r) {
          const double m = data.S.col(ja.v_start + r).dot(F);
          data.M(ja.v_start + r, col) = m;
          data.M(col, ja.v_start + r) = m;
        }
      }
    }
  }
  AddFlexibleMassMatrix(model, data);
}

void CalcMassMatrixDiagonal(const Model& model, Data& data, Eigen::Ref<Eigen::VectorXd> diagonal) {
  // Composite inertias, leaves to root, as CalcMassMatrix
  for (BodyIndex b = 0; b < model.nbodies; ++b) data.I_c[b] = data.I_W[b];
  for (auto it = model.tree_order.rbegin(); it != model.tree_order.rend(); ++it) {
    const Joint& jt = model.joints[*it];
    if (jt.spec.parent != kWorldBody) data.I_c[jt.spec.parent] += data.I_c[jt.spec.child];
  }
  // M_kk = S_k . (I_c S_k), CalcMassMatrix's expression for its r = k entry
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    const SpatialInertia& Ic = data.I_c[jt.spec.child];
    for (int k = 0; k < jt.nv; ++k) {
      const Vec6 F = Ic * data.S.col(jt.v_start + k).eval();
      diagonal(jt.v_start + k) = data.S.col(jt.v_start + k).dot(F);
    }
  }
}

double CalcKineticEnergy(const Model& model, const Data& data) {
  double T = 0;
  for (BodyIndex b = 1; b < model.nbodies; ++b)
    T += 0.5 * data.V_WB[b].dot(data.I_W[b] * data.V_WB[b]);
  return T + FlexibleKineticEnergy(model, data);
}

double CalcGravityPotential(const Model& model, const Data& data) {
  double U = 0;
  for (BodyIndex b = 1; b < model.nbodies; ++b) U -= data.I_W[b].h.dot(model.gravity);
  return U;
}

}  // namespace orrery

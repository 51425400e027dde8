#include "mbd/dynamics.h"

#include "mbd/flexible_dynamics.h"

namespace orrery {
namespace {

// I A + V x* (I V) - f_ext of a body turning about z (Body::turns_about_z), whose V = (0, 0, w,
// vx, vy, 0) and A = (0, 0, alpha, ax, ay, az) hold exact zeros: the general expression
// (SpatialInertia's product, CrossForce) with the products of those zeros left out. A product
// with an exact zero is a zero and adding it changes nothing, and the remaining terms are
// grouped as the general expression groups them, so the force is the general path's to the last
// bit (a zero component may differ in sign). 28 multiplications against the general 66.
Vec6 BodyForceTurningAboutZ(const SpatialInertia& I, const Vec6& V, const Vec6& A,
                            const Vec6& f_ext) {
  const Mat3& J = I.I;
  const Vec3& h = I.h;
  const double w = V(2), vx = V(3), vy = V(4);
  const double alpha = A(2), ax = A(3), ay = A(4), az = A(5);
  // Momentum I V: angular n (n_z is not needed below), linear l (l_z = 0).
  const double n0 = J(0, 2) * w - h(2) * vy, n1 = J(1, 2) * w + h(2) * vx;
  const double l0 = I.m * vx - h(1) * w, l1 = I.m * vy + h(0) * w;
  // I A and V x* (I V), then the sum as the general path forms it.
  Vec6 f;
  f(0) = ((J(0, 2) * alpha + (h(1) * az - h(2) * ay)) - w * n1) - f_ext(0);
  f(1) = ((J(1, 2) * alpha + (h(2) * ax - h(0) * az)) + w * n0) - f_ext(1);
  f(2) = ((J(2, 2) * alpha + (h(0) * ay - h(1) * ax)) + (vx * l1 - vy * l0)) - f_ext(2);
  f(3) = ((I.m * ax - h(1) * alpha) - w * l1) - f_ext(3);
  f(4) = ((I.m * ay + h(0) * alpha) + w * l0) - f_ext(4);
  f(5) = I.m * az - f_ext(5);
  return f;
}

// Composite inertias data.I_c (each body's subtree, world axes), leaves to root: the mass
// matrix's and its diagonal's common first pass.
void CalcCompositeInertias(const Model& model, Data& data) {
  for (BodyIndex b = 0; b < model.nbodies; ++b) data.I_c[b] = data.I_W[b];
  for (auto it = model.tree_order.rbegin(); it != model.tree_order.rend(); ++it) {
    const Joint& jt = model.joints[*it];
    if (jt.spec.parent != kWorldBody) data.I_c[jt.spec.parent] += data.I_c[jt.spec.child];
  }
}

}  // namespace

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
    if (model.bodies[b].turns_about_z) {
      data.f_joint[b] = BodyForceTurningAboutZ(I, V, data.A_WB[b], data.f_ext[b]);
      continue;
    }
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
  CalcCompositeInertias(model, data);
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
  CalcCompositeInertias(model, data);
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

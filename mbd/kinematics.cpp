#include "mbd/kinematics.h"

#include <cmath>

#include "mbd/flexible_dynamics.h"

namespace orrery {

void NormalizeQuaternions(const Model& model, Eigen::Ref<Eigen::VectorXd> q) {
  if (!model.has_quaternions) return;
  for (const Joint& j : model.joints) {
    const int quat = JointInfo(j.spec.type).quaternion;
    if (quat >= 0) q.segment<4>(j.q_start + quat).normalize();
  }
}

void CalcPositionKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                            Data& data) {
  CalcFramePoses(model, q, data);
  for (BodyIndex b = 1; b < model.nbodies; ++b) {
    const Body& body = model.bodies[b];
    const Transform& X = data.X_WB[b];
    data.I_W[b] = SpatialInertia::FromCentral(body.mass, X * body.com_B,
                                              X.R * body.inertia_cm_B * X.R.transpose());
  }
  CalcFlexibleInertiaTerms(model, data);
}

namespace {

// A revolute joint about sigma z of F (Joint::revolute_z = sigma): X_FM = Rz(sigma q), the
// child's pose X_WF X_FM and the motion subspace Ad(X_WF) (sigma z, 0), with the zeros of the
// rotation written out. The same roundings as the general path (RevolutePosition's AngleAxis
// matrix holds c, -+sigma s, zeros and (1 - c) + c; the zero terms of the products add nothing
// exactly; no fused multiply-adds), so the poses are the general path's to the last bit.
void RevoluteAboutZ(int sigma, double angle, const Transform& X_WF, Transform& X_FM, Transform& X_WB,
                    Eigen::Ref<Vec6> S) {
  const double c = std::cos(angle), s_z = sigma * std::sin(angle), r22 = (1 - c) + c;
  X_FM.R << c, -s_z, 0, s_z, c, 0, 0, 0, r22;
  X_FM.p.setZero();
  const Mat3& R = X_WF.R;
  X_WB.R.col(0) = R.col(0) * c + R.col(1) * s_z;
  X_WB.R.col(1) = R.col(0) * -s_z + R.col(1) * c;
  X_WB.R.col(2) = R.col(2) * r22;
  X_WB.p = X_WF.p;
  S.head<3>() = sigma > 0 ? Vec3(R.col(2)) : Vec3(-R.col(2));
  S.tail<3>() = X_WF.p.cross(S.head<3>());
}

// A free joint: X_FM = (R(quaternion), p), the child's pose X_WF X_FM and the motion subspace
// Ad(X_WF) of the table entry's S_F = ((0, e_k), (e_k, p x e_k)), k = x, y, z, without the
// table's function and the six general MotionToWorld products. The same roundings as the general
// path: R_WF e_k and R_WF 0 are R_WF's column k and zeros exactly (a product with 1 or 0 and the
// sum with zeros round nothing), and the rotation columns' moments keep the general path's
// expressions R_WF (p x e_k) + p_WF x (R_WF e_k), so the poses are its own to the last bit.
void FreeJoint(const double* q, const Transform& X_WF, Transform& X_FM, Transform& X_WB,
               Eigen::Ref<Eigen::Matrix<double, 6, 6>> S) {
  const Vec3 p(q[0], q[1], q[2]);
  X_FM.R = Quat(q[3], q[4], q[5], q[6]).toRotationMatrix();
  X_FM.p = p;
  const Mat3& R = X_WF.R;
  for (int k = 0; k < 3; ++k) {
    S.col(k).head<3>().setZero();
    S.col(k).tail<3>() = R.col(k);
    S.col(3 + k).head<3>() = R.col(k);
    S.col(3 + k).tail<3>() = R * p.cross(Vec3::Unit(k)) + X_WF.p.cross(R.col(k));
  }
  X_WB = X_WF * X_FM;
}

}  // namespace

void CalcFramePoses(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q_in, Data& data) {
  data.q_normalized = q_in;
  NormalizeQuaternions(model, data.q_normalized);
  const Eigen::VectorXd& q = data.q_normalized;

  data.X_WB[kWorldBody] = Transform::Identity();
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    const int qs = jt.q_start, vs = jt.v_start;
    // F: on the world its pose is X_PF itself (what the identity's product gives).
    const Transform& X_WP = data.X_WB[jt.spec.parent];
    Transform& X_WF = data.X_WF[j];
    X_WF = jt.spec.parent == kWorldBody ? jt.spec.X_PF : jt.X_PF_is_identity ? X_WP : X_WP * jt.spec.X_PF;
    Transform& X_FM = data.X_FM[j];
    const BodyIndex b = jt.spec.child;
    if (jt.revolute_z != 0) {
      RevoluteAboutZ(jt.revolute_z, q(qs), X_WF, X_FM, data.X_WB[b], data.S.col(vs));
    } else if (jt.spec.type == JointType::kFree) {
      FreeJoint(q.data() + qs, X_WF, X_FM, data.X_WB[b], data.S.middleCols<6>(vs));
    } else {
      // Joint transform and motion subspace S_F (about F's origin, F axes), mapped to world.
      const JointTypeInfo& info = JointInfo(jt.spec.type);
      Vec6 S_F[6];
      info.position(jt, q.data() + qs, X_FM, S_F);
      for (int k = 0; k < info.nv; ++k) data.S.col(vs + k) = MotionToWorld(X_WF, S_F[k]);
      data.X_WB[b] = X_WF * X_FM;
    }
    if (!jt.X_MC_is_identity) data.X_WB[b] = data.X_WB[b] * jt.X_MC;
  }

  // Named frames (those on nodes follow their node).
  for (size_t f = 0; f < model.frames.size(); ++f) {
    const Frame& frame = model.frames[f];
    data.X_WFrame[f] = frame.is_body_frame ? data.X_WB[frame.body] : data.X_WB[frame.body] * frame.X_BF;
  }
  CalcNodeFramePoses(model, q, data);
}

void CalcVelocityKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& v,
                            Data& data) {
  const Eigen::VectorXd& q = data.q_normalized;
  data.V_WB[kWorldBody].setZero();
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    const int qs = jt.q_start, vs = jt.v_start;
    const Vec6& V_WP = data.V_WB[jt.spec.parent];
    const Vec6 V_joint = JointMotion(data, vs, jt.nv, v);
    data.V_WB[jt.spec.child] = V_WP + V_joint;
    // S-dot v: frame F moves with the parent, plus the joint's own dS_F/dt v (in F).
    Vec6 c = CrossMotion(V_WP, V_joint);
    if (jt.spec.type == JointType::kFree) {
      // The table's (0, p-dot x w) in F, mapped: R_WF 0 and p_WF x 0 add zeros only (FreeJoint)
      const Vec3 pdot(v(vs), v(vs + 1), v(vs + 2)), w(v(vs + 3), v(vs + 4), v(vs + 5));
      c.tail<3>() += data.X_WF[j].R * pdot.cross(w);
    } else if (const JointVelocityProductFn dS_F = JointInfo(jt.spec.type).velocity_product) {
      c += MotionToWorld(data.X_WF[j], dS_F(jt, q.data() + qs, v.data() + vs));
    }
    data.c_J[j] = c;
  }
  CalcFrameVelocities(model, v, data);
}

void CalcAccelerationKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& vdot,
                                Data& data) {
  data.A_WB[kWorldBody] << Vec3::Zero(), -model.gravity;
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    data.A_WB[jt.spec.child] =
        data.A_WB[jt.spec.parent] + JointMotion(data, jt.v_start, jt.nv, vdot) + data.c_J[j];
  }
}

void CalcBodyJacobians(const Model& model, Data& data) {
  data.J_WB[kWorldBody].setZero();
  for (const JointIndex j : model.tree_order) {
    const Joint& jt = model.joints[j];
    auto& J = data.J_WB[jt.spec.child];
    J = data.J_WB[jt.spec.parent];
    J.middleCols(jt.v_start, jt.nv) += data.S.middleCols(jt.v_start, jt.nv);
  }
}

void CalcQDot(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> qdot) {
  if (!model.has_quaternions) {
    qdot = v;
    return;
  }
  for (const Joint& jt : model.joints) {
    const int qs = jt.q_start, vs = jt.v_start;
    const int quat = JointInfo(jt.spec.type).quaternion;  // offset of the quaternion block
    if (quat < 0) {
      qdot.segment(qs, jt.nq) = v.segment(vs, jt.nv);
      continue;
    }
    // Coordinates before the quaternion (a free joint's translation) are their own rates.
    qdot.segment(qs, quat) = v.segment(vs, quat);
    // (0, w) x (w0, u) = (-w.u, w0 w + w x u), halved; w is the angular velocity in F.
    const Vec3 w = v.segment<3>(vs + quat);
    const double w0 = q(qs + quat);
    const Vec3 u = q.segment<3>(qs + quat + 1);
    qdot(qs + quat) = -0.5 * w.dot(u);
    qdot.segment<3>(qs + quat + 1) = 0.5 * (w0 * w + w.cross(u));
  }
  for (const FlexibleBody& fb : model.flexible_bodies)
    qdot.segment(fb.q_start, fb.nf) = v.segment(fb.v_start, fb.nf);
}

void IntegratePositions(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& dv,
                        Eigen::Ref<Eigen::VectorXd> q) {
  for (const Joint& jt : model.joints) {
    const int qs = jt.q_start, vs = jt.v_start;
    const int quat = JointInfo(jt.spec.type).quaternion;
    if (quat < 0) {
      q.segment(qs, jt.nq) += dv.segment(vs, jt.nv);
      continue;
    }
    q.segment(qs, quat) += dv.segment(vs, quat);
    // Spatial (F-frame) angular increment: q <- exp(dphi) x q.
    const Quat current(q(qs + quat), q(qs + quat + 1), q(qs + quat + 2), q(qs + quat + 3));
    const Quat next = (QuatExp(dv.segment<3>(vs + quat)) * current).normalized();
    q(qs + quat) = next.w();
    q.segment<3>(qs + quat + 1) = next.vec();
  }
  for (const FlexibleBody& fb : model.flexible_bodies)
    q.segment(fb.q_start, fb.nf) += dv.segment(fb.v_start, fb.nf);
}

}  // namespace orrery

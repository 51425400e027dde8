#pragma once
// Spatial algebra used by every pipeline stage.
//
// Conventions (Featherstone, "Rigid Body Dynamics Algorithms", ch. 2, in ground coordinates):
// - A spatial motion vector V = (w, v) holds an angular velocity w and the velocity v of the body
//   point that momentarily coincides with the origin of the frame it is expressed in. Inside the
//   engine all spatial vectors are expressed in world coordinates about the world origin W_o.
// - A spatial force f = (n, f) holds the moment n about that same origin and the force f.
// - Poses use Drake's monogram names: X_WB is the pose of frame B in W (R_WB, p_WoBo_W).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace orrery {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Quat = Eigen::Quaterniond;

// Skew-symmetric matrix [a]x with [a]x b = a x b.
inline Mat3 Skew(const Vec3& a) {
  Mat3 s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

// Rigid transform X_AB: pose of frame B in frame A (rotation R_AB, position p_AoBo_A).
struct Transform {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();

  Transform() = default;
  Transform(const Mat3& rotation, const Vec3& position) : R(rotation), p(position) {}
  static Transform Identity() { return {}; }
  static Transform Translation(const Vec3& position) { return {Mat3::Identity(), position}; }

  // X_AC = X_AB * X_BC.
  Transform operator*(const Transform& X_BC) const { return {R * X_BC.R, R * X_BC.p + p}; }
  // p_AoQ_A from p_BoQ_B.
  Vec3 operator*(const Vec3& p_BoQ_B) const { return R * p_BoQ_B + p; }
  Transform Inverse() const { return {R.transpose(), -(R.transpose() * p)}; }
  bool IsIdentity() const { return R == Mat3::Identity() && p == Vec3::Zero(); }
};

// Rotation of `angle` rad about the unit axis `axis`.
inline Mat3 AxisAngle(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

// Spatial cross product for motion vectors: a x b (Featherstone crm(a) b).
inline Vec6 CrossMotion(const Vec6& a, const Vec6& b) {
  Vec6 r;
  r.head<3>() = a.head<3>().cross(b.head<3>());
  r.tail<3>() = a.head<3>().cross(b.tail<3>()) + a.tail<3>().cross(b.head<3>());
  return r;
}

// Spatial cross product for forces: a x* f (Featherstone crf(a) f).
inline Vec6 CrossForce(const Vec6& a, const Vec6& f) {
  Vec6 r;
  r.head<3>() = a.head<3>().cross(f.head<3>()) + a.tail<3>().cross(f.tail<3>());
  r.tail<3>() = a.head<3>().cross(f.tail<3>());
  return r;
}

// Motion vector given about the origin of frame F in F coordinates, to world coordinates about
// the world origin: w_W = R w_F, v_Wo = R v_F + p x w_W.
inline Vec6 MotionToWorld(const Transform& X_WF, const Vec6& m_F) {
  Vec6 r;
  r.head<3>() = X_WF.R * m_F.head<3>();
  r.tail<3>() = X_WF.R * m_F.tail<3>() + X_WF.p.cross(r.head<3>());
  return r;
}

// Force given about the origin of frame F in F coordinates, to world coordinates about the
// world origin: f_W = R f_F, n_Wo = R n_F + p x f_W.
inline Vec6 ForceToWorld(const Transform& X_WF, const Vec6& f_F) {
  Vec6 r;
  r.tail<3>() = X_WF.R * f_F.tail<3>();
  r.head<3>() = X_WF.R * f_F.head<3>() + X_WF.p.cross(r.tail<3>());
  return r;
}

// Spatial force of a force `f_W` applied at point `p_WoQ_W` (plus a free moment `n_W`).
inline Vec6 ForceAtPoint(const Vec3& p_WoQ_W, const Vec3& f_W, const Vec3& n_W = Vec3::Zero()) {
  Vec6 r;
  r.head<3>() = n_W + p_WoQ_W.cross(f_W);
  r.tail<3>() = f_W;
  return r;
}

// Moves a world spatial force from the world origin to a point Q (moment about Q, world coords).
inline Vec6 ForceAboutPoint(const Vec6& f_Wo, const Vec3& p_WoQ_W) {
  Vec6 r = f_Wo;
  r.head<3>() -= p_WoQ_W.cross(f_Wo.tail<3>());
  return r;
}

// Velocity of the body point at `p_WoQ_W` from a world spatial velocity.
inline Vec3 PointVelocity(const Vec6& V_Wo, const Vec3& p_WoQ_W) {
  return V_Wo.tail<3>() + V_Wo.head<3>().cross(p_WoQ_W);
}

// Spatial inertia about a reference point, compact form: mass m, first moment h = m c (c: centre
// of mass from the reference point) and rotational inertia I_o about the reference point.
struct SpatialInertia {
  double m = 0;
  Vec3 h = Vec3::Zero();
  Mat3 I = Mat3::Zero();

  // World-origin inertia of a body with mass `m`, centre of mass at `p_WoBcm_W`, and central
  // inertia `I_cm_W` expressed in world axes (parallel-axis theorem).
  static SpatialInertia FromCentral(double m, const Vec3& p_WoBcm_W, const Mat3& I_cm_W) {
    SpatialInertia s;
    s.m = m;
    s.h = m * p_WoBcm_W;
    // I_cm - m [c]x [c]x = I_cm + m (|c|^2 1 - c c^T)
    s.I = I_cm_W - m * p_WoBcm_W * p_WoBcm_W.transpose();
    s.I.diagonal().array() += m * p_WoBcm_W.squaredNorm();
    return s;
  }
  // Momentum I * V (V about the same reference point).
  Vec6 operator*(const Vec6& V) const {
    Vec6 r;
    r.head<3>() = I * V.head<3>() + h.cross(V.tail<3>());
    r.tail<3>() = m * V.tail<3>() - h.cross(V.head<3>());
    return r;
  }
  SpatialInertia& operator+=(const SpatialInertia& o) {
    m += o.m;
    h += o.h;
    I += o.I;
    return *this;
  }
  Mat6 Matrix() const {
    Mat6 M;
    M.topLeftCorner<3, 3>() = I;
    M.topRightCorner<3, 3>() = Skew(h);
    M.bottomLeftCorner<3, 3>() = -Skew(h);
    M.bottomRightCorner<3, 3>() = m * Mat3::Identity();
    return M;
  }
};

// Rotation vector (axis * angle, |angle| <= pi) of a rotation matrix (SO(3) logarithm).
inline Vec3 RotationVector(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

// Quaternion exponential: rotation by rotation vector `phi` as a unit quaternion.
inline Quat QuatExp(const Vec3& phi) {
  const double angle = phi.norm();
  if (angle < 1e-12) return Quat(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()).normalized();
  return Quat(Eigen::AngleAxisd(angle, phi / angle));
}

}  // namespace orrery

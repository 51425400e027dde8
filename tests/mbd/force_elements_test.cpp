// Force elements against closed forms.
// - Oscillators (mass on a prismatic joint with a translational spring, with damping, with a
//   coordinate spring; a torsional oscillator with a rotational spring) integrated with Newmark's
//   average-acceleration rule (generalized-alpha with alpha_m = alpha_f = 0, beta = 1/4,
//   gamma = 1/2), which is the trapezoidal rule on (x, v): its discrete solution is
//   y_n = R^n y_0, R = (I - hA/2)^-1 (I + hA/2), computed here independently; and the continuous
//   closed form x(t) = x0 + e^(-zeta w t) (A cos wd t + B sin wd t), whose distance from the
//   discrete solution is computed exactly (undamped: |x_n - x(t_n)| <= A t |2 atan(wh/2)/h - w|).
// - A 6-DOF bushing with a full K under a constant load: static deflection d = K^-1 F, checked by
//   the EvaluateDynamics residual.
// - Applied loads in frame and world axes, joint loads: generalized forces in closed form.
// - Data::potential_energy against the closed-form spring energies, and the generalized forces
//   against -dV/dq by central differences.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

constexpr double kEps = 2.220446049250313e-16;

JointSpec MakeJoint(const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                const Transform& X_PF = Transform(), const Vec3& axis = Vec3::UnitZ()) {
  JointSpec j;
  j.name = name, j.type = type, j.parent = parent, j.child = child, j.X_PF = X_PF, j.axis = axis;
  return j;
}

IntegratorOptions Newmark(double h) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = h;
  o.alpha_m = 0, o.alpha_f = 0, o.beta = 0.25, o.gamma = 0.5;
  return o;
}

// Integrates a one-coordinate oscillator m x'' + c x' + k (x - x0) = 0 from x(0) = x0 + A, v = 0
// with Newmark and checks it against the discrete and continuous closed forms.
void CheckOscillator(const Model& model, double m, double c, double k, double x0, double A,
                     const char* what) {
  const double h = 1e-3, t_end = 2.0;
  const int n = static_cast<int>(std::lround(t_end / h));
  std::unique_ptr<Integrator> integ = MakeIntegrator(model, Newmark(h));
  State s0 = State::Initial(model);
  ASSERT_NEAR(s0.q(0), x0 + A, 1e-15);
  integ->Initialize(s0);
  // Continuous closed form (underdamped).
  const double w = std::sqrt(k / m), zeta = c / (2 * std::sqrt(k * m));
  ASSERT_LT(zeta, 1.0);
  const double wd = w * std::sqrt(1 - zeta * zeta);
  auto exact = [&](double t) {
    return x0 + std::exp(-zeta * w * t) * (A * std::cos(wd * t) + A * zeta * w / wd * std::sin(wd * t));
  };
  // Discrete closed form: trapezoidal rule on y = (x - x0, v), y' = [0 1; -k/m -c/m] y.
  Eigen::Matrix2d Am;
  Am << 0, 1, -k / m, -c / m;
  const Eigen::Matrix2d R = (Eigen::Matrix2d::Identity() - h / 2 * Am).inverse() *
                            (Eigen::Matrix2d::Identity() + h / 2 * Am);
  Eigen::Vector2d y(A, 0);
  // Solver floor: Newton stops at |force residual| <= 1e-10 max(1, m|a|) per step, i.e. an
  // acceleration error of 1e-10 max(1, m w^2 A)/m, moving x by h^2/4 of it; plus rounding of x
  // per step; both summed over the n steps.
  const double floor = n * (h * h / 4 * 1e-10 * std::max(1.0, m * w * w * std::abs(A)) / m +
                            4 * kEps * (std::abs(x0) + std::abs(A)));
  double err_discrete = 0, err_exact = 0, gap = 0, amp = 0;
  for (int i = 1; i <= n; ++i) {
    integ->AdvanceTo(i * h);
    y = R * y;
    const double t = integ->state().t, x = integ->state().q(0);
    err_discrete = std::max(err_discrete, std::abs(x - (x0 + y(0))));
    err_exact = std::max(err_exact, std::abs(x - exact(t)));
    gap = std::max(gap, std::abs(x0 + y(0) - exact(t)));
    amp = std::max(amp, std::abs(x - x0));
  }
  EXPECT_LE(err_discrete, floor) << what;
  EXPECT_LE(err_exact, gap + floor) << what;
  if (c == 0) {
    // Undamped: amplitude kept, phase error 2 atan(wh/2)/h - w per unit time.
    const double phase = std::abs(2 * std::atan(w * h / 2) / h - w) * t_end;
    EXPECT_LE(err_exact, std::abs(A) * phase + floor) << what;
  }
  EXPECT_GT(amp, 0.5 * std::abs(A)) << what;  // it did oscillate
  std::printf("[%s] max|x - discrete| %.3g (floor %.3g), max|x - closed form| %.3g (Newmark gap %.3g)\n",
              what, err_discrete, floor, err_exact, gap);
}

TEST(ForceElements, TranslationalSpringOscillatorPeriodAndDamping) {
  const double m = 2.0, k = 800.0, L0 = 0.5, A = 0.02;  // period 2 pi sqrt(m/k) = 0.314 s
  for (double c : {0.0, 4.0}) {
    ModelBuilder b;
    const BodyIndex mass = b.AddBody("mass", m, Vec3::Zero(), Mat3::Identity() * 1e-3);
    const JointIndex j = b.AddJoint(MakeJoint("slide", JointType::kPrismatic, kWorldBody, mass, Transform(), Vec3::UnitX()));
    b.AddTranslationalSpring({"spring", kWorldFrame, b.body_frame(mass), k, c, L0, 0.0});
    b.SetJointPosition(j, Eigen::VectorXd::Constant(1, L0 + A));
    b.SetGravity(Vec3(0, -9.81, 0));  // across the slide: carried by the joint
    const auto model = std::move(b).Finalize();
    CheckOscillator(*model, m, c, k, L0, A, c == 0 ? "translational spring" : "translational spring-damper");
  }
}

TEST(ForceElements, CoordinateSpringOscillator) {
  const double m = 0.5, k = 200.0, c = 1.0, q0 = -0.1, A = 0.05;
  ModelBuilder b;
  const BodyIndex mass = b.AddBody("mass", m, Vec3::Zero(), Mat3::Identity() * 1e-3);
  const JointIndex j = b.AddJoint(MakeJoint("slide", JointType::kPrismatic, kWorldBody, mass, Transform(), Vec3::UnitY()));
  b.AddCoordinateSpring({"coord", j, 0, k, c, q0});
  b.SetJointPosition(j, Eigen::VectorXd::Constant(1, q0 + A));
  const auto model = std::move(b).Finalize();
  CheckOscillator(*model, m, c, k, q0, A, "coordinate spring-damper");
}

TEST(ForceElements, RotationalSpringTorsionalOscillator) {
  // Period 2 pi sqrt(I/k): I = 0.01 kg m^2 about z, k = 4 N m/rad, amplitude 0.5 rad (no wrap).
  const double I = 0.01, k = 4.0, theta0 = 0.2, A = 0.5;
  ModelBuilder b;
  const BodyIndex disk = b.AddBody("disk", 1.0, Vec3::Zero(), Vec3(0.006, 0.006, I).asDiagonal());
  const JointIndex j = b.AddJoint(MakeJoint("shaft", JointType::kRevolute, kWorldBody, disk));
  b.AddRotationalSpring({"torsion", kWorldFrame, b.body_frame(disk), k, 0.0, theta0});
  b.SetJointPosition(j, Eigen::VectorXd::Constant(1, theta0 + A));
  const auto model = std::move(b).Finalize();
  CheckOscillator(*model, I, 0.0, k, theta0, A, "rotational spring");
}

// Quaternion (w, x, y, z) of the rotation by rotation vector r (written out, not via the engine).
Eigen::Vector4d QuatOf(const Vec3& r) {
  const double a = r.norm();
  const Vec3 u = r / a;
  return Eigen::Vector4d(std::cos(a / 2), std::sin(a / 2) * u.x(), std::sin(a / 2) * u.y(), std::sin(a / 2) * u.z());
}

TEST(ForceElements, BushingStaticDeflectionIsKInverseF) {
  // Full symmetric positive-definite K (translation-rotation coupling), A = world frame, B = body
  // frame, load (force, torque) at B's origin in world axes. The bushing wrench -K d acts at B's
  // origin in A's axes, so equilibrium is exactly K d = F with d = (translation, rotation vector).
  Mat6 K;
  K << 2e5, 1e4, 0, 0, 2e3, 0,
       1e4, 3e5, 2e4, 0, 0, 1e3,
       0, 2e4, 4e5, 3e3, 0, 0,
       0, 0, 3e3, 5e3, 200, 0,
       2e3, 0, 0, 200, 6e3, 300,
       0, 1e3, 0, 0, 300, 7e3;
  Vec6 F;
  F << 120, -80, 200, 15, -10, 25;
  const Vec6 d = K.ldlt().solve(F);
  ModelBuilder b;
  const BodyIndex body = b.AddBody("body", 3.0, Vec3::Zero(), Vec3(0.02, 0.03, 0.04).asDiagonal());
  const JointIndex j = b.AddJoint(MakeJoint("float", JointType::kFree, kWorldBody, body));
  b.AddBushing({"mount", kWorldFrame, b.body_frame(body), K, K * 1e-3});
  b.AddAppliedLoad({"load", b.body_frame(body), F.head<3>(), F.tail<3>(), TimeFunction::Constant(1.0), false});
  const auto model = std::move(b).Finalize();
  Data data(*model);
  Eigen::VectorXd q(7), v = Eigen::VectorXd::Zero(6), vdot = Eigen::VectorXd::Zero(6);
  q << d.head<3>(), QuatOf(d.tail<3>());
  EvaluateDynamics(*model, 0.0, q, v, vdot, data);
  // Residual rounding: eps times the size of the balanced wrenches (|K| |d| ~ |F|), times the
  // rotation-vector log's conditioning (a few eps per unit).
  const double tol = 1e3 * kEps * F.lpNorm<Eigen::Infinity>();
  EXPECT_LE(data.tau_id.lpNorm<Eigen::Infinity>(), tol) << data.tau_id.transpose();
  // Not vacuous: undeflected, the residual is the unbalanced load.
  Eigen::VectorXd q0(7);
  q0 << 0, 0, 0, 1, 0, 0, 0;
  EvaluateDynamics(*model, 0.0, q0, v, vdot, data);
  EXPECT_GT(data.tau_id.lpNorm<Eigen::Infinity>(), 10.0);
  (void)j;
}

TEST(ForceElements, AppliedLoadAxesAndJointLoad) {
  // A link on a revolute joint (z) at the origin turned by theta; a frame at (L, 0, 0) on it.
  // Force (0, F, 0) in frame axes is tangential: torque L F; in world axes: L F cos(theta).
  // Torque (0, 0, N) on a frame flipped about x (z_frame = -z): -N in frame axes, +N in world axes.
  // Joint load f(t) adds directly. Static (v = vdot = 0, no gravity): tau_id = -Q.
  const double L = 0.3, Fy = 7.0, N = 2.0, theta = 0.7, t = 0.37;
  const TimeFunction scale = TimeFunction::Sine(1.0, 1.0, 0.3, 0.5);
  const TimeFunction motor = TimeFunction::Ramp(0, 1, 0, 4);
  for (bool in_frame : {true, false}) {
    ModelBuilder b;
    const BodyIndex link = b.AddBody("link", 1.0, Vec3(L / 2, 0, 0), Mat3::Identity() * 0.01);
    const JointIndex j = b.AddJoint(MakeJoint("hinge", JointType::kRevolute, kWorldBody, link));
    const FrameIndex tip = b.AddFrame("tip", link, Transform::Translation(Vec3(L, 0, 0)));
    const FrameIndex flipped = b.AddFrame("flipped", link, Transform(AxisAngle(Vec3::UnitX(), M_PI), Vec3::Zero()));
    b.AddAppliedLoad({"push", tip, Vec3(0, Fy, 0), Vec3::Zero(), scale, in_frame});
    b.AddAppliedLoad({"twist", flipped, Vec3::Zero(), Vec3(0, 0, N), TimeFunction::Constant(1.0), in_frame});
    b.AddJointLoad({"motor", j, 0, motor});
    const auto model = std::move(b).Finalize();
    Data data(*model);
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, theta), z = Eigen::VectorXd::Zero(1);
    EvaluateDynamics(*model, t, q, z, z, data);
    const double Q = scale.Value(t) * L * Fy * (in_frame ? 1.0 : std::cos(theta)) + (in_frame ? -N : N) +
                     motor.Value(t);
    EXPECT_NEAR(-data.tau_id(0), Q, 100 * kEps * (L * Fy + N + 4)) << (in_frame ? "frame axes" : "world axes");
  }
}

TEST(ForceElements, PotentialEnergyMatchesClosedFormsAndForcesAreItsGradient) {
  // Body 1 on a free joint: bushing (full K) to a world frame, translational spring with preload
  // from a world point to an off-centre point. Body 2 on a revolute joint: rotational spring and
  // coordinate spring. Damping zero (v = 0 anyway), gravity zero.
  Mat6 K = Mat6::Identity();
  K.diagonal() << 3e3, 4e3, 5e3, 60, 70, 80;
  K(0, 4) = K(4, 0) = 50;
  K(2, 3) = K(3, 2) = -40;
  const double ks = 250, L0 = 0.4, P = 3.0, kr = 9, a0 = 0.1, kc = 11, q0c = -0.2;
  const Transform X_WA(AxisAngle(Vec3(1, 2, 3).normalized(), 0.4), Vec3(0.1, 0.2, 0.3));
  const Vec3 p_anchor(0.9, -0.3, 0.2), p_mark_B(0.05, 0.1, -0.02);
  ModelBuilder b;
  const BodyIndex b1 = b.AddBody("b1", 2.0, Vec3(0.01, 0, 0), Vec3(0.02, 0.03, 0.04).asDiagonal());
  const BodyIndex b2 = b.AddBody("b2", 1.0, Vec3(0.1, 0, 0), Vec3(0.01, 0.01, 0.015).asDiagonal());
  b.AddJoint(MakeJoint("float", JointType::kFree, kWorldBody, b1));
  const JointIndex hinge = b.AddJoint(MakeJoint("hinge", JointType::kRevolute, kWorldBody, b2, Transform::Translation(Vec3(0, 0, -1))));
  const FrameIndex fa = b.AddFrame("A", kWorldBody, X_WA);
  const FrameIndex anchor = b.AddFrame("anchor", kWorldBody, Transform::Translation(p_anchor));
  const FrameIndex mark = b.AddFrame("mark", b1, Transform::Translation(p_mark_B));
  const FrameIndex base = b.AddFrame("base", kWorldBody, Transform::Translation(Vec3(0, 0, -1)));
  b.AddBushing({"mount", fa, b.body_frame(b1), K, Mat6::Zero()});
  b.AddTranslationalSpring({"spring", anchor, mark, ks, 0.0, L0, P});
  b.AddRotationalSpring({"torsion", base, b.body_frame(b2), kr, 0.0, a0});
  b.AddCoordinateSpring({"coord", hinge, 0, kc, 0.0, q0c});
  const auto model = std::move(b).Finalize();
  const Model& m = *model;
  Data data(m);
  // A configuration: b1 at p with rotation vector r; b2 at angle phi.
  const Vec3 p(0.15, 0.22, 0.28), r(0.3, -0.2, 0.5);
  const double phi = 0.6;
  Eigen::VectorXd q(m.nq);
  const Joint& jf = m.joints[m.joint("float")];
  const Joint& jh = m.joints[hinge];
  q.segment<3>(jf.q_start) = p;
  q.segment<4>(jf.q_start + 3) = QuatOf(r);
  q(jh.q_start) = phi;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.nv);
  EvaluateDynamics(m, 0.0, q, zero, zero, data);
  // Closed forms. Bushing: d = (R_A^T (p - p_A), log(R_A^T R_B)) with the log written out.
  const Mat3 R_B = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
  const Mat3 R_AB = X_WA.R.transpose() * R_B;
  const double ang = std::acos(std::clamp((R_AB.trace() - 1) / 2, -1.0, 1.0));
  const Vec3 axis = Vec3(R_AB(2, 1) - R_AB(1, 2), R_AB(0, 2) - R_AB(2, 0), R_AB(1, 0) - R_AB(0, 1)) / (2 * std::sin(ang));
  Vec6 d;
  d << X_WA.R.transpose() * (p - X_WA.p), ang * axis;
  const double V_bushing = 0.5 * d.dot(K * d);
  const double Ls = (p + R_B * p_mark_B - p_anchor).norm();
  const double V_spring = 0.5 * ks * (Ls - L0) * (Ls - L0) + P * Ls;  // preload: P L (zero at L = 0)
  const double V_torsion = 0.5 * kr * (phi - a0) * (phi - a0);
  const double V_coord = 0.5 * kc * (phi - q0c) * (phi - q0c);
  const double V = V_bushing + V_spring + V_torsion + V_coord;
  // Rounding of a handful of products and the acos-based log (~sqrt(eps)-free here: angle 0.6).
  EXPECT_NEAR(data.potential_energy, V, 1e-12 * V);
  // Forces are -dV/dq: tau_id (v = vdot = 0, no gravity) = dV/d(dq), dq along q (+) dq.
  // Central difference, step e: truncation e^2/6 |V'''| (|V'''| ~ |K| / length ~ 1e5) + rounding
  // eps |V| / e. The bushing's torque -K d (seed 002 eq. 10, d_rot the rotation vector) is the
  // gradient of 1/2 d^T K d only to first order in the rotation: d(d_rot)/d(phi) is the inverse
  // SO(3) Jacobian, I + 1/2 [d_rot]x + O(|d_rot|^2). The gradient check is therefore made with the
  // body turned back to a small relative rotation (|d_rot| ~ 2e-3 rad), where that term is bounded
  // by 1/2 |d_rot| |K d| (times 1.1 for the O(|d_rot|^2) rest) on the rotational coordinates.
  q.segment<4>(jf.q_start + 3) = QuatOf(RotationVector(X_WA.R) + Vec3(1e-3, -1e-3, 1e-3));
  EvaluateDynamics(m, 0.0, q, zero, zero, data);
  Vec6 ds;
  ds << X_WA.R.transpose() * (p - X_WA.p), RotationVector(X_WA.R.transpose() * data.X_WB[b1].R);
  const double nonconservative = 1.1 * 0.5 * ds.tail<3>().norm() * (K * ds).norm();
  const double e = 1e-6;
  for (int k = 0; k < m.nv; ++k) {
    const bool rotational = k >= jf.v_start + 3 && k < jf.v_start + 6;
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(m.nv), qp = q, qm = q;
    dq(k) = e;
    IntegratePositions(m, dq, qp);
    IntegratePositions(m, -dq, qm);
    EvaluateDynamics(m, 0.0, qp, zero, zero, data);
    const double Vp = data.potential_energy;
    EvaluateDynamics(m, 0.0, qm, zero, zero, data);
    const double Vm = data.potential_energy;
    EvaluateDynamics(m, 0.0, q, zero, zero, data);
    const double tol = e * e / 6 * 1e5 + 10 * kEps * V / e + (rotational ? nonconservative : 0.0);
    EXPECT_NEAR(data.tau_id(k), (Vp - Vm) / (2 * e), tol) << "coordinate " << k;
  }
}

}  // namespace
}  // namespace orrery

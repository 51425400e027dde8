// Rigid bodies on quaternion joints (free and spherical), integrated by IDA.
//
// Oracles:
// - first integrals of torque-free motion: kinetic energy, world linear momentum and world
//   angular momentum about the world origin, h = R I_cm R^T w + m c x v_cm;
// - the closed-form body-frame angular velocity of a torque-free symmetric top (derived below
//   from Euler's equations);
// - total energy of a heavy body on a spherical joint away from its centre of mass.
// Tolerances: IDA holds every step's local error below rtol |y| + atol (weighted RMS norm); with
// errors added without cancellation, a first integral Q(y) (quadratic or linear in the velocities)
// drifts at most steps * (|dQ/dy| |y|) * rtol ~ steps * 2 rtol |Q|scale, times sqrt(n) to turn
// the weighted RMS norm over the n = nq + nv differential components into a max norm.
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

constexpr double kRtol = 1e-10, kAtol = 1e-12;

IntegratorOptions IdaOptions() {
  IntegratorOptions opt;
  opt.kind = IntegratorKind::kIda;
  opt.rtol = kRtol;
  opt.atol = kAtol;
  return opt;
}

Eigen::VectorXd QuatCoords(const Quat& q) {
  Eigen::VectorXd c(4);
  c << q.w(), q.x(), q.y(), q.z();
  return c;
}

// World linear momentum and angular momentum about the world origin of body b.
void Momenta(const Model& model, const Data& data, BodyIndex b, Vec3* p, Vec3* h) {
  const Body& body = model.bodies[b];
  const Transform& X = data.X_WB[b];
  const Vec3 c = X * body.com_B;
  const Vec3 v_cm = PointVelocity(data.V_WB[b], c);
  const Vec3 w = data.V_WB[b].head<3>();
  *p = body.mass * v_cm;
  *h = X.R * body.inertia_cm_B * X.R.transpose() * w + body.mass * c.cross(v_cm);
}

// An asymmetric body on a free joint, spun almost about its intermediate principal axis (it
// flips periodically, the Dzhanibekov effect). Principal axes rotated against the body frame,
// centre of mass off the body origin, joint frames off the origins: nothing is trivially aligned.
TEST(RigidBody, TorqueFreeAsymmetricBodyConservesEnergyAndMomentum) {
  ModelBuilder b;
  const Mat3 R_BP = AxisAngle(Vec3(0.3, -0.5, 0.8).normalized(), 0.9);
  const Mat3 I_cm = R_BP * Vec3(0.1, 0.2, 0.27).asDiagonal() * R_BP.transpose();
  const BodyIndex body = b.AddBody("body", 3.0, Vec3(0.1, -0.05, 0.2), I_cm);
  const JointIndex free = b.AddJoint(
      {.name = "free", .type = JointType::kFree, .parent = kWorldBody, .child = body,
       .X_PF = Transform(AxisAngle(Vec3::UnitX(), 0.4), Vec3(1, 2, 3)),
       .X_CM = Transform(AxisAngle(Vec3::UnitY(), -0.3), Vec3(0.02, 0.0, -0.1))});
  Eigen::VectorXd q0(7), v0(6);
  q0 << 0.2, -0.1, 0.5, QuatCoords(Quat(AxisAngle(Vec3(1, 1, 0).normalized(), 0.6)));
  // Body-frame spin: mostly about the intermediate principal axis, slightly off it.
  const Vec3 w_P(0.02, 4.0, 0.03);
  const Mat3 R_FB = Quat(q0(3), q0(4), q0(5), q0(6)).toRotationMatrix() *
                    AxisAngle(Vec3::UnitY(), -0.3).transpose();
  v0 << 0.3, -0.2, 0.1, R_FB * R_BP * w_P;
  b.SetJointPosition(free, q0);
  b.SetJointVelocity(free, v0);
  const std::shared_ptr<const Model> model = std::move(b).Finalize();

  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, IdaOptions());
  integ->Initialize(State::Initial(*model));
  Data data(*model);
  auto evaluate = [&](double* T, Vec3* p, Vec3* h, Vec3* w_P_now) {
    CalcPositionKinematics(*model, integ->state().q, data);
    CalcVelocityKinematics(*model, integ->state().v, data);
    *T = CalcKineticEnergy(*model, data);
    Momenta(*model, data, body, p, h);
    *w_P_now = (data.X_WB[body].R * R_BP).transpose() * data.V_WB[body].head<3>();
  };
  double T0, T;
  Vec3 p0, h0, p, h, w;
  evaluate(&T0, &p0, &h0, &w);
  double dT = 0, dp = 0, dh = 0, min_w2 = 1e300;
  const double t_end = 12.0, dt_out = 0.02;
  for (int i = 1; i * dt_out <= t_end + 1e-9; ++i) {
    integ->AdvanceTo(i * dt_out);
    evaluate(&T, &p, &h, &w);
    dT = std::max(dT, std::abs(T - T0) / T0);
    dp = std::max(dp, (p - p0).norm() / p0.norm());
    dh = std::max(dh, (h - h0).norm() / h0.norm());
    min_w2 = std::min(min_w2, w.y());
  }
  // The body really flips: the intermediate-axis rate reverses within the run.
  EXPECT_LT(min_w2, -0.9 * w_P.y());
  const long steps = integ->stats().steps;
  const double bound = 2 * steps * kRtol * std::sqrt(model->nq + model->nv);
  std::printf("[rigid] asymmetric free body: %ld steps, rel. drift T %.2e, p %.2e, h %.2e "
              "(bound %.2e), min w2 %.3f\n", steps, dT, dp, dh, bound, min_w2);
  EXPECT_LE(dT, bound);
  EXPECT_LE(dp, bound);
  EXPECT_LE(dh, bound);
}

// Torque-free symmetric top, I1 = I2 != I3, principal axes = body axes. Euler's equations
//   I1 w1' = (I2 - I3) w2 w3,  I2 w2' = (I3 - I1) w3 w1,  I3 w3' = 0
// give w3 constant and, with Omega = (I3 - I1) / I1 w3,  w1' = -Omega w2,  w2' = Omega w1, so
//   w_b(t) = (w_perp cos(Omega t + phi), w_perp sin(Omega t + phi), w3).
constexpr double kI1 = 0.2, kI3 = 0.35, kW3 = 3.0, kWPerp = 1.0, kPhi = 0.4;

Vec3 TopRate(double t) {
  const double Omega = (kI3 - kI1) / kI1 * kW3;
  return Vec3(kWPerp * std::cos(Omega * t + kPhi), kWPerp * std::sin(Omega * t + kPhi), kW3);
}

// Runs the top for 4 precession periods (2 pi / Omega each) and returns the largest deviation
// of the body-frame angular velocity from the closed form, relative to |w|.
double TopError(const Model& model, BodyIndex body, long* steps) {
  std::unique_ptr<Integrator> integ = MakeIntegrator(model, IdaOptions());
  integ->Initialize(State::Initial(model));
  Data data(model);
  const double Omega = (kI3 - kI1) / kI1 * kW3;
  const double t_end = 4 * 2 * M_PI / Omega, dt_out = 0.05;
  double err = 0;
  for (int i = 0; i * dt_out <= t_end; ++i) {
    if (i > 0) integ->AdvanceTo(i * dt_out);
    CalcPositionKinematics(model, integ->state().q, data);
    CalcVelocityKinematics(model, integ->state().v, data);
    const Vec3 w_b = data.X_WB[body].R.transpose() * data.V_WB[body].head<3>();
    err = std::max(err, (w_b - TopRate(integ->state().t)).norm() / TopRate(0).norm());
  }
  *steps = integ->stats().steps;
  return err;
}

// Bound on the rate error: the phase Omega t is the sensitive quantity; every step's local
// error (relative rtol) shifts the rates by at most rtol |w| and the phase by as much, so after
// N steps |w_b - closed form| / |w| <= N rtol (1 + 1) (amplitude and phase parts), times
// sqrt(nq + nv) for the RMS norm.
double TopBound(const Model& model, long steps) {
  return 2 * steps * kRtol * std::sqrt(model.nq + model.nv);
}

TEST(RigidBody, SymmetricTopOnFreeJointMatchesClosedForm) {
  ModelBuilder b;
  const Vec3 com_B(0.1, -0.2, 0.05);
  const BodyIndex top = b.AddBody("top", 2.0, com_B, Vec3(kI1, kI1, kI3).asDiagonal());
  const Mat3 R_FM0 = AxisAngle(Vec3(2, -1, 1).normalized(), 1.1);
  const JointIndex free = b.AddJoint(
      {.name = "free", .type = JointType::kFree, .parent = kWorldBody, .child = top,
       .X_PF = Transform(AxisAngle(Vec3::UnitZ(), 0.5), Vec3(0, 1, 0)),
       .X_CM = Transform::Identity()});
  Eigen::VectorXd q0(7), v0(6);
  q0 << 0.1, 0.2, -0.3, QuatCoords(Quat(R_FM0));
  // v = (velocity of the body origin, angular velocity), both in F; R_FB = R_FM0.
  v0 << 0.5, 0.0, -0.4, R_FM0 * TopRate(0);
  b.SetJointPosition(free, q0);
  b.SetJointVelocity(free, v0);
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  long steps = 0;
  const double err = TopError(*model, top, &steps);
  std::printf("[rigid] symmetric top, free joint: %ld steps, max |w_b - closed form| / |w| = "
              "%.2e (bound %.2e)\n", steps, err, TopBound(*model, steps));
  EXPECT_LE(err, TopBound(*model, steps));
}

TEST(RigidBody, SymmetricTopOnSphericalJointAtCentreOfMassMatchesClosedForm) {
  ModelBuilder b;
  const Vec3 com_B(0.1, -0.2, 0.05);
  const BodyIndex top = b.AddBody("top", 2.0, com_B, Vec3(kI1, kI1, kI3).asDiagonal());
  const Mat3 R_FM0 = AxisAngle(Vec3(2, -1, 1).normalized(), 1.1);
  // Joint frame M at the centre of mass: the joint force has no moment about it.
  const JointIndex ball = b.AddJoint(
      {.name = "ball", .type = JointType::kSpherical, .parent = kWorldBody, .child = top,
       .X_PF = Transform(AxisAngle(Vec3::UnitZ(), 0.5), Vec3(0, 1, 0)),
       .X_CM = Transform::Translation(com_B)});
  b.SetJointPosition(ball, QuatCoords(Quat(R_FM0)));
  b.SetJointVelocity(ball, R_FM0 * TopRate(0));  // angular velocity in F; R_MB = I
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  long steps = 0;
  const double err = TopError(*model, top, &steps);
  std::printf("[rigid] symmetric top, spherical joint at COM: %ld steps, max |w_b - closed form| "
              "/ |w| = %.2e (bound %.2e)\n", steps, err, TopBound(*model, steps));
  EXPECT_LE(err, TopBound(*model, steps));
}

// A heavy asymmetric body on a spherical joint 0.4 m from its centre of mass, under gravity: the
// joint does no work, so T + V is conserved. Scale: the energy exchanged, max(T) ~ T0 + 2 m g d.
TEST(RigidBody, HeavyBodyOnOffsetSphericalJointConservesEnergy) {
  ModelBuilder b;
  const double mass = 1.5, g = 9.81;
  const Vec3 com_B(0.05, 0.1, -0.02);
  const BodyIndex body =
      b.AddBody("body", mass, com_B, Vec3(0.02, 0.035, 0.045).asDiagonal());
  const Vec3 p_BJ = com_B + Vec3(0.1, 0.2, 0.33);  // joint point on the body, |p - com| = 0.4
  const JointIndex ball = b.AddJoint(
      {.name = "ball", .type = JointType::kSpherical, .parent = kWorldBody, .child = body,
       .X_PF = Transform(AxisAngle(Vec3(1, 0, 1).normalized(), 0.3), Vec3(0.2, 0, 1)),
       .X_CM = Transform(AxisAngle(Vec3::UnitX(), 0.2), p_BJ)});
  b.SetJointPosition(ball, QuatCoords(Quat(AxisAngle(Vec3(0, 1, 1).normalized(), 2.0))));
  b.SetJointVelocity(ball, Eigen::Vector3d(1.5, -2.0, 4.0));
  b.SetGravity(Vec3(0, 0, -g));
  const std::shared_ptr<const Model> model = std::move(b).Finalize();

  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, IdaOptions());
  integ->Initialize(State::Initial(*model));
  Data data(*model);
  auto energy = [&](double* kinetic) {
    CalcPositionKinematics(*model, integ->state().q, data);
    CalcVelocityKinematics(*model, integ->state().v, data);
    *kinetic = CalcKineticEnergy(*model, data);
    return *kinetic + CalcGravityPotential(*model, data);
  };
  double T0;
  const double E0 = energy(&T0);
  const double scale = T0 + 2 * mass * g * (p_BJ - com_B).norm();
  double drift = 0, T;
  for (int i = 1; i <= 500; ++i) {
    integ->AdvanceTo(i * 0.02);
    drift = std::max(drift, std::abs(energy(&T) - E0) / scale);
  }
  const long steps = integ->stats().steps;
  const double bound = 2 * steps * kRtol * std::sqrt(model->nq + model->nv);
  std::printf("[rigid] heavy body on spherical joint: %ld steps, rel. energy drift %.2e (bound "
              "%.2e)\n", steps, drift, bound);
  EXPECT_LE(drift, bound);
}

}  // namespace
}  // namespace orrery

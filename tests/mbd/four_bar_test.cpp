// A four-bar linkage with independent constraints: crank (revolute z at O2 = 0), coupler on a
// universal joint at the crank pin (z, then y turned), rocker (revolute z at O4 = (d, 0, 0)),
// spherical loop closure between the coupler end and the rocker end. Grashof crank-rocker
// (a + d = 0.5 < b + c = 0.65), so the crank turns fully.
//
// Oracles
// - Rocker angle from the crank angle by intersecting the circles |E - P| = b, |E - O4| = c
//   (P the crank pin, E the rocker end), solved here in closed form (the Freudenstein position
//   problem), elbow-up branch.
// - Drift bounds from IDA's Newton stopping rule; IDA against generalized-alpha.
// - Undriven under gravity: kinetic + potential energy conserved, the drift shrinking with the
//   tolerance (so it is integration error, not a modelling leak).
// - A planar four-bar closed with a revolute cut (5 rows, 2 of them redundant) is rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

constexpr double kA = 0.1, kB = 0.35, kC = 0.3, kD = 0.4;  // crank, coupler, rocker, ground (m)
constexpr double kOmega = 2 * 3.14159265358979323846;       // 1 rev/s
constexpr double kEps = 2.220446049250313e-16;

struct Angles {
  double coupler, rocker;  // absolute angles (world), rad
};
// Circle intersection: E on |E - P| = b and |E - O4| = c, above the line P-O4 (elbow up).
Angles Solve(double theta2) {
  const Eigen::Vector2d P(kA * std::cos(theta2), kA * std::sin(theta2)), O4(kD, 0);
  const Eigen::Vector2d u = O4 - P;
  const double r = u.norm();
  const double along = (kB * kB - kC * kC + r * r) / (2 * r);
  const double across = std::sqrt(kB * kB - along * along);
  const Eigen::Vector2d n(-u.y() / r, u.x() / r);
  const Eigen::Vector2d E = P + along * u / r + across * n;
  return {std::atan2(E.y() - P.y(), E.x() - P.x()), std::atan2(E.y(), E.x() - kD)};
}

JointSpec MakeJoint(const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                    const Transform& X_PF = Transform(), const Vec3& axis = Vec3::UnitZ(),
                    const Vec3& axis2 = Vec3::UnitX()) {
  JointSpec j;
  j.name = name, j.type = type, j.parent = parent, j.child = child, j.X_PF = X_PF;
  j.axis = axis, j.axis2 = axis2;
  return j;
}

struct FourBar {
  std::shared_ptr<const Model> model;
  JointIndex crank = -1, coupler = -1, rocker = -1;
};

// coupler_type: kUniversal (independent rows with a spherical cut) or kSpherical/kRevolute for
// the rejection cases; cut_type the loop closure.
FourBar Build(bool driven, JointType coupler_type = JointType::kUniversal,
              JointType cut_type = JointType::kSpherical, double theta2 = 0.0) {
  ModelBuilder b;
  auto rod = [](double m, double len) {
    return Vec3(1e-4, m * len * len / 12 + 1e-4, m * len * len / 12 + 1e-4).asDiagonal().toDenseMatrix();
  };
  const BodyIndex crank = b.AddBody("crank", 0.5, Vec3(kA / 2, 0, 0), rod(0.5, kA));
  const BodyIndex coupler = b.AddBody("coupler", 1.0, Vec3(kB / 2, 0, 0), rod(1.0, kB));
  const BodyIndex rocker = b.AddBody("rocker", 0.8, Vec3(kC / 2, 0, 0), rod(0.8, kC));
  FourBar fb;
  fb.crank = b.AddJoint(MakeJoint("crank", JointType::kRevolute, kWorldBody, crank));
  fb.coupler = b.AddJoint(MakeJoint("coupler", coupler_type, crank, coupler,
                                    Transform::Translation(Vec3(kA, 0, 0)), Vec3::UnitZ(), Vec3::UnitY()));
  fb.rocker = b.AddJoint(MakeJoint("rocker", JointType::kRevolute, kWorldBody, rocker,
                                   Transform::Translation(Vec3(kD, 0, 0))));
  const FrameIndex a = b.AddFrame("coupler_end", coupler, Transform::Translation(Vec3(kB, 0, 0)));
  const FrameIndex e = b.AddFrame("rocker_end", rocker, Transform::Translation(Vec3(kC, 0, 0)));
  b.AddLoopClosure({"cut", cut_type, a, e});
  if (driven)
    b.AddDriver({"motor", fb.crank, 0, DriverSpec::Mode::kSpeed, TimeFunction::Constant(kOmega)});
  b.SetGravity(Vec3(0, -9.81, 0));
  const Angles s = Solve(theta2);
  b.SetJointPosition(fb.crank, Eigen::VectorXd::Constant(1, theta2));
  if (coupler_type == JointType::kUniversal)
    b.SetJointPosition(fb.coupler, Eigen::Vector2d(s.coupler - theta2, 0));
  if (coupler_type == JointType::kRevolute)
    b.SetJointPosition(fb.coupler, Eigen::VectorXd::Constant(1, s.coupler - theta2));
  if (coupler_type == JointType::kSpherical) {
    const double h = 0.5 * (s.coupler - theta2);
    b.SetJointPosition(fb.coupler, Eigen::Vector4d(std::cos(h), 0, 0, std::sin(h)));
  }
  b.SetJointPosition(fb.rocker, Eigen::VectorXd::Constant(1, s.rocker));
  if (driven) b.SetJointVelocity(fb.crank, Eigen::VectorXd::Constant(1, kOmega));
  fb.model = std::move(b).Finalize();
  return fb;
}

struct Trace {
  std::vector<double> t, theta2, theta4, effort, energy;
  IntegratorStats stats;
  double max_abs_q = 0, max_abs_v = 0;
};

Trace RunModel(const FourBar& fb, const IntegratorOptions& opt, double t_end, double dt) {
  const Model& m = *fb.model;
  std::unique_ptr<Integrator> integ = MakeIntegrator(m, opt);
  integ->Initialize(State::Initial(m));
  Data data(m);
  Trace tr;
  const int n = static_cast<int>(std::lround(t_end / dt));
  for (int k = 0; k <= n; ++k) {
    if (k > 0) integ->AdvanceTo(k * dt);
    const State& s = integ->state();
    EvaluateDynamics(m, s.t, s.q, s.v, integ->vdot(), data);
    tr.t.push_back(s.t);
    tr.theta2.push_back(s.q(m.joints[fb.crank].q_start));
    tr.theta4.push_back(s.q(m.joints[fb.rocker].q_start));
    tr.effort.push_back(m.drivers.empty() ? 0.0 : -integ->lambda()(m.driver_row[0]));
    tr.energy.push_back(CalcKineticEnergy(m, data) + CalcGravityPotential(m, data));
    tr.max_abs_q = std::max(tr.max_abs_q, s.q.lpNorm<Eigen::Infinity>());
    tr.max_abs_v = std::max(tr.max_abs_v, s.v.lpNorm<Eigen::Infinity>());
  }
  tr.stats = integ->stats();
  return tr;
}

IntegratorOptions Ida(double rtol, double atol) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kIda;
  o.rtol = rtol;
  o.atol = atol;
  return o;
}
IntegratorOptions Alpha(double h) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = h;
  o.rho_inf = 0.9;
  return o;
}

// Row sums of |dPhi/dv| of the loop rows: lever arms a + b (crank), b, b (coupler), c (rocker).
constexpr double kPhiQNorm = kA + 3 * kB + kC;

// Smallest |sin(transmission angle)| = |sin(theta4 - theta3)| over a crank turn (closed form).
double MinTransmissionSine() {
  double s = 1.0;
  for (int i = 0; i < 3600; ++i) {
    const Angles a = Solve(i * 2 * 3.14159265358979323846 / 3600);
    s = std::min(s, std::abs(std::sin(a.rocker - a.coupler)));
  }
  return s;
}

double Wrap(double a) { return std::remainder(a, 2 * 3.14159265358979323846); }

TEST(FourBar, RockerFollowsFreudensteinSolutionWithBoundedDrift) {
  const FourBar fb = Build(true);
  const Model& m = *fb.model;
  const double rtol = 1e-8, atol = 1e-10;
  const Trace tr = RunModel(fb, Ida(rtol, atol), 1.2, 0.01);
  // Drift: IDA's Newton stops at a WRMS correction below 0.33; one of n components may carry
  // sqrt(n) of it in units of rtol |y| + atol; the constraint residual left is at most |Phi_q|
  // times that correction.
  const int n = m.nq + m.nv + m.n_constraints + m.n_holonomic;
  const double phi_bound = 0.33 * std::sqrt(double(n)) * kPhiQNorm * (rtol * tr.max_abs_q + atol);
  const double phidot_bound = 0.33 * std::sqrt(double(n)) * kPhiQNorm * (rtol * tr.max_abs_v + atol);
  EXPECT_LE(tr.stats.max_abs_phi, phi_bound);
  EXPECT_LE(tr.stats.max_abs_phidot, phidot_bound);
  // Rocker from the crank: linearizing the loop, |d theta4| <= sqrt(2) |Phi| / (c |sin mu|).
  const double sin_mu = MinTransmissionSine();
  ASSERT_GT(sin_mu, 0.2);
  double err4 = 0, err2 = 0;
  for (size_t k = 0; k < tr.t.size(); ++k) {
    const double e4 = std::abs(Wrap(tr.theta4[k] - Solve(tr.theta2[k]).rocker));
    EXPECT_LE(e4, std::sqrt(2.0) * tr.stats.max_abs_phi / (kC * sin_mu) + 100 * kEps) << "t = " << tr.t[k];
    err4 = std::max(err4, e4);
    // The crank angle integrates the driven speed (exact for BDF up to the speed residual and
    // the GGL correction). The speed residual of every step, not only of the output points, adds
    // up: each is within the Newton bound phidot_bound.
    const double e2 = std::abs(tr.theta2[k] - kOmega * tr.t[k]);
    EXPECT_LE(e2, tr.t[k] * phidot_bound + phi_bound) << "t = " << tr.t[k];
    err2 = std::max(err2, e2);
  }
  std::printf("[four-bar IDA] max|Phi| %.3g (bound %.3g), max|Phidot| %.3g (bound %.3g), "
              "max|theta4 - closed form| %.3g, max|theta2 - w t| %.3g\n",
              tr.stats.max_abs_phi, phi_bound, tr.stats.max_abs_phidot, phidot_bound, err4, err2);
}

TEST(FourBar, IdaAndGeneralizedAlphaAgree) {
  const FourBar fb = Build(true);
  const double h = 1e-3, t_end = 0.6, dt = 0.01;
  const Trace ga1 = RunModel(fb, Alpha(h), t_end, dt);
  const Trace ga2 = RunModel(fb, Alpha(h / 2), t_end, dt);
  const Trace ida = RunModel(fb, Ida(1e-9, 1e-11), t_end, dt);
  const Trace ida_tight = RunModel(fb, Ida(1e-11, 1e-13), t_end, dt);
  // GA error at h/2 ~ |GA(h) - GA(h/2)| / 3 (second order), twice that as the bound, plus the IDA
  // error estimated against a 100x tighter run. Efforts: the index-3 start-up transient (O(h),
  // damped like rho_inf^n) is left out for t < 0.15 s (150 steps).
  double est4 = 0, estf = 0, ida4 = 0, idaf = 0, d4 = 0, df = 0, fmax = 0;
  for (size_t k = 0; k < ga1.t.size(); ++k) {
    est4 = std::max(est4, std::abs(Wrap(ga1.theta4[k] - ga2.theta4[k])) / 3);
    ida4 = std::max(ida4, std::abs(Wrap(ida.theta4[k] - ida_tight.theta4[k])));
    d4 = std::max(d4, std::abs(Wrap(ida.theta4[k] - ga2.theta4[k])));
    if (ga1.t[k] < 0.15) continue;
    estf = std::max(estf, std::abs(ga1.effort[k] - ga2.effort[k]) / 3);
    idaf = std::max(idaf, std::abs(ida.effort[k] - ida_tight.effort[k]));
    df = std::max(df, std::abs(ida.effort[k] - ga2.effort[k]));
    fmax = std::max(fmax, std::abs(ida.effort[k]));
  }
  // Positions: both follow the crank angle, which both integrate exactly; rounding floor 1e-13.
  EXPECT_LE(d4, 2 * est4 + 2 * ida4 + 1e-13);
  EXPECT_LE(df, 2 * estf + 2 * idaf);
  EXPECT_GT(fmax, 100 * (2 * estf + 2 * idaf));  // not vacuous
  std::printf("[four-bar IDA vs GA] theta4: diff %.3g (GA est %.3g, IDA est %.3g); effort: diff %.3g "
              "(GA est %.3g, IDA est %.3g, max %.3g)\n", d4, est4, ida4, df, estf, idaf, fmax);
}

TEST(FourBar, FreeFourBarConservesEnergy) {
  // Released from rest at a crank angle of 1 rad under gravity: no driver, no damping, ideal
  // joints. The energy drift must be integration error: it shrinks with the tolerance (at least
  // 10x for 100x tighter tolerances; BDF global errors scale about linearly with rtol) and stays
  // below 1e3 rtol |E| over the ~400 steps of the run.
  const FourBar fb = Build(false, JointType::kUniversal, JointType::kSpherical, 1.0);
  // Tolerances down to 1e-12 also check that IDA starts and runs at tight tolerances (with the
  // multipliers' own Newton tolerance too tight it failed at t = 0 for rtol <= 1e-8).
  constexpr int kRuns = 4;
  const double rtols[kRuns] = {1e-6, 1e-8, 1e-10, 1e-12};
  double drift[kRuns] = {}, scale = 0;
  for (int i = 0; i < kRuns; ++i) {
    const Trace tr = RunModel(fb, Ida(rtols[i], rtols[i] * 1e-2), 2.0, 0.01);
    for (size_t k = 0; k < tr.t.size(); ++k) {
      drift[i] = std::max(drift[i], std::abs(tr.energy[k] - tr.energy[0]));
      scale = std::max(scale, std::abs(tr.energy[k]));
    }
    std::printf("[four-bar free] rtol %.0e: energy drift %.3g, |E| %.3g\n", rtols[i], drift[i], scale);
  }
  for (int i = 1; i < kRuns; ++i) {
    // Once the drift is down at the rounding level of the energy it cannot shrink further.
    const double floor = 1e4 * kEps * scale;
    EXPECT_LT(drift[i], std::max(drift[i - 1] / 10, floor)) << "rtol " << rtols[i];
    EXPECT_LT(drift[i], std::max(1e3 * rtols[i] * scale, floor)) << "rtol " << rtols[i];
  }
}

TEST(FourBar, PlanarRevoluteCutIsRejectedNamingTheLoopClosure) {
  // Coupler on a spherical joint: 1 + 3 + 1 = 5 coordinates for the 5 rows of a revolute cut, so
  // Finalize's count passes; the mechanism still moves (one degree of freedom), so G has a null
  // space and the rows are redundant: Initialize must say which loop closure.
  const FourBar fb = Build(false, JointType::kSpherical, JointType::kRevolute, 0.4);
  for (IntegratorKind kind : {IntegratorKind::kIda, IntegratorKind::kGeneralizedAlpha}) {
    IntegratorOptions o;
    o.kind = kind;
    std::unique_ptr<Integrator> integ = MakeIntegrator(*fb.model, o);
    try {
      integ->Initialize(State::Initial(*fb.model));
      ADD_FAILURE() << "redundant revolute cut accepted by " << integ->name();
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("loop closure 'cut'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("redundant"), std::string::npos) << msg;
    }
  }
  // All-revolute planar four-bar: 3 coordinates for 5 rows, refused already by Finalize.
  EXPECT_THROW(Build(false, JointType::kRevolute, JointType::kRevolute, 0.4), std::invalid_argument);
  // The same mechanism with a spherical cut and a universal coupler initializes.
  const FourBar ok = Build(false, JointType::kUniversal, JointType::kSpherical, 0.4);
  std::unique_ptr<Integrator> integ = MakeIntegrator(*ok.model, IntegratorOptions{});
  EXPECT_NO_THROW(integ->Initialize(State::Initial(*ok.model)));
}

// Issue 17: a planar loop of revolute joints closes with a planar_pin cut (the two in-plane rows,
// mbd/joint_types.h), no spherical cut and universal coupler needed: driven, the rocker follows
// Freudenstein's closed form as the spherical-cut mechanism does, within the drift bound of
// RockerFollowsFreudensteinSolutionWithBoundedDrift; the pin is no tree joint.
TEST(FourBar, PlanarPinCutClosesTheAllRevoluteFourBar) {
  const FourBar fb = Build(true, JointType::kRevolute, JointType::kPlanarPin);
  const Model& m = *fb.model;
  EXPECT_EQ(m.n_constraints, 2 + 1);  // the pin's two rows and the motor
  const double rtol = 1e-8, atol = 1e-10;
  const Trace tr = RunModel(fb, Ida(rtol, atol), 1.2, 0.01);
  const int n = m.nq + m.nv + m.n_constraints + m.n_holonomic;
  const double phi_bound = 0.33 * std::sqrt(double(n)) * kPhiQNorm * (rtol * tr.max_abs_q + atol);
  EXPECT_LE(tr.stats.max_abs_phi, phi_bound);
  const double sin_mu = MinTransmissionSine();
  for (size_t k = 0; k < tr.t.size(); ++k)
    EXPECT_LE(std::abs(Wrap(tr.theta4[k] - Solve(tr.theta2[k]).rocker)),
              std::sqrt(2.0) * tr.stats.max_abs_phi / (kC * sin_mu) + 100 * kEps)
        << "t = " << tr.t[k];
  EXPECT_GT(tr.theta2.back(), 7.0);  // the crank turned (1.2 rev)
  // As a tree joint it is refused with the reason
  ModelBuilder b;
  const BodyIndex body = b.AddBody("b", 1.0, Vec3::Zero(), Mat3::Identity());
  try {
    b.AddJoint(MakeJoint("pin", JointType::kPlanarPin, kWorldBody, body));
    ADD_FAILURE() << "planar_pin accepted as a tree joint";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("joint 'pin': a planar_pin is a cut joint only"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace orrery

// Drivers (rheonomic constraints) against closed forms.
// - Position driver: a pendulum (revolute z, centre of mass L below the pivot) moved along a
//   smooth step. The recorded driver effort (-lambda, /drivers/<name>/effort) must equal
//   I_O theta'' + m g L sin(theta), theta'' from the quintic written out here.
// - Speed driver with the seed 002 trapezoid (w0 = 0, w1 = 20 rpm, w2 = 0, t4 = 0.2 s,
//   alpha1 = alpha2 = 0.1, alpha3 = 0.6): the joint speed follows the profile and the angle is its
//   integral (areas of the trapezoid, written out here).
// - One constraint row (a speed driver): the shortcuts the generalized-alpha residual and
//   projection take for it (AddConstraintForces; the 1 x 1 Schur complement's division and the
//   update v - mu y) against Eigen's general products and PartialPivLU, compared with ==.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

#include <Eigen/LU>

#include "mbd/constraints.h"
#include "mbd/hdf5_reader.h"
#include "mbd/integrator.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kEps = 2.220446049250313e-16;
constexpr double kM = 1.5, kLen = 0.4, kIcm = 0.02, kG = 9.81;  // kg, m, kg m^2, m/s^2
constexpr double kT0 = 0.1, kT1 = 0.6, kTheta1 = kPi / 2;          // smooth step

std::shared_ptr<const Model> Pendulum(const DriverSpec::Mode mode, const TimeFunction& f) {
  ModelBuilder b;
  const BodyIndex link = b.AddBody("link", kM, Vec3(0, -kLen, 0), Mat3::Identity() * kIcm);
  JointSpec j;
  j.name = "pivot", j.type = JointType::kRevolute, j.parent = kWorldBody, j.child = link;
  const JointIndex pivot = b.AddJoint(j);
  DriverSpec d;
  d.name = "drive", d.joint = pivot, d.coordinate = 0, d.mode = mode, d.function = f;
  b.AddDriver(d);
  b.SetGravity(Vec3(0, -kG, 0));
  if (mode == DriverSpec::Mode::kSpeed) b.SetJointVelocity(pivot, Eigen::VectorXd::Constant(1, f.Value(0)));
  return std::move(b).Finalize();
}

// Runs with result recording; returns /time, /joints/pivot/q, /joints/pivot/v, effort columns.
struct Series {
  Eigen::VectorXd t, q, v, effort;
  IntegratorStats stats;
};
Series Record(const Model& m, const IntegratorOptions& opt, double t_end, double dt, const std::string& tag) {
  const std::string path = ::testing::TempDir() + "orrery_drivers_" + tag + "_" + std::to_string(::getpid()) + ".h5";
  Series s;
  {
    ResultFile out = ResultFile::Create(path);
    SimulationOptions so;
    so.end_time = t_end;
    so.output_interval = dt;
    so.integrator = opt;
    s.stats = Simulate(m, so, &out).stats;
  }
  {
    Hdf5Reader in(path);
    s.t = in.ReadMatrix("/time").col(0);
    s.q = in.ReadMatrix("/joints/pivot/q").col(0);
    s.v = in.ReadMatrix("/joints/pivot/v").col(0);
    s.effort = in.ReadMatrix("/drivers/drive/effort").col(0);
  }
  std::filesystem::remove(path);
  return s;
}

IntegratorOptions Alpha(double h) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = h;
  o.rho_inf = 0.9;
  return o;
}

// theta(t) and theta''(t) of the quintic smooth step 10 s^3 - 15 s^4 + 6 s^5.
double Theta(double t) {
  const double s = std::clamp((t - kT0) / (kT1 - kT0), 0.0, 1.0);
  return kTheta1 * s * s * s * (10 - 15 * s + 6 * s * s);
}
double ThetaDdot(double t) {
  if (t <= kT0 || t >= kT1) return 0.0;
  const double T = kT1 - kT0, s = (t - kT0) / T;
  return kTheta1 / (T * T) * (60 * s - 180 * s * s + 120 * s * s * s);
}

TEST(Drivers, PositionDriverEffortIsInverseDynamicsOfThePendulum) {
  const auto model = Pendulum(DriverSpec::Mode::kPosition, TimeFunction::SmoothStep(kT0, kT1, 0, kTheta1));
  const double I_O = kIcm + kM * kLen * kLen;
  const double h = 1e-3, t_end = 0.8, dt = 0.01;
  const Series a = Record(*model, Alpha(h), t_end, dt, "h");
  const Series b = Record(*model, Alpha(h / 2), t_end, dt, "h2");
  const Series c = Record(*model, Alpha(h / 4), t_end, dt, "h4");
  ASSERT_EQ(a.t.size(), b.t.size());
  // The positions are the driver's (index 3, to the Newton rounding floor); the effort converges
  // at second order: its error at h/2 is ~ |e(h) - e(h/2)| / 3; the bound takes twice that.
  // The quintic is only C2: its jerk jumps at t0 and t1, which starts the index-3 scheme's
  // alternating multiplier transient (O(h) per step, damped like rho_inf^n, Arnold & Bruls 2007).
  // Outputs within 0.15 s (150 steps at h, rho_inf^150 = 1.4e-7) after a jump are left out.
  auto in_transient = [&](double t) { return (t > kT0 && t <= kT0 + 0.15) || (t > kT1 && t <= kT1 + 0.15); };
  double est = 0, est2 = 0, err = 0, emax = 0;
  for (Eigen::Index k = 0; k < a.t.size(); ++k) {
    EXPECT_NEAR(b.q(k), Theta(b.t(k)), 1e-12) << "t = " << b.t(k);
    if (in_transient(b.t(k))) continue;
    est = std::max(est, std::abs(a.effort(k) - b.effort(k)) / 3);
    est2 = std::max(est2, std::abs(b.effort(k) - c.effort(k)) / 3);
    const double exact = I_O * ThetaDdot(b.t(k)) + kM * kG * kLen * std::sin(Theta(b.t(k)));
    err = std::max(err, std::abs(b.effort(k) - exact));
    emax = std::max(emax, std::abs(exact));
  }
  std::printf("[drivers position] max|effort - closed form| %.3g (GA est %.3g, next %.3g, max effort %.3g)\n",
              err, est, est2, emax);
  EXPECT_LE(err, 2 * est);
  EXPECT_GT(est / est2, 3.0);  // second order: 4 within the next-order term
  EXPECT_LT(est / est2, 5.3);
  EXPECT_GT(emax, 1e3 * est);  // the check is not vacuous
}

TEST(Drivers, SpeedDriverFollowsSeed002TrapezoidAndIntegratesIt) {
  const double w1 = 20 * 2 * kPi / 60;  // 20 rpm in rad/s
  const double t1 = 0.02, t2 = 0.1, t3 = 0.12;  // alpha1 t4, alpha3 t4 - alpha2 t4, alpha3 t4
  const auto model = Pendulum(DriverSpec::Mode::kSpeed, TimeFunction::Trapezoid(0, w1, 0, 0.2, 0.1, 0.1, 0.6));
  // Closed form of the profile and its integral (areas of the ramps and the plateau).
  auto w = [&](double t) {
    if (t <= t1) return w1 * t / t1;
    if (t <= t2) return w1;
    if (t <= t3) return w1 * (t3 - t) / (t3 - t2);
    return 0.0;
  };
  auto angle = [&](double t) {
    if (t <= t1) return 0.5 * w1 * t * t / t1;
    double a = 0.5 * w1 * t1;
    if (t <= t2) return a + w1 * (t - t1);
    a += w1 * (t2 - t1);
    if (t <= t3) return a + 0.5 * (w1 + w(t)) * (t - t2);
    return a + 0.5 * w1 * (t3 - t2);
  };
  const double h = 1e-3;
  const Series s = Record(*model, Alpha(h), 0.3, 0.005, "speed");
  // Speeds: the speed row is solved in Newton and the velocities projected: rounding only.
  // Angles: with the knots on step boundaries, a slope jump ds excites the pseudo-acceleration
  // a_{n+k} - s = ds (1-gamma)/gamma (-(1-gamma)/gamma)^(k-1); summing the position updates
  // h^2 [(1/2 - beta) a_n + beta a_{n+1}] over the decaying tail leaves h^2 c gamma ds per knot,
  // c = (1/2 - beta) - beta (1 - gamma)/gamma (derived in this test's comment; knots at t1, t2, t3
  // with |ds| = w1 / 0.02 each; the knot at 0 starts from the exact slope). Twice that for the
  // finite tail and the knot times' rounding.
  const double rho = 0.9, am = (2 * rho - 1) / (rho + 1), af = rho / (rho + 1);
  const double gamma = 0.5 + af - am, beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
  const double cf = (0.5 - beta) - beta * (1 - gamma) / gamma;
  const double angle_tol = 2 * 3 * h * h * std::abs(cf) * gamma * (w1 / 0.02) + 1e3 * kEps;
  double err_v = 0, err_q = 0;
  for (Eigen::Index k = 0; k < s.t.size(); ++k) {
    EXPECT_NEAR(s.v(k), w(s.t(k)), 1e3 * kEps * w1) << "t = " << s.t(k);
    EXPECT_NEAR(s.q(k), angle(s.t(k)), angle_tol) << "t = " << s.t(k);
    err_v = std::max(err_v, std::abs(s.v(k) - w(s.t(k))));
    err_q = std::max(err_q, std::abs(s.q(k) - angle(s.t(k))));
  }
  std::printf("[drivers speed] max|v - w(t)| %.3g, max|q - integral| %.3g (tol %.3g), final angle %.6f\n",
              err_v, err_q, angle_tol, s.q(s.t.size() - 1));
  // The final angle is the trapezoid's area, 0.1 * w1 (= 0.2094 rad).
  EXPECT_NEAR(angle(0.3), 0.1 * w1, 1e-15);
}

// The general path: Eigen's G^T lambda (nc x nv, row-major kernel on the transpose), the 1 x 1
// PartialPivLU's solve and the matrix-vector update; the shortcuts must give the same bits.
TEST(Drivers, OneRowShortcutsAreEigensProducts) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto value = [&] { return std::ldexp(u(rng), static_cast<int>(std::floor(40 * u(rng)))); };
  for (const int nv : {1, 6, 7, 36, 41}) {
    for (int trial = 0; trial < 50; ++trial) {
      Eigen::MatrixXd G(1, nv);
      Eigen::VectorXd lambda(1), out(nv), y(nv), v(nv), rhs(1);
      for (int k = 0; k < nv; ++k) G(0, k) = k % 5 == 3 ? 0.0 : value(), out(k) = value();
      for (int k = 0; k < nv; ++k) y(k) = value(), v(k) = value();
      lambda(0) = value(), rhs(0) = value();
      Eigen::VectorXd general = out, shortcut = out;
      general.noalias() += G.transpose() * lambda;
      AddConstraintForces(G, lambda, shortcut);
      for (int k = 0; k < nv; ++k) EXPECT_EQ(general(k), shortcut(k)) << nv << " " << k;
      // The projection's Schur complement G M^-1 G^T of one row, its solve and the update
      Eigen::MatrixXd schur(1, 1);
      schur(0, 0) = value();
      Eigen::PartialPivLU<Eigen::MatrixXd> lu(schur);
      const Eigen::VectorXd mu = lu.solve(rhs);
      EXPECT_EQ(mu(0), rhs(0) / schur(0, 0));
      Eigen::MatrixXd Y = y;
      Eigen::VectorXd v_general = v, v_shortcut = v;
      v_general.noalias() -= Y * mu;
      v_shortcut -= mu(0) * Y.col(0);
      for (int k = 0; k < nv; ++k) EXPECT_EQ(v_general(k), v_shortcut(k)) << nv << " " << k;
    }
  }
  // More rows take Eigen's product itself
  Eigen::MatrixXd G = Eigen::MatrixXd::Random(2, 7);
  Eigen::VectorXd lambda = Eigen::VectorXd::Random(2), general = Eigen::VectorXd::Random(7);
  Eigen::VectorXd shortcut = general;
  general.noalias() += G.transpose() * lambda;
  AddConstraintForces(G, lambda, shortcut);
  EXPECT_TRUE(general == shortcut);
}

}  // namespace
}  // namespace orrery

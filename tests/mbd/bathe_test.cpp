// Time-integrator check on the 2-DOF system of Bathe, "Finite Element Procedures", examples
// 9.3/9.4 (docs/validation/bathe_2dof.md), built as a multibody model:
//   M = diag(2, 1), K = [[6, -2], [-2, 4]], C = 0, R = (0, 10), U(0) = U'(0) = 0.
// Two bodies slide along x on prismatic joints to the world; a coordinate spring (k = 4) on joint 1,
// a point-to-point spring (k = 2) between the bodies, a coordinate spring (k = 2) on joint 2 and a
// joint load of 10 on joint 2 give K and R exactly (the bodies' origins sit at x = 0 and x = 10 at
// rest and the spring's free length is 10, so its length 10 + U2 - U1 stays positive and along x:
// the spring force 2 (U2 - U1) is exactly linear).
//
// Oracles:
// - the table printed in the validation file (Newmark, average acceleration, dt = 0.28), to its
//   printed precision (3 significant digits: half a unit in the last printed digit);
// - an independent Newmark recurrence on the 2x2 matrices written here (Bathe table 9.3
//   effective-stiffness form), which pins the engine's generalized-alpha step far below the
//   printed precision;
// - the exact modal solution given in the validation file, for IDA.
#include <cmath>
#include <memory>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

constexpr double kDt = 0.28;
constexpr int kSteps = 12;
constexpr double kRestGap = 10.0;  // m: body 2's joint frame sits this far along x

// The validation file's table (U at t = 0, dt, ..., 12 dt).
const double kTableU1[kSteps + 1] = {0,    0.00673, 0.0505, 0.189, 0.485, 0.961, 1.58,
                                     2.23, 2.76,    3.00,   2.85,  2.28,  1.40};
const double kTableU2[kSteps + 1] = {0,    0.364, 1.35, 2.68, 4.00, 4.95, 5.34,
                                     5.13, 4.48,  3.64, 2.90, 2.44, 2.31};

// Half a unit in the last of 3 significant digits of a printed value (0 is exact).
double HalfUnitLastDigit(double printed) {
  if (printed == 0) return 0;
  const int exponent = static_cast<int>(std::floor(std::log10(std::abs(printed))));
  return 0.5 * std::pow(10.0, exponent - 2);
}

std::shared_ptr<const Model> BuildBatheModel() {
  ModelBuilder b;
  const Mat3 inertia = Vec3(0.3, 0.2, 0.25).asDiagonal();  // irrelevant: no rotation
  const BodyIndex m1 = b.AddBody("m1", 2.0, Vec3::Zero(), inertia);
  const BodyIndex m2 = b.AddBody("m2", 1.0, Vec3::Zero(), inertia);
  const JointIndex x1 = b.AddJoint({.name = "x1", .type = JointType::kPrismatic,
                                    .parent = kWorldBody, .child = m1, .X_PF = Transform::Identity(),
                                    .X_CM = Transform::Identity(), .axis = Vec3::UnitX()});
  const JointIndex x2 = b.AddJoint({.name = "x2", .type = JointType::kPrismatic,
                                    .parent = kWorldBody, .child = m2,
                                    .X_PF = Transform::Translation(Vec3(kRestGap, 0, 0)),
                                    .X_CM = Transform::Identity(), .axis = Vec3::UnitX()});
  b.AddCoordinateSpring({.name = "k1", .joint = x1, .coordinate = 0, .stiffness = 4.0});
  b.AddTranslationalSpring({.name = "k12", .frame_a = b.body_frame(m1),
                            .frame_b = b.body_frame(m2), .stiffness = 2.0,
                            .free_length = kRestGap});
  b.AddCoordinateSpring({.name = "k2", .joint = x2, .coordinate = 0, .stiffness = 2.0});
  b.AddJointLoad({.name = "R2", .joint = x2, .coordinate = 0,
                  .function = TimeFunction::Constant(10.0)});
  return std::move(b).Finalize();
}

// Independent oracle: Newmark's method (beta = 1/4, gamma = 1/2) on M U'' + K U = R in the
// effective-stiffness form of Bathe's table 9.3, on plain 2x2 matrices.
std::vector<Eigen::Vector2d> NewmarkRecurrence() {
  const Eigen::Matrix2d M = Eigen::Vector2d(2, 1).asDiagonal();
  Eigen::Matrix2d K;
  K << 6, -2, -2, 4;
  const Eigen::Vector2d R(0, 10);
  const double beta = 0.25, gamma = 0.5, h = kDt;
  const double a0 = 1 / (beta * h * h), a1 = gamma / (beta * h), a2 = 1 / (beta * h),
               a3 = 1 / (2 * beta) - 1, a6 = h * (1 - gamma), a7 = gamma * h;
  (void)a1;
  Eigen::Vector2d u = Eigen::Vector2d::Zero(), v = Eigen::Vector2d::Zero();
  Eigen::Vector2d a = M.inverse() * (R - K * u);
  const Eigen::Matrix2d K_eff = K + a0 * M;
  std::vector<Eigen::Vector2d> out{u};
  for (int n = 0; n < kSteps; ++n) {
    const Eigen::Vector2d u_new = K_eff.lu().solve(R + M * (a0 * u + a2 * v + a3 * a));
    const Eigen::Vector2d a_new = a0 * (u_new - u) - a2 * v - a3 * a;
    v += a6 * a + a7 * a_new;
    u = u_new;
    a = a_new;
    out.push_back(u);
  }
  return out;
}

// Exact solution from the validation file.
Eigen::Vector2d ExactSolution(double t) {
  Eigen::Matrix2d phi;
  phi << 1, 0.5, 1, -1;
  const Eigen::Vector2d scale(1 / std::sqrt(3.0), std::sqrt(2.0 / 3.0));
  const Eigen::Vector2d modal(5 / std::sqrt(3.0) * (1 - std::cos(std::sqrt(2.0) * t)),
                              2 * std::sqrt(2.0 / 3.0) * (-1 + std::cos(std::sqrt(5.0) * t)));
  return phi * scale.asDiagonal() * modal;
}

TEST(Bathe, NewmarkAverageAccelerationReproducesPublishedTable) {
  const std::shared_ptr<const Model> model = BuildBatheModel();
  ASSERT_EQ(model->nv, 2);
  IntegratorOptions opt;
  opt.kind = IntegratorKind::kGeneralizedAlpha;
  opt.step = kDt;
  opt.alpha_m = 0;
  opt.alpha_f = 0;
  opt.beta = 0.25;
  opt.gamma = 0.5;
  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, opt);
  integ->Initialize(State::Initial(*model));
  const std::vector<Eigen::Vector2d> recurrence = NewmarkRecurrence();

  // Bound on the engine-vs-recurrence difference: Newton stops when the force residual is below
  // newton_tolerance * scale (scale = max(1, |M_kk vdot_k|) <= max |R| + |K| max|U| ~ 60 N here);
  // an acceleration error of that over the smallest mass (1 kg) moves U by beta h^2 times it per
  // step; over 12 steps of a non-expanding (|eigenvalues| = 1) recurrence, the sum, with a
  // factor 10 for the non-normal amplification matrix.
  const double force_scale = 60.0;
  const double recurrence_tol =
      10 * kSteps * opt.beta * kDt * kDt * opt.newton_tolerance * force_scale / 1.0;

  double max_recurrence_error = 0;
  double min_spring_length = kRestGap;
  for (int n = 0; n <= kSteps; ++n) {
    if (n > 0) integ->AdvanceTo(n * kDt);
    const Eigen::VectorXd& q = integ->state().q;
    ASSERT_NEAR(integ->state().t, n * kDt, 1e-12);
    // The spring between the bodies stays stretched along +x (linear force).
    min_spring_length = std::min(min_spring_length, kRestGap + q(1) - q(0));
    // Published table, to its printed precision.
    double table_u1 = kTableU1[n];
    // Erratum: the table prints U1(2 dt) = 0.0505, but Newmark arithmetic gives 0.0504480
    // (both the recurrence above and a hand computation), which rounds to 0.0504: the published
    // digit comes from rounded intermediate values. The recurrence check below pins the value.
    if (n == 2) table_u1 = 0.0504;
    EXPECT_NEAR(q(0), table_u1, HalfUnitLastDigit(kTableU1[n])) << "U1 at step " << n;
    EXPECT_NEAR(q(1), kTableU2[n], HalfUnitLastDigit(kTableU2[n])) << "U2 at step " << n;
    // Independent recurrence, far below the printed precision.
    max_recurrence_error =
        std::max(max_recurrence_error, (q.head<2>() - recurrence[n]).lpNorm<Eigen::Infinity>());
  }
  EXPECT_GT(min_spring_length, 0.0);
  EXPECT_LE(max_recurrence_error, recurrence_tol);
  // The erratum entry really is off by more than half a unit (guards the comment above).
  EXPECT_GT(std::abs(recurrence[2](0) - kTableU1[2]), HalfUnitLastDigit(kTableU1[2]));
  RecordProperty("max_recurrence_error", std::to_string(max_recurrence_error));
  std::printf("[bathe] Newmark: max |U - recurrence| = %.3e (bound %.3e)\n", max_recurrence_error,
              recurrence_tol);
}

TEST(Bathe, IdaMatchesExactSolution) {
  const std::shared_ptr<const Model> model = BuildBatheModel();
  IntegratorOptions opt;
  opt.kind = IntegratorKind::kIda;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, opt);
  integ->Initialize(State::Initial(*model));
  double max_error = 0;
  std::vector<double> errors;
  for (int n = 0; n <= kSteps; ++n) {
    if (n > 0) integ->AdvanceTo(n * kDt);
    const Eigen::Vector2d u = integ->state().q.head<2>();
    const double e = (u - ExactSolution(n * kDt)).lpNorm<Eigen::Infinity>();
    errors.push_back(e);
    max_error = std::max(max_error, e);
  }
  // Global error bound: IDA keeps each step's local error below rtol |y| + atol (weighted RMS
  // norm <= 1). The undamped linear system's flow is an isometry in the energy norm, so the
  // global error is at most the sum of the local errors, times the conversion factor between the
  // max norm and the energy norm, sqrt(cond(M^{-1} K) * cond(M)) = sqrt(5/2 * 2) ~ 2.3, and
  // sqrt(n) = 2 from IDA's weighted RMS norm over the n = 4 differential components.
  const IntegratorStats stats = integ->stats();
  const double y_max = 6.0;  // max |U|, |U'| over the interval (|U2| <= 5.4, |U'| <= 5.5)
  const double bound = 2.3 * 2 * stats.steps * (opt.rtol * y_max + opt.atol);
  std::printf("[bathe] IDA: %ld steps, max |U - exact| = %.3e (bound %.3e)\n", stats.steps,
              max_error, bound);
  EXPECT_LE(max_error, bound);
}

}  // namespace
}  // namespace orrery

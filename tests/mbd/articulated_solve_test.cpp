// ArticulatedSolve (mbd/articulated_solve.h) against an independent algorithm: the mass matrix
// formed by the composite-rigid-body pass (CalcMassMatrix) and solved densely (Eigen's LDLT).
// Both are backward stable, so they agree to the conditioning of M: |x - x_dense| <= c nv eps
// kappa(M) |x| with c = 8 (a few roundings per entry on each side). A wrong sign, a missing
// subtree term or a transposed block moves x by O(1).
// Also: CalcMassMatrixDiagonal is CalcMassMatrix's diagonal to the last bit (the force scale of
// the generalized-alpha Newton test reads it, and the run must not move).
#include <cmath>
#include <limits>
#include <memory>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "mbd/articulated_solve.h"
#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "tests/common/random_spatial.h"

namespace orrery {
namespace {

using test_support::RandomFrame;
using test_support::RandomInertia;
using test_support::RandomRotation;

// Three subtrees on the world: a chain of revolute, prismatic, cylindrical, universal joints
// with a fixed body; a spherical joint carrying a planar one; a free body carrying a revolute
// and a free child (as a carrier carries its planets).
std::shared_ptr<const Model> EveryJointTree(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  ModelBuilder b;
  auto body = [&](const std::string& name) {
    return b.AddBody(name, 0.5 + std::abs(u(rng)), Vec3(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)),
                     RandomInertia(rng));
  };
  auto joint = [&](const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                   const Vec3& axis, const Vec3& axis2) {
    b.AddJoint({.name = name,
                .type = type,
                .parent = parent,
                .child = child,
                .X_PF = RandomFrame(rng, 0.3),
                .X_CM = RandomFrame(rng, 0.2),
                .axis = axis,
                .axis2 = axis2});
  };
  const BodyIndex b1 = body("b1"), b2 = body("b2"), b3 = body("b3"), b4 = body("b4"),
                  b5 = body("b5"), b6 = body("b6"), b7 = body("b7"), b8 = body("b8"),
                  b9 = body("b9"), b10 = body("b10");
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  joint("rev", JointType::kRevolute, kWorldBody, b1, Vec3(1, 2, 3), x);
  joint("pri", JointType::kPrismatic, b1, b2, Vec3(0, 1, 1), x);
  joint("cyl", JointType::kCylindrical, b2, b3, Vec3(1, 0, 1), x);
  joint("uni", JointType::kUniversal, b3, b4, z, Vec3(1, 1, 0));
  joint("fix", JointType::kFixed, b4, b8, z, x);
  joint("sph", JointType::kSpherical, kWorldBody, b5, z, x);
  joint("pla", JointType::kPlanar, b5, b6, y, Vec3(1, 0, 1));
  joint("free", JointType::kFree, kWorldBody, b7, z, x);
  joint("rev2", JointType::kRevolute, b7, b9, Vec3(-1, 1, 0.5), x);
  joint("free2", JointType::kFree, b7, b10, z, x);
  return std::move(b).Finalize();
}

Eigen::VectorXd RandomPositions(const Model& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd q = State::Initial(m).q;
  for (int k = 0; k < m.nq; ++k) q(k) = 0.6 * u(rng);
  for (const Joint& jt : m.joints) {
    const int quat = JointInfo(jt.spec.type).quaternion;
    if (quat < 0) continue;
    const Quat r(RandomRotation(rng, 0.8));
    q.segment<4>(jt.q_start + quat) << r.w(), r.x(), r.y(), r.z();
  }
  return q;
}

constexpr double kEps = std::numeric_limits<double>::epsilon();

double Condition(const Eigen::MatrixXd& M) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(M);
  return eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
}

TEST(ArticulatedSolve, InverseMassAsTheFormedMassMatrix) {
  std::mt19937 rng(17);
  const std::shared_ptr<const Model> model = EveryJointTree(rng);
  const Model& m = *model;
  Data d(m);
  ArticulatedSolve solve(m);
  ASSERT_TRUE(solve.applies());
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    CalcPositionKinematics(m, RandomPositions(m, rng), d);
    CalcMassMatrix(m, d);
    const Eigen::MatrixXd M = d.M;
    Eigen::VectorXd tau(m.nv);
    for (int k = 0; k < m.nv; ++k) tau(k) = u(rng);
    ASSERT_TRUE(solve.Factorize(m, d, tau.transpose()));
    Eigen::VectorXd x(m.nv);
    solve.Solve(m, d, tau, x);
    const Eigen::VectorXd x_dense = M.ldlt().solve(tau);
    const double bound = 8 * m.nv * kEps * Condition(M) * x_dense.lpNorm<Eigen::Infinity>();
    EXPECT_LE((x - x_dense).lpNorm<Eigen::Infinity>(), bound) << "trial " << trial;
  }
}

// A right-hand side in one subtree on the world: the others are not factored and their entries
// of x are exactly zero (M is block diagonal over the world's subtrees); the touched subtree's
// entries are the full solve's.
TEST(ArticulatedSolve, OnlyTheSubtreesTheRowsTouch) {
  std::mt19937 rng(29);
  const std::shared_ptr<const Model> model = EveryJointTree(rng);
  const Model& m = *model;
  Data d(m);
  ArticulatedSolve solve(m);
  CalcPositionKinematics(m, RandomPositions(m, rng), d);
  CalcMassMatrix(m, d);
  // The free body's rotation about z of its joint frame (as seed 002's carrier driver)
  const Joint& free = m.joints[m.joint("free")];
  const Eigen::VectorXd tau = Eigen::VectorXd::Unit(m.nv, free.v_start + 5);
  ASSERT_TRUE(solve.Factorize(m, d, tau.transpose()));
  Eigen::VectorXd x = Eigen::VectorXd::Constant(m.nv, 7.0);
  solve.Solve(m, d, tau, x);
  const Eigen::VectorXd x_dense = d.M.ldlt().solve(tau);
  const double bound = 8 * m.nv * kEps * Condition(d.M) * x_dense.lpNorm<Eigen::Infinity>();
  for (const char* name : {"rev", "pri", "cyl", "uni", "sph", "pla"}) {
    const Joint& jt = m.joints[m.joint(name)];
    for (int k = 0; k < jt.nv; ++k) EXPECT_EQ(x(jt.v_start + k), 0.0) << name;
  }
  for (const char* name : {"free", "rev2", "free2"}) {
    const Joint& jt = m.joints[m.joint(name)];
    for (int k = 0; k < jt.nv; ++k)
      EXPECT_NEAR(x(jt.v_start + k), x_dense(jt.v_start + k), bound) << name;
  }
}

// A body without inertia along its joint's motion makes M singular (the builder refuses such a
// body, so its inertia is cleared in Data): Factorize says so instead of returning a solve.
TEST(ArticulatedSolve, SingularMassMatrixRefused) {
  std::mt19937 rng(5);
  const std::shared_ptr<const Model> model = EveryJointTree(rng);
  const Model& m = *model;
  Data d(m);
  ArticulatedSolve solve(m);
  CalcPositionKinematics(m, RandomPositions(m, rng), d);
  const Eigen::MatrixXd rows = Eigen::MatrixXd::Ones(1, m.nv);
  EXPECT_TRUE(solve.Factorize(m, d, rows));
  d.I_W[m.joints[m.joint("free2")].spec.child] = SpatialInertia{};
  EXPECT_FALSE(solve.Factorize(m, d, rows));
}

TEST(ArticulatedSolve, MassMatrixDiagonalIsCalcMassMatrixsToTheLastBit) {
  std::mt19937 rng(41);
  const std::shared_ptr<const Model> model = EveryJointTree(rng);
  const Model& m = *model;
  Data d(m);
  Eigen::VectorXd diagonal(m.nv);
  for (int trial = 0; trial < 3; ++trial) {
    CalcPositionKinematics(m, RandomPositions(m, rng), d);
    CalcMassMatrix(m, d);
    CalcMassMatrixDiagonal(m, d, diagonal);
    for (int k = 0; k < m.nv; ++k) EXPECT_EQ(diagonal(k), d.M(k, k)) << "coordinate " << k;
  }
}

}  // namespace
}  // namespace orrery

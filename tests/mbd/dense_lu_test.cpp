// DenseLu (mbd/dense_lu.h) against Eigen's PartialPivLU (an independent implementation of the
// same algorithm) and against the backward-error bound of Gaussian elimination with partial
// pivoting (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., Thm. 9.4: the
// computed x solves (A + dA) x = b with |dA| <= gamma_3n |L| |U|; for a random matrix the growth
// is small, so the normwise residual ||b - A x|| / (||A|| ||x||) is a small multiple of n eps).
// The two solutions differ by at most the sum of their forward errors, each bounded by
// kappa(A) times the backward error: the tolerance is 2 * 3n eps * kappa_inf(A) (a growth factor
// of 1; the matrices here are random or built from random orthogonal factors, whose growth is
// O(1), and the test would fail on a real pivoting or ordering defect by many orders more).
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/LU>
#include <Eigen/QR>
#include <gtest/gtest.h>

#include "mbd/dense_lu.h"

namespace orrery {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

Eigen::MatrixXd RandomMatrix(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd a(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) a(i, j) = u(rng);
  return a;
}

// U diag(s) V^T with random orthogonal U, V and singular values from 1 down to 1/condition,
// evenly in the logarithm: a matrix of the given 2-norm condition number.
Eigen::MatrixXd MatrixWithCondition(int n, double condition, std::mt19937& rng) {
  const Eigen::MatrixXd U = Eigen::HouseholderQR<Eigen::MatrixXd>(RandomMatrix(n, rng)).householderQ();
  const Eigen::MatrixXd V = Eigen::HouseholderQR<Eigen::MatrixXd>(RandomMatrix(n, rng)).householderQ();
  Eigen::VectorXd s(n);
  for (int k = 0; k < n; ++k) s(k) = std::pow(condition, -static_cast<double>(k) / std::max(1, n - 1));
  return U * s.asDiagonal() * V.transpose();
}

double ConditionInf(const Eigen::MatrixXd& a) {
  const Eigen::MatrixXd inv = a.fullPivLu().inverse();
  return a.lpNorm<Eigen::Infinity>() * inv.cwiseAbs().rowwise().sum().maxCoeff();
}

// Solves with both factorizations and checks the residual and the agreement.
void ExpectAgreesWithEigen(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(a.rows());
  DenseLu lu(n);
  lu.Compute(a);
  Eigen::VectorXd x(n);
  lu.Solve(b, x);
  const Eigen::VectorXd x_eigen = Eigen::PartialPivLU<Eigen::MatrixXd>(a).solve(b);
  const double anorm = a.cwiseAbs().rowwise().sum().maxCoeff();
  const double residual = (b - a * x).lpNorm<Eigen::Infinity>() / (anorm * x.lpNorm<Eigen::Infinity>());
  EXPECT_LE(residual, 3 * n * kEps) << "n = " << n;
  const double difference = (x - x_eigen).lpNorm<Eigen::Infinity>() / x_eigen.lpNorm<Eigen::Infinity>();
  EXPECT_LE(difference, 2 * 3 * n * kEps * ConditionInf(a)) << "n = " << n;
}

TEST(DenseLu, RandomMatricesAsEigensPartialPivLu) {
  std::mt19937 rng(7);
  for (int n : {1, 2, 5, 16, 37, 60}) {
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::MatrixXd a = RandomMatrix(n, rng);
      Eigen::VectorXd b(n);
      for (int i = 0; i < n; ++i) b(i) = std::uniform_real_distribution<double>(-1, 1)(rng);
      ExpectAgreesWithEigen(a, b);
    }
  }
}

TEST(DenseLu, IllConditionedMatricesAsEigensPartialPivLu) {
  std::mt19937 rng(11);
  for (double condition : {1e6, 1e10, 1e13}) {
    for (int n : {8, 37}) {
      const Eigen::MatrixXd a = MatrixWithCondition(n, condition, rng);
      Eigen::VectorXd b(n);
      for (int i = 0; i < n; ++i) b(i) = std::uniform_real_distribution<double>(-1, 1)(rng);
      ExpectAgreesWithEigen(a, b);
    }
  }
}

// A saddle-point matrix as the generalized-alpha iteration matrix is: an SPD block with a
// constraint row and column and a zero diagonal entry, which only pivoting can factor.
TEST(DenseLu, SaddlePointNeedsPivoting) {
  std::mt19937 rng(3);
  const int nv = 12;
  const Eigen::MatrixXd r = RandomMatrix(nv, rng);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(nv + 1, nv + 1);
  a.topLeftCorner(nv, nv) = r * r.transpose() + nv * Eigen::MatrixXd::Identity(nv, nv);
  a(nv, 5) = a(5, nv) = 1;
  a.col(nv).swap(a.col(0));  // the zero diagonal entry moved to the first column
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(nv + 1, -1, 1);
  ExpectAgreesWithEigen(a, b);
}

TEST(DenseLu, SolveInPlaceAndSingularColumn) {
  std::mt19937 rng(5);
  const Eigen::MatrixXd a = RandomMatrix(9, rng);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(9, 1, 2);
  DenseLu lu;
  lu.Compute(a);
  Eigen::VectorXd x(9), y = b;
  lu.Solve(b, x);
  lu.Solve(y, y);  // x aliasing b
  EXPECT_EQ(x, y);
  // An exactly singular matrix (a zero column): the pivot shows it, the solution is not finite.
  Eigen::MatrixXd s = a;
  s.col(4).setZero();
  lu.Compute(s);
  EXPECT_EQ(lu.Pivot(4), 0.0);
  lu.Solve(b, x);
  EXPECT_FALSE(x.allFinite());
  EXPECT_THROW(lu.Compute(Eigen::MatrixXd::Zero(3, 4)), std::invalid_argument);
}

}  // namespace
}  // namespace orrery

// The thick-restart Lanczos (flex/thick_restart_lanczos.cpp). Oracles: operators whose
// eigenpairs are known in closed form (a diagonal matrix in a random orthogonal basis);
// fe_modes_test.cpp runs the solver through CalcFeModes against a dense generalized eigen solver
// on a free FE mesh.
//   - Eigenvalues: Ritz values of converged pairs lie within residual^2 / gap of an eigenvalue
//     (Parlett, The Symmetric Eigenvalue Problem, 1998, Thm 11.7.1), far below the test's
//     1e-12 relative for residuals of 1e-10 |theta| and gaps of 1e-3 or more; double eigenvalues
//     are found twice.
//   - Residuals ||A y - theta y|| at most the tolerance times |theta| (the convergence test, with
//     the basis' rounding: a bound of 2x), vectors orthonormal to 1e-12.
//   - An operator with an eigenvalue of multiplicity n - 2 exhausts the Krylov space of its start
//     vector after three columns (the remainder falls to rounding), and the zero operator leaves
//     no remainder at all: the next columns are random directions orthogonal to the basis.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "flex/thick_restart_lanczos.h"

namespace orrery::flex {
namespace {

// A = Q diag(d) Q^T with Q a random orthogonal matrix (fixed seed).
Eigen::MatrixXd RotatedDiagonal(const Eigen::VectorXd& d, unsigned seed) {
  const Eigen::Index n = d.size();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd G(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) G(i, j) = normal(rng);
  const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(G).householderQ();
  return Q * d.asDiagonal() * Q.transpose();
}

ThickRestartResult Solve(const Eigen::MatrixXd& A, int nev, const ThickRestartOptions& options) {
  return SolveThickRestartLanczos(
      [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, A.rows()).noalias() =
            A * Eigen::Map<const Eigen::VectorXd>(x, A.rows());
      },
      A.rows(), nev, options);
}

void ExpectEigenpairs(const Eigen::MatrixXd& A, const ThickRestartResult& r,
                      const Eigen::VectorXd& expected, double tolerance) {
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(r.theta.size(), expected.size());
  for (Eigen::Index i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(r.theta(i), expected(i), 1e-12 * std::abs(expected(i))) << "pair " << i;
    EXPECT_LE((A * r.vectors.col(i) - r.theta(i) * r.vectors.col(i)).norm(),
              2 * tolerance * std::abs(r.theta(i)))
        << "pair " << i;
  }
  const Eigen::Index k = expected.size();
  EXPECT_LT(
      (r.vectors.transpose() * r.vectors - Eigen::MatrixXd::Identity(k, k)).cwiseAbs().maxCoeff(),
      1e-12);
}

// The shift-invert spectrum of a clamped structure: nu = 1 / lambda for lambda = 1, 1 (a double
// pair), 1.5, 1.5, 2, ... clustered toward zero, plus a tail down to 1e-6; 20 wanted of 400,
// a basis of 41 columns, so it restarts.
TEST(ThickRestartLanczos, LargestEigenvaluesOfAClusteredSpectrumWithDoublePairs) {
  const int n = 400, nev = 20;
  Eigen::VectorXd lambda(n);
  for (int i = 0; i < n; ++i)
    lambda(i) = 1.0 + 0.5 * (i / 2) + 1e-3 * (i % 2) * (i >= 8) + 1e3 * (i >= 200) * i;
  const Eigen::VectorXd nu = lambda.cwiseInverse();
  Eigen::VectorXd sorted = nu;
  std::sort(sorted.data(), sorted.data() + n, [](double a, double b) { return a > b; });
  const Eigen::MatrixXd A = RotatedDiagonal(nu, 7);
  const ThickRestartResult r = Solve(A, nev, {.tolerance = 1e-10});
  ExpectEigenpairs(A, r, sorted.head(nev), 1e-10);
  EXPECT_GT(r.restarts, 0);
  // Repeatable to the bit
  const ThickRestartResult again = Solve(A, nev, {.tolerance = 1e-10});
  EXPECT_EQ((again.theta - r.theta).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((again.vectors - r.vectors).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(again.operations, r.operations);
}

// Indefinite operators: the largest |theta| of either sign, in |theta| order.
TEST(ThickRestartLanczos, LargestMagnitudesOfEitherSign) {
  const int n = 120;
  Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(n, -1.0, 0.8);
  d(n - 1) = 2.0;
  const Eigen::MatrixXd A = RotatedDiagonal(d, 11);
  Eigen::VectorXd expected(4);
  expected << 2.0, -1.0, d(1), d(2);
  const ThickRestartResult r = Solve(A, 4, {.max_basis = 24, .tolerance = 1e-11});
  ExpectEigenpairs(A, r, expected, 1e-11);
}

// The start vector's Krylov space is 3-dimensional (eigenvalues 3, 2 and 1 of multiplicity n - 2):
// after three columns the remainder is rounding, and the eigenvalue 1 is still found three times.
TEST(ThickRestartLanczos, ExhaustedKrylovSpaceStillFindsAMultipleEigenvalue) {
  const int n = 60;
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  d(0) = 3.0;
  d(1) = 2.0;
  const Eigen::MatrixXd A = RotatedDiagonal(d, 3);
  Eigen::VectorXd expected(5);
  expected << 3.0, 2.0, 1.0, 1.0, 1.0;
  const ThickRestartResult r = Solve(A, 5, {.max_basis = 12, .tolerance = 1e-10});
  ExpectEigenpairs(A, r, expected, 1e-10);
}

// The zero operator: every image is exactly zero, so the remainder vanishes at every column and
// each next column is a random direction orthogonal to the basis (without that, w / 0 fills the
// basis with NaN). All eigenvalues 0, the vectors orthonormal.
TEST(ThickRestartLanczos, VanishingRemainderGivesRandomOrthogonalDirections) {
  const Eigen::MatrixXd A = Eigen::MatrixXd::Zero(40, 40);
  const ThickRestartResult r = Solve(A, 3, {.max_basis = 8, .tolerance = 1e-10});
  ExpectEigenpairs(A, r, Eigen::VectorXd::Zero(3), 1e-10);
  EXPECT_EQ(r.operations, 8);
}

TEST(ThickRestartLanczos, ArgumentsAreChecked) {
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(10, 10);
  EXPECT_THROW(Solve(A, 0, {}), std::invalid_argument);
  EXPECT_THROW(Solve(A, 10, {}), std::invalid_argument);
  EXPECT_THROW(Solve(A, 5, {.max_basis = 5}), std::invalid_argument);
}

// Not converged: the result says so and holds the current Ritz pairs.
TEST(ThickRestartLanczos, NoConvergenceIsReported) {
  const int n = 300;
  const Eigen::VectorXd d = Eigen::VectorXd::LinSpaced(n, 1.0, 1.001);
  const Eigen::MatrixXd A = RotatedDiagonal(d, 5);
  const ThickRestartResult r =
      Solve(A, 10, {.max_basis = 14, .tolerance = 1e-14, .max_restarts = 2});
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.restarts, 2);
  EXPECT_EQ(r.theta.size(), 10);
}

}  // namespace
}  // namespace orrery::flex

#pragma once
// LU factorization with partial pivoting of a small dense square matrix (tens of unknowns: the
// generalized-alpha iteration matrix of a lumped train, 36 to 60 rows), written for that size.
//
// Math: P A = L U (Golub & Van Loan, Matrix Computations, 4th ed., Alg. 3.4.1, the outer-product
// "kij" form with row interchanges), L unit lower triangular, U upper triangular, stored in one
// contiguous column-major n x n array (L below the diagonal); the pivot of column k is the row of
// largest magnitude at or below the diagonal (the first such row on ties, as LAPACK's dgetf2 and
// Eigen's PartialPivLU). Solve: b permuted, forward substitution with L, back substitution with
// U, both row-oriented on copies of the triangles packed by rows (each row's sum runs over
// contiguous memory, Eigen's vectorized dot product).
// Why not Eigen's PartialPivLU: for these sizes its blocked factorization and general-size
// triangular solves spend about three times the solve's flops in set-up and dispatch (seed 002:
// 8.5k instructions per 37-unknown solve against 2.7k flops; this one 6.0k; docs/performance.md).
// Rounding: the same pivots as Eigen's PartialPivLU in exact arithmetic, the sums in another
// order, so the two agree to the backward-error bound of Gaussian elimination with partial
// pivoting, |dA| <= gamma_n |L| |U| (Higham, Accuracy and Stability of Numerical Algorithms, 2nd
// ed., Thm. 9.3), not to the last bit (tests/mbd/dense_lu_test.cpp compares them).
// Sizes: Compute sizes the storage once for n (allocates when n changes); Solve never allocates.
// Preconditions: a square matrix; Solve after Compute, b and x of size n (x may alias b).
// A zero pivot (an exactly singular column) is kept: Solve then returns non-finite values, as
// Eigen's PartialPivLU does, for the caller's finiteness checks.
#include <vector>

#include <Eigen/Core>

namespace orrery {

class DenseLu {
 public:
  DenseLu() = default;
  // Storage for n x n systems (Compute of that size will not allocate).
  explicit DenseLu(int n) { Reserve(n); }

  // Factorizes a (n x n). Throws std::invalid_argument when a is not square.
  void Compute(const Eigen::Ref<const Eigen::MatrixXd>& a);
  // x = A^-1 b (b, x of size n; x may be b).
  void Solve(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> x) const;

  int size() const { return n_; }
  // U's diagonal (the pivots), for singularity checks: entry k of column k.
  double Pivot(int k) const { return lu_[static_cast<size_t>(k) * n_ + k]; }

 private:
  void Reserve(int n);

  int n_ = 0;
  std::vector<double> lu_;   // n x n column-major: L (unit, strictly below), U (on and above)
  std::vector<int> perm_;    // row k of P A is row perm_[k] of A
  std::vector<double> lower_;  // L's strict lower triangle by rows, packed (n (n - 1) / 2)
  std::vector<double> upper_;  // U by rows from the diagonal, packed (n (n + 1) / 2)
  std::vector<int> upper_start_;  // n: where U's row i starts in upper_
  mutable std::vector<double> work_;  // Solve's scratch (n): the permuted right-hand side
};

}  // namespace orrery

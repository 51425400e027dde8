#include "flex/sparse_ldlt_shift_invert.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orrery::flex {

SparseLdltShiftInvert::SparseLdltShiftInvert(const Eigen::SparseMatrix<double>& A,
                                             const Eigen::SparseMatrix<double>& B, ShiftInvertMethod method)
    : A_(A), B_(B), method_(method) {
  if (A.rows() != A.cols() || B.rows() != B.cols() || A.rows() != B.rows())
    throw std::invalid_argument("SparseLdltShiftInvert: A and B must be square and of equal size");
}

void SparseLdltShiftInvert::set_shift(double sigma) {
  // Same pattern for every sigma (the sum keeps explicit zeros), as both symbolic analyses need
  const Eigen::SparseMatrix<double> S = A_ - sigma * B_;
  if (method_ != ShiftInvertMethod::kLdlt) {
    if (!cholesky_) cholesky_ = std::make_unique<CholmodCholesky>();
    if (cholesky_->factorize(S)) {
      uses_cholesky_ = true;
      negative_pivots_ = 0;
      sigma_ = sigma;
      return;
    }
    if (method_ == ShiftInvertMethod::kCholesky)
      throw std::runtime_error("K - sigma M is not positive definite at sigma = " + std::to_string(sigma) +
                               " (Cholesky requested; the shift must lie below the lowest eigenvalue)");
  }
  uses_cholesky_ = false;
  // The pattern of A - sigma B does not depend on sigma: analyse once
  if (!analyzed_) {
    ldlt_.analyzePattern(S);
    analyzed_ = true;
  }
  ldlt_.factorize(S);
  if (ldlt_.info() != Eigen::Success)
    throw std::runtime_error("LDL^T factorization of K - sigma M failed at sigma = " + std::to_string(sigma));
  const Eigen::VectorXd d = ldlt_.vectorD();
  negative_pivots_ = 0;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (d(i) == 0 || !std::isfinite(d(i)))
      throw std::runtime_error("K - sigma M is singular at sigma = " + std::to_string(sigma) +
                               " (sigma is an eigenvalue; choose another shift)");
    if (d(i) < 0) ++negative_pivots_;
  }
  sigma_ = sigma;
}

void SparseLdltShiftInvert::perform_op(const double* x_in, double* y_out) const {
  Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
  Eigen::Map<Eigen::VectorXd> y(y_out, rows());
  if (uses_cholesky_)
    cholesky_->solve(x_in, y_out);
  else
    y = ldlt_.solve(x);
}

Eigen::Index SparseLdltShiftInvert::factor_nonzeros() const {
  if (uses_cholesky_) return cholesky_->factor_nonzeros();
  return analyzed_ ? ldlt_.matrixL().nestedExpression().nonZeros() : 0;
}

}  // namespace orrery::flex

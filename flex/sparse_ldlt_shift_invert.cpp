#include "flex/sparse_ldlt_shift_invert.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orrery::flex {

Eigen::SparseMatrix<double> UpperShifted(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& B,
                                         double sigma) {
  if (A.rows() != A.cols() || B.rows() != B.cols() || A.rows() != B.rows())
    throw std::invalid_argument("UpperShifted: A and B must be square and of equal size");
  if (!A.isCompressed() || !B.isCompressed()) throw std::invalid_argument("UpperShifted: A and B must be compressed");
  const int n = static_cast<int>(A.rows());
  const int *ap = A.outerIndexPtr(), *ai = A.innerIndexPtr(), *bp = B.outerIndexPtr(), *bi = B.innerIndexPtr();
  const double *ax = A.valuePtr(), *bx = B.valuePtr();
  // Column c: merge the rows <= c of A and B (both ascending), twice: count, then fill
  Eigen::SparseMatrix<double> S(n, n);
  int* sp = S.outerIndexPtr();
  for (int pass = 0; pass < 2; ++pass) {
    int nz = 0;
    for (int c = 0; c < n; ++c) {
      if (pass == 1) sp[c] = nz;
      int i = ap[c], j = bp[c];
      const int ie = ap[c + 1], je = bp[c + 1];
      int last = -1;
      while ((i < ie && ai[i] <= c) || (j < je && bi[j] <= c)) {
        const int ra = i < ie && ai[i] <= c ? ai[i] : n, rb = j < je && bi[j] <= c ? bi[j] : n;
        const int r = std::min(ra, rb);
        if (r <= last) throw std::invalid_argument("UpperShifted: rows must be sorted in each column");
        last = r;
        double v = 0;
        if (ra == r) v += ax[i++];
        if (rb == r) v -= sigma * bx[j++];
        if (pass == 1) {
          S.innerIndexPtr()[nz] = r;
          S.valuePtr()[nz] = v;
        }
        ++nz;
      }
    }
    if (pass == 0) S.resizeNonZeros(nz);
    else sp[n] = nz;
  }
  return S;
}

void ShiftedFactor::Factorize(const Eigen::SparseMatrix<double>& S, double sigma, ShiftInvertMethod method) {
  if (S.rows() != S.cols()) throw std::invalid_argument("ShiftedFactor: matrix must be square");
  if (n_ != 0 && S.rows() != n_)
    throw std::invalid_argument("ShiftedFactor: size " + std::to_string(S.rows()) + " differs from the analysed " +
                                std::to_string(n_));
  if (method != ShiftInvertMethod::kLdlt) {
    if (FactorizeIfPositiveDefinite(S, sigma)) return;
    if (method == ShiftInvertMethod::kCholesky)
      throw std::runtime_error("K - sigma M is not positive definite at sigma = " + std::to_string(sigma) +
                               " (Cholesky requested; the shift must lie below the lowest eigenvalue)");
  }
  n_ = S.rows();
  factorized_ = uses_cholesky_ = false;
  // The pattern does not depend on sigma (UpperShifted): analyse once
  if (!ldlt_analyzed_) {
    ldlt_.analyzePattern(S);
    ldlt_analyzed_ = true;
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
  factorized_ = true;
}

bool ShiftedFactor::FactorizeIfPositiveDefinite(const Eigen::SparseMatrix<double>& S, double sigma) {
  return FactorizeCholesky(S, sigma, nullptr);
}

bool ShiftedFactor::FactorizeIfPositiveDefinite(Eigen::SparseMatrix<double>&& S, double sigma) {
  return FactorizeCholesky(S, sigma, &S);
}

bool ShiftedFactor::FactorizeCholesky(const Eigen::SparseMatrix<double>& S, double sigma,
                                      Eigen::SparseMatrix<double>* release) {
  if (S.rows() != S.cols()) throw std::invalid_argument("ShiftedFactor: matrix must be square");
  if (n_ != 0 && S.rows() != n_)
    throw std::invalid_argument("ShiftedFactor: size " + std::to_string(S.rows()) + " differs from the analysed " +
                                std::to_string(n_));
  n_ = S.rows();
  if (!cholesky_) cholesky_ = std::make_unique<CholmodCholesky>();
  factorized_ = uses_cholesky_ = release ? cholesky_->factorize(std::move(*release)) : cholesky_->factorize(S);
  negative_pivots_ = 0;
  sigma_ = sigma;
  return factorized_;
}

void ShiftedFactor::Solve(const double* B, double* X, int columns) const {
  if (!factorized_) throw std::logic_error("ShiftedFactor::Solve without a successful Factorize()");
  if (uses_cholesky_) {
    cholesky_->solve(B, X, columns);
    return;
  }
  const Eigen::Map<const Eigen::MatrixXd> b(B, n_, columns);
  Eigen::Map<Eigen::MatrixXd> x(X, n_, columns);
  x = ldlt_.solve(b);
}

void ShiftedFactor::SolveForward(const double* B, double* X, int columns) const {
  if (!factorized_ || !uses_cholesky_) throw std::logic_error("ShiftedFactor::SolveForward without a Cholesky factorization");
  cholesky_->solve_forward(B, X, columns);
}

void ShiftedFactor::SolveBackward(const double* B, double* X, int columns) const {
  if (!factorized_ || !uses_cholesky_) throw std::logic_error("ShiftedFactor::SolveBackward without a Cholesky factorization");
  cholesky_->solve_backward(B, X, columns);
}

Eigen::Index ShiftedFactor::factor_nonzeros() const {
  if (uses_cholesky_) return cholesky_->factor_nonzeros();
  return ldlt_analyzed_ ? ldlt_.matrixL().nestedExpression().nonZeros() : 0;
}

SparseLdltShiftInvert::SparseLdltShiftInvert(const Eigen::SparseMatrix<double>& A,
                                             const Eigen::SparseMatrix<double>& B, ShiftInvertMethod method)
    : A_(A), B_(B), method_(method) {
  if (A.rows() != A.cols() || B.rows() != B.cols() || A.rows() != B.rows())
    throw std::invalid_argument("SparseLdltShiftInvert: A and B must be square and of equal size");
}

void SparseLdltShiftInvert::set_shift(double sigma) { factor_.Factorize(UpperShifted(A_, B_, sigma), sigma, method_); }

}  // namespace orrery::flex

#include "mbd/dense_lu.h"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace orrery {

void DenseLu::Reserve(int n) {
  n_ = n;
  lu_.assign(static_cast<size_t>(n) * n, 0.0);
  perm_.resize(n);
  work_.assign(n, 0.0);
}

void DenseLu::Compute(const Eigen::Ref<const Eigen::MatrixXd>& a) {
  if (a.rows() != a.cols()) throw std::invalid_argument("DenseLu: the matrix is not square");
  const int n = static_cast<int>(a.rows());
  if (n != n_) Reserve(n);
  double* lu = lu_.data();
  Eigen::Map<Eigen::MatrixXd>(lu, n, n) = a;
  for (int k = 0; k < n; ++k) perm_[k] = k;
  for (int k = 0; k < n; ++k) {
    double* col_k = lu + static_cast<size_t>(k) * n;
    // Pivot: the first row of largest magnitude at or below the diagonal
    int p = k;
    double largest = std::abs(col_k[k]);
    for (int i = k + 1; i < n; ++i)
      if (std::abs(col_k[i]) > largest) largest = std::abs(col_k[i]), p = i;
    if (p != k) {
      for (int j = 0; j < n; ++j) std::swap(lu[static_cast<size_t>(j) * n + k], lu[static_cast<size_t>(j) * n + p]);
      std::swap(perm_[k], perm_[p]);
    }
    const double pivot = col_k[k];
    if (pivot == 0) continue;  // an exactly singular column: Solve gives non-finite values
    // Multipliers, then the rank-one update of the trailing columns
    for (int i = k + 1; i < n; ++i) col_k[i] /= pivot;
    for (int j = k + 1; j < n; ++j) {
      double* __restrict col_j = lu + static_cast<size_t>(j) * n;
      const double* __restrict l = col_k;
      const double u = col_j[k];
      if (u == 0) continue;
      for (int i = k + 1; i < n; ++i) col_j[i] -= l[i] * u;
    }
  }
}

void DenseLu::Solve(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> x) const {
  const int n = n_;
  double* __restrict y = work_.data();
  const double* lu = lu_.data();
  for (int k = 0; k < n; ++k) y[k] = b(perm_[k]);
  // Forward substitution with the unit lower triangle, column by column
  for (int k = 0; k < n; ++k) {
    const double yk = y[k];
    const double* __restrict l = lu + static_cast<size_t>(k) * n;
    for (int i = k + 1; i < n; ++i) y[i] -= l[i] * yk;
  }
  // Back substitution with the upper triangle, column by column
  for (int k = n - 1; k >= 0; --k) {
    const double* __restrict u = lu + static_cast<size_t>(k) * n;
    y[k] /= u[k];
    const double yk = y[k];
    for (int i = 0; i < k; ++i) y[i] -= u[i] * yk;
  }
  for (int k = 0; k < n; ++k) x(k) = y[k];
}

}  // namespace orrery

#pragma once
// Sparse Cholesky factorization A = L L^T of a symmetric positive definite matrix with CHOLMOD's
// supernodal method (SuiteSparse; dense BLAS kernels on the supernodes, fill-reducing ordering
// chosen by cholmod_analyze: AMD, and METIS nested dissection when AMD's fill is large, as it is
// for 3-D solid meshes). The symbolic analysis (ordering, elimination tree, supernodes) is done
// on the first factorize() and kept: later calls must pass a matrix with the same nonzero
// pattern (or a subset of it), e.g. K - sigma M for another sigma.
//
// This header does not include CHOLMOD (only flex/ .cpp files do).
//
// Usage:
//   CholmodCholesky chol;
//   if (!chol.factorize(S)) { /* S is not positive definite */ }
//   chol.solve(b.data(), x.data());
#include <memory>

#include <Eigen/SparseCore>

namespace orrery::flex {

class CholmodCholesky {
 public:
  CholmodCholesky();
  ~CholmodCholesky();
  CholmodCholesky(const CholmodCholesky&) = delete;
  CholmodCholesky& operator=(const CholmodCholesky&) = delete;

  // Factorizes the symmetric matrix S (n x n, compressed; only its upper triangle is read, the
  // lower may be stored or not). Returns false if S is not positive definite (then the factor is
  // unusable until the next successful call); throws std::runtime_error on other CHOLMOD
  // failures (out of memory, ...) and std::invalid_argument if S is not square or its size
  // differs from the first call's.
  bool factorize(const Eigen::SparseMatrix<double>& S);

  // x = S^-1 b (n values each) with the last successful factorization; throws std::logic_error
  // if there is none.
  void solve(const double* b, double* x) const;

  bool factorized() const { return factorized_; }
  Eigen::Index rows() const { return n_; }
  // Nonzeros of L (from the symbolic analysis; 0 before the first factorize()).
  Eigen::Index factor_nonzeros() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Eigen::Index n_ = 0;
  bool factorized_ = false;
};

}  // namespace orrery::flex

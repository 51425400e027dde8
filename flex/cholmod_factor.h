#pragma once
// Sparse Cholesky factorization A = L L^T of a symmetric positive definite matrix with CHOLMOD's
// supernodal method (SuiteSparse; dense BLAS kernels on the supernodes, fill-reducing ordering
// chosen by cholmod_analyze: AMD, and METIS nested dissection when AMD's fill is large, as it is
// for 3-D solid meshes). The symbolic analysis (ordering, elimination tree, supernodes) is done
// on the first factorize() and kept: later calls must pass a matrix with the same nonzero
// pattern (or a subset of it), e.g. K - sigma M for another sigma.
// Memory: CHOLMOD factorizes a permuted lower triangle B = P S P^T, which cholmod_factorize copies
// from S and holds next to it. Here the ordering P is taken from CHOLMOD's analysis of S, B is
// formed once per factorization and L is analysed on B with the natural ordering, in which case
// cholmod_factorize reads B as it is; with factorize(S&&) S is freed before the numeric
// factorization, so only B is held (the rvalue overload; on the 91k-DOF block S is 86 MB).
// The supernodes are those of S's analysis (B's elimination tree is postordered already), so the
// factor and its solves are the same operations as CHOLMOD's own permuted factorization; the
// solves permute the right-hand sides themselves.
//
// This header does not include CHOLMOD (only flex/ .cpp files do).
//
// Solves take any number of right-hand sides at once: a supernode's triangular solve is then a
// dense BLAS-3 product instead of BLAS-2 (on a 91k-DOF hex20 block a solve of 8 columns costs
// about 2.5 single solves: 0.32 s against 0.127 s); the solve workspace is kept, so repeated
// solves of as many columns allocate nothing.
//
// Usage:
//   CholmodCholesky chol;
//   if (!chol.factorize(S)) { /* S is not positive definite */ }
//   chol.solve(b.data(), x.data());            // one column
//   chol.solve(B.data(), X.data(), B.cols());  // n x k, column-major
#include <memory>

#include <Eigen/SparseCore>

struct cholmod_sparse_struct;  // cholmod.h's cholmod_sparse

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
  // The same, freeing S's storage (S is left empty) as soon as CHOLMOD has its permuted copy, so
  // that S and the copy never coexist during the numeric factorization (the 91k-DOF block: 86 MB).
  bool factorize(Eigen::SparseMatrix<double>&& S);

  // X = S^-1 B for `columns` right-hand sides (B and X: n x columns, column-major, leading
  // dimension n; X may not overlap B) with the last successful factorization. Throws
  // std::logic_error if there is none, std::invalid_argument for columns < 1.
  void solve(const double* B, double* X, int columns = 1) const;

  // The two halves of a solve, for an operator in the symmetric standard form L^-1 P A P^T L^-T
  // (fe_modes.cpp), where S = P^T L L^T P and P is the fill-reducing permutation:
  //   solve_forward:  X = L^-1 P B     solve_backward: X = P^T L^-T B
  // so that solve_backward(solve_forward(B)) = S^-1 B. Same arguments and throws as solve().
  void solve_forward(const double* B, double* X, int columns = 1) const;
  void solve_backward(const double* B, double* X, int columns = 1) const;

  bool factorized() const { return factorized_; }
  Eigen::Index rows() const { return n_; }
  // Nonzeros of L (from the symbolic analysis; 0 before the first factorize()).
  Eigen::Index factor_nonzeros() const;

 private:
  bool Factorize(const Eigen::SparseMatrix<double>& S, Eigen::SparseMatrix<double>* release);
  void Order(cholmod_sparse_struct& A);
  void AnalyzePermuted(cholmod_sparse_struct& B);
  const double* Permuted(const double* B, int columns, const char* name) const;
  void Unpermute(double* X, int columns) const;
  void SolveSystem(int sys, const double* B, int columns, const char* name) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  Eigen::Index n_ = 0;
  bool factorized_ = false;
};

}  // namespace orrery::flex

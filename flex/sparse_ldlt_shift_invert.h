#pragma once
// Shift-invert solves y = (A - sigma B)^-1 x over a sparse factorization of S = A - sigma B (A, B
// symmetric, B positive definite), for the eigen solvers of fe_modes.h:
//   - Cholesky (default when it succeeds): CHOLMOD's supernodal L L^T (flex/cholmod_factor.h)
//     with AMD / METIS ordering. Used when S is positive definite, i.e. sigma lies below the
//     lowest eigenvalue (fe_modes.cpp's negative shift, or 0 for a clamped structure). Success
//     itself proves that no eigenvalue lies below sigma (num_eigenvalues_below_shift() = 0).
//     Scales to 100k+ DOF solid meshes where the simplicial LDL^T does not. Its speed is that of
//     the BLAS behind CHOLMOD (supernodes are dense blocks): a 112k-DOF hex20 cube factorizes in
//     11 s with a serial OpenBLAS, 112 s with Debian's reference (netlib) BLAS.
//   - LDL^T (fallback when CHOLMOD reports "not positive definite", or on request): simplicial
//     LDL^T with AMD ordering (Eigen::SimplicialLDLT); gives the inertia: by Sylvester's law the
//     number of negative pivots of D is the number of eigenvalues of A x = lambda B x below sigma.
// Only the upper triangle of S is formed and read; it lives only while it is factorized. Solves
// take blocks of right-hand sides (one supernodal solve for all columns).
//
// Two classes:
//   ShiftedFactor: the factorization of a given S (upper triangle), with its solves; what the
//     block Lanczos of fe_modes.cpp and the Craig-Bampton reduction use.
//   SparseLdltShiftInvert: A and B kept by reference and S = A - sigma B factorized on
//     set_shift(sigma); Spectra's `OpType` for SymGEigsShiftSolver in GEigsMode::ShiftInvert
//     (rows(), cols(), set_shift, perform_op), used by fe_modes.cpp's Spectra path (the oracle of
//     the block Lanczos) and by tests.
//
// This header does not include Spectra or CHOLMOD (flex/ keeps them private).
//
// Usage:
//   ShiftedFactor f;
//   f.Factorize(UpperShifted(K, M, sigma), sigma);     // throws if S is singular
//   f.Solve(B.data(), X.data(), B.cols());             // X = (K - sigma M)^-1 B
#include <memory>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "flex/cholmod_factor.h"

namespace orrery::flex {

enum class ShiftInvertMethod {
  kAuto,      // CHOLMOD Cholesky; LDL^T if A - sigma B is not positive definite
  kCholesky,  // CHOLMOD Cholesky only; throws if A - sigma B is not positive definite
  kLdlt,      // simplicial LDL^T only
};

// The upper triangle (diagonal included) of A - sigma B, compressed, rows sorted. A and B:
// square, equal size, compressed with rows sorted in each column (as Eigen's products and
// fe_assembly.cpp leave them); only their upper triangles are read. The pattern is the union of
// theirs whatever sigma (explicit zeros kept), so one symbolic analysis serves every shift.
// Throws std::invalid_argument for sizes that differ or unsorted rows.
Eigen::SparseMatrix<double> UpperShifted(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& B,
                                         double sigma);

class ShiftedFactor {
 public:
  ShiftedFactor() = default;
  ShiftedFactor(const ShiftedFactor&) = delete;
  ShiftedFactor& operator=(const ShiftedFactor&) = delete;

  // Factorizes S (n x n; only its upper triangle is read), recording sigma as the shift it
  // stands for. The symbolic analysis of each method is done on its first use and kept: later
  // calls must pass the same pattern. Throws std::runtime_error if the factorization fails or a
  // pivot is zero (sigma is an eigenvalue), or, with kCholesky, if S is not positive definite;
  // std::invalid_argument if S is not square or its size changes.
  void Factorize(const Eigen::SparseMatrix<double>& S, double sigma, ShiftInvertMethod method = ShiftInvertMethod::kAuto);

  // Cholesky only: returns false (and leaves no factorization) if S is not positive definite;
  // throws as Factorize for other failures.
  bool FactorizeIfPositiveDefinite(const Eigen::SparseMatrix<double>& S, double sigma);
  // The same, freeing S's storage (S is left empty) before the numeric factorization
  // (CholmodCholesky::factorize(S&&)): S and CHOLMOD's permuted copy never coexist.
  bool FactorizeIfPositiveDefinite(Eigen::SparseMatrix<double>&& S, double sigma);

  // X = S^-1 B for `columns` right-hand sides (B, X: n x columns, column-major, leading dimension
  // n, not overlapping). Throws std::logic_error before a successful Factorize.
  void Solve(const double* B, double* X, int columns = 1) const;

  // Cholesky only (uses_cholesky()): the two halves of Solve, X = L^-1 P B and X = P^T L^-T B
  // with S = P^T L L^T P (CholmodCholesky::solve_forward / solve_backward). Throws
  // std::logic_error without a Cholesky factorization.
  void SolveForward(const double* B, double* X, int columns = 1) const;
  void SolveBackward(const double* B, double* X, int columns = 1) const;

  Eigen::Index rows() const { return n_; }
  double shift() const { return sigma_; }
  bool factorized() const { return factorized_; }
  // Eigenvalues below the shift (0 after a successful Cholesky, else the negative pivots of D).
  int num_eigenvalues_below_shift() const { return negative_pivots_; }
  // Nonzeros of the factor L (fill-in measure).
  Eigen::Index factor_nonzeros() const;
  // True if the current factorization is CHOLMOD's Cholesky, false for LDL^T.
  bool uses_cholesky() const { return uses_cholesky_; }

 private:
  bool FactorizeCholesky(const Eigen::SparseMatrix<double>& S, double sigma, Eigen::SparseMatrix<double>* release);

  std::unique_ptr<CholmodCholesky> cholesky_;  // created on the first Cholesky attempt
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::AMDOrdering<int>> ldlt_;
  bool ldlt_analyzed_ = false;
  bool uses_cholesky_ = false;
  bool factorized_ = false;
  Eigen::Index n_ = 0;
  double sigma_ = 0;
  int negative_pivots_ = 0;
};

class SparseLdltShiftInvert {
 public:
  using Scalar = double;

  // A, B: symmetric n x n (upper triangles read), kept by reference.
  SparseLdltShiftInvert(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& B,
                        ShiftInvertMethod method = ShiftInvertMethod::kAuto);

  Eigen::Index rows() const { return A_.rows(); }
  Eigen::Index cols() const { return A_.cols(); }

  // Factorizes A - sigma B (ShiftedFactor::Factorize; the symbolic analysis is done once).
  void set_shift(double sigma);

  // y_out = (A - sigma B)^-1 x_in (n values each).
  void perform_op(const double* x_in, double* y_out) const { factor_.Solve(x_in, y_out, 1); }

  double shift() const { return factor_.shift(); }
  int num_eigenvalues_below_shift() const { return factor_.num_eigenvalues_below_shift(); }
  Eigen::Index factor_nonzeros() const { return factor_.factor_nonzeros(); }
  bool uses_cholesky() const { return factor_.uses_cholesky(); }
  const ShiftedFactor& factor() const { return factor_; }

 private:
  const Eigen::SparseMatrix<double>& A_;
  const Eigen::SparseMatrix<double>& B_;
  ShiftInvertMethod method_;
  ShiftedFactor factor_;
};

}  // namespace orrery::flex

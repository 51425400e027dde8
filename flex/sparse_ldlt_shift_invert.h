#pragma once
// Shift-invert operator y = (A - sigma B)^-1 x over a sparse LDL^T factorization, for Spectra's
// SymGEigsShiftSolver in GEigsMode::ShiftInvert (it is the `OpType`: rows(), cols(),
// set_shift(sigma), perform_op(x_in, y_out)). Spectra's own SymShiftInvert factorizes sparse
// matrices with SparseLU; A - sigma B of an FE model is symmetric, so a simplicial LDL^T with
// AMD ordering (Eigen::SimplicialLDLT) needs about half the memory and time, and it also
// gives the inertia: by Sylvester's law the number of negative pivots of D is the number of
// eigenvalues of A x = lambda B x below sigma (B positive definite).
//
// This header does not include Spectra (flex/ keeps Spectra private).
//
// Usage (fe_modes.cpp):
//   SparseLdltShiftInvert op(K, M);      // keeps references: K and M must outlive op
//   Spectra::SparseSymMatProd<double> bop(M);
//   Spectra::SymGEigsShiftSolver<SparseLdltShiftInvert, Spectra::SparseSymMatProd<double>,
//                                Spectra::GEigsMode::ShiftInvert> eigs(op, bop, nev, ncv, sigma);
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace orrery::flex {

class SparseLdltShiftInvert {
 public:
  using Scalar = double;

  // A, B: symmetric n x n (both triangles stored), kept by reference.
  SparseLdltShiftInvert(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& B);

  Eigen::Index rows() const { return A_.rows(); }
  Eigen::Index cols() const { return A_.cols(); }

  // Factorizes A - sigma B (the symbolic analysis is done once). Throws std::runtime_error if
  // the factorization fails or a pivot is zero (sigma is an eigenvalue).
  void set_shift(double sigma);

  // y_out = (A - sigma B)^-1 x_in (n values each).
  void perform_op(const double* x_in, double* y_out) const;

  double shift() const { return sigma_; }
  // Eigenvalues below the current shift (negative pivots of D).
  int num_eigenvalues_below_shift() const { return negative_pivots_; }
  // Nonzeros of the factor L (fill-in measure).
  Eigen::Index factor_nonzeros() const;

 private:
  const Eigen::SparseMatrix<double>& A_;
  const Eigen::SparseMatrix<double>& B_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
  bool analyzed_ = false;
  double sigma_ = 0;
  int negative_pivots_ = 0;
};

}  // namespace orrery::flex

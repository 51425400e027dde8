#include "flex/fe_modes.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "flex/sparse_ldlt_shift_invert.h"

namespace orrery::flex {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// The rows and columns `keep` (ascending) of a sparse matrix.
Eigen::SparseMatrix<double> Restrict(const Eigen::SparseMatrix<double>& A, const std::vector<int>& keep) {
  std::vector<int> map(A.rows(), -1);
  for (int i = 0; i < static_cast<int>(keep.size()); ++i) map[keep[i]] = i;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(A.nonZeros());
  for (int c = 0; c < A.outerSize(); ++c) {
    if (map[c] < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (map[it.row()] >= 0) t.emplace_back(map[it.row()], map[c], it.value());
  }
  Eigen::SparseMatrix<double> R(keep.size(), keep.size());
  R.setFromTriplets(t.begin(), t.end());
  return R;
}

}  // namespace

double EigenvalueToHz(double w2) { return (w2 < 0 ? -1.0 : 1.0) * std::sqrt(std::abs(w2)) / (2 * std::numbers::pi); }

FeModes SolveLowestModes(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                         const FeModesOptions& options) {
  const int n = static_cast<int>(K.rows());
  const int nev = options.num_modes;
  if (nev < 1 || nev >= n)
    throw std::invalid_argument("number of modes must be in [1, " + std::to_string(n - 1) + "] for " +
                                std::to_string(n) + " free DOFs, got " + std::to_string(nev));
  FeModes r;
  // Shift: given, or a millionth of the mean diagonal ratio below zero
  const double trace_ratio = K.diagonal().sum() / M.diagonal().sum();
  r.shift = options.use_shift ? options.shift : -1e-6 * trace_ratio;
  const int ncv = std::min(n, options.lanczos_vectors > 0 ? options.lanczos_vectors : std::max(2 * nev + 1, nev + 20));

  // Factorize K - sigma M: the solver's constructor calls op.set_shift(sigma)
  const Clock::time_point t0 = Clock::now();
  SparseLdltShiftInvert op(K, M);
  Spectra::SparseSymMatProd<double> bop(M);
  Spectra::SymGEigsShiftSolver<SparseLdltShiftInvert, Spectra::SparseSymMatProd<double>, Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, nev, ncv, r.shift);
  const Clock::time_point t1 = Clock::now();
  r.factorize_seconds = Seconds(t0, t1);
  r.factor_nonzeros = static_cast<long>(op.factor_nonzeros());
  // Nothing may lie below a negative shift (K positive semi-definite)
  if (op.num_eigenvalues_below_shift() > 0 && !options.use_shift)
    throw std::runtime_error(std::to_string(op.num_eigenvalues_below_shift()) +
                             " eigenvalues below the negative shift: K is not positive semi-definite");

  // Implicitly restarted Lanczos on (K - sigma M)^-1 M
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, options.max_iterations, options.tolerance, Spectra::SortRule::SmallestAlge);
  r.solve_seconds = Seconds(t1, Clock::now());
  if (eigs.info() != Spectra::CompInfo::Successful)
    throw std::runtime_error("eigen solve did not converge: " + std::to_string(eigs.eigenvalues().size()) + " of " +
                             std::to_string(nev) + " modes after " + std::to_string(eigs.num_iterations()) +
                             " restarts (raise the number of Lanczos vectors or iterations)");
  r.iterations = static_cast<int>(eigs.num_iterations());
  r.operations = static_cast<int>(eigs.num_operations());
  r.eigenvalues = eigs.eigenvalues();
  r.shapes = eigs.eigenvectors();
  // Ascending order (Spectra sorts already; keep it explicit) and rigid-body modes to zero
  std::vector<int> order(r.eigenvalues.size());
  for (int i = 0; i < static_cast<int>(order.size()); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return r.eigenvalues(a) < r.eigenvalues(b); });
  const Eigen::VectorXd lambda = r.eigenvalues;
  const Eigen::MatrixXd shapes = r.shapes;
  for (int i = 0; i < static_cast<int>(order.size()); ++i) {
    r.eigenvalues(i) = lambda(order[i]);
    r.shapes.col(i) = shapes.col(order[i]);
  }
  const double largest = std::max(r.eigenvalues.cwiseAbs().maxCoeff(), std::abs(r.shift));
  for (int i = 0; i < r.eigenvalues.size(); ++i) {
    if (std::abs(r.eigenvalues(i)) <= options.rigid_body_tolerance * largest) {
      r.eigenvalues(i) = 0;
      ++r.num_rigid_body_modes;
    }
    r.frequencies_hz.push_back(EigenvalueToHz(r.eigenvalues(i)));
  }
  return r;
}

FeModes CalcFeModes(const FeSystem& system, std::span<const int> fixed_dofs, const FeModesOptions& options) {
  const int ndof = static_cast<int>(system.K.rows());
  std::vector<char> fixed(ndof, 0);
  for (int d : fixed_dofs) {
    if (d < 0 || d >= ndof) throw std::out_of_range("fixed DOF " + std::to_string(d) + " out of range");
    fixed[d] = 1;
  }
  std::vector<int> free;
  for (int d = 0; d < ndof; ++d)
    if (!fixed[d]) free.push_back(d);
  if (free.size() == static_cast<std::size_t>(ndof)) {
    FeModes r = SolveLowestModes(system.K, system.M, options);
    r.free_dofs = std::move(free);
    return r;
  }
  const Eigen::SparseMatrix<double> K = Restrict(system.K, free), M = Restrict(system.M, free);
  FeModes r = SolveLowestModes(K, M, options);
  // Scatter the shapes back to all DOFs
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(ndof, r.shapes.cols());
  for (int i = 0; i < static_cast<int>(free.size()); ++i) full.row(free[i]) = r.shapes.row(i);
  r.shapes = std::move(full);
  r.free_dofs = std::move(free);
  return r;
}

}  // namespace orrery::flex

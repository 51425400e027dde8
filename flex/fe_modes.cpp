#include "flex/fe_modes.h"

#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "flex/block_lanczos.h"
#include "flex/thick_restart_lanczos.h"

namespace orrery::flex {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

void CheckModeCount(int nev, Eigen::Index n) {
  if (nev < 1 || nev >= n)
    throw std::invalid_argument("number of modes must be in [1, " + std::to_string(n - 1) + "] for " +
                                std::to_string(n) + " free DOFs, got " + std::to_string(nev));
}

// The default shift: a millionth of the mean diagonal ratio below zero (header).
double DefaultShift(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M) {
  return -1e-6 * K.diagonal().sum() / M.diagonal().sum();
}

// Spectra's OpType over a factorization made beforehand: set_shift (called by the solver's
// constructor) only checks that the shift is the factor's.
class FactorOp {
 public:
  using Scalar = double;
  explicit FactorOp(const ShiftedFactor& f) : f_(f) {}
  Eigen::Index rows() const { return f_.rows(); }
  Eigen::Index cols() const { return f_.rows(); }
  void set_shift(double sigma) {
    if (sigma != f_.shift()) throw std::logic_error("FactorOp: shift differs from the factor's");
  }
  void perform_op(const double* x, double* y) const { f_.Solve(x, y, 1); }

 private:
  const ShiftedFactor& f_;
};

// The symmetric standard form of the shift-invert operator over a Cholesky factor
// S = K - sigma M = P^T L L^T P: A = L^-1 P M P^T L^-T has the eigenvalues nu = 1 / (w^2 - sigma)
// of S^-1 M, with eigenvectors y = L^T P x (Ericsson & Ruhe 1980, sec. 2). One application is a
// forward and a backward triangular solve (one solve of S) and one product with M, and the
// Lanczos basis is orthogonal in the Euclidean inner product: the M-inner products of the
// generalized form (an M product for each, 4 to 6 per Lanczos vector in Spectra's
// reorthogonalization) are gone.
class StandardFormOp {
 public:
  using Scalar = double;
  StandardFormOp(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M)
      : f_(f), M_(M), x_(f.rows()), mx_(f.rows()) {}
  Eigen::Index rows() const { return f_.rows(); }
  Eigen::Index cols() const { return f_.rows(); }
  void perform_op(const double* y, double* z) const {
    f_.SolveBackward(y, x_.data(), 1);
    mx_.noalias() = M_.selfadjointView<Eigen::Upper>() * x_;
    f_.SolveForward(mx_.data(), z, 1);
  }

 private:
  const ShiftedFactor& f_;
  const Eigen::SparseMatrix<double>& M_;
  mutable Eigen::VectorXd x_, mx_;
};

// Spectra's ncv: max(2 N + 1, N + 20) unless set, at most n.
int LanczosVectors(const FeModesOptions& o, int n) {
  return std::min(n, o.lanczos_vectors > 0 ? o.lanczos_vectors : std::max(2 * o.num_modes + 1, o.num_modes + 20));
}

// Runs a Spectra solver for the largest nu, throwing if it does not converge; counts into r.
template <typename Solver>
void RunSpectra(Solver& eigs, const FeModesOptions& o, FeModes& r) {
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, o.max_iterations, o.tolerance, Spectra::SortRule::SmallestAlge);
  if (eigs.info() != Spectra::CompInfo::Successful)
    throw std::runtime_error("eigen solve did not converge: " + std::to_string(eigs.eigenvalues().size()) + " of " +
                             std::to_string(o.num_modes) + " modes after " + std::to_string(eigs.num_iterations()) +
                             " restarts (raise the number of Lanczos vectors or iterations)");
  r.iterations = static_cast<int>(eigs.num_iterations());
  r.operations = r.block_solves = static_cast<int>(eigs.num_operations());
}

// Eigenpairs (nu, y) of the standard form above mapped back: w^2 = sigma + 1 / nu,
// x = P^T L^-T y (one solve of N columns), M-normalized.
void MapStandardFormBack(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M,
                         const Eigen::VectorXd& nu, const Eigen::MatrixXd& Y, FeModes& r) {
  const Eigen::Index n = f.rows(), nev = nu.size();
  r.eigenvalues = f.shift() + nu.cwiseInverse().array();
  r.shapes.resize(n, nev);
  f.SolveBackward(Y.data(), r.shapes.data(), static_cast<int>(nev));
  const Eigen::MatrixXd MX = M.selfadjointView<Eigen::Upper>() * r.shapes;
  for (Eigen::Index i = 0; i < nev; ++i)
    r.shapes.col(i) /= std::sqrt(r.shapes.col(i).dot(MX.col(i)));
}

// Eigenpairs of S^-1 M by Spectra's implicitly restarted Lanczos on the standard form.
void SolveStandardFormWithSpectra(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M,
                                  const FeModesOptions& o, FeModes& r) {
  const int n = static_cast<int>(f.rows()), nev = o.num_modes;
  StandardFormOp op(f, M);
  Spectra::SymEigsSolver<StandardFormOp> eigs(op, nev, LanczosVectors(o, n));
  RunSpectra(eigs, o, r);
  MapStandardFormBack(f, M, eigs.eigenvalues(), eigs.eigenvectors(), r);
}

// The same by the thick-restart Lanczos (thick_restart_lanczos.h).
void SolveStandardFormWithThickRestart(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M,
                                       const FeModesOptions& o, FeModes& r) {
  const StandardFormOp op(f, M);
  const ThickRestartResult t = SolveThickRestartLanczos(
      [&](const double* y, double* z) { op.perform_op(y, z); }, f.rows(), o.num_modes,
      {.max_basis = o.lanczos_vectors, .tolerance = o.tolerance, .max_restarts = o.max_iterations});
  if (!t.converged)
    throw std::runtime_error("eigen solve did not converge: " + std::to_string(o.num_modes) +
                             " modes after " + std::to_string(t.restarts) +
                             " restarts (raise the number of Lanczos vectors or iterations)");
  r.iterations = t.restarts;
  r.operations = r.block_solves = t.operations;
  MapStandardFormBack(f, M, t.theta, t.vectors, r);
}

// Eigenpairs (nu, x) of (K - sigma M)^-1 M by Spectra's implicitly restarted Lanczos in the
// M-inner product (a factorization that is not a Cholesky: LDL^T at a shift above eigenvalues).
void SolveWithSpectra(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M, const FeModesOptions& o,
                      FeModes& r) {
  if (f.uses_cholesky()) {
    SolveStandardFormWithSpectra(f, M, o, r);
    return;
  }
  const int n = static_cast<int>(f.rows()), nev = o.num_modes;
  const int ncv = LanczosVectors(o, n);
  FactorOp op(f);
  Spectra::SparseSymMatProd<double, Eigen::Upper> bop(M);
  Spectra::SymGEigsShiftSolver<FactorOp, Spectra::SparseSymMatProd<double, Eigen::Upper>, Spectra::GEigsMode::ShiftInvert>
      eigs(op, bop, nev, ncv, f.shift());
  RunSpectra(eigs, o, r);
  r.eigenvalues = eigs.eigenvalues();  // w^2 (Spectra transforms back)
  r.shapes = eigs.eigenvectors();
}

// Purification of converged Ritz vectors Y (Ericsson & Ruhe 1980, sec. 3): one more application
// of the operator, Z = (K - sigma M)^-1 M Y, damps a stiff mode j's share of a Ritz vector by
// (lambda_i - sigma) / (lambda_j - sigma): the rounding the large-|theta| pairs (rigid-body modes
// at a negative shift) leave in the basis would otherwise show as residuals
// (lambda_j - lambda_i) M x_j. Then Rayleigh-Ritz on span(Z) for the pencil (K - sigma M, M)
// without K: Z^T (K - sigma M) Z = Z^T M Y. One solve of nev right-hand sides.
void Purify(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M, const Eigen::MatrixXd& Y, FeModes& r) {
  const auto Mu = M.selfadjointView<Eigen::Upper>();
  const Eigen::Index n = Y.rows(), k = Y.cols();
  Eigen::MatrixXd MY(n, k), Z(n, k);
  MY.noalias() = Mu * Y;
  f.Solve(MY.data(), Z.data(), static_cast<int>(k));
  const Eigen::MatrixXd H = Z.transpose() * MY;
  MY.noalias() = Mu * Z;  // now M Z
  const Eigen::MatrixXd G = Z.transpose() * MY;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (H + H.transpose()),
                                                                    0.5 * (G + G.transpose()));
  if (es.info() != Eigen::Success) throw std::runtime_error("eigen solve: Rayleigh-Ritz of the purified vectors failed");
  r.eigenvalues = f.shift() + es.eigenvalues().array();
  r.shapes.noalias() = Z * es.eigenvectors();
}

// The same by the block Lanczos, its Ritz vectors purified.
void SolveWithBlockLanczos(const ShiftedFactor& f, const Eigen::SparseMatrix<double>& M, const FeModesOptions& o,
                           FeModes& r) {
  const BlockLanczosResult b = SolveBlockLanczos([&](const double* B, double* X, int k) { f.Solve(B, X, k); }, M,
                                                 o.num_modes,
                                                 {.block_size = o.block_size, .max_basis = o.lanczos_vectors,
                                                  .tolerance = o.tolerance, .max_restarts = o.max_iterations});
  if (!b.converged)
    throw std::runtime_error("eigen solve did not converge: " + std::to_string(o.num_modes) + " modes after " +
                             std::to_string(b.restarts) +
                             " restarts (raise the number of Lanczos vectors or iterations)");
  r.iterations = b.restarts;
  r.operations = b.columns + o.num_modes;
  r.block_solves = b.block_solves + 1;
  Purify(f, M, b.vectors, r);
}

// Ascending order, rigid-body modes to zero, frequencies.
void FinishModes(const FeModesOptions& options, FeModes& r) {
  std::vector<int> order(r.eigenvalues.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return r.eigenvalues(a) < r.eigenvalues(b); });
  const Eigen::VectorXd lambda = r.eigenvalues;
  Eigen::MatrixXd shapes(r.shapes.rows(), r.shapes.cols());
  for (int i = 0; i < static_cast<int>(order.size()); ++i) {
    r.eigenvalues(i) = lambda(order[i]);
    shapes.col(i) = r.shapes.col(order[i]);
  }
  r.shapes = std::move(shapes);
  const double largest = std::max(r.eigenvalues.cwiseAbs().maxCoeff(), std::abs(r.shift));
  r.frequencies_hz.clear();
  for (int i = 0; i < r.eigenvalues.size(); ++i) {
    if (std::abs(r.eigenvalues(i)) <= options.rigid_body_tolerance * largest) {
      r.eigenvalues(i) = 0;
      ++r.num_rigid_body_modes;
    }
    r.frequencies_hz.push_back(EigenvalueToHz(r.eigenvalues(i)));
  }
}

// Factorizes S = K - sigma M into f; returns the seconds. At the default (negative) shift S is
// released before the numeric factorization (a Cholesky must succeed there: throws if K is not
// positive semi-definite); at a shift of the caller's it is kept for the LDL^T fallback.
double Factorize(Eigen::SparseMatrix<double>&& S, double sigma, const FeModesOptions& options, ShiftedFactor& f) {
  const Clock::time_point t0 = Clock::now();
  if (options.use_shift) {
    f.Factorize(S, sigma);
  } else if (!f.FactorizeIfPositiveDefinite(std::move(S), sigma)) {
    throw std::runtime_error("K - sigma M is not positive definite at the negative shift sigma = " +
                             std::to_string(sigma) + ": K is not positive semi-definite");
  }
  return Seconds(t0, Clock::now());
}

// Map of the free DOFs (header: RestrictUpper) and their list, checked.
std::vector<int> FreeMap(Eigen::Index ndof, std::span<const int> fixed_dofs, std::vector<int>& free) {
  std::vector<int> map(ndof, 0);
  for (int d : fixed_dofs) {
    if (d < 0 || d >= ndof) throw std::out_of_range("fixed DOF " + std::to_string(d) + " out of range");
    map[d] = -1;
  }
  free.clear();
  for (int d = 0; d < static_cast<int>(ndof); ++d) {
    if (map[d] < 0) continue;
    map[d] = static_cast<int>(free.size());
    free.push_back(d);
  }
  return map;
}

// Modes of the free DOFs of `system`; its K and M are released once restricted when `release`.
FeModes ModesOfFreeDofs(const FeSystem& system, FeSystem* release, std::span<const int> fixed_dofs,
                        const FeModesOptions& options) {
  const Eigen::Index ndof = system.K.rows();
  std::vector<int> free;
  const std::vector<int> map = FreeMap(ndof, fixed_dofs, free);
  CheckModeCount(options.num_modes, static_cast<Eigen::Index>(free.size()));
  // Free-DOF upper triangles; K - sigma M lives only while it is factorized
  const Eigen::SparseMatrix<double> Mf = RestrictUpper(system.M, map);
  ShiftedFactor f;
  double sigma = 0, factorize_seconds = 0;
  {
    // Only S = K_f - sigma M_f (and M_f) stay while CHOLMOD works: K_f goes once S is formed.
    // Eigen 3.4's SparseMatrix has no move assignment and keeps its storage when assigned an
    // empty matrix: released storage is swapped out (K and M of the 92k-DOF block: 230 MB).
    Eigen::SparseMatrix<double> S = [&] {
      const Eigen::SparseMatrix<double> Kf = RestrictUpper(system.K, map);
      if (release) {
        Eigen::SparseMatrix<double>().swap(release->K);
        Eigen::SparseMatrix<double>().swap(release->M);
      }
      sigma = options.use_shift ? options.shift : DefaultShift(Kf, Mf);
      return UpperShifted(Kf, Mf, sigma);
    }();
    factorize_seconds = Factorize(std::move(S), sigma, options, f);
  }
  FeModes r = SolveLowestModes(f, Mf, options);
  r.factorize_seconds = factorize_seconds;
  // Scatter the shapes back to all DOFs
  Eigen::MatrixXd shapes = Eigen::MatrixXd::Zero(ndof, r.shapes.cols());
  for (int i = 0; i < static_cast<int>(free.size()); ++i) shapes.row(free[i]) = r.shapes.row(i);
  r.shapes = std::move(shapes);
  r.free_dofs = std::move(free);
  return r;
}

}  // namespace

double EigenvalueToHz(double w2) { return (w2 < 0 ? -1.0 : 1.0) * std::sqrt(std::abs(w2)) / (2 * std::numbers::pi); }

Eigen::SparseMatrix<double> RestrictUpper(const Eigen::SparseMatrix<double>& A, const std::vector<int>& map) {
  if (A.rows() != A.cols() || static_cast<Eigen::Index>(map.size()) != A.rows())
    throw std::invalid_argument("RestrictUpper: matrix must be square with one map entry per row");
  if (!A.isCompressed()) throw std::invalid_argument("RestrictUpper: matrix must be compressed");
  const int n = static_cast<int>(std::count_if(map.begin(), map.end(), [](int m) { return m >= 0; }));
  const int *ap = A.outerIndexPtr(), *ai = A.innerIndexPtr();
  const double* ax = A.valuePtr();
  // Kept columns in order, their kept rows up to the diagonal: count, then fill
  Eigen::SparseMatrix<double> R(n, n);
  int nz = 0;
  for (int c = 0; c < A.cols(); ++c)
    if (map[c] >= 0)
      for (int k = ap[c]; k < ap[c + 1]; ++k) nz += map[ai[k]] >= 0 && map[ai[k]] <= map[c];
  R.resizeNonZeros(nz);
  int* rp = R.outerIndexPtr();
  nz = 0;
  for (int c = 0; c < A.cols(); ++c) {
    if (map[c] < 0) continue;
    rp[map[c]] = nz;
    for (int k = ap[c]; k < ap[c + 1]; ++k) {
      const int row = map[ai[k]];
      if (row < 0 || row > map[c]) continue;
      R.innerIndexPtr()[nz] = row;
      R.valuePtr()[nz++] = ax[k];
    }
  }
  rp[n] = nz;
  return R;
}

FeModes SolveLowestModes(const ShiftedFactor& factor, const Eigen::SparseMatrix<double>& M,
                         const FeModesOptions& options) {
  CheckModeCount(options.num_modes, factor.rows());
  if (M.rows() != factor.rows() || M.cols() != factor.rows())
    throw std::invalid_argument("SolveLowestModes: M's size differs from the factor's");
  FeModes r;
  r.shift = factor.shift();
  r.factor_nonzeros = static_cast<long>(factor.factor_nonzeros());
  const Clock::time_point t0 = Clock::now();
  switch (options.solver) {
    case EigenSolver::kThickRestart:
      if (factor.uses_cholesky())
        SolveStandardFormWithThickRestart(factor, M, options, r);
      else
        SolveWithSpectra(factor, M, options, r);  // LDL^T: the generalized form
      break;
    case EigenSolver::kSpectra: SolveWithSpectra(factor, M, options, r); break;
    case EigenSolver::kBlockLanczos: SolveWithBlockLanczos(factor, M, options, r); break;
  }
  r.solve_seconds = Seconds(t0, Clock::now());
  FinishModes(options, r);
  return r;
}

FeModes SolveLowestModes(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                         const FeModesOptions& options) {
  CheckModeCount(options.num_modes, K.rows());
  const double sigma = options.use_shift ? options.shift : DefaultShift(K, M);
  ShiftedFactor f;
  const double factorize_seconds = Factorize(UpperShifted(K, M, sigma), sigma, options, f);
  FeModes r = SolveLowestModes(f, M, options);
  r.factorize_seconds = factorize_seconds;
  return r;
}

FeModes CalcFeModes(const FeSystem& system, std::span<const int> fixed_dofs, const FeModesOptions& options) {
  return ModesOfFreeDofs(system, nullptr, fixed_dofs, options);
}

FeModes CalcFeModes(FeSystem&& system, std::span<const int> fixed_dofs, const FeModesOptions& options) {
  return ModesOfFreeDofs(system, &system, fixed_dofs, options);
}

}  // namespace orrery::flex

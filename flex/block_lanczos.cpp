#include "flex/block_lanczos.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace orrery::flex {
namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

// Directions of a new block whose M-norm fell below this fraction of the block's norm before
// its orthogonalization against the basis lie in the basis to rounding: replaced by random ones.
constexpr double kDeflation = 1e-10;

// Rows per chunk when the basis is combined in place (restart).
constexpr Eigen::Index kRowChunk = 2048;

class Lanczos {
 public:
  Lanczos(const BlockSolve& solve, const Eigen::SparseMatrix<double>& M, int nev, int b, int max_basis, double tol)
      : solve_(solve), M_(M), n_(M.rows()), nev_(nev), b_(b), mmax_(max_basis), tol_(tol),
        V_(n_, mmax_), T_(Mat::Zero(mmax_, mmax_)), W_(n_, b_), MW_(n_, b_), MP_(n_, b_), rng_(20240611) {}

  BlockLanczosResult Run(int max_restarts);

 private:
  // Y = M X (upper triangle of M).
  void MultiplyM(const Eigen::Ref<const Mat>& X, Eigen::Ref<Mat> Y) const {
    Y.noalias() = M_.selfadjointView<Eigen::Upper>() * X;
  }
  // X = pseudo-random values in [-1/2, 1/2) (fixed seed: repeatable).
  void FillRandom(Eigen::Ref<Mat> X) {
    for (Eigen::Index j = 0; j < X.cols(); ++j)
      for (Eigen::Index i = 0; i < X.rows(); ++i) X(i, j) = double(rng_() >> 11) * 0x1.0p-53 - 0.5;
  }
  // X -= V C, C = V^T M X (V: first m columns of the basis), twice; returns the sum of the C.
  Mat Orthogonalize(int m, Eigen::Ref<Mat> X, Eigen::Ref<Mat> MX) const;
  // X (n x p) = Q R with Q^T M Q = I, Q M-orthogonal to the first m basis columns, written over
  // X; returns R (p x p). ref2: the squared M-norm scale below which directions are replaced.
  Mat Orthonormalize(int m, Eigen::Ref<Mat> X, double ref2);
  // One SVQB pass: X = Q R over the directions whose squared M-norm exceeds `floor2`, which
  // become the first `kept` columns of X; the others are left zero (R's rows too).
  Mat Svqb(Eigen::Ref<Mat> X, double floor2, int& kept);
  // Expands the pending block (columns me_ .. me_ + p_): T's columns for it, the next block.
  // Returns the coupling R of the next block (q x p_) and its size q.
  Mat Expand(int& q);
  // Ritz pairs of the expanded part, ordered by |theta| descending.
  void Ritz(Vec& theta, Mat& S) const;
  // Restart: the basis becomes the k best Ritz vectors; returns their coupling to the pending
  // block given its coupling R to the last expanded block.
  void Restart(int k, const Vec& theta, const Mat& S, const Mat& R, int p_last, int q);

  const BlockSolve& solve_;
  const Eigen::SparseMatrix<double>& M_;
  const Eigen::Index n_;
  const int nev_, b_, mmax_;
  const double tol_;
  Mat V_, T_;          // basis (n x mmax), projection V^T M Op V (mmax x mmax)
  Mat W_, MW_, MP_;    // blocks (n x b)
  std::mt19937_64 rng_;
  int me_ = 0, p_ = 0;  // expanded columns, pending block columns (after them)
  int block_solves_ = 0, columns_ = 0;
};

Mat Lanczos::Orthogonalize(int m, Eigen::Ref<Mat> X, Eigen::Ref<Mat> MX) const {
  Mat total = Mat::Zero(m, X.cols());
  if (m == 0) return total;
  const auto V = V_.leftCols(m);
  for (int pass = 0; pass < 2; ++pass) {
    MultiplyM(X, MX);
    const Mat C = V.transpose() * MX;
    X.noalias() -= V * C;
    total += C;
  }
  return total;
}

Mat Lanczos::Svqb(Eigen::Ref<Mat> X, double floor2, int& kept) {
  const Eigen::Index p = X.cols();
  auto MX = MW_.leftCols(p);
  MultiplyM(X, MX);
  Mat G = X.transpose() * MX;
  G = (0.5 * (G + G.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<Mat> es(G);
  // Q = X U L^-1/2 over the kept directions (largest first), R = L^1/2 U^T; the rest zero
  Mat R = Mat::Zero(p, p), U = Mat::Zero(p, p);
  kept = 0;
  for (Eigen::Index i = p - 1; i >= 0; --i) {
    const double l = es.eigenvalues()(i);
    if (!(l > floor2)) continue;
    U.col(kept) = es.eigenvectors().col(i) / std::sqrt(l);
    R.row(kept) = std::sqrt(l) * es.eigenvectors().col(i).transpose();
    ++kept;
  }
  const Mat Q = X * U;
  X = Q;
  return R;
}

Mat Lanczos::Orthonormalize(int m, Eigen::Ref<Mat> X, double ref2) {
  const Eigen::Index p = X.cols();
  // Two SVQB passes: the second corrects the first's rounding (Stathopoulos & Wu); after the
  // first the kept columns have unit norm, the lost ones are zero
  int kept = 0, kept2 = 0;
  const Mat R1 = Svqb(X, kDeflation * kDeflation * ref2, kept);
  const Mat R2 = Svqb(X.leftCols(kept), 0.25, kept2);
  Mat R = Mat::Zero(p, p);
  R.topRows(kept) = R2.topLeftCorner(kept, kept) * R1.topRows(kept);
  // Lost directions: random vectors M-orthonormal to the basis and to the columns before them
  Mat x(n_, 1), Mx(n_, 1);
  for (Eigen::Index j = kept; j < p; ++j) {
    FillRandom(x);
    for (int pass = 0; pass < 2; ++pass) {
      Orthogonalize(m, x, Mx);
      MultiplyM(x, Mx);
      const Vec c = X.leftCols(j).transpose() * Mx;
      x.col(0).noalias() -= X.leftCols(j) * c;
    }
    MultiplyM(x, Mx);
    X.col(j) = x.col(0) / std::sqrt(x.col(0).dot(Mx.col(0)));
  }
  return R;
}

Mat Lanczos::Expand(int& q) {
  const int p = p_, m = me_ + p;
  auto P = V_.middleCols(me_, p);
  auto W = W_.leftCols(p);
  // W = Op P = (K - sigma M)^-1 M P: one solve for the block
  MultiplyM(P, MP_.leftCols(p));
  solve_(MP_.data(), W.data(), p);
  ++block_solves_;
  columns_ += p;
  // Scale of the block, then its projections on the basis: T's columns of the pending block
  MultiplyM(W, MW_.leftCols(p));
  const double ref2 = (W.transpose() * MW_.leftCols(p)).diagonal().maxCoeff();
  const Mat C = Orthogonalize(m, W, MW_.leftCols(p));
  T_.block(0, me_, m, p) = C;
  T_.block(me_, 0, p, m) = C.transpose();
  T_.block(me_, me_, p, p) = 0.5 * (C.bottomRows(p) + C.bottomRows(p).transpose());
  me_ = m;
  // Next block: as many columns as the space has left
  q = static_cast<int>(std::min<Eigen::Index>(p, n_ - m));
  if (q == 0) return Mat(0, p);
  Mat R = Orthonormalize(m, W, std::max(ref2, std::numeric_limits<double>::min()));
  return R.topRows(q);
}

void Lanczos::Ritz(Vec& theta, Mat& S) const {
  const Eigen::SelfAdjointEigenSolver<Mat> es(T_.topLeftCorner(me_, me_));
  std::vector<int> order(me_);
  std::iota(order.begin(), order.end(), 0);
  const Vec& ev = es.eigenvalues();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(ev(a)) > std::abs(ev(b)); });
  theta.resize(me_);
  S.resize(me_, me_);
  for (int i = 0; i < me_; ++i) {
    theta(i) = ev(order[i]);
    S.col(i) = es.eigenvectors().col(order[i]);
  }
}

void Lanczos::Restart(int k, const Vec& theta, const Mat& S, const Mat& R, int p_last, int q) {
  // V(:, 0..k) = V(:, 0..me) S(:, 0..k), row chunk by row chunk (no n x k temporary)
  const Mat Sk = S.leftCols(k);
  Mat chunk;
  for (Eigen::Index r0 = 0; r0 < n_; r0 += kRowChunk) {
    const Eigen::Index rows = std::min(kRowChunk, n_ - r0);
    chunk.noalias() = V_.block(r0, 0, rows, me_) * Sk;
    V_.block(r0, 0, rows, k) = chunk;
  }
  // T: diag(theta) on the Ritz vectors, their coupling to the next block R S(last block rows)
  const Mat coupling = R * Sk.bottomRows(p_last);
  T_.topLeftCorner(k + q, k + q).setZero();
  T_.topLeftCorner(k, k).diagonal() = theta.head(k);
  T_.block(k, 0, q, k) = coupling;
  T_.block(0, k, k, q) = coupling.transpose();
  me_ = k;
}

BlockLanczosResult Lanczos::Run(int max_restarts) {
  BlockLanczosResult r;
  // Start: a random block, M-orthonormal
  p_ = static_cast<int>(std::min<Eigen::Index>(b_, n_));
  FillRandom(W_.leftCols(p_));
  Orthonormalize(0, W_.leftCols(p_), 0);
  V_.leftCols(p_) = W_.leftCols(p_);
  Vec theta;
  Mat S;
  const double eps23 = std::pow(std::numeric_limits<double>::epsilon(), 2.0 / 3.0);
  while (true) {
    const int p_last = p_;
    int q = 0;
    const Mat R = Expand(q);
    // Ritz pairs and their residuals ||R s(last block)||
    Ritz(theta, S);
    const int k = std::min(nev_, me_);
    bool converged = k == nev_;
    for (int i = 0; i < k && converged; ++i) {
      const double residual = q > 0 ? (R * S.col(i).tail(p_last)).norm() : 0.0;
      converged = residual <= tol_ * std::max(eps23, std::abs(theta(i)));
    }
    if (converged || q == 0 || r.restarts >= max_restarts) {
      r.converged = converged || q == 0;
      r.theta = theta.head(k);
      r.vectors.noalias() = V_.leftCols(me_) * S.leftCols(k);
      break;
    }
    // Room for the next block, else restart from the best Ritz vectors
    if (me_ + q > mmax_) {
      Restart(std::min(me_, nev_ + b_), theta, S, R, p_last, q);
      ++r.restarts;
    } else {
      T_.block(me_, me_ - p_last, q, p_last) = R;
      T_.block(me_ - p_last, me_, p_last, q) = R.transpose();
    }
    V_.middleCols(me_, q) = W_.leftCols(q);
    p_ = q;
  }
  r.block_solves = block_solves_;
  r.columns = columns_;
  return r;
}

}  // namespace

BlockLanczosResult SolveBlockLanczos(const BlockSolve& solve, const Eigen::SparseMatrix<double>& M, int nev,
                                     const BlockLanczosOptions& options) {
  const int n = static_cast<int>(M.rows());
  if (M.cols() != n) throw std::invalid_argument("SolveBlockLanczos: M must be square");
  if (nev < 1 || nev >= n)
    throw std::invalid_argument("SolveBlockLanczos: nev must be in [1, " + std::to_string(n - 1) + "], got " +
                                std::to_string(nev));
  const int b = std::clamp(options.block_size > 0 ? options.block_size : 8, 1, n);
  const int m = options.max_basis > 0 ? options.max_basis : std::max(2 * nev + 2 * b, nev + 6 * b);
  // Room for the kept Ritz vectors and two blocks, never beyond the space
  const int max_basis = std::min(n, std::max(m, nev + 2 * b));
  Lanczos lanczos(solve, M, nev, b, max_basis, options.tolerance);
  return lanczos.Run(options.max_restarts);
}

}  // namespace orrery::flex

#include "flex/thick_restart_lanczos.h"

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

// Rows of V per chunk when the first update and the second projection share a pass (a chunk of a
// 61-column basis is 250 kB), and when the basis is combined in place at a restart.
constexpr Eigen::Index kRowChunk = 512;

class ThickRestart {
 public:
  ThickRestart(const SymmetricOperator& op, Eigen::Index n, int nev, int max_basis, double tol)
      : op_(op),
        n_(n),
        nev_(nev),
        mmax_(max_basis),
        tol_(tol),
        V_(n, max_basis),
        T_(Mat::Zero(max_basis, max_basis)),
        w_(n),
        h_(max_basis),
        h2_(max_basis),
        rng_(20261128) {}

  ThickRestartResult Run(int max_restarts);

 private:
  // w -= V h, h = V^T w over the first m columns, twice (header); h_ holds the sum of the two
  // projections. Returns ||w|| after.
  double Orthogonalize(int m);
  // Pseudo-random values in [-1/2, 1/2) (fixed seed: repeatable).
  void FillRandom(Eigen::Ref<Vec> x) {
    for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = double(rng_() >> 11) * 0x1.0p-53 - 0.5;
  }
  // Column m of V: w / beta, or, when the remainder vanished, a random vector orthogonal to the
  // first m columns.
  void SetNextColumn(int m, double beta, bool lost);
  // Ritz pairs of T's leading m x m block, ordered by |theta| descending.
  void Ritz(int m, Vec& theta, Mat& S) const;

  const SymmetricOperator& op_;
  const Eigen::Index n_;
  const int nev_, mmax_;
  const double tol_;
  Mat V_, T_;   // basis (n x mmax), projection V^T A V (mmax x mmax)
  Vec w_;       // the image of the newest column, then the remainder
  Vec h_, h2_;  // projections on the basis
  std::mt19937_64 rng_;
};

double ThickRestart::Orthogonalize(int m) {
  const auto V = V_.leftCols(m);
  auto h = h_.head(m);
  auto h2 = h2_.head(m);
  h.noalias() = V.transpose() * w_;
  h2.setZero();
  for (Eigen::Index r0 = 0; r0 < n_; r0 += kRowChunk) {
    const Eigen::Index rows = std::min(kRowChunk, n_ - r0);
    const auto Vc = V_.block(r0, 0, rows, m);
    auto wc = w_.segment(r0, rows);
    wc.noalias() -= Vc * h;
    h2.noalias() += Vc.transpose() * wc;
  }
  double norm = w_.norm();
  if (h2.cwiseAbs().maxCoeff() > std::numeric_limits<double>::epsilon() * norm) {
    w_.noalias() -= V * h2;
    h += h2;
    norm = w_.norm();
  }
  return norm;
}

void ThickRestart::SetNextColumn(int m, double beta, bool lost) {
  if (!lost) {
    V_.col(m) = w_ / beta;
    return;
  }
  FillRandom(w_);
  const double norm = Orthogonalize(m);
  V_.col(m) = w_ / norm;
}

void ThickRestart::Ritz(int m, Vec& theta, Mat& S) const {
  const Eigen::SelfAdjointEigenSolver<Mat> es(T_.topLeftCorner(m, m));
  std::vector<int> order(m);
  std::iota(order.begin(), order.end(), 0);
  const Vec& ev = es.eigenvalues();
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(ev(a)) > std::abs(ev(b)); });
  theta.resize(m);
  S.resize(m, m);
  for (int i = 0; i < m; ++i) {
    theta(i) = ev(order[i]);
    S.col(i) = es.eigenvectors().col(order[i]);
  }
}

ThickRestartResult ThickRestart::Run(int max_restarts) {
  ThickRestartResult r;
  const double eps = std::numeric_limits<double>::epsilon();
  const double eps23 = std::pow(eps, 2.0 / 3.0);
  FillRandom(V_.col(0));
  V_.col(0).normalize();
  Vec theta;
  Mat S, chunk;
  int m = 0;  // columns whose image is projected; column m is the next one
  while (true) {
    op_(V_.col(m).data(), w_.data());
    ++r.operations;
    const double image = w_.norm();
    const double beta_raw = Orthogonalize(m + 1);
    T_.block(0, m, m + 1, 1) = h_.head(m + 1);
    T_.block(m, 0, 1, m + 1) = h_.head(m + 1).transpose();
    ++m;
    // A remainder at the rounding of the image: the basis spans an invariant subspace
    const bool lost = !(beta_raw > eps * std::sqrt(double(n_)) * image);
    const double beta = lost ? 0.0 : beta_raw;
    if (m == mmax_ || m == n_) {
      // The basis is full: the Ritz pairs and their residuals
      Ritz(m, theta, S);
      int converged = 0;
      for (int i = 0; i < nev_; ++i)
        if (beta * std::abs(S(m - 1, i)) <= tol_ * std::max(eps23, std::abs(theta(i)))) ++converged;
      if (converged == nev_ || r.restarts == max_restarts || m == n_) {
        r.converged = converged == nev_ || m == n_;
        r.theta = theta.head(nev_);
        r.vectors.noalias() = V_.leftCols(m) * S.leftCols(nev_);
        return r;
      }
      // Thick restart from the k best Ritz vectors, combined in place row chunk by row chunk
      const int k = std::min(nev_ + std::min(converged, (mmax_ - nev_) / 2), m - 1);
      const Mat Sk = S.leftCols(k);
      for (Eigen::Index r0 = 0; r0 < n_; r0 += kRowChunk) {
        const Eigen::Index rows = std::min(kRowChunk, n_ - r0);
        chunk.noalias() = V_.block(r0, 0, rows, m) * Sk;
        V_.block(r0, 0, rows, k) = chunk;
      }
      T_.topLeftCorner(m, m).setZero();
      T_.topLeftCorner(k, k).diagonal() = theta.head(k);
      m = k;
      ++r.restarts;
    }
    SetNextColumn(m, beta, lost);
  }
}

}  // namespace

ThickRestartResult SolveThickRestartLanczos(const SymmetricOperator& op, Eigen::Index n, int nev,
                                            const ThickRestartOptions& options) {
  if (nev < 1 || nev >= n)
    throw std::invalid_argument("SolveThickRestartLanczos: need 1 <= nev < n, got nev = " +
                                std::to_string(nev) + ", n = " + std::to_string(n));
  const Eigen::Index wanted =
      options.max_basis > 0 ? options.max_basis : std::max(2 * nev + 1, nev + 20);
  const int max_basis = static_cast<int>(std::min(wanted, n));
  if (max_basis <= nev)
    throw std::invalid_argument("SolveThickRestartLanczos: the basis (" +
                                std::to_string(max_basis) +
                                " columns) must exceed nev = " + std::to_string(nev));
  ThickRestart solver(op, n, nev, max_basis, options.tolerance);
  return solver.Run(options.max_restarts);
}

}  // namespace orrery::flex

#pragma once
// Shifted block Lanczos: the eigenvalues of K x = lambda M x nearest a shift sigma, through a
// factorization of K - sigma M that is applied to a block of vectors at once.
//
// Method (the spectral transformation of Ericsson & Ruhe, Math. Comp. 35 (1980) 1251-1268; the
// shifted block Lanczos of Grimes, Lewis & Simon, SIAM J. Matrix Anal. Appl. 15 (1994) 228-272,
// here with full reorthogonalization; thick restart as Wu & Simon, SIAM J. Matrix Anal. Appl. 22
// (2000) 602-616):
//   Op = (K - sigma M)^-1 M is self-adjoint in the M inner product, with eigenvalues
//   theta = 1 / (lambda - sigma): the lambda nearest sigma have the largest |theta|.
//   A basis V (n x m, V^T M V = I) grows by a block P of b columns per step: W = Op P is one
//   solve with b right-hand sides (a supernodal solve of 8 columns costs about 2.5 single ones,
//   cholmod_factor.h), W is M-orthogonalized against V twice (classical Gram-Schmidt), giving the
//   projection T = V^T M Op V (m x m, symmetric) column block by column block, and W = Q R with
//   Q^T M Q = I (SVQB, Stathopoulos & Wu, SIAM J. Sci. Comput. 23 (2002) 2165-2182; directions
//   W has lost are replaced by random ones). The Ritz pairs (theta_i, y_i = V s_i) of T have the
//   residual ||Op y_i - theta_i y_i||_M = ||R s_i(last block)||, since Op V = V T + Q R E^T.
//   Converged when the residual of each of the nev pairs of largest |theta| is at most
//   tolerance * max(eps^(2/3), |theta|) (Spectra's test). When the basis is full it restarts
//   from the nev + b best Ritz vectors and the pending block (their residuals lie in it).
// Start: a block of pseudo-random vectors from a fixed seed (std::mt19937_64), so a run is
// repeatable to the last bit.
// Memory: the basis V (n x max_basis), three n x b blocks, the solver's own workspace.
//
// Usage (fe_modes.cpp):
//   BlockLanczosResult r = SolveBlockLanczos(
//       [&](const double* B, double* X, int k) { chol.solve(B, X, k); }, M_upper, 30, {});
//   lambda_i = sigma + 1 / r.theta(i);   x_i = r.vectors.col(i)
#include <functional>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace orrery::flex {

struct BlockLanczosOptions {
  int block_size = 0;        // b; 0: 8 (at most n)
  int max_basis = 0;         // columns of V before a restart; 0: max(2 nev + 2 b, nev + 6 b), at most n
  double tolerance = 1e-10;  // relative residual of the Ritz pairs (see above)
  int max_restarts = 200;
};

// Filled by SolveBlockLanczos.
struct BlockLanczosResult {
  Eigen::VectorXd theta;    // (nev) eigenvalues of Op, largest |theta| first
  Eigen::MatrixXd vectors;  // (n x nev) M-orthonormal eigenvectors, in theta's order
  int restarts = 0;
  int block_solves = 0;     // calls of the solve
  int columns = 0;          // right-hand sides solved in all
  bool converged = false;
};

// X = (K - sigma M)^-1 B for k right-hand sides (B, X: n x k, column-major, leading dimension n).
using BlockSolve = std::function<void(const double* B, double* X, int k)>;

// The nev eigenpairs of Op of largest |theta|. M: n x n symmetric positive definite, only its
// upper triangle is read (a matrix holding both triangles works as well). Throws
// std::invalid_argument unless 1 <= nev < n. On no convergence after max_restarts the result
// holds the current Ritz pairs with converged = false.
BlockLanczosResult SolveBlockLanczos(const BlockSolve& solve, const Eigen::SparseMatrix<double>& M, int nev,
                                     const BlockLanczosOptions& options);

}  // namespace orrery::flex

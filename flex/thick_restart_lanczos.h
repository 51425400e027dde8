#pragma once
// Thick-restart Lanczos for the largest eigenvalues of a symmetric operator A in the Euclidean
// inner product: the standard form L^-1 P M P^T L^-T of the shift-invert operator over a Cholesky
// factor (fe_modes.cpp), whose Lanczos basis needs no M products.
//
// Method (Wu & Simon, SIAM J. Matrix Anal. Appl. 22 (2000) 602-616, with full
// reorthogonalization):
//   The basis V (n x m, V^T V = I) grows by one column per operator application, w = A v_j. Its
//   projection on the basis, h = V^T w, is T's column j (T = V^T A V, symmetric), and the
//   remainder w - V h becomes the next column. Classical Gram-Schmidt is applied twice ("twice is
//   enough": Giraud, Langou & Rozloznik, Comput. Math. Appl. 50 (2005) 1069-1075): the second
//   projection h2 = V^T (w - V h) is formed row chunk by row chunk together with the first update,
//   while the chunk of V is in cache, and its update is skipped when max |h2| <= eps ||w - V h||
//   (the orthogonality test of Spectra's Lanczos). Two or three passes over V per column.
//   Only the last column couples to the remainder f = beta v_m (A V = V T + f e_m^T), so a Ritz
//   pair (theta_i, V s_i) of T has the residual beta |s_i(m)|. It is converged when that is at most
//   tolerance * max(eps^(2/3), |theta_i|) (Spectra's and ARPACK's test). The test runs when the
//   basis is full, as in Spectra and ARPACK: a Krylov space of one start vector holds one vector of
//   each eigenspace, and the second of a double eigenvalue (an 18-tooth gear's modes come in
//   pairs) enters only through rounding, which needs the steps; tested after every column, a
//   cantilever of square section converged without the second bending mode of a pair.
//   When it is not converged, it restarts from the k Ritz vectors of largest |theta| (V <- V S_k,
//   T <- diag(theta_k)) and the remainder f / beta as column k; k = nev + min(converged,
//   (max_basis - nev) / 2) (ARPACK's choice, also Spectra's). Column k's projection then gives the
//   Ritz vectors' coupling beta s_i(m) to it.
// Start: pseudo-random values from a fixed seed (std::mt19937_64), so a run repeats to the bit.
// A remainder that vanishes (an invariant subspace) is replaced by a random vector orthogonal to V,
// with no coupling.
// Memory: V (n x max_basis) and two vectors of n.
//
// Usage (fe_modes.cpp):
//   ThickRestartResult r = SolveThickRestartLanczos(apply_A, n, 30, {});
//   r.theta(i), r.vectors.col(i): largest |theta| first.
#include <functional>

#include <Eigen/Core>

namespace orrery::flex {

struct ThickRestartOptions {
  int max_basis = 0;  // columns of V before a restart; 0: max(2 nev + 1, nev + 20), at most n
  double tolerance = 1e-10;  // relative residual of the Ritz pairs (above)
  int max_restarts = 1000;
};

// Filled by SolveThickRestartLanczos.
struct ThickRestartResult {
  Eigen::VectorXd theta;    // (nev) eigenvalues of A, largest |theta| first
  Eigen::MatrixXd vectors;  // (n x nev) orthonormal eigenvectors, in theta's order
  int restarts = 0;
  int operations = 0;  // applications of A
  bool converged = false;
};

// y = A x for vectors of n entries (x and y do not overlap).
using SymmetricOperator = std::function<void(const double* x, double* y)>;

// The nev eigenpairs of A of largest |theta|. Throws std::invalid_argument unless
// 1 <= nev < n. On no convergence after max_restarts the result holds the current Ritz pairs with
// converged = false.
ThickRestartResult SolveThickRestartLanczos(const SymmetricOperator& op, Eigen::Index n, int nev,
                                            const ThickRestartOptions& options);

}  // namespace orrery::flex

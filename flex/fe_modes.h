#pragma once
// Lowest natural modes of an FE model: K phi = w^2 M phi, for the lowest N eigenvalues.
//
// Method: shift-invert (Ericsson & Ruhe 1980): eigenvalues nu = 1 / (w^2 - sigma) of
// (K - sigma M)^-1 M, through one sparse factorization of K - sigma M (ShiftedFactor,
// sparse_ldlt_shift_invert.h: CHOLMOD's supernodal Cholesky, or a sparse LDL^T where that matrix
// is not positive definite), by
//   - a Lanczos with one solve per vector: with a Cholesky factor S = K - sigma M = P^T L L^T P
//     on the symmetric standard form L^-1 P M P^T L^-T (Euclidean inner products: one M product
//     per vector instead of 4 to 6 for the M-inner products of the generalized form), the
//     eigenvectors mapped back by x = P^T L^-T y, by the thick-restart Lanczos of
//     thick_restart_lanczos.h (default: two or three passes over the basis per vector against
//     three to five in Spectra's, the same number of vectors) or Spectra's implicitly restarted
//     Lanczos; with an LDL^T factor by Spectra's on the generalized form
//     (SymGEigsShiftSolver, M-inner products);
//   - or the shifted block Lanczos of block_lanczos.h (FeModesOptions::solver): a block of b
//     right-hand sides per solve (8 cost about 2.5 single solves on a 91k-DOF hex20 block), but
//     it needs 2 to 3 times the vectors for 30 modes (clamped hex20 block 91k DOF: 224 against
//     110; 37k-DOF planet held at its bore: 534 against 178), so it is no faster there and slower
//     on clustered spectra (docs/performance.md, FE rows). Its Ritz vectors are purified (one more
//     solve, Rayleigh-Ritz) before they are returned.
// The default shift is negative,
//   sigma = -1e-6 * trace(K) / trace(M),
// i.e. a millionth of the mesh's mean diagonal ratio (about its highest eigenvalue), so
// K - sigma M is positive definite also for a free-free mesh (6 zero eigenvalues) with a
// condition number near 1e6, and the zero eigenvalues are found first (nu = 1 / |sigma|).
// Fixed DOFs are eliminated (rows and columns removed) before the solve; only the upper
// triangles of K - sigma M and M are formed for the free DOFs (K - sigma M only while it is
// factorized), so the memory is that of the factor, M and the Krylov basis.
// Rigid-body modes: eigenvalues with |w^2| <= rigid_body_tolerance * max(largest computed |w^2|,
// |sigma|) are reported as exactly 0 (their computed values are rounding noise of order
// eps * cond * |sigma|); with the default tolerance 1e-6 a structure whose first flexible mode is
// below 1e-3 times the highest requested frequency would be misread, so ask for enough modes.
// Check: no eigenvalue below the shift was skipped (a Cholesky factorization succeeding proves
// it; the LDL^T fallback counts them by its inertia).
// Mode shapes are M-normalized; their signs are the solver's (arbitrary, but repeatable).
//
// Usage:
//   FeSystem sys = AssembleFeSystem(mesh);
//   FeModes modes = CalcFeModes(sys, NodeDofs(mesh.NodeSet("FIXED")), {.num_modes = 20});
//   modes.frequencies_hz[0];
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "flex/fe_assembly.h"
#include "flex/sparse_ldlt_shift_invert.h"

namespace orrery::flex {

enum class EigenSolver {
  kThickRestart,  // thick_restart_lanczos.h, standard form (default); no Cholesky: Spectra's
  kSpectra,       // Spectra's Lanczos: standard form over a Cholesky factor, else generalized
  kBlockLanczos,  // block_lanczos.h, Ritz vectors purified (measured slower, see below)
};

struct FeModesOptions {
  int num_modes = 10;
  double shift = 0;                    // (rad/s)^2; used when use_shift is set
  bool use_shift = false;              // false: the default negative shift above
  double tolerance = 1e-10;            // relative residual of the Ritz pairs (every solver's test)
  int max_iterations = 1000;           // restarts
  // Block Lanczos: basis columns before a restart (0: BlockLanczosOptions' default);
  // thick restart and Spectra: the basis (Spectra's ncv; 0: max(2 N + 1, N + 20)); at most n.
  int lanczos_vectors = 0;
  int block_size = 0;                  // block Lanczos; 0: BlockLanczosOptions' default (8)
  EigenSolver solver = EigenSolver::kThickRestart;
  double rigid_body_tolerance = 1e-6;  // see above
};

// Filled by CalcFeModes / SolveLowestModes.
struct FeModes {
  Eigen::VectorXd eigenvalues;         // (N) w^2 in (rad/s)^2, ascending; rigid-body modes 0
  std::vector<double> frequencies_hz;  // (N) w / 2 pi, rigid-body modes 0
  Eigen::MatrixXd shapes;              // (ndof x N) M-normalized; zero rows at fixed DOFs
  std::vector<int> free_dofs;          // DOFs of the reduced problem (CalcFeModes)
  int num_rigid_body_modes = 0;
  double shift = 0;                    // (rad/s)^2
  int iterations = 0;                  // restarts
  int operations = 0;                  // right-hand sides solved (operator applications)
  int block_solves = 0;                // solves (each of up to block_size right-hand sides)
  long factor_nonzeros = 0;            // nonzeros of L
  double factorize_seconds = 0, solve_seconds = 0;
};

// Modes of K x = lambda M x (both symmetric, M positive definite; only their upper triangles are
// read, rows sorted in each column). Throws std::invalid_argument if N < 1 or N >= n,
// std::runtime_error if the factorization fails or Lanczos does not converge.
FeModes SolveLowestModes(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                         const FeModesOptions& options);

// The same through a factorization of K - sigma M made by the caller (sigma = factor.shift();
// options.shift and use_shift are not used), e.g. the Craig-Bampton reduction's factor of K_ii
// at sigma = 0, which also gives its constraint modes. Does not check for eigenvalues below the
// shift (factor.num_eigenvalues_below_shift() tells).
FeModes SolveLowestModes(const ShiftedFactor& factor, const Eigen::SparseMatrix<double>& M,
                         const FeModesOptions& options);

// Modes of an assembled system with `fixed_dofs` (any order, duplicates allowed) held at zero.
FeModes CalcFeModes(const FeSystem& system, std::span<const int> fixed_dofs, const FeModesOptions& options);
// The same, releasing the system's K and M once the free-DOF matrices are made, and at the default
// shift K - sigma M once CHOLMOD has its permuted copy (peak memory, during the numeric
// factorization: the factor, that copy, the free-DOF upper triangle of M and CHOLMOD's workspace;
// `orrery fe-modes` uses it).
FeModes CalcFeModes(FeSystem&& system, std::span<const int> fixed_dofs, const FeModesOptions& options);

// The rows and columns of the free DOFs (map[d] = new index, -1 for a removed DOF; ascending
// among the kept) of a symmetric matrix, upper triangle only. A: compressed, rows sorted.
Eigen::SparseMatrix<double> RestrictUpper(const Eigen::SparseMatrix<double>& A, const std::vector<int>& map);

// Frequency (Hz) of an eigenvalue w^2: sign(w^2) sqrt(|w^2|) / 2 pi.
double EigenvalueToHz(double w2);

}  // namespace orrery::flex

#pragma once
// Lowest natural modes of an FE model: K phi = w^2 M phi, for the lowest N eigenvalues.
//
// Method: Spectra's SymGEigsShiftSolver in shift-invert mode (implicitly restarted Lanczos on
// (K - sigma M)^-1 M, eigenvalues nu = 1 / (w^2 - sigma)) with SparseLdltShiftInvert
// (CHOLMOD's supernodal Cholesky of K - sigma M, or a sparse LDL^T where that matrix is not
// positive definite). The default shift is negative,
//   sigma = -1e-6 * trace(K) / trace(M),
// i.e. a millionth of the mesh's mean diagonal ratio (about its highest eigenvalue), so
// K - sigma M is positive definite also for a free-free mesh (6 zero eigenvalues) with a
// condition number near 1e6, and the zero eigenvalues are found first (nu = 1 / |sigma|).
// Fixed DOFs are eliminated (rows and columns removed) before the solve.
// Rigid-body modes: eigenvalues with |w^2| <= rigid_body_tolerance * max(largest computed |w^2|,
// |sigma|) are reported as exactly 0 (their computed values are rounding noise of order
// eps * cond * |sigma|); with the default tolerance 1e-6 a structure whose first flexible mode is
// below 1e-3 times the highest requested frequency would be misread, so ask for enough modes.
// Check: no eigenvalue below the shift was skipped (a Cholesky factorization succeeding proves
// it; the LDL^T fallback counts them by its inertia).
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

namespace orrery::flex {

struct FeModesOptions {
  int num_modes = 10;
  double shift = 0;                    // (rad/s)^2; used when use_shift is set
  bool use_shift = false;              // false: the default negative shift above
  double tolerance = 1e-10;            // Spectra's relative tolerance on the Ritz values
  int max_iterations = 1000;           // Lanczos restarts
  int lanczos_vectors = 0;             // Spectra's ncv; 0: max(2 N + 1, N + 20), at most n
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
  int iterations = 0, operations = 0;  // Spectra's restarts and operator applications
  long factor_nonzeros = 0;            // nonzeros of L
  double factorize_seconds = 0, solve_seconds = 0;
};

// Modes of K x = lambda M x (both symmetric, M positive definite). Throws std::invalid_argument
// if N < 1 or N >= n, std::runtime_error if the factorization fails or Lanczos does not converge.
FeModes SolveLowestModes(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                         const FeModesOptions& options);

// Modes of an assembled system with `fixed_dofs` (any order, duplicates allowed) held at zero.
FeModes CalcFeModes(const FeSystem& system, std::span<const int> fixed_dofs, const FeModesOptions& options);

// Frequency (Hz) of an eigenvalue w^2: sign(w^2) sqrt(|w^2|) / 2 pi.
double EigenvalueToHz(double w2);

}  // namespace orrery::flex

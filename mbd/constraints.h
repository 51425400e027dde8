#pragma once
// Loop-closure and driver constraints, Phi(q, t) = 0 with velocity Jacobian G (seed 003 eq. 4),
// and the assembly of a consistent initial state.
#include <string>

#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {

// Fills data.phi (n_holonomic), data.G (n_constraints x nv), data.g_t (n_constraints), and the
// per-row spatial partials c_rows_a/b, at time t. Needs CalcPositionKinematics. The velocity
// constraint is G v + g_t = 0; for holonomic rows it is the time derivative of Phi.
void CalcConstraints(const Model& model, double t, Data& data);

// Spatial force on each body from the constraint multipliers lambda (n_constraints): the
// loop-closure rows act on bodies as -c lambda (world origin), added into `f` (nbodies).
// Driver rows act on joint coordinates (their effort is -lambda) and are not included.
void AddConstraintBodyForces(const Model& model, const Data& data,
                             const Eigen::Ref<const Eigen::VectorXd>& lambda,
                             std::vector<Vec6>& f);

// out += G^T lambda (the constraint forces on the coordinates, G: n_constraints x nv). One row (a
// speed driver): out_k + lambda_0 G_0k, the numbers of Eigen's product to the last bit (its
// row-major kernel forms the single product, scales it by 1 and adds it) without its dispatch,
// about 800 instructions a call against 36 multiply-adds on seed 002.
void AddConstraintForces(const Eigen::MatrixXd& G, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                         Eigen::Ref<Eigen::VectorXd> out);

// Brings a state onto the constraint manifold: Gauss-Newton on Phi(q, t) = 0 with minimum-norm
// steps, then projects v onto G v + g_t = 0. Throws std::runtime_error with the constraint names
// when the constraints are redundant (rank-deficient G) or the assembly does not converge.
void AssembleState(const Model& model, State& state, Data& data, double tolerance = 1e-12);

// Constraint-row name for messages and output ("loop 'name' row k", "driver 'name'").
std::string ConstraintRowName(const Model& model, int row);

// The constraint rows that a singular (or nearly singular) constraint Jacobian G (nc x nv) makes
// dependent, for messages: G^T y = 0 for the right singular vector y of G's smallest singular
// value s_min, and the rows named are those with |y_i| >= 0.1 |y|_inf, joined with " and ", then
// "; s_min / s_max = ...". Empty when s_min > relative_threshold s_max (or G has no rows). Where
// it matters: a mechanism at a singular position (a four-bar with its links in line) loses a
// rank of G, and the multipliers of those rows are unbounded. Allocates (an error path only).
std::string DependentConstraintRows(const Model& model, const Eigen::MatrixXd& G, double relative_threshold);

}  // namespace orrery

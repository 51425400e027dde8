#pragma once
// Time integrators of the constrained equations of motion.
//
// Two choices, measured scene by scene:
// - IDA (SUNDIALS): variable-order BDF with adaptive steps on the stabilized index-2 (GGL) DAE
//   of dae.h; multipliers algebraic and excluded from the error test, with their own absolute
//   tolerance; consistent initial values by IDACalcIC; assembled dense Jacobian.
// - Generalized-alpha (Chung & Hulbert 1993; Arnold & Bruls 2007 for constrained systems): fixed
//   step, index-3 position constraints and velocity constraints solved at every step, numerical
//   dissipation set by the spectral radius at infinity rho_inf (rho_inf = 1: none). With
//   alpha_m = alpha_f = 0 it is Newmark's method (beta, gamma).
//
// Usage:
//   IntegratorOptions opt;  opt.kind = IntegratorKind::kIda;  opt.rtol = 1e-6;
//   std::unique_ptr<Integrator> integ = MakeIntegrator(*model, opt);
//   integ->Initialize(State::Initial(*model));
//   integ->AdvanceTo(0.01);   // then integ->state(), vdot(), lambda()
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {

enum class IntegratorKind { kIda, kGeneralizedAlpha };

struct IntegratorOptions {
  IntegratorKind kind = IntegratorKind::kIda;
  // IDA
  double rtol = 1e-6;             // relative tolerance on q and v
  double atol = 1e-8;             // absolute tolerance on q and v (m, rad, m/s, rad/s)
  // Absolute tolerance on lambda and mu (N, N m; mu has the units of v). Both are index-2
  // variables excluded from the error test, so this only enters the Newton convergence test,
  // where their corrections grow like 1/h at small steps: with 1e-3, IDA could not start a free
  // four-bar at rtol <= 1e-8 (the corrector failed at t = 0 with h -> 1e-17), nor a driven one at
  // rtol 1e-11; with 1e3 both run down to rtol 1e-12. The constraints stay satisfied to the
  // Newton tolerance of q and v, and the multipliers converge with the velocities.
  double atol_multiplier = 1e3;
  double max_step = 0;            // s, 0: unlimited
  double initial_step = 0;        // s, 0: IDA's choice
  long max_steps_per_output = 100000;
  int max_order = 5;
  // Generalized-alpha
  double step = 1e-3;             // s, fixed step
  double rho_inf = 0.9;           // spectral radius at infinite frequency, in [0, 1]
  // Explicit parameters override rho_inf when all are finite (Newmark: 0, 0, 1/4, 1/2).
  double alpha_m = std::numeric_limits<double>::quiet_NaN();
  double alpha_f = std::numeric_limits<double>::quiet_NaN();
  double beta = std::numeric_limits<double>::quiet_NaN();
  double gamma = std::numeric_limits<double>::quiet_NaN();
  int max_newton_iterations = 25;
  // Relative Newton tolerance: on the scaled residual against the largest force of the balance,
  // and on the acceleration increment against the accelerations. 1e-8 sits far below the
  // method's O(h^2) error and above the rounding floor of stiff drivetrains (1e-10 stalled on
  // seed 001's 1e10 N m/rad brakes, whose accelerations reach 1e5 rad/s^2).
  double newton_tolerance = 1e-8;
  // A step whose Newton iteration fails is taken again as two halves, and so on down to
  // step / 2^max_step_halvings (contact coming on within a step); 0: fail at once. The halves
  // count as steps, their failures as newton_failures.
  int max_step_halvings = 4;
  // The iteration matrix is refreshed when an iteration with the old one contracts the
  // increment by less than this factor. A refresh takes finite differences of the pipeline
  // (about 2 nv evaluations) except for elements with analytic tangents (tooth contact,
  // external_force.h), which are evaluated once: with contact on every mesh of a planetary
  // stage 0.1 is best with the contraction estimate (newton_estimate), rigid or with a 24-mode
  // flexible planet; the rigid stage with measured ends and Broyden updates 0.01 (measured in
  // the seed 003 scenes; docs/performance.md).
  double matrix_refresh_rate = 0.1;
  // Whether an increment may end a step's Newton iteration on the contraction estimate (Hairer &
  // Wanner IV.8; GeneralizedAlpha::IncrementEnds) instead of a measured residual. The estimate
  // assumes a steady contraction rate; tooth contact's residual jumps where a contact point
  // changes faces or comes on (faceted flanks), so there it accepts iterates above the
  // tolerance (docs/performance.md, perf-newton2 section). false: every step ends on a measured
  // residual (or an increment at the tolerance), and the kept matrix's inverse takes Broyden
  // rank-1 updates within the step (Dennis & Schnabel 1983, Sec. 8.1/8.3) to need fewer.
  bool newton_estimate = true;
  // Both: threads for the external force elements of one evaluation (tooth contacts; Data::
  // threads, force_elements.h). 0: OMP_NUM_THREADS if set, else 1 (ResolveThreads).
  int threads = 0;
};

// The thread count of IntegratorOptions::threads: `requested` if >= 1; for 0 the environment's
// OMP_NUM_THREADS if it is a number >= 1, else 1. Throws std::invalid_argument for a negative
// count or an OMP_NUM_THREADS that is not a positive number.
int ResolveThreads(int requested);

struct IntegratorStats {
  long steps = 0;
  long residual_evaluations = 0;
  long jacobian_evaluations = 0;
  long newton_iterations = 0;
  long newton_failures = 0;
  long newton_backtracks = 0;  // generalized-alpha: increments halved where the residual grew
  long error_test_failures = 0;
  int last_order = 0;
  double last_step = 0;
  double max_abs_phi = 0;     // max |Phi| seen at output points
  double max_abs_phidot = 0;  // max |G v + g_t| seen at output points
};

class Integrator;

// Dense output: told of every step an integrator accepts, so it can sample the solution inside
// the step (Integrator::Interpolate) at times of its own choosing, such as the fixed internal rate
// of the sensors (sensor_sampler.h). Called from inside AdvanceTo().
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  // The integrator accepted a step from t_begin to t_end (t_end may lie beyond the t_out of the
  // AdvanceTo() call: IDA steps past its output times and interpolates back).
  virtual void OnStep(Integrator& integrator, double t_begin, double t_end) = 0;
};

class Integrator {
 public:
  // Called after every accepted step with the time and state the integrator reached (its own
  // steps: IDA's internal steps, generalized-alpha's steps and halves; not interpolated
  // outputs). It may throw to stop the run (an interrupt, a health check that found the result
  // meaningless); AdvanceTo passes the exception on, never as a failed step. It runs inside the
  // step loop, so it must not allocate.
  using StepCallback = std::function<void(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                                          const Eigen::Ref<const Eigen::VectorXd>& v)>;

  virtual ~Integrator() = default;
  // Starts from `state`: assembles it onto the constraints, computes consistent accelerations
  // and multipliers. Throws std::runtime_error with the reason if it cannot.
  virtual void Initialize(const State& state) = 0;
  // Integrates up to t_out exactly. Throws std::runtime_error with the solver's reason (and the
  // time reached) on failure.
  virtual void AdvanceTo(double t_out) = 0;
  virtual const State& state() const = 0;
  virtual const Eigen::VectorXd& vdot() const = 0;     // nv, at state().t
  virtual const Eigen::VectorXd& lambda() const = 0;   // n_constraints, at state().t
  virtual IntegratorStats stats() const = 0;
  virtual std::string name() const = 0;
  // The Data of the integrator's last pipeline evaluation (a Newton iterate or IDA residual
  // near state(), not necessarily at it: the generalized-alpha step ends without evaluating its
  // accepted iterate). Read-only: the recorder warms its own element workspaces from it
  // (WarmStartExternalWorkspaces); nothing may rely on its values being those at state().
  virtual const Data& data() const = 0;
  // data() when its last evaluation (EvaluateDynamics) was at exactly (state().t, state().q,
  // state().v, vdot()) and nothing has written to it since, so that it holds every field of the
  // pipeline at the state (the recorder's row and the health read it instead of evaluating
  // again; the same arguments give the same numbers to the last bit). nullptr otherwise, and
  // always with constraints (the velocity projection moves v after the last evaluation).
  virtual const Data* DataAtState() const { return nullptr; }
  // Data whose position kinematics and constraints (CalcPositionKinematics and CalcConstraints:
  // q_normalized, the poses, S, I_W, phi, G, g_t) were computed at exactly (state().t,
  // state().q) and not written since, so that they are what those functions give there to the
  // last bit (the per-step health reads the gear frames' poses from it instead of computing them
  // again). nullptr otherwise. Valid until the next call that moves the integrator.
  virtual const Data* PositionKinematicsAtState() const { return DataAtState(); }

  // The solution at t inside the last accepted step [t_begin, t_end] (of the last OnStep):
  // q (nq), v (nv), vdot (nv). IDA: its interpolating polynomial (IDAGetDky, orders 0 and 1).
  // Generalized-alpha: cubic Hermite interpolation between the step's ends, v from (v, vdot) at
  // both ends (vdot its derivative), q as q_n (+) d(s) with d the Hermite cubic in velocity space
  // through 0 and the step's increment with end slopes h v_n and h v_{n+1}; exact at the ends.
  // Allocation-free.
  virtual void Interpolate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v,
                           Eigen::Ref<Eigen::VectorXd> vdot) = 0;
  // Observer of accepted steps (not owned; nullptr: none).
  void set_step_observer(StepObserver* observer) { observer_ = observer; }

  // Replaces the step callback (empty: none).
  virtual void SetStepCallback(StepCallback callback) = 0;

 protected:
  StepObserver* observer_ = nullptr;
};

std::unique_ptr<Integrator> MakeIntegrator(const Model& model, const IntegratorOptions& options);

}  // namespace orrery

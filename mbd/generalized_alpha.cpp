// Fixed-step generalized-alpha for constrained multibody systems.
//
// Chung & Hulbert (1993) parameters from the spectral radius rho_inf:
//   alpha_m = (2 rho - 1)/(rho + 1), alpha_f = rho/(rho + 1), gamma = 1/2 + alpha_f - alpha_m,
//   beta = (gamma + 1/2)^2 / 4.
// Arnold & Bruls (2007) form: the pseudo-acceleration a obeys
//   (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) vdot_{n+1} + alpha_f vdot_n,
//   v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1},
//   q_{n+1} = q_n (+) [h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}],
// with the equations of motion, Phi(q_{n+1}) = 0 and G v_{n+1} + g_t = 0 enforced at t_{n+1}: the
// stabilized index-2 form of Arnold, Cardona & Bruls (2016, "A Lie algebra approach to Lie group
// time integration of constrained systems"; the GGL idea of Gear, Gupta & Leimkuhler 1985), where
// the position update takes a second multiplier mu along the constraint normals,
//   q_{n+1} = q_n (+) [h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1} + G_h(q_n)^T mu],
// so that both the positions and the velocities of the holonomic rows satisfy their constraints.
// Newton on (vdot_{n+1}, lambda_{n+1}, mu~) with the usual scaling (Arnold & Bruls 2007; Bottasso,
// Bauchau & Cardona 2007): position rows divided by h^2 beta', velocity rows by h gamma', mu = h^2
// beta' mu~, so that the iteration matrix
//   [M + gamma' h C + beta' h^2 K, G^T, beta' h^2 K G_h^T;  G_h, 0, G_h G_h^T;  G, 0, 0]
// does not depend on h as h -> 0 (its condition number stays that of [M G^T; G 0]).
// Why index 2: the index-3 scheme (positions only) leaves the recurrence's velocities off the
// velocity constraint, and for rho_inf = 1 that error mode is undamped: it alternates in sign
// from step to step and drives an alternating acceleration (and multiplier) error that grows
// linearly, fed by the rounding of Phi the Newton test allows. On the slider-crank at h = 1e-6 s
// and rho_inf = 1 the driver effort swung between -17 and +21 N m after 20 ms (1.7 to 2.1 N m
// from IDA); with both levels enforced it follows IDA (tests/mbd/slider_crank_test.cpp).
// After each step the reported velocities are also projected onto G v + g_t = 0 in the metric of
// M (to rounding; the Newton tolerance leaves up to h gamma' tol). The recurrence keeps its own
// velocities (v_alpha_): feeding the projection back into it leaves a inconsistent with v, which
// costs an O(h) error in vdot and lambda instead of O(h^2).
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/LU>

#include "mbd/articulated_solve.h"
#include "mbd/constraints.h"
#include "mbd/dae.h"
#include "mbd/dynamics.h"
#include "mbd/element_names.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"

namespace orrery {
namespace {

// Times a step's Newton iteration may take back half of an increment (Step()).
constexpr int kMaxBacktracks = 6;
// An increment ends the iteration when the residual it leaves is estimated below this fraction
// of the tolerance (IncrementEnds).
constexpr double kEstimateMargin = 0.5;
// Steps an estimate may rely on a carried contraction rate before a step is iterated to a
// measured residual again (Converge).
constexpr long kRateCheckSteps = 8;
constexpr double kRateDecay = 0.9;
// Broyden updates of the iteration matrix's inverse a step may make (SolveIteration); a step's
// iteration rarely takes more increments than this, and one that does starts the updates anew.
constexpr int kMaxBroydenUpdates = 16;

// The size of the position coordinate behind each velocity coordinate (what one ulp of it is
// relative to): |q| for angles, lengths and modal coordinates; 1 for a quaternion's angular
// velocity components (its rotation is held to eps by a unit quaternion). A free joint's lengths
// follow its quaternion in v and in q alike, in the same order.
void CoordinateSizes(const Model& model, const Eigen::VectorXd& q, Eigen::VectorXd* size) {
  for (const Joint& j : model.joints) {
    const JointTypeInfo& info = JointInfo(j.spec.type);
    int q_length = 0;  // the next length coordinate among q's
    for (int k = 0; k < j.nv; ++k) {
      double s = 1;
      if (j.nq == j.nv) {
        s = std::abs(q(j.q_start + k));
      } else if (info.v_kind[k] == CoordinateKind::kLength) {
        while (q_length < j.nq && info.q_kind[q_length] != CoordinateKind::kLength) ++q_length;
        s = std::abs(q(j.q_start + q_length++));
      }
      (*size)(j.v_start + k) = s;
    }
  }
  for (const FlexibleBody& f : model.flexible_bodies)
    (*size).segment(f.v_start, f.nf) = q.segment(f.q_start, f.nf).cwiseAbs();
}

class GeneralizedAlpha final : public Integrator {
 public:
  GeneralizedAlpha(const Model& model, const IntegratorOptions& options)
      : model_(model), options_(options), dae_(model), inverse_mass_(model) {
    dae_.data().threads = ResolveThreads(options.threads);
    if (!(options.step > 0)) throw std::invalid_argument("generalized-alpha: step must be > 0");
    const bool explicit_params = std::isfinite(options.alpha_m) && std::isfinite(options.alpha_f) &&
                                 std::isfinite(options.beta) && std::isfinite(options.gamma);
    if (explicit_params) {
      am_ = options.alpha_m, af_ = options.alpha_f, beta_ = options.beta, gamma_ = options.gamma;
    } else {
      const double rho = options.rho_inf;
      if (!(rho >= 0 && rho <= 1)) throw std::invalid_argument("generalized-alpha: rho_inf must be in [0, 1]");
      am_ = (2 * rho - 1) / (rho + 1);
      af_ = rho / (rho + 1);
      gamma_ = 0.5 + af_ - am_;
      beta_ = 0.25 * (gamma_ + 0.5) * (gamma_ + 0.5);
    }
    const int nv = model.nv, nc = model.n_constraints, nh = model.n_holonomic;
    const int n = nv + nc + nh;  // unknowns: vdot, lambda, mu~
    vdot_.setZero(nv);
    a_.setZero(nv);
    lambda_.setZero(nc);
    vdot_new_.setZero(nv);
    a_new_.setZero(nv);
    lambda_new_.setZero(nc);
    mu_new_.setZero(nh);
    G_h0_.setZero(nh, nv);
    dq_.setZero(nv);
    Kq_.setZero(nv + nc, nv);
    Cv_.setZero(nv, nv);
    iteration_.setZero(n, n);
    rhs_.setZero(n);
    delta_.setZero(n);
    lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
    broyden_s_.setZero(n, kMaxBroydenUpdates);
    broyden_p_.setZero(n, kMaxBroydenUpdates);
    last_delta_.setZero(n);
    proj_.setZero(nv + nc, nv + nc);
    proj_rhs_.setZero(nv + nc);
    proj_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(nv + nc);
    proj_residual_.setZero(nv + nc);
    proj_y_.setZero(nv, nc);
    proj_schur_.setZero(nc, nc);
    proj_schur_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(nc);
    proj_mu_.setZero(nc);
    proj_tau_.setZero(nv);
    mass_diagonal_.setZero(nv);
    rounding_floor_.setZero(nv);
    coordinate_size_.setZero(nv);
    proj_update_.setZero(nv + nc);
    q_start_.setZero(model.nq);
    v_start_.setZero(nv);
    vdot_start_.setZero(nv);
    dq_step_.setZero(nv);
    dq_interp_.setZero(nv);
  }

  void Initialize(const State& initial) override {
    state_ = initial;
    evaluated_at_iterate_ = false;
    kinematics_at_state_ = false;
    AssembleState(model_, state_, dae_.data());
    dae_.SolveAccelerations(state_.t, state_.q, state_.v, vdot_, lambda_);
    mass_diagonal_ = dae_.data().M.diagonal();
    a_ = vdot_;
    q_new_ = state_.q;
    v_new_ = state_.v;
    v_alpha_ = state_.v;
    StoreConstraintNormals();
    RecordDrift();
  }

  // Steps of equal length between two outputs: n = ceil(span / step - 1e-6) steps of span / n,
  // the last ending on t_out exactly. Outputs on the step grid keep the scene's step (to a
  // relative 1e-15, which reuses the iteration matrix); others shorten every step of the interval
  // alike (to no less than half the step when the interval spans a step or more) instead of
  // leaving a remainder step: a sliver of 1e-12 s scales the position rows by 1/h^2 and
  // Newton stalls on their rounding. Outputs stay true integrator states (no interpolation of
  // the accelerations and multipliers the result file records).
  void AdvanceTo(double t_out) override {
    const double t_start = state_.t, span = t_out - t_start;
    if (span > 0) {
      const double n = std::max(1.0, std::ceil(span / options_.step - 1e-6));
      for (double k = 1; k <= n; ++k) {
        const double t_next = k == n ? t_out : t_start + span * (k / n);
        if (!(t_next > state_.t)) {
          std::ostringstream s;
          s << "generalized-alpha: step " << options_.step << " s is below the resolution of time at t = "
            << state_.t << " s";
          throw std::runtime_error(s.str());
        }
        StepOrHalve(t_next, 0);
      }
    }
    RecordDrift();
  }

  void SetStepCallback(StepCallback callback) override { step_callback_ = std::move(callback); }

  const State& state() const override { return state_; }
  const Eigen::VectorXd& vdot() const override { return vdot_; }
  const Data& data() const override { return dae_.data(); }
  // The last Newton iterate was evaluated and accepted unchanged (no projection without
  // constraints, no quaternion normalization without quaternions).
  const Data* DataAtState() const override {
    const bool at_state =
        evaluated_at_iterate_ && model_.n_constraints == 0 && !model_.has_quaternions;
    return at_state ? &dae_.data() : nullptr;
  }
  // With constraints, the velocity projection left the kinematics at the state (Step).
  const Data* PositionKinematicsAtState() const override {
    return kinematics_at_state_ ? &dae_.data() : DataAtState();
  }
  const Eigen::VectorXd& lambda() const override { return lambda_; }
  std::string name() const override { return "generalized-alpha"; }

  void Interpolate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v,
                   Eigen::Ref<Eigen::VectorXd> vdot) override {
    const double h = h_step_;
    const double s = std::clamp((t - t_start_) / h, 0.0, 1.0);
    // Cubic Hermite basis and its derivative (per unit s).
    const double s2 = s * s, s3 = s2 * s;
    const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = 3 * s2 - 2 * s3, h11 = s3 - s2;
    const double d00 = 6 * s2 - 6 * s, d10 = 3 * s2 - 4 * s + 1, d01 = -d00, d11 = 3 * s2 - 2 * s;
    v = h00 * v_start_ + (h10 * h) * vdot_start_ + h01 * state_.v + (h11 * h) * vdot_;
    vdot = (d00 / h) * v_start_ + d10 * vdot_start_ + (d01 / h) * state_.v + d11 * vdot_;
    // Positions: q_n (+) d(s), d the Hermite cubic through 0 and the increment.
    if (s == 1.0) {
      q = state_.q;
      return;
    }
    dq_interp_ = (h10 * h) * v_start_ + h01 * dq_step_ + (h11 * h) * state_.v;
    q = q_start_;
    IntegratePositions(model_, dq_interp_, q);
  }
  IntegratorStats stats() const override {
    IntegratorStats s = stats_;
    s.residual_evaluations = dae_.residual_evaluations() + pipeline_evaluations_;
    return s;
  }

 private:
  // Predicts a, v, q at t + h from the current unknowns vdot_new_ and mu_new_.
  void UpdateKinematics(double h) {
    a_new_ = ((1 - af_) * vdot_new_ + af_ * vdot_ - am_ * a_) / (1 - am_);
    v_new_ = v_alpha_ + h * (1 - gamma_) * a_ + h * gamma_ * a_new_;
    dq_ = h * v_alpha_ + h * h * (0.5 - beta_) * a_ + h * h * beta_ * a_new_;
    if (model_.n_holonomic > 0) {
      const double ca = (1 - af_) / (1 - am_);
      dq_.noalias() += (h * h * beta_ * ca) * (G_h0_.transpose() * mu_new_);
    }
    q_new_ = state_.q;
    IntegratePositions(model_, dq_, q_new_);
  }

  // What the largest row of the last residual (rhs_) belongs to: "the equation of motion of
  // joint 'j' coordinate 0 (body 'b')", "the position constraint of loop closure 'c' row 1", ...
  std::string WorstRow() const {
    const int nv = model_.nv, nh = model_.n_holonomic;
    Eigen::Index row = 0;
    if (rhs_.size() == 0 || !rhs_.allFinite()) {
      for (row = 0; row < rhs_.size() && std::isfinite(rhs_(row)); ++row) {
      }
      if (row == rhs_.size()) return "no row";
    } else {
      rhs_.cwiseAbs().maxCoeff(&row);
    }
    const int r = static_cast<int>(row);
    if (r < nv) return "the equation of motion of " + CoordinateName(model_, r);
    if (r < nv + nh) return "the position constraint of " + ConstraintRowName(model_, r - nv);
    return "the velocity constraint of " + ConstraintRowName(model_, r - nv - nh);
  }

  // For a failed step's message: the constraint rows that lose a rank at the step's start (a
  // mechanism reaching a singular position, where the iteration matrix is singular and Newton
  // fails with a non-finite residual), or nothing. The tolerance is loose (1e-4 of the largest
  // singular value): a step that fails near a singular position starts close to it.
  std::string SingularConstraints() {
    if (model_.n_constraints == 0) return "";
    Data& d = dae_.data();
    CalcPositionKinematics(model_, state_.q, d);
    CalcConstraints(model_, state_.t, d);
    const std::string rows = DependentConstraintRows(model_, d.G, 1e-4);
    if (rows.empty()) return "";
    return "; the constraint Jacobian (nearly) loses a rank at the step's start (" + rows +
           "): a singular position of the mechanism (a four-bar's links in line, say)";
  }

  // Size of a Newton increment: the accelerations' and the (equally scaled) position
  // multipliers' (a position still moving along the constraint normals is not converged).
  double Increment() const {
    const int nv = model_.nv, nh = model_.n_holonomic;
    double increment = delta_.head(nv).lpNorm<Eigen::Infinity>();
    if (nh > 0) increment = std::max(increment, delta_.tail(nh).lpNorm<Eigen::Infinity>());
    return increment;
  }

  // G_h at the step's start (state_.q): the directions of the position correction mu.
  void StoreConstraintNormals() {
    if (model_.n_holonomic == 0) return;
    Data& d = dae_.data();
    CalcPositionKinematics(model_, state_.q, d);
    CalcConstraints(model_, state_.t, d);
    G_h0_ = d.G.topRows(model_.n_holonomic);
  }

  // Residual (scaled) at the predicted state into rhs_; returns its max norm. Also sets
  // position_floor_: the rounding level of the scaled position rows, |Phi| ~ eps * (size of the
  // positions), which 1/(h^2 beta') can lift above newton_tolerance at small steps.
  double Residual(double t, double h) {
    const int nv = model_.nv, nh = model_.n_holonomic, nc = model_.n_constraints;
    const double ca = (1 - af_) / (1 - am_);
    Data& d = dae_.data();
    EvaluateDynamics(model_, t, q_new_, v_new_, vdot_new_, d);
    ++pipeline_evaluations_;
    rhs_.head(nv) = d.tau_id;
    if (nc > 0) {
      // Position rows of the holonomic constraints, velocity rows of every constraint
      AddConstraintForces(d.G, lambda_new_, rhs_.head(nv));
      rhs_.segment(nv, nh) = d.phi / (h * h * beta_ * ca);
      auto velocity = rhs_.segment(nv + nh, nc);
      velocity.noalias() = d.G * v_new_;
      velocity += d.g_t;
      velocity /= h * gamma_ * ca;
    }
    if (nh > 0) {  // (only the position rows read it)
      double size = std::max(1.0, q_new_.lpNorm<Eigen::Infinity>());
      for (const Transform& X : d.X_WFrame) size = std::max(size, X.p.lpNorm<Eigen::Infinity>());
      position_floor_ = 64 * std::numeric_limits<double>::epsilon() * size / (h * h * beta_ * ca);
    }
    return rhs_.lpNorm<Eigen::Infinity>();
  }

  // rhs_ against the convergence test: the largest of the rows' max norms, each over its
  // tolerance (tol; the dynamic rows max(tol, rounding_floor_), the position rows max(tol,
  // position_floor_)). <= 1: converged; infinite for a residual with a NaN.
  double ResidualRatio(double tol) const {
    const int nv = model_.nv, nh = model_.n_holonomic, nc = model_.n_constraints;
    double ratio = 0;
    for (int r = 0; r < nv; ++r) {
      const double x = std::abs(rhs_(r)) / std::max(tol, rounding_floor_(r));
      if (std::isnan(x)) return std::numeric_limits<double>::infinity();
      ratio = std::max(ratio, x);
    }
    if (nh > 0) ratio = std::max(ratio, rhs_.segment(nv, nh).lpNorm<Eigen::Infinity>() / std::max(tol, position_floor_));
    if (nc > 0) ratio = std::max(ratio, rhs_.segment(nv + nh, nc).lpNorm<Eigen::Infinity>() / tol);
    return std::isnan(ratio) ? std::numeric_limits<double>::infinity() : ratio;
  }

  // The dynamic rows' rounding floor at the current iterate, from the tangents just made:
  //   floor_r = (eps / 2) sum_j (|K_rj| |q_j| + |C_rj| |v_j|),
  // what row r moves by when every coordinate moves by half its ulp (|q_j|: the size of the
  // position coordinate behind velocity j, CoordinateSizes), the least residual that iterates can
  // be told apart by. Angles of turning gears grow without bound, and a stiff mesh on a ring
  // turned through 12 rad (ulp 1.8e-15 rad) moves a planet's modal rows by about 1e-6 N per ulp:
  // seed 003's flexible stage at newton_tolerance 1e-11 (2.5e-7 N there) stalled Newton at 2 to 4
  // times the tolerance in 104 steps from t = 0.13 s on (the residuals 0.7-1.2e-6 N, this floor
  // 1.0-1.9e-6 N; docs/performance.md, "rounding-floor"). Zero until the first refresh.
  void UpdateRoundingFloor() {
    const int nv = model_.nv;
    CoordinateSizes(model_, q_new_, &coordinate_size_);
    rounding_floor_.setZero();
    for (int j = 0; j < nv; ++j) {
      const double sq = coordinate_size_(j), sv = std::abs(v_new_(j));
      for (int r = 0; r < nv; ++r)
        rounding_floor_(r) += std::abs(Kq_(r, j)) * sq + std::abs(Cv_(r, j)) * sv;
    }
    rounding_floor_ *= 0.5 * std::numeric_limits<double>::epsilon();
  }

  // Iteration matrix at the current iterate (the file's top comment), unknowns (vdot, lambda,
  // mu~), rows (dynamics, positions, velocities).
  void RefreshIterationMatrix(double t, double h) {
    const int nv = model_.nv, nc = model_.n_constraints, nh = model_.n_holonomic;
    const double ca = (1 - af_) / (1 - am_), b = h * h * beta_ * ca;
    dae_.Tangents(t, q_new_, v_new_, vdot_new_, lambda_new_, Kq_, Cv_);
    ++stats_.jacobian_evaluations;
    Data& d = dae_.data();
    mass_diagonal_ = d.M.diagonal();
    UpdateRoundingFloor();
    iteration_.setZero();
    iteration_.topLeftCorner(nv, nv) = d.M + (h * gamma_ * ca) * Cv_ + b * Kq_.topRows(nv);
    if (nc > 0) {
      iteration_.block(0, nv, nv, nc) = d.G.transpose();
      iteration_.block(nv + nh, 0, nc, nv) = d.G;
    }
    if (nh > 0) {
      iteration_.block(0, nv + nc, nv, nh).noalias() = b * (Kq_.topRows(nv) * G_h0_.transpose());
      iteration_.block(nv, 0, nh, nv) = d.G.topRows(nh);
      iteration_.block(nv, nv + nc, nh, nh).noalias() = d.G.topRows(nh) * G_h0_.transpose();
    }
    lu_.compute(iteration_);
    matrix_h_ = h;
    broyden_count_ = 0;
  }

  // delta_ = B^-1 rhs_, B the iteration matrix with this step's Broyden updates: the LU's solve,
  // then each update's Sherman-Morrison correction in the order they were made,
  // z <- z + p_j (s_j . z) (BroydenUpdate). O(n) per update.
  void SolveIteration() {
    delta_.noalias() = lu_.solve(rhs_);
    for (int j = 0; j < broyden_count_; ++j)
      delta_ += broyden_p_.col(j) * broyden_s_.col(j).dot(delta_);
  }

  // Broyden's update after a full increment s = -last_delta_ from an iterate with residual F_k,
  // delta_ = B^-1 F_{k+1} just solved with the matrix that took it: B+ = B + (F_{k+1} - F_k -
  // B s) s^T / (s^T s) (Dennis & Schnabel, Numerical Methods for Unconstrained Optimization and
  // Nonlinear Equations, 1983, Sec. 8.1, eq. 8.1.5), whose inverse follows by Sherman-Morrison
  // (ibid., Sec. 8.3, eq. 8.3.1). With B s = -F_k the update's vector is F_{k+1}; with z =
  // B^-1 F_{k+1}, B+^-1 v = B^-1 v + p (s . B^-1 v), p = -z / (s.s + s.z), and the next
  // increment B+^-1 F_{k+1} = z (s.s) / (s.s + s.z): delta_ is rescaled in place. No update
  // when s.s + s.z is near 0 against s.s (B+ near singular). With kMaxBroydenUpdates held, the
  // updates start anew from the LU alone, without this one (B s = -F_k held for the matrix with
  // the updates, not for the LU).
  void BroydenUpdate() {
    if (broyden_count_ == kMaxBroydenUpdates) {
      broyden_count_ = 0;
      delta_.noalias() = lu_.solve(rhs_);
      return;
    }
    const double ss = last_delta_.squaredNorm();
    const double denom = ss - last_delta_.dot(delta_);
    if (!(std::abs(denom) > 1e-3 * ss)) return;
    broyden_s_.col(broyden_count_) = -last_delta_;
    broyden_p_.col(broyden_count_) = (-1.0 / denom) * delta_;
    ++broyden_count_;
    delta_ *= ss / denom;
  }

  // Step() leaves the state alone when Newton fails: retry as two halves (options' halvings).
  // The observer sees every accepted step; what it throws is not a failed step.
  void StepOrHalve(double t_next, int halvings) {
    try {
      Step(t_next);
    } catch (const std::runtime_error&) {
      if (halvings >= options_.max_step_halvings) throw;
      const double t_mid = state_.t + 0.5 * (t_next - state_.t);
      StepOrHalve(t_mid, halvings + 1);
      StepOrHalve(t_next, halvings + 1);
      return;
    }
    if (step_callback_) step_callback_(state_.t, state_.q, state_.v);
  }

  // Force scale for the convergence test: the largest force in the balance (inertia, applied,
  // element and constraint forces, as the last evaluation left them in Data), so the tolerance is
  // relative to what the rows add up. The inertia forces take the mass matrix's diagonal where
  // it was last computed (mass_diagonal_: the step's start after a projection, else the last
  // refresh or Initialize).
  double ForceScale() {
    const Data& d = dae_.data();
    double scale = 1.0;
    for (int k = 0; k < model_.nv; ++k)
      scale = std::max(scale, std::abs(mass_diagonal_(k) * vdot_new_(k)));
    scale = std::max(scale, d.tau_applied.lpNorm<Eigen::Infinity>());
    for (const Vec6& f : d.f_ext) scale = std::max(scale, f.tail<3>().lpNorm<Eigen::Infinity>());
    if (model_.n_constraints > 0) scale = std::max(scale, lambda_new_.lpNorm<Eigen::Infinity>());
    return scale;
  }

  // Takes the iterate (vdot_new_, lambda_new_, mu_new_) forward by `fraction` of -delta_.
  void TakeIncrement(double fraction) {
    const int nv = model_.nv, nc = model_.n_constraints, nh = model_.n_holonomic;
    vdot_new_ -= fraction * delta_.head(nv);
    lambda_new_ -= fraction * delta_.segment(nv, nc);
    mu_new_ -= fraction * delta_.tail(nh);
  }

  // Whether the last increment (size `increment`, from an iterate whose residual ratio was
  // `ratio` with the contraction `theta`) ends the iteration without evaluating its result:
  // - the increment is small against the accelerations (newton_tolerance), or no longer moves
  //   positions and velocities beyond their rounding (stiff springs of 1e8-1e10 on angles of many
  //   radians leave a residual floor of eps |q| k);
  // - the residual it leaves is estimated below the tolerance: Hairer & Wanner (Solving
  //   Ordinary Differential Equations II, 2nd ed., Sec. IV.8, eqs. 8.10-8.13) bound the error
  //   left after an increment of a linearly converging iteration by eta ||Delta_k||, eta =
  //   theta / (1 - theta), theta its contraction rate; taken on the residual ratio (the next
  //   ratio ~ theta ratio), accepted when eta ratio <= kEstimateMargin (theta >= 1: never).
  //   theta < 0 (no contraction measured in this step yet): never.
  bool IncrementEnds(double h, double increment, double ratio, double theta) const {
    const double ca = (1 - af_) / (1 - am_);
    constexpr double kRound = 64 * std::numeric_limits<double>::epsilon();
    const bool at_rounding =
        beta_ * ca * h * h * increment <= kRound * std::max(1.0, q_new_.lpNorm<Eigen::Infinity>()) &&
        gamma_ * ca * h * increment <= kRound * std::max(1.0, v_new_.lpNorm<Eigen::Infinity>());
    if (increment <= options_.newton_tolerance * std::max(1.0, vdot_new_.lpNorm<Eigen::Infinity>()) || at_rounding)
      return true;
    return theta >= 0 && theta < 1 && theta / (1 - theta) * ratio <= kEstimateMargin;
  }

  // Modified Newton: the iteration matrix is kept from step to step and refreshed when the step
  // size changes or the iteration converges slowly (rate above options' matrix_refresh_rate)
  // or not at all. With a matrix fresh in this step, an increment after which the residual grew
  // is taken back by halves (up to kMaxBacktracks times). Converged when the scaled residual is
  // below newton_tolerance times the force scale (ResidualRatio <= 1), or when an increment
  // ends the iteration (IncrementEnds: small, at rounding, or leaving a residual estimated below
  // the tolerance from the contraction rate; kinks of tabulated mesh stiffness can hold the
  // residual above its floor while the iterates no longer move). The contraction rate theta of
  // the estimate is the larger of this step's last measured rate (ratio of successive residual
  // ratios) and the rate carried from the steps before (rate_): the largest rate measured after a
  // step's first increment, decaying by kRateDecay per step. Both guards are measured needs: on
  // seed 002's ramp the first contraction of a step (from the predictor's large residual) is
  // 1e-4, the later ones 1e-2, and single later samples fall to 1e-6 where a residual drops onto
  // its floor; trusting either accepted iterates at up to 7.8 times the tolerance. With them,
  // none of 4000 estimated iterates there (nor of 11000 on seed 001) exceeded the tolerance
  // (largest 0.95 and 0.34 of it, evaluated in a check run). After kRateCheckSteps steps
  // without a new measurement, steps iterate to a measured residual until one comes.
  // Returns whether it converged; evaluated_at_iterate_ says whether Data holds the accepted
  // iterate's evaluation (false after an increment that ended the iteration).
  bool Converge(double t, double h) {
    const double tol = options_.newton_tolerance * ForceScale();
    bool fresh = false;
    if (std::abs(matrix_h_ - h) > 1e-6 * h) {
      RefreshIterationMatrix(t, h);
      fresh = true;
    }
    double previous = std::numeric_limits<double>::infinity();  // last increment's size
    double previous_ratio = -1;  // residual ratio where the last full increment started (-1: none)
    int previous_it = 0;         // the iteration of previous_ratio
    double measured = -1;        // this step's last contraction rate (-1: none yet)
    double later = -1;           // this step's last rate measured after its first increment
    const bool estimates =
        options_.newton_estimate && rate_ > 0 && steps_since_rate_ < kRateCheckSteps;
    // Broyden updates (without the estimate only: their contraction is not the steady rate the
    // estimate assumes): this step's, from its second increment on, after full increments only.
    const bool broyden = !options_.newton_estimate;
    bool full_increment = false;  // last_delta_ is a full increment from the last residual
    broyden_count_ = 0;
    // Damping (below): the residual where the last increment started, the fraction of it taken.
    double start_norm = std::numeric_limits<double>::infinity(), fraction = 1;
    int backtracks = 0;
    evaluated_at_iterate_ = false;
    for (int it = 0; it < options_.max_newton_iterations; ++it) {
      newton_norm_ = Residual(t, h);
      evaluated_at_iterate_ = true;
      ++stats_.newton_iterations;
      double ratio = ResidualRatio(tol);
      if (previous_ratio > 0) {
        measured = ratio / previous_ratio;
        if (previous_it > 0) later = measured;
      }
      if (it > 0 && ratio <= 1) break;
      // With a fresh matrix, a residual that grew means the increment crossed a switch of the
      // forces (tooth contact coming on or off, a node changing faces) where Newton can cycle
      // between two contact states for ever: take back half of the increment instead.
      if (fresh && it > 0 && newton_norm_ > start_norm && backtracks < kMaxBacktracks) {
        fraction *= 0.5;
        TakeIncrement(-fraction);
        UpdateKinematics(h);
        ++backtracks;
        ++stats_.newton_backtracks;
        full_increment = false;
        previous_ratio = measured = -1;
        continue;
      }
      SolveIteration();
      if (broyden && full_increment) BroydenUpdate();
      double increment = Increment();
      if (!fresh && (increment > options_.matrix_refresh_rate * previous || !std::isfinite(increment))) {
        // Slow with an old matrix: refresh it at the current iterate and take this step again.
        // The iterate has not moved since Residual(): rhs_ and ratio are still its residual
        // (evaluating it again gave the same numbers: one whole evaluation per refresh saved).
        RefreshIterationMatrix(t, h);
        fresh = true;
        measured = -1;
        SolveIteration();
        increment = Increment();
      }
      start_norm = newton_norm_;
      fraction = 1;
      last_delta_ = delta_;
      full_increment = true;
      TakeIncrement(1);
      UpdateKinematics(h);
      evaluated_at_iterate_ = false;
      previous = increment;
      previous_ratio = ratio;
      previous_it = it;
      const double theta = !estimates || backtracks > 0 || measured < 0 ? -1 : std::max(measured, rate_);
      if (IncrementEnds(h, increment, ratio, theta)) break;
      if (it + 1 == options_.max_newton_iterations) return false;
    }
    rate_ *= kRateDecay;
    if (later >= 0) {
      rate_ = std::max(rate_, later);
      steps_since_rate_ = 0;
    } else {
      ++steps_since_rate_;
    }
    return (evaluated_at_iterate_ ? ResidualRatio(tol) <= 1 : true) && vdot_new_.allFinite();
  }

  // One step to t: predictor (the accelerations and multipliers of the step's start, no position
  // correction), Newton (Converge), then acceptance and the velocity projection.
  void Step(double t) {
    const int nc = model_.n_constraints, nh = model_.n_holonomic;
    const double h = t - state_.t;
    kinematics_at_state_ = false;  // the iterates' evaluations and the tangents write Data
    vdot_new_ = vdot_;
    lambda_new_ = lambda_;
    mu_new_.setZero();
    UpdateKinematics(h);
    if (!Converge(t, h)) {
      evaluated_at_iterate_ = false;  // DataAtState: the state did not move to this iterate
      ++stats_.newton_failures;
      matrix_h_ = 0;  // never reuse a matrix that failed
      std::ostringstream s;
      s << "generalized-alpha: Newton did not converge at t = " << t << " s (step " << h << " s, residual "
        << newton_norm_ << "); largest in " << WorstRow() << SingularConstraints()
        << "; reduce the step or lower rho_inf (more damping)";
      throw std::runtime_error(s.str());
    }
    // Accept, then project velocities onto G v + g_t = 0 in the metric of M.
    if (observer_) KeepStepStart(h);
    state_.t = t;
    state_.q = q_new_;
    NormalizeQuaternions(model_, state_.q);
    state_.v = v_new_;
    v_alpha_ = v_new_;
    vdot_ = vdot_new_;
    a_ = a_new_;
    lambda_ = lambda_new_;
    if (nc > 0) {
      ProjectVelocities();
      G_h0_ = dae_.data().G.topRows(nh);  // at state_.q, from the projection
      kinematics_at_state_ = true;        // (ProjectVelocities) read by RecordDrift and the health
    }
    ++stats_.steps;
    stats_.last_step = h;
    if (observer_) observer_->OnStep(*this, t_start_, state_.t);
  }

  // The step's start and increment, for Interpolate (only with an observer).
  void KeepStepStart(double h) {
    t_start_ = state_.t;
    q_start_ = state_.q;
    v_start_ = state_.v;
    vdot_start_ = vdot_;
    dq_step_ = dq_;
    h_step_ = h;
  }

  // The kinematics and constraints at state_.q are those of the step's last residual (at q_new_)
  // unless quaternions were normalized since or the accepted iterate was not evaluated.
  // The projection v <- v - M^-1 G^T (G M^-1 G^T)^-1 (G v + g_t) (the KKT system
  // [M G^T; G 0] [dv; l] = [0; G v + g_t] with the constraint rows eliminated) needs M only
  // through M^-1 G^T, one articulated solve per constraint row (mbd/articulated_solve.h), and the
  // nc x nc matrix G M^-1 G^T; the mass matrix is formed, and the KKT system factored, only where
  // that does not apply (flexible bodies, a singular M: a driven massless coordinate) or fails.
  void ProjectVelocities() {
    const int nv = model_.nv, nc = model_.n_constraints;
    Data& d = dae_.data();
    if (model_.has_quaternions || !evaluated_at_iterate_) {
      CalcPositionKinematics(model_, state_.q, d);
      CalcConstraints(model_, state_.t, d);
    }
    proj_rhs_.tail(nc).noalias() = d.G * state_.v;
    proj_rhs_.tail(nc) += d.g_t;
    if (ProjectByArticulatedSolves()) return;
    CalcMassMatrix(model_, d);
    mass_diagonal_ = d.M.diagonal();
    proj_.topLeftCorner(nv, nv) = d.M;
    proj_.topRightCorner(nv, nc) = d.G.transpose();
    proj_.bottomLeftCorner(nc, nv) = d.G;
    proj_.bottomRightCorner(nc, nc).setZero();
    proj_rhs_.head(nv).setZero();
    auto correction = delta_.head(nv + nc);
    if (!SolveProjection(correction)) {
      proj_lu_.compute(proj_);
      ++projection_factorizations_;
      correction.noalias() = proj_lu_.solve(proj_rhs_);
    }
    state_.v -= correction.head(nv);
  }

  // ProjectVelocities without the mass matrix: Y = M^-1 G^T by articulated solves, then
  // v -= Y (G Y)^-1 r with r = G v + g_t (in proj_rhs_'s tail). Also the mass matrix's diagonal
  // for ForceScale (CalcMassMatrixDiagonal, CalcMassMatrix's to the last bit). false (v
  // untouched) where the recursion does not apply or gives no finite correction.
  bool ProjectByArticulatedSolves() {
    const int nc = model_.n_constraints;
    Data& d = dae_.data();
    if (!inverse_mass_.Factorize(model_, d, d.G)) return false;
    for (int c = 0; c < nc; ++c) {
      proj_tau_ = d.G.row(c).transpose();
      inverse_mass_.Solve(model_, d, proj_tau_, proj_y_.col(c));
    }
    proj_schur_.noalias() = d.G * proj_y_;
    if (nc == 1) {
      // The 1 x 1 LU's solve is the division, the product's update v_k - y_k mu (as Eigen's)
      proj_mu_(0) = proj_rhs_(proj_rhs_.size() - 1) / proj_schur_(0, 0);
      if (!std::isfinite(proj_mu_(0)) || !proj_y_.allFinite()) return false;
      CalcMassMatrixDiagonal(model_, d, mass_diagonal_);
      state_.v -= proj_mu_(0) * proj_y_.col(0);
      return true;
    }
    proj_schur_lu_.compute(proj_schur_);
    proj_mu_.noalias() = proj_schur_lu_.solve(proj_rhs_.tail(nc));
    if (!proj_mu_.allFinite() || !proj_y_.allFinite()) return false;
    CalcMassMatrixDiagonal(model_, d, mass_diagonal_);
    state_.v.noalias() -= proj_y_ * proj_mu_;
    return true;
  }

  // x = proj_^-1 proj_rhs_ with the factors of an earlier projection matrix (the mass matrix and
  // constraint Jacobian move little in a step), refined by iteration: x += LU^-1 (rhs - K x)
  // until the refinement is at rounding (1e-14 of x). false (x unusable) when there are no
  // factors yet or the refinement does not settle in kMaxRefinements sweeps: then refactorize.
  bool SolveProjection(Eigen::Ref<Eigen::VectorXd> x) {
    constexpr int kMaxRefinements = 3;
    if (projection_factorizations_ == 0) return false;
    x.noalias() = proj_lu_.solve(proj_rhs_);
    for (int k = 0; k < kMaxRefinements; ++k) {
      auto& residual = proj_residual_;
      residual = proj_rhs_;
      residual.noalias() -= proj_ * x;
      auto& update = proj_update_;
      update.noalias() = proj_lu_.solve(residual);
      x += update;
      if (!(update.lpNorm<Eigen::Infinity>() <= 1e-14 * x.lpNorm<Eigen::Infinity>())) continue;
      return x.allFinite();
    }
    return false;
  }

  // Constraint drift at the state: position kinematics and constraints only (no forces: they
  // do not enter Phi or G v + g_t), and nothing without constraints.
  void RecordDrift() {
    if (model_.n_constraints == 0) return;
    Data& d = dae_.data();
    if (!kinematics_at_state_) {
      CalcPositionKinematics(model_, state_.q, d);
      CalcConstraints(model_, state_.t, d);
      kinematics_at_state_ = true;
    }
    if (model_.n_holonomic > 0) stats_.max_abs_phi = std::max(stats_.max_abs_phi, d.phi.lpNorm<Eigen::Infinity>());
    if (model_.n_constraints > 0) {
      auto phidot = proj_rhs_.tail(model_.n_constraints);  // scratch: no allocation
      phidot.noalias() = d.G * state_.v;
      phidot += d.g_t;
      stats_.max_abs_phidot = std::max(stats_.max_abs_phidot, phidot.lpNorm<Eigen::Infinity>());
    }
  }

  const Model& model_;
  IntegratorOptions options_;
  DaeSystem dae_;
  double am_ = 0, af_ = 0, beta_ = 0.25, gamma_ = 0.5;
  State state_;
  Eigen::VectorXd vdot_, a_, lambda_;                 // at state_.t
  Eigen::VectorXd vdot_new_, a_new_, lambda_new_, q_new_, v_new_, dq_;  // iterates at t + h
  Eigen::VectorXd mu_new_;   // n_holonomic: scaled position multiplier mu~ of the step
  Eigen::MatrixXd G_h0_;     // n_holonomic x nv: G_h at the step's start (StoreConstraintNormals)
  Eigen::VectorXd v_alpha_;  // the recurrence's velocity at state_.t (before projection)
  Eigen::MatrixXd Kq_, Cv_, iteration_, proj_;
  Eigen::VectorXd rhs_, delta_, proj_rhs_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_, proj_lu_;
  // Converge without the estimate: this step's Broyden updates of lu_'s inverse (BroydenUpdate).
  Eigen::MatrixXd broyden_s_, broyden_p_;  // n x kMaxBroydenUpdates: the updates' s_j and p_j
  Eigen::VectorXd last_delta_;             // n: the last full increment's delta_
  int broyden_count_ = 0;                  // updates held (since the step's start or a refresh)
  Eigen::VectorXd proj_residual_, proj_update_;  // SolveProjection's scratch (nv + nc)
  ArticulatedSolve inverse_mass_;                // ProjectByArticulatedSolves: M^-1 without M
  Eigen::MatrixXd proj_y_;                       // nv x nc: M^-1 G^T (ProjectByArticulatedSolves)
  Eigen::MatrixXd proj_schur_;                   // nc x nc: G M^-1 G^T
  Eigen::PartialPivLU<Eigen::MatrixXd> proj_schur_lu_;  // its factors
  Eigen::VectorXd proj_mu_;                             // nc: (G M^-1 G^T)^-1 (G v + g_t)
  Eigen::VectorXd proj_tau_;                            // nv: a row of G as a generalized force
  Eigen::VectorXd
      mass_diagonal_;  // nv: the mass matrix's diagonal where last computed (ForceScale)
  long projection_factorizations_ = 0;
  IntegratorStats stats_;
  long pipeline_evaluations_ = 0;
  double position_floor_ = 0;  // set by Residual
  Eigen::VectorXd rounding_floor_;   // nv: the dynamic rows' rounding floor (UpdateRoundingFloor)
  Eigen::VectorXd coordinate_size_;  // nv: scratch of UpdateRoundingFloor
  double newton_norm_ = 0;     // Converge: max norm of the last residual (for the failure message)
  bool evaluated_at_iterate_ = false;  // Converge: Data holds the evaluation at the accepted iterate
  // Data holds CalcPositionKinematics and CalcConstraints at (state_.t, state_.q), nothing
  // written since: set by Step's projection and RecordDrift, cleared where a step starts.
  bool kinematics_at_state_ = false;
  long steps_since_rate_ = 0;  // Converge: steps since rate_ was measured
  double rate_ = -1;            // Converge: contraction rate carried from step to step
  double matrix_h_ = 0;         // step the iteration matrix was built for (0: none)
  // Dense output (KeepStepStart, with an observer): the last step's start and increment.
  Eigen::VectorXd q_start_, v_start_, vdot_start_, dq_step_, dq_interp_;
  double t_start_ = 0, h_step_ = 1;
  StepCallback step_callback_;  // SetStepCallback
};

}  // namespace

std::unique_ptr<Integrator> MakeGeneralizedAlpha(const Model& model, const IntegratorOptions& o) {
  return std::make_unique<GeneralizedAlpha>(model, o);
}

}  // namespace orrery

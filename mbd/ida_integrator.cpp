// IDA (SUNDIALS) on the stabilized index-2 DAE of dae.h. SUNDIALS headers stay in this file.
#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "mbd/constraints.h"
#include "mbd/dae.h"
#include "mbd/element_names.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"

namespace orrery {

std::unique_ptr<Integrator> MakeGeneralizedAlpha(const Model& model, const IntegratorOptions& o);

namespace {

using VecMap = Eigen::Map<Eigen::VectorXd>;

class IdaIntegrator final : public Integrator {
 public:
  IdaIntegrator(const Model& model, const IntegratorOptions& options)
      : model_(model), options_(options), dae_(model) {
    dae_.data().threads = ResolveThreads(options.threads);
    if (SUNContext_Create(nullptr, &ctx_) != 0) throw std::runtime_error("IDA: cannot create a SUNContext");
  }
  ~IdaIntegrator() override {
    if (mem_) IDAFree(&mem_);
    if (ls_) SUNLinSolFree(ls_);
    if (A_) SUNMatDestroy(A_);
    for (N_Vector v : {y_, yp_, atol_, id_, y_out_, yp_out_, y_dense_, yp_dense_})
      if (v) N_VDestroy(v);
    if (ctx_) SUNContext_Free(&ctx_);
  }

  void Initialize(const State& initial) override {
    const int n = dae_.size();
    state_ = initial;
    AssembleState(model_, state_, dae_.data());
    y_ = N_VNew_Serial(n, ctx_);
    yp_ = N_VNew_Serial(n, ctx_);
    atol_ = N_VNew_Serial(n, ctx_);
    id_ = N_VNew_Serial(n, ctx_);
    y_out_ = N_VNew_Serial(n, ctx_);
    yp_out_ = N_VNew_Serial(n, ctx_);
    y_dense_ = N_VNew_Serial(n, ctx_);
    yp_dense_ = N_VNew_Serial(n, ctx_);
    drift_scratch_.setZero(model_.n_constraints);
    t_step_ = state_.t;
    VecMap y(N_VGetArrayPointer(y_), n), yp(N_VGetArrayPointer(yp_), n);
    dae_.ConsistentInitial(state_, y, yp);
    // Differential (q, v) and algebraic (lambda, mu) components, their absolute tolerances.
    VecMap atol(N_VGetArrayPointer(atol_), n), id(N_VGetArrayPointer(id_), n);
    const int ndiff = dae_.nq() + dae_.nv();
    atol.head(ndiff).setConstant(options_.atol);
    atol.tail(n - ndiff).setConstant(options_.atol_multiplier);
    id.head(ndiff).setOnes();
    id.tail(n - ndiff).setZero();

    mem_ = IDACreate(ctx_);
    if (!mem_) throw std::runtime_error("IDA: IDACreate failed");
    Check(IDASetErrHandlerFn(mem_, &IdaIntegrator::OnError, this), "IDASetErrHandlerFn");
    Check(IDAInit(mem_, &IdaIntegrator::ResidualFn, state_.t, y_, yp_), "IDAInit");
    Check(IDASVtolerances(mem_, options_.rtol, atol_), "IDASVtolerances");
    Check(IDASetUserData(mem_, this), "IDASetUserData");
    Check(IDASetId(mem_, id_), "IDASetId");
    Check(IDASetSuppressAlg(mem_, SUNTRUE), "IDASetSuppressAlg");
    Check(IDASetMaxNumSteps(mem_, options_.max_steps_per_output), "IDASetMaxNumSteps");
    Check(IDASetMaxOrd(mem_, options_.max_order), "IDASetMaxOrd");
    if (options_.max_step > 0) Check(IDASetMaxStep(mem_, options_.max_step), "IDASetMaxStep");
    if (options_.initial_step > 0) Check(IDASetInitStep(mem_, options_.initial_step), "IDASetInitStep");
    A_ = SUNDenseMatrix(n, n, ctx_);
    ls_ = SUNLinSol_Dense(y_, A_, ctx_);
    Check(IDASetLinearSolver(mem_, ls_, A_), "IDASetLinearSolver");
    Check(IDASetJacFn(mem_, &IdaIntegrator::JacobianFn), "IDASetJacFn");
    vdot_ = yp.segment(dae_.nq(), dae_.nv());
    lambda_ = y.segment(dae_.nq() + dae_.nv(), dae_.nc());
    needs_ic_ = true;
    RecordDrift();
  }

  void AdvanceTo(double t_out) override {
    if (t_out <= state_.t) return;
    const int n = dae_.size();
    if (needs_ic_) {
      // Consistent initial values. With constraints they come from the KKT solve in Initialize
      // (DaeSystem::ConsistentInitial): IDACalcIC handles semi-explicit index-1 systems, and in
      // the GGL index-2 form the rows G v + g_t and Phi involve none of its unknowns (algebraic
      // lambda, mu and the derivatives of q, v), so its Newton matrix is singular there (seen as
      // IDA_LINESEARCH_FAIL on a slider-crank). Without constraints IDACalcIC polishes q-dot and
      // v-dot.
      if (model_.n_constraints == 0) {
        const int flag = IDACalcIC(mem_, IDA_YA_YDP_INIT, t_out);
        if (flag < 0) Fail("IDACalcIC", flag);
        Check(IDAGetConsistentIC(mem_, y_, yp_), "IDAGetConsistentIC");
      }
      needs_ic_ = false;
    }
    // Internal steps up to t_out (drift measured at each), then the solution at t_out from
    // IDA's interpolating polynomial.
    for (long steps = 0; t_step_ < t_out; ++steps) {
      if (steps == options_.max_steps_per_output) Fail("IDASolve", IDA_TOO_MUCH_WORK);
      const double t_begin = t_step_;
      const int flag = IDASolve(mem_, t_out, &t_step_, y_, yp_, IDA_ONE_STEP);
      if (flag < 0) Fail("IDASolve", flag);
      RecordStepDrift();
      if (observer_) observer_->OnStep(*this, t_begin, t_step_);
      if (step_callback_) {
        VecMap y(N_VGetArrayPointer(y_), n);
        step_callback_(t_step_, y.head(dae_.nq()), y.segment(dae_.nq(), dae_.nv()));
      }
    }
    Check(IDAGetDky(mem_, t_out, 0, y_out_), "IDAGetDky");
    Check(IDAGetDky(mem_, t_out, 1, yp_out_), "IDAGetDky");
    VecMap y(N_VGetArrayPointer(y_out_), n), yp(N_VGetArrayPointer(yp_out_), n);
    state_.t = t_out;
    state_.q = y.head(dae_.nq());
    NormalizeQuaternions(model_, state_.q);
    state_.v = y.segment(dae_.nq(), dae_.nv());
    vdot_ = yp.segment(dae_.nq(), dae_.nv());
    lambda_ = y.segment(dae_.nq() + dae_.nv(), dae_.nc());
    // With constraints, accelerations and multipliers (driver efforts, reactions) come from the
    // equations of motion at the output state: the multipliers are index-2 variables with a loose
    // Newton tolerance (see atol_multiplier) and their interpolant is not error-controlled.
    if (dae_.nc() > 0) dae_.SolveAccelerations(state_.t, state_.q, state_.v, vdot_, lambda_);
  }

  const State& state() const override { return state_; }
  const Eigen::VectorXd& vdot() const override { return vdot_; }
  const Data& data() const override { return dae_.data(); }
  const Eigen::VectorXd& lambda() const override { return lambda_; }
  std::string name() const override { return "ida"; }
  void SetStepCallback(StepCallback callback) override { step_callback_ = std::move(callback); }

  void Interpolate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v,
                   Eigen::Ref<Eigen::VectorXd> vdot) override {
    const int n = dae_.size();
    Check(IDAGetDky(mem_, t, 0, y_dense_), "IDAGetDky");
    Check(IDAGetDky(mem_, t, 1, yp_dense_), "IDAGetDky");
    const VecMap y(N_VGetArrayPointer(y_dense_), n), yp(N_VGetArrayPointer(yp_dense_), n);
    q = y.head(dae_.nq());
    v = y.segment(dae_.nq(), dae_.nv());
    vdot = yp.segment(dae_.nq(), dae_.nv());
  }

  IntegratorStats stats() const override {
    IntegratorStats s = drift_;
    if (!mem_) return s;
    long v = 0;
    int order = 0;
    double h = 0;
    IDAGetNumSteps(mem_, &v), s.steps = v;
    IDAGetNumResEvals(mem_, &v), s.residual_evaluations = v;
    IDAGetNumJacEvals(mem_, &v), s.jacobian_evaluations = v;
    IDAGetNumNonlinSolvIters(mem_, &v), s.newton_iterations = v;
    IDAGetNumNonlinSolvConvFails(mem_, &v), s.newton_failures = v;
    IDAGetNumErrTestFails(mem_, &v), s.error_test_failures = v;
    IDAGetLastOrder(mem_, &order), s.last_order = order;
    IDAGetLastStep(mem_, &h), s.last_step = h;
    // Residual evaluations inside our Jacobian (finite-difference columns) count too.
    s.residual_evaluations = dae_.residual_evaluations();
    return s;
  }

 private:
  static int ResidualFn(realtype t, N_Vector y, N_Vector yp, N_Vector r, void* user) {
    auto* self = static_cast<IdaIntegrator*>(user);
    const int n = self->dae_.size();
    try {
      self->dae_.Residual(t, VecMap(N_VGetArrayPointer(y), n), VecMap(N_VGetArrayPointer(yp), n),
                          VecMap(N_VGetArrayPointer(r), n));
      return VecMap(N_VGetArrayPointer(r), n).allFinite() ? 0 : 1;  // recoverable: smaller step
    } catch (const std::exception& e) {
      self->callback_error_ = e.what();
      return -1;
    }
  }

  static int JacobianFn(realtype t, realtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix J,
                        void* user, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<IdaIntegrator*>(user);
    const int n = self->dae_.size();
    try {
      Eigen::Map<Eigen::MatrixXd> Jm(SM_DATA_D(J), n, n);
      self->dae_.Jacobian(t, cj, VecMap(N_VGetArrayPointer(y), n),
                          VecMap(N_VGetArrayPointer(yp), n), Jm);
      return Jm.allFinite() ? 0 : 1;
    } catch (const std::exception& e) {
      self->callback_error_ = e.what();
      return -1;
    }
  }

  static void OnError(int, const char* module, const char* function, char* msg, void* user) {
    auto* self = static_cast<IdaIntegrator*>(user);
    self->last_message_ = std::string(module) + "/" + function + ": " + msg;
  }

  // Constraint residuals of the integrator's own solution at (t, q, v): max |Phi|, |G v + g_t|.
  void RecordDrift(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                   const Eigen::Ref<const Eigen::VectorXd>& v) {
    if (model_.n_constraints == 0) return;
    Data& d = dae_.data();
    CalcPositionKinematics(model_, q, d);
    CalcConstraints(model_, t, d);
    if (model_.n_holonomic > 0) drift_.max_abs_phi = std::max(drift_.max_abs_phi, d.phi.lpNorm<Eigen::Infinity>());
    auto phidot = drift_scratch_.head(model_.n_constraints);
    phidot.noalias() = d.G * v;
    phidot += d.g_t;
    drift_.max_abs_phidot = std::max(drift_.max_abs_phidot, phidot.lpNorm<Eigen::Infinity>());
  }
  void RecordDrift() { RecordDrift(state_.t, state_.q, state_.v); }
  // At the step IDA just took (drift is measured on steps, not on interpolated outputs, whose
  // interpolation error shows in the result file's /constraints/drift instead).
  void RecordStepDrift() {
    const int n = dae_.size();
    VecMap y(N_VGetArrayPointer(y_), n);
    RecordDrift(t_step_, y.head(dae_.nq()), y.segment(dae_.nq(), dae_.nv()));
  }

  // "; largest weighted local error in <unknown>" from IDA's estimate of the last step, or "".
  std::string WorstComponent() {
    if (!mem_ || !y_out_ || !yp_out_) return "";
    const int n = dae_.size();
    if (IDAGetErrWeights(mem_, y_out_) < 0 || IDAGetEstLocalErrors(mem_, yp_out_) < 0) return "";
    VecMap w(N_VGetArrayPointer(y_out_), n), e(N_VGetArrayPointer(yp_out_), n);
    Eigen::Index worst = 0;
    if (!(e.cwiseProduct(w).cwiseAbs().maxCoeff(&worst) > 0)) return "";
    return "; largest weighted local error in the " + DaeUnknownName(model_, static_cast<int>(worst));
  }

  void Check(int flag, const char* call) {
    if (flag < 0) Fail(call, flag);
  }

  [[noreturn]] void Fail(const char* call, int flag) {
    std::ostringstream s;
    char* flag_name = IDAGetReturnFlagName(flag);
    s << "IDA stopped at t = " << std::max(state_.t, t_step_) << " s: " << call << " returned " << flag_name;
    free(flag_name);
    long steps = 0;
    if (mem_) IDAGetNumSteps(mem_, &steps);
    if ((flag == IDA_CONV_FAIL || flag == IDA_ERR_FAIL) && steps == 0)
      // Not a single step: at the start nothing is stiff or discontinuous yet, the tolerances are
      // what IDA cannot meet (rounding of q, v near rtol |y| + atol, or the multipliers' Newton test)
      s << " (no step succeeded: the tolerances rtol = " << options_.rtol << ", atol = " << options_.atol
        << " may be below what the model's rounding allows; loosen solver.rtol or solver.atol, or "
           "raise solver.atol_multiplier (now "
        << options_.atol_multiplier << ", on the multipliers' Newton test))";
    else if (flag == IDA_CONV_FAIL || flag == IDA_ERR_FAIL)
      s << " (steps kept failing: the model may be too stiff for the tolerances, or a force or "
           "constraint is discontinuous; try the generalized-alpha integrator or a smaller max step)";
    if (flag == IDA_TOO_MUCH_WORK) s << " (more than " << options_.max_steps_per_output << " steps between outputs)";
    if (flag == IDA_CONV_FAIL || flag == IDA_ERR_FAIL || flag == IDA_TOO_MUCH_WORK) s << WorstComponent();
    if (!callback_error_.empty()) s << "; " << callback_error_;
    if (!last_message_.empty()) s << "; " << last_message_;
    throw std::runtime_error(s.str());
  }

  const Model& model_;
  IntegratorOptions options_;
  DaeSystem dae_;
  State state_;
  Eigen::VectorXd vdot_, lambda_;
  IntegratorStats drift_;
  SUNContext ctx_ = nullptr;
  void* mem_ = nullptr;
  N_Vector y_ = nullptr, yp_ = nullptr, atol_ = nullptr, id_ = nullptr;  // IDA's own (at t_step_)
  N_Vector y_out_ = nullptr, yp_out_ = nullptr;  // interpolated at the output time
  N_Vector y_dense_ = nullptr, yp_dense_ = nullptr;  // interpolated for a step observer
  double t_step_ = 0;                            // time of IDA's last internal step
  Eigen::VectorXd drift_scratch_;
  SUNMatrix A_ = nullptr;
  SUNLinearSolver ls_ = nullptr;
  bool needs_ic_ = true;
  std::string callback_error_, last_message_;
  StepCallback step_callback_;  // SetStepCallback
};

}  // namespace

int ResolveThreads(int requested) {
  if (requested < 0)
    throw std::invalid_argument("threads must be >= 1 (0: OMP_NUM_THREADS or 1), got " +
                                std::to_string(requested));
  if (requested > 0) return requested;
  const char* env = std::getenv("OMP_NUM_THREADS");
  if (!env || !*env) return 1;
  // OpenMP allows a list ("4,2" for nested levels); the first level is what the loop uses.
  char* end = nullptr;
  const long n = std::strtol(env, &end, 10);
  if (end == env || (*end != '\0' && *end != ',') || n < 1 || n > 4096)
    throw std::invalid_argument(std::string("OMP_NUM_THREADS='") + env +
                                "' is not a positive thread count");
  return static_cast<int>(n);
}

std::unique_ptr<Integrator> MakeIntegrator(const Model& model, const IntegratorOptions& options) {
  if (options.kind == IntegratorKind::kIda) return std::make_unique<IdaIntegrator>(model, options);
  return MakeGeneralizedAlpha(model, options);
}

}  // namespace orrery

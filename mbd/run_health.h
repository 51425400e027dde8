#pragma once
// The health of a run, watched while it goes: what makes a result doubtful (a warning) or
// meaningless (the run stops), each with the time, the element and the cause. Simulate
// (simulation.h) feeds it; the result file keeps it under /health; `orrery run` prints it.
//
// Checks:
//   step_vs_stiffest_mode  (start, generalized-alpha) omega_max h > pi, h the step (or the output
//       interval when shorter, which then sets the step): the step spans more than half the
//       period of the stiffest mode of the linearization at the initial state (Linearize +
//       CalcModes), which the fixed step cannot represent. With numerical damping (spectral
//       radius at infinity below 0.99) the mode is damped out, as a stiff spring standing for a
//       rigid connection relies on (seed001_three_stage's 1e10 N m/rad brakes: omega h = 405),
//       and omega_max h is only reported; without damping it aliases into the result: warning.
//   non_finite             (every step) a position or velocity not finite: stops, naming the
//       joint or flexible body of the first such coordinate.
//   mesh_ratchet           (lumped gear meshes with a base pitch) the teeth pass each other. The
//       rotational deflection e of a mesh (gear_mesh.h) is taken modulo the base pitch p around
//       the middle of the backlash b, so at half a pitch the force changes sign and the teeth
//       ratchet; elastic deflections are micrometres against pitches of millimetres. Stops when
//       e is more than p/4 past its flank (|e + b/2| - b/2 > p/4) or jumps by more than p/2
//       between two checks (every generalized-alpha step; IDA, whose error control resolves
//       the deflections, every row), or (every row) the gears roll against each other by
//       more than p/4 per step (|e-dot| h > p/4, e-dot the relative speed along the line of
//       action, h the last step): a step that skips whole teeth leaves e small at every step
//       while the train spins at a speed its gears do not allow (seed003_lumped_healthy at a 0.05 s step
//       ended with the carrier at -75000 rad/s instead of 59 rad/s, every sampled deflection
//       below 0.1 um).
//   energy_balance         (output rows) residual r = E(t) - E(0) - integral (P_applied +
//       P_drivers - P_dissipated) dt (trapezoid over the rows; E kinetic + gravity + elastic),
//       less twice the quadrature's estimated error U (|sum over the rows of dt (P_k+1 - 2 P_k
//       + P_k-1) / 12|, the trapezoid rule against Simpson's; P the net power: a power that
//       varies within an output interval is integrated from the rows only that well), relative
//       to the energy scale S = max(largest kinetic energy,
//       largest |V - V(0)|, integral of |P_applied| + |P_drivers| + |P_dissipated|): a warning
//       when it is above energy_warning at the end of the run (Finish; the largest value during
//       the run and its time are in the cause). Never a stop: a force element that does not
//       account its energy (a penalty contact whose points switch) shows here too, and a start
//       transient weighs less as the run goes on.
//   constraint_drift       (output rows) max |Phi| above drift_tolerance times the model's length
//       L (largest frame distance from the origin at the start, at least 1 mm), or max |G v + g_t|
//       above drift_tolerance times L times the largest body angular speed (or 1 rad/s); the
//       tolerance is at least 100 times the solver's (IDA's rtol, generalized-alpha's Newton
//       tolerance), which bounds what the solver promises.
//       Warning; names the constraint row.
//   <element check>        (output rows) checks of force elements (element_health.h): tooth
//       contact's penetration against its margin (contact/contact_element.h), a warning, and
//       against the depth its gaps can stand for (half the thinner tooth for gear pairs), a stop.
// A check warns once per element (its first time, then the count and the worst value and time).
// With `strict`, the first warning stops the run.
//
// Result file (/health): attributes warnings (count), stopped (0/1), energy_residual_relative and
// energy_quadrature_relative (at the last row),
// max_abs_phi, max_abs_phidot, omega_max_h (or -1), rho_infinity; datasets warnings/{check, element, cause}
// (strings), warnings/{time, worst_time, worst_value, limit, count} (one per warning),
// energy_balance (rows x 4: stored, work_in, dissipated, residual; J; one per output row),
// elements/<element>/<check> attributes max, max_time, limit, unit.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/element_health.h"
#include "mbd/integrator.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/state.h"

namespace orrery {

struct HealthOptions {
  bool strict = false;            // stop at the first warning
  double energy_warning = 0.05;   // relative energy-balance residual that warns
  double drift_tolerance = 1e-4;  // constraint drift relative to the model's length (and speed),
                                  // at least 100 times the solver's relative tolerance
  double ratchet_fraction = 0.25; // mesh deflection past its flank, in base pitches, that stops
};

struct HealthWarning {
  std::string check;    // "energy_balance", "mesh_ratchet", ... (run_health.h)
  std::string element;  // "mesh 'S1.sun-planet1'", "joint 'crank'", "loop closure 'c' row 0", "run"
  std::string cause;    // what was seen, with the numbers, at its first time
  double t = 0;         // first time (s)
  double worst_value = 0, worst_t = 0, limit = 0;  // in the check's unit
  long count = 0;       // samples (steps or rows) at which it held
  bool stops = false;   // the run stopped on it
};

// Thrown when a check stops the run (or any warning, when strict): what() is
// "t = <t> s: <element>: <cause>".
class RunHealthError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class RunHealth {
 public:
  // output_interval_s: the run's output interval (generalized-alpha steps no further).
  RunHealth(const Model& model, const IntegratorOptions& integrator, const HealthOptions& options,
            double output_interval_s);

  // Declares the /health/energy_balance series in `out` (before the first output row).
  void Declare(ResultFile& out);
  // At the initial state: the step against the stiffest mode (generalized-alpha only).
  void Start(const State& initial);
  // After every accepted step. Allocation-free; throws RunHealthError to stop. `at_q`: nullptr,
  // or a Data holding the position kinematics at exactly q (Integrator::
  // PositionKinematicsAtState), from which the gear angles are read instead of computing the
  // frame poses again.
  void OnStep(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& v, const Data* at_q = nullptr);
  // At an output row: `evaluated` holds the pipeline at (state, vdot) (EvaluateDynamics, as the
  // recorder leaves it), `step_s` the integrator's last step. Appends a row to the declared
  // series; throws RunHealthError to stop.
  void OnOutput(const State& state, const Eigen::VectorXd& lambda, const Data& evaluated, double step_s);
  // At the end of a run that reached its end time: the energy balance over the whole run.
  void Finish(double t);
  // Writes /health (attributes, warnings, element maxima); safe after a failure.
  void Write(ResultFile& out) const;

  const std::vector<HealthWarning>& warnings() const { return warnings_; }
  // At the last row: |r| / S, and what the rows' quadrature cannot resolve, 2 U / S.
  double energy_residual_relative() const { return energy_relative_; }
  double energy_quadrature_relative() const { return energy_quadrature_relative_; }
  double omega_max_h() const { return omega_max_h_; }
  // Generalized-alpha's damping of modes it does not resolve (1: none), from Start().
  double rho_infinity() const { return rho_infinity_; }
  double max_abs_phi() const { return max_phi_; }
  double max_abs_phidot() const { return max_phidot_; }

 private:
  // Records a sample of `check` on `element` at t (value against limit); warns the first time,
  // and throws RunHealthError when it stops the run (or strict).
  void Report(const std::string& check, const std::string& element, double t, double value, double limit,
              bool stops, const std::string& cause);
  // Meshes past their flank or jumping by half a pitch; angles_current: d.gear_angle holds the
  // gear angles at d's configuration (CalcGearAngles), else each mesh takes its own.
  void CheckMeshes(double t, const Data& d, bool angles_current);
  void CheckMeshRates(double t, const Data& d, double step_s);
  void CheckEnergy(const State& state, const Eigen::VectorXd& lambda, const Data& d);
  void CheckDrift(const State& state, const Data& d);
  double DriftTolerance() const;
  void CheckElements(double t, const Data& d);

  const Model& model_;
  IntegratorOptions integrator_;
  HealthOptions options_;
  double output_interval_s_ = 0;
  Data data_;  // per-step kinematics (mesh checks)
  std::vector<HealthWarning> warnings_;
  double length_m_ = 1e-3;  // model length scale L
  double omega_max_h_ = -1;
  double rho_infinity_ = 1;  // generalized-alpha's spectral radius at infinity (Start)
  // Meshes: previous rotational deflection per mesh (NaN before the first step).
  std::vector<double> mesh_e_prev_;
  // Energy balance.
  long energy_rows_ = 0;
  double t_prev_ = 0, e0_ = 0, v0_ = 0, abs_p_prev_ = 0, net_prev_ = 0, net_prev2_ = 0, quadrature_error_ = 0;
  double abs_work_ = 0, scale_ = 0, energy_relative_ = 0, energy_quadrature_relative_ = 0;
  double energy_excess_ = 0, worst_energy_ = 0, worst_energy_t_ = 0, last_residual_ = 0, last_stored_ = 0;
  double dissipated_ = 0, diss_prev_ = 0, work_in_ = 0, in_prev_ = 0;
  ResultFile* out_ = nullptr;
  ResultFile::SeriesId energy_series_ = -1;
  // Drift.
  double max_phi_ = 0, max_phidot_ = 0;
  // Element checks: per element with a reporter, its checks, values and maxima.
  struct ElementChecks {
    int element = -1;
    std::vector<ElementHealthCheck> checks;
    Eigen::VectorXd values, max, max_t;
  };
  std::vector<ElementChecks> elements_;
};

}  // namespace orrery

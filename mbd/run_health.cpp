#include "mbd/run_health.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "mbd/constraints.h"
#include "mbd/dynamics.h"
#include "mbd/element_names.h"
#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"
#include "mbd/linearization.h"

namespace orrery {
namespace {

// printf-style text for messages.
template <class... Args>
std::string Text(const char* format, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}

// Largest distance of a frame or centre of mass from the world origin at q (at least 1 mm).
double LengthScale(const Model& model, Data& data, const Eigen::VectorXd& q) {
  CalcPositionKinematics(model, q, data);
  double length = 1e-3;
  for (const Transform& X : data.X_WFrame) length = std::max(length, X.p.norm());
  for (BodyIndex b = 1; b < model.nbodies; ++b)
    length = std::max(length, (data.X_WB[b] * model.bodies[b].com_B).norm());
  return length;
}

// Spectral radius of generalized-alpha's amplification matrix for x'' = -w^2 x in the limit
// w h -> oo (Chung & Hulbert 1993), from the integrator's parameters (rho_inf, or the explicit
// four): the damping the method gives a mode it does not resolve. In that limit the equation of
// motion at alpha_f forces (1 - af) x_n+1 + af x_n = 0, one eigenvalue -af / (1 - af); with h = 1
// the updates of q and v then map (v, a) by
//   [1 - gamma / beta,  1 - gamma - gamma (1/2 - beta) / beta;  -1 / beta,  -(1/2 - beta) / beta].
double SpectralRadiusAtInfinity(const IntegratorOptions& o) {
  double af, beta, gamma;
  if (std::isfinite(o.alpha_m) && std::isfinite(o.alpha_f) && std::isfinite(o.beta) && std::isfinite(o.gamma)) {
    af = o.alpha_f, beta = o.beta, gamma = o.gamma;
  } else {
    const double r = o.rho_inf, am = (2 * r - 1) / (r + 1);
    af = r / (r + 1), gamma = 0.5 + af - am, beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
  }
  const double a11 = 1 - gamma / beta, a12 = 1 - gamma - gamma * (0.5 - beta) / beta;
  const double a21 = -1 / beta, a22 = -(0.5 - beta) / beta;
  const double tr = a11 + a22, det = a11 * a22 - a12 * a21, disc = tr * tr - 4 * det;
  const double block = disc < 0 ? std::sqrt(std::abs(det))
                                : std::max(std::abs(0.5 * (tr + std::sqrt(disc))), std::abs(0.5 * (tr - std::sqrt(disc))));
  return std::max(std::abs(af / (1 - af)), block);
}

}  // namespace

RunHealth::RunHealth(const Model& model, const IntegratorOptions& integrator, const HealthOptions& options,
                     double output_interval_s)
    : model_(model), integrator_(integrator), options_(options), output_interval_s_(output_interval_s), data_(model) {
  mesh_e_prev_.assign(model.gear_meshes.size(), std::numeric_limits<double>::quiet_NaN());
  // Force elements with checks of their own
  for (std::size_t e = 0; e < model.external_forces.size(); ++e) {
    const auto* reporter = dynamic_cast<const ElementHealthReporter*>(model.external_forces[e].get());
    if (reporter == nullptr) continue;
    ElementChecks c;
    c.element = static_cast<int>(e);
    c.checks = reporter->HealthChecks();
    const auto n = static_cast<Eigen::Index>(c.checks.size());
    c.values.setZero(n);
    c.max.setConstant(n, -std::numeric_limits<double>::infinity());
    c.max_t.setZero(n);
    if (n > 0) elements_.push_back(std::move(c));
  }
}

void RunHealth::Declare(ResultFile& out) {
  out_ = &out;
  energy_series_ = out.AddSeries("/health/energy_balance", 4, "J", {"stored", "work_in", "dissipated", "residual"});
}

void RunHealth::Report(const std::string& check, const std::string& element, double t, double value, double limit,
                       bool stops, const std::string& cause) {
  // One warning per check and element: the first time, then the count and the worst value
  auto it = std::find_if(warnings_.begin(), warnings_.end(),
                         [&](const HealthWarning& w) { return w.check == check && w.element == element; });
  if (it == warnings_.end()) {
    warnings_.push_back({.check = check, .element = element, .cause = cause, .t = t, .worst_value = value,
                         .worst_t = t, .limit = limit, .count = 0, .stops = false});
    it = warnings_.end() - 1;
  }
  ++it->count;
  if (std::abs(value) > std::abs(it->worst_value)) it->worst_value = value, it->worst_t = t;
  // Stop where the result is meaningless (or at any warning when strict)
  if (stops || options_.strict) {
    it->stops = true;
    throw RunHealthError(Text("t = %.6g s: ", t) + element + ": " + cause +
                         (stops ? "" : " (--strict: stopped at the first warning)"));
  }
}

void RunHealth::Start(const State& initial) {
  length_m_ = LengthScale(model_, data_, initial.q);
  if (integrator_.kind != IntegratorKind::kGeneralizedAlpha || model_.nv == 0) return;
  // The stiffest mode of the linearization at the start against the fixed step
  double f_max = 0;
  try {
    const ModalResult modes = CalcModes(Linearize(model_, initial));
    for (double f : modes.frequencies_hz) f_max = std::max(f_max, std::abs(f));
  } catch (const std::exception&) {
    return;  // no linearization (e.g. a singular reduced mass matrix): nothing to compare
  }
  const double h = output_interval_s_ > 0 ? std::min(integrator_.step, output_interval_s_) : integrator_.step;
  omega_max_h_ = 2 * std::numbers::pi * f_max * h;
  rho_infinity_ = SpectralRadiusAtInfinity(integrator_);
  // An unresolved mode is damped out when rho_inf < 1 (what a stiff spring standing for a rigid
  // connection relies on); without damping it aliases into the result
  if (omega_max_h_ > std::numbers::pi && rho_infinity_ > 0.99)
    Report("step_vs_stiffest_mode", "run", initial.t, omega_max_h_, std::numbers::pi, false,
           Text("the step %.3g s spans %.3g periods of the stiffest mode (%.4g Hz at the start, omega h = %.3g > pi), "
                "and generalized-alpha without damping (rho_inf %.3g) leaves that mode to alias into the result; "
                "reduce solver.step below %.3g s or set solver.rho_inf below 1",
                h, f_max * h, f_max, omega_max_h_, rho_infinity_, 1 / (2 * f_max)));
}

void RunHealth::OnStep(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& v, const Data* at_q) {
  // Positions and velocities finite
  if (!q.allFinite() || !v.allFinite()) {
    int k = 0;
    while (k < v.size() && std::isfinite(v(k))) ++k;
    int i = 0;
    while (i < q.size() && std::isfinite(q(i))) ++i;
    Report("non_finite", k < v.size() ? CoordinateName(model_, k) : PositionName(model_, i), t,
           std::numeric_limits<double>::quiet_NaN(), 0, true, "a position or velocity is not finite (the solution diverged)");
  }
  // Meshes after every fixed step (generalized-alpha); IDA's error control resolves the
  // deflections, so its rows suffice (a kinematics pass per step cost 14 % of seed003_lumped_healthy)
  if (model_.gear_meshes.empty() || integrator_.kind != IntegratorKind::kGeneralizedAlpha) return;
  // The gear angles (once per gear for all its meshes) are all the check reads: from the
  // coordinates alone where the model allows, else from the frame poses (the integrator's at q
  // where it has them: GearAngleAt reads the same poses and q_normalized CalcFramePoses would
  // leave in data_, so the angles are the same to the last bit).
  if (model_.gear_angles_by_coordinates) {
    for (std::size_t i = 0; i < model_.gear_angles.size(); ++i)
      data_.gear_angle[i] = GearAngleFromCoordinates(model_.gear_angles[i], q.data());
  } else if (at_q) {
    for (std::size_t i = 0; i < model_.gear_angles.size(); ++i)
      data_.gear_angle[i] = GearAngleAt(model_, *at_q, static_cast<int>(i));
  } else {
    CalcFramePoses(model_, q, data_);
    CalcGearAngles(model_, data_);
  }
  CheckMeshes(t, data_, true);
}

void RunHealth::CheckMeshes(double t, const Data& d, bool angles_current) {
  for (std::size_t i = 0; i < model_.gear_meshes.size(); ++i) {
    const GearMesh& m = model_.gear_meshes[i];
    const double p = m.geometry.base_pitch;
    if (!(p > 0) || m.small_rotations_only) continue;
    const GearMeshSpec& s = m.spec;
    const double e =
        angles_current ? MeshTransmissionCoordinate(m.geometry, s.base_radius_a, s.base_radius_b, s.backlash,
                                                    d.gear_angle[m.angle_a], d.gear_angle[m.angle_b])
                       : CalcMeshState(m.geometry, d, s.gear_a, s.gear_b, s.reference, s.base_radius_a,
                                       s.base_radius_b, s.backlash).e;
    // Past its flank by more than the fraction of a pitch, or a jump of half a pitch
    const double past = std::abs(e + 0.5 * s.backlash) - 0.5 * s.backlash;
    const double jump = std::abs(e - mesh_e_prev_[i]);
    mesh_e_prev_[i] = e;
    const double limit = options_.ratchet_fraction * p;
    if (past > limit)
      Report("mesh_ratchet", "mesh '" + s.name + "'", t, past / p, options_.ratchet_fraction, true,
             Text("the deflection reached %.3g base pitches past the flank (%.3g mm, base pitch %.3g mm): the teeth "
                  "ratchet past each other (the mesh is too soft for its load, or the step too large)",
                  past / p, 1e3 * past, 1e3 * p));
    if (jump > 0.5 * p)
      Report("mesh_ratchet", "mesh '" + s.name + "'", t, jump / p, 0.5, true,
             Text("the deflection jumped by %.3g base pitches in one step (%.3g mm, base pitch %.3g mm): the teeth "
                  "ratchet past each other (the mesh is too soft for its load, or the step too large)",
                  jump / p, 1e3 * jump, 1e3 * p));
  }
}

void RunHealth::CheckMeshRates(double t, const Data& d, double step_s) {
  for (const GearMesh& m : model_.gear_meshes) {
    const double p = m.geometry.base_pitch;
    if (!(p > 0) || m.small_rotations_only || !(step_s > 0)) continue;
    const GearMeshSpec& s = m.spec;
    // The rate reads the lever points and normals, not the angles: those of the model's angles.
    const MeshState st = CalcMeshState(m.geometry, d, s.gear_a, s.gear_b, s.reference, s.base_radius_a,
                                       s.base_radius_b, s.backlash, GearAngleAt(model_, d, m.angle_a),
                                       GearAngleAt(model_, d, m.angle_b));
    const double rate = CalcMeshRate(model_, d, s.gear_a, s.gear_b, s.reference, st, st.n_drive_W);
    const double roll = std::abs(rate) * step_s / p;
    if (roll > options_.ratchet_fraction)
      Report("mesh_ratchet", "mesh '" + s.name + "'", t, roll, options_.ratchet_fraction, true,
             Text("the gears roll %.3g base pitches against each other per step (%.3g m/s along the line of action, "
                  "step %.3g s): the step skips teeth and the speeds are wrong; reduce solver.step below %.3g s",
                  roll, rate, step_s, options_.ratchet_fraction * p / std::abs(rate)));
  }
}

void RunHealth::OnOutput(const State& state, const Eigen::VectorXd& lambda, const Data& evaluated, double step_s) {
  if (integrator_.kind == IntegratorKind::kIda) CheckMeshes(state.t, evaluated, false);
  CheckMeshRates(state.t, evaluated, step_s);
  CheckEnergy(state, lambda, evaluated);
  CheckDrift(state, evaluated);
  CheckElements(state.t, evaluated);
}

void RunHealth::CheckEnergy(const State& s, const Eigen::VectorXd& lambda, const Data& d) {
  // Energy stored and the power flowing in (applied, drivers) and out (dissipated)
  const double kinetic = CalcKineticEnergy(model_, d);
  const double potential = CalcGravityPotential(model_, d) + d.potential_energy;
  double p_drivers = 0;
  for (std::size_t k = 0; k < model_.drivers.size(); ++k)
    p_drivers += -lambda(model_.driver_row[k]) * s.v(model_.drivers[k].v_index);
  const double p_in = d.power_applied + p_drivers;
  const double p_net = p_in - d.power_dissipated;
  const double p_abs = std::abs(d.power_applied) + std::abs(p_drivers) + std::abs(d.power_dissipated);
  ++energy_rows_;
  if (energy_rows_ == 1) {
    e0_ = kinetic + potential;
    v0_ = potential;
  } else {
    // Trapezoid rule from the previous row; its error over the previous interval estimated from
    // the second difference of the net power, dt (P_k+1 - 2 P_k + P_k-1) / 12 (the first
    // interval takes the first estimate twice); summed with their signs, the estimate of the
    // whole integral's error (trapezoid against Simpson)
    const double dt = s.t - t_prev_;
    work_in_ += 0.5 * dt * (p_in + in_prev_);
    dissipated_ += 0.5 * dt * (d.power_dissipated + diss_prev_);
    abs_work_ += 0.5 * dt * (p_abs + abs_p_prev_);
    if (energy_rows_ >= 3) {
      const double e = dt * (p_net - 2 * net_prev_ + net_prev2_) / 12;
      quadrature_error_ += energy_rows_ == 3 ? 2 * e : e;
    }
  }
  net_prev2_ = net_prev_, net_prev_ = p_net;
  t_prev_ = s.t, in_prev_ = p_in, diss_prev_ = d.power_dissipated, abs_p_prev_ = p_abs;
  const double stored = kinetic + potential - e0_;
  const double residual = stored - work_in_ + dissipated_;
  scale_ = std::max({scale_, kinetic, std::abs(potential - v0_), abs_work_});
  if (out_ != nullptr && energy_series_ >= 0) {
    const double row[4] = {stored, work_in_, dissipated_, residual};
    out_->Append(energy_series_, row);
  }
  // Judged from the third row on, beyond what the quadrature of the rows can tell (twice its
  // estimated error): a power varying faster than the output interval is not integrated by the
  // rows, and the balance cannot be checked closer than that
  if (!(scale_ > 0)) return;
  energy_relative_ = std::abs(residual) / scale_;
  energy_quadrature_relative_ = 2 * std::abs(quadrature_error_) / scale_;
  energy_excess_ = energy_rows_ < 3 ? 0.0 : std::max(0.0, std::abs(residual) - 2 * std::abs(quadrature_error_)) / scale_;
  if (energy_excess_ > worst_energy_) worst_energy_ = energy_excess_, worst_energy_t_ = s.t;
  last_residual_ = residual, last_stored_ = stored;
}

void RunHealth::Finish(double t) {
  // The energy balance over the whole run (a start transient weighs less as the run goes on)
  if (!(energy_excess_ <= options_.energy_warning))
    Report("energy_balance", "run", t, energy_excess_, options_.energy_warning, false,
           Text("the energy balance is off by %.3g J at the end, %.3g of the run's energy scale %.3g J beyond the "
                "rows' quadrature error %.3g J (stored %.3g J, work in %.3g J, dissipated %.3g J; largest %.3g at "
                "t = %.6g s): the integration is not accurate, a force element does not account its energy, or the "
                "power varies faster than output.interval can integrate",
                last_residual_, energy_excess_, scale_, std::abs(quadrature_error_), last_stored_, work_in_,
                dissipated_, worst_energy_, worst_energy_t_));
}

double RunHealth::DriftTolerance() const {
  const double solver = integrator_.kind == IntegratorKind::kIda ? integrator_.rtol : integrator_.newton_tolerance;
  return std::max(options_.drift_tolerance, 100 * solver);
}

void RunHealth::CheckDrift(const State& s, const Data& d) {
  if (model_.n_constraints == 0) return;
  // Position rows against the model's length
  Eigen::Index worst = 0;
  const double phi = model_.n_holonomic > 0 ? d.phi.cwiseAbs().maxCoeff(&worst) : 0.0;
  max_phi_ = std::max(max_phi_, phi);
  const double phi_limit = DriftTolerance() * length_m_;
  if (phi > phi_limit)
    Report("constraint_drift", ConstraintRowName(model_, static_cast<int>(worst)), s.t, phi, phi_limit, false,
           Text("|Phi| = %.3g (m or rad) exceeds %.3g: the constraint drifted; tighten the tolerances", phi, phi_limit));
  // Velocity rows against length times the largest angular speed
  double omega = 1;
  for (BodyIndex b = 1; b < model_.nbodies; ++b) omega = std::max(omega, d.V_WB[b].head<3>().norm());
  double phidot = 0;
  int worst_row = 0;
  for (int r = 0; r < model_.n_constraints; ++r) {
    const double x = std::abs(d.G.row(r).dot(s.v) + d.g_t(r));
    if (x > phidot) phidot = x, worst_row = r;
  }
  max_phidot_ = std::max(max_phidot_, phidot);
  const double phidot_limit = DriftTolerance() * length_m_ * omega;
  if (phidot > phidot_limit)
    Report("constraint_drift", ConstraintRowName(model_, worst_row), s.t, phidot, phidot_limit, false,
           Text("|G v + g_t| = %.3g (m/s or rad/s) exceeds %.3g: the velocity constraint drifted; tighten the "
                "tolerances",
                phidot, phidot_limit));
}

void RunHealth::CheckElements(double t, const Data& d) {
  for (ElementChecks& c : elements_) {
    const auto& element = model_.external_forces[static_cast<std::size_t>(c.element)];
    const auto* reporter = dynamic_cast<const ElementHealthReporter*>(element.get());
    reporter->GetHealthValues(*d.external[static_cast<std::size_t>(c.element)], c.values.data());
    for (Eigen::Index k = 0; k < c.values.size(); ++k) {
      const ElementHealthCheck& check = c.checks[static_cast<std::size_t>(k)];
      const double x = c.values(k);
      if (x > c.max(k)) c.max(k) = x, c.max_t(k) = t;
      if (!(x <= check.limit))
        Report(check.name, "element '" + element->name() + "'", t, x, check.limit, check.stops,
               Text("%s = %.3g %s exceeds %.3g %s: ", check.name.c_str(), x, check.unit.c_str(), check.limit,
                    check.unit.c_str()) +
                   check.cause);
    }
  }
}

void RunHealth::Write(ResultFile& out) const {
  const std::string g = "/health";
  // Summary attributes
  bool stopped = false;
  for (const HealthWarning& w : warnings_) stopped = stopped || w.stops;
  out.SetAttribute(g, "warnings", static_cast<std::int64_t>(warnings_.size()));
  out.SetAttribute(g, "stopped", std::int64_t{stopped ? 1 : 0});
  out.SetAttribute(g, "energy_residual_relative", energy_relative_);
  out.SetAttribute(g, "energy_quadrature_relative", energy_quadrature_relative_);
  out.SetAttribute(g, "max_abs_phi", max_phi_);
  out.SetAttribute(g, "max_abs_phidot", max_phidot_);
  out.SetAttribute(g, "omega_max_h", omega_max_h_);
  out.SetAttribute(g, "rho_infinity", rho_infinity_);
  // Warnings, one entry per check and element
  if (!warnings_.empty()) {
    std::vector<std::string> check, element, cause;
    std::vector<double> t, worst_t, worst, limit, count;
    for (const HealthWarning& w : warnings_) {
      check.push_back(w.check), element.push_back(w.element), cause.push_back(w.cause);
      t.push_back(w.t), worst_t.push_back(w.worst_t), worst.push_back(w.worst_value), limit.push_back(w.limit);
      count.push_back(static_cast<double>(w.count));
    }
    out.WriteStrings(g + "/warnings/check", check);
    out.WriteStrings(g + "/warnings/element", element);
    out.WriteStrings(g + "/warnings/cause", cause);
    out.WriteVector(g + "/warnings/time", t, "s");
    out.WriteVector(g + "/warnings/worst_time", worst_t, "s");
    out.WriteVector(g + "/warnings/worst_value", worst, "1");
    out.WriteVector(g + "/warnings/limit", limit, "1");
    out.WriteVector(g + "/warnings/count", count, "1");
  }
  // Largest values of the elements' checks
  for (const ElementChecks& c : elements_) {
    const std::string name = model_.external_forces[static_cast<std::size_t>(c.element)]->name();
    for (std::size_t k = 0; k < c.checks.size(); ++k) {
      const std::string path = g + "/elements/" + name + "/" + c.checks[k].name;
      const auto i = static_cast<Eigen::Index>(k);
      out.SetAttribute(path, "max", std::isfinite(c.max(i)) ? c.max(i) : 0.0);
      out.SetAttribute(path, "max_time", c.max_t(i));
      out.SetAttribute(path, "limit", c.checks[k].limit);
      out.SetAttribute(path, "unit", c.checks[k].unit);
    }
  }
}

}  // namespace orrery

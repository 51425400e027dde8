// Tests for mbd/run_health.cpp: each check of a run's health on a model built to trip it (and one
// built not to), against closed forms where the check measures a number: the stiffest mode of a
// spring-mass (omega = sqrt(k / m)), the spectral radius at infinity of generalized-alpha
// (rho_inf by construction, 1 for the trapezoidal rule), the static deflection of a lumped mesh
// under torque (T / (r_b k)), the kinetic energy a torque that reports no power puts into a rotor
// ((T t)^2 / (2 J)).
#include "mbd/run_health.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "mbd/constraints.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/external_force.h"
#include "mbd/hdf5_reader.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "tests/common/plain_test_element.h"

namespace orrery {
namespace {

constexpr double kPi = std::numbers::pi;

// A mass on a prismatic joint with a spring to ground: omega = sqrt(k / m).
std::shared_ptr<const Model> SpringMass(double mass_kg, double k_n_per_m) {
  ModelBuilder b;
  const BodyIndex body = b.AddBody("mass", mass_kg, Vec3::Zero(), Mat3::Identity() * 1e-3);
  const JointIndex slide = b.AddJoint({.name = "slide", .type = JointType::kPrismatic, .parent = kWorldBody,
                                       .child = body, .axis = Vec3::UnitX()});
  b.AddCoordinateSpring({.name = "spring", .joint = slide, .coordinate = 0, .stiffness = k_n_per_m});
  b.SetJointPosition(slide, Eigen::VectorXd::Constant(1, 1e-3));
  return std::move(b).Finalize();
}

IntegratorOptions Alpha(double h, double rho) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = h;
  o.rho_inf = rho;
  return o;
}

TEST(RunHealth, StepAgainstTheStiffestModeWarnsOnlyWithoutDamping) {
  const double m = 2.0, k = 2e8;  // omega = 1e4 rad/s
  const auto model = SpringMass(m, k);
  const double omega = std::sqrt(k / m), h = 1e-3;  // omega h = 10
  // No damping: the mode aliases, a warning with omega h
  RunHealth undamped(*model, Alpha(h, 1.0), {}, 1.0);
  undamped.Start(State::Initial(*model));
  EXPECT_NEAR(undamped.omega_max_h(), omega * h, 1e-6 * omega * h);
  EXPECT_NEAR(undamped.rho_infinity(), 1.0, 1e-6);
  ASSERT_EQ(undamped.warnings().size(), 1u);
  EXPECT_EQ(undamped.warnings()[0].check, "step_vs_stiffest_mode");
  // rho_inf 0.9: damped out, reported only; the spectral radius is the method's
  RunHealth damped(*model, Alpha(h, 0.9), {}, 1.0);
  damped.Start(State::Initial(*model));
  EXPECT_NEAR(damped.rho_infinity(), 0.9, 1e-6);
  EXPECT_TRUE(damped.warnings().empty());
  // The output interval caps the step: at 1e-4 s, omega h = 1 < pi
  RunHealth capped(*model, Alpha(h, 1.0), {}, 1e-4);
  capped.Start(State::Initial(*model));
  EXPECT_NEAR(capped.omega_max_h(), omega * 1e-4, 1e-6);
  EXPECT_TRUE(capped.warnings().empty());
  // Newmark's trapezoidal rule (explicit parameters 0, 0, 1/4, 1/2) does not damp either
  IntegratorOptions newmark = Alpha(h, 0.5);
  newmark.alpha_m = 0, newmark.alpha_f = 0, newmark.beta = 0.25, newmark.gamma = 0.5;
  RunHealth trapezoidal(*model, newmark, {}, 1.0);
  trapezoidal.Start(State::Initial(*model));
  EXPECT_NEAR(trapezoidal.rho_infinity(), 1.0, 1e-6);
  EXPECT_EQ(trapezoidal.warnings().size(), 1u);
}

TEST(RunHealth, NonFiniteStateStopsNamingTheJoint) {
  const auto model = SpringMass(1.0, 1e3);
  RunHealth health(*model, Alpha(1e-3, 0.9), {}, 1e-2);
  health.Start(State::Initial(*model));
  Eigen::VectorXd q = Eigen::VectorXd::Zero(1), v = Eigen::VectorXd::Zero(1);
  health.OnStep(0.001, q, v);  // finite: nothing
  v(0) = std::numeric_limits<double>::quiet_NaN();
  try {
    health.OnStep(0.002, q, v);
    FAIL() << "a NaN velocity passed";
  } catch (const RunHealthError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("t = 0.002 s"), std::string::npos) << what;
    EXPECT_NE(what.find("joint 'slide' coordinate 0"), std::string::npos) << what;
  }
}

// Two gears on revolute joints (30 and 50 teeth, base radii 30 and 50 mm, 20 deg), a lumped mesh
// of stiffness k; gear b held by a speed driver at 0, gear a under torque T: the static
// deflection along the line of action is T / (r_ba k).
std::shared_ptr<const Model> LoadedPair(double torque_n_m, double k_n_per_m) {
  ModelBuilder b;
  const double alpha = 20 * kPi / 180, rba = 0.03, rbb = 0.05;
  const BodyIndex ga = b.AddBody("a", 1.0, Vec3::Zero(), Vec3(1e-4, 1e-4, 2e-4).asDiagonal());
  const BodyIndex gb = b.AddBody("b", 2.0, Vec3::Zero(), Vec3(5e-4, 5e-4, 1e-3).asDiagonal());
  const JointIndex ja = b.AddJoint({.name = "ja", .type = JointType::kRevolute, .parent = kWorldBody, .child = ga});
  const JointIndex jb = b.AddJoint({.name = "jb", .type = JointType::kRevolute, .parent = kWorldBody, .child = gb,
                                    .X_PF = Transform::Translation(Vec3((rba + rbb) / std::cos(alpha), 0, 0))});
  GearMeshSpec s;
  s.name = "pair";
  s.gear_a = b.body_frame(ga), s.gear_b = b.body_frame(gb);
  s.teeth_a = 30, s.teeth_b = 50, s.base_radius_a = rba, s.base_radius_b = rbb;
  s.working_pressure_angle = alpha;
  s.stiffness = k_n_per_m;
  s.damping_ratio = 0.3;
  b.AddGearMesh(s);
  b.AddDriver({.name = "hold", .joint = jb, .coordinate = 0, .mode = DriverSpec::Mode::kSpeed,
               .function = TimeFunction::Constant(0)});
  b.AddJointLoad({.name = "torque", .joint = ja, .coordinate = 0, .function = TimeFunction::Constant(torque_n_m)});
  return std::move(b).Finalize();
}

TEST(RunHealth, LumpedMeshDeflectedBeyondAQuarterPitchStopsTheRun) {
  const double k = 1e5, rba = 0.03, pitch = 2 * kPi * rba / 30;  // 6.28 mm
  SimulationOptions o;
  o.end_time = 0.5;
  o.output_interval = 1e-3;
  o.integrator = Alpha(1e-4, 0.9);
  // Static deflection 0.1 pitch (overshoot with damping ratio 0.3: below 0.2): runs through
  const auto light = LoadedPair(0.1 * pitch * rba * k, k);
  const SimulationReport ok = Simulate(*light, o, nullptr);
  EXPECT_TRUE(ok.health.empty());
  // 0.6 pitch: the teeth would ratchet; stopped when the deflection passes a quarter pitch
  const auto heavy = LoadedPair(0.6 * pitch * rba * k, k);
  try {
    Simulate(*heavy, o, nullptr);
    FAIL() << "a mesh loaded past half a pitch ran through";
  } catch (const RunHealthError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("mesh 'pair'"), std::string::npos) << what;
    EXPECT_NE(what.find("ratchet"), std::string::npos) << what;
  }
  // The same under IDA (checked at the rows)
  o.integrator = IntegratorOptions();
  EXPECT_THROW(Simulate(*heavy, o, nullptr), RunHealthError);
}

// A torque on a rotor that reports no power (an element that forgets its energy): the energy
// balance is off by the kinetic energy it put in, (T t)^2 / (2 J).
class SilentTorque final : public test_support::PlainTestElement {
 public:
  explicit SilentTorque(BodyIndex body, double torque) : body_(body), torque_(torque) {}
  const std::string& name() const override { return name_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model&) const override {
    return std::make_unique<ExternalForceWorkspace>();
  }
  void Apply(const Model&, double, Data& data, ExternalForceWorkspace&) const override {
    data.f_ext[body_].head<3>() += Vec3(0, 0, torque_);
  }

 private:
  std::string name_ = "silent";
  BodyIndex body_;
  double torque_;
};

std::shared_ptr<const Model> Rotor(double torque, bool accounted) {
  ModelBuilder b;
  const BodyIndex rotor = b.AddBody("rotor", 1.0, Vec3::Zero(), Vec3(0.01, 0.01, 0.02).asDiagonal());
  const JointIndex j = b.AddJoint({.name = "spin", .type = JointType::kRevolute, .parent = kWorldBody, .child = rotor});
  if (accounted)
    b.AddJointLoad({.name = "torque", .joint = j, .coordinate = 0, .function = TimeFunction::Constant(torque)});
  else
    b.AddExternalForce(std::make_shared<SilentTorque>(rotor, torque));
  return std::move(b).Finalize();
}

TEST(RunHealth, EnergyBalanceWarnsWhenAnElementForgetsItsWork) {
  const double torque = 2.0, J = 0.02, t_end = 0.5;
  SimulationOptions o;
  o.end_time = t_end;
  o.output_interval = 1e-2;
  o.integrator.rtol = 1e-9, o.integrator.atol = 1e-12;
  // Accounted (a joint load reports its power): balanced to the integration error
  const SimulationReport ok = Simulate(*Rotor(torque, true), o, nullptr);
  EXPECT_TRUE(ok.health.empty());
  EXPECT_LT(ok.energy_residual_relative, 1e-6);
  // Not accounted: the residual is all the kinetic energy, the whole scale
  const std::string path = ::testing::TempDir() + "orrery_energy_" + std::to_string(::getpid()) + ".h5";
  SimulationReport off;
  {
    ResultFile out = ResultFile::Create(path);
    off = Simulate(*Rotor(torque, false), o, &out);
  }
  ASSERT_EQ(off.health.size(), 1u);
  EXPECT_EQ(off.health[0].check, "energy_balance");
  EXPECT_NEAR(off.health[0].t, t_end, 1e-12);
  EXPECT_NEAR(off.energy_residual_relative, 1.0, 1e-6);
  const double kinetic = (torque * t_end) * (torque * t_end) / (2 * J);
  const Eigen::MatrixXd balance = Hdf5Reader(path).ReadMatrix("/health/energy_balance");
  EXPECT_NEAR(balance(balance.rows() - 1, 3), kinetic, 1e-6 * kinetic);  // residual column
  std::filesystem::remove(path);
}

TEST(RunHealth, ConstraintDriftNamesTheRow) {
  // A free body pinned to the world by a spherical cut (3 rows, 6 coordinates)
  ModelBuilder b;
  const BodyIndex ball = b.AddBody("ball", 1.0, Vec3::Zero(), Mat3::Identity() * 0.01);
  b.AddJoint({.name = "float", .type = JointType::kFree, .parent = kWorldBody, .child = ball});
  const FrameIndex anchor = b.AddFrame("anchor", kWorldBody, Transform());
  b.AddLoopClosure({.name = "pin", .type = JointType::kSpherical, .frame_a = anchor, .frame_b = b.body_frame(ball)});
  const auto model = std::move(b).Finalize();
  // A state 1 mm off the pin along x
  State s = State::Initial(*model);
  Data data(*model);
  s.q(model->joints[0].q_start) += 1e-3;
  Eigen::VectorXd vdot = Eigen::VectorXd::Zero(model->nv), lambda = Eigen::VectorXd::Zero(model->n_constraints);
  EvaluateDynamics(*model, 0, s.q, s.v, vdot, data);
  RunHealth health(*model, IntegratorOptions(), {}, 1e-2);
  health.Start(State::Initial(*model));
  health.OnOutput(s, lambda, data, 1e-3);
  ASSERT_EQ(health.warnings().size(), 1u);
  EXPECT_EQ(health.warnings()[0].check, "constraint_drift");
  EXPECT_EQ(health.warnings()[0].element, "loop closure 'pin' row 0");
  EXPECT_NEAR(health.max_abs_phi(), 1e-3, 1e-9);
}

// An element with checks of its own (element_health.h): a value it reports against its limit.
class ReportingElement final : public test_support::PlainTestElement, public ElementHealthReporter {
 public:
  ReportingElement(double value, bool stops) : value_(value), stops_(stops) {}
  const std::string& name() const override { return name_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model&) const override {
    return std::make_unique<ExternalForceWorkspace>();
  }
  void Apply(const Model&, double, Data&, ExternalForceWorkspace&) const override {}
  std::vector<ElementHealthCheck> HealthChecks() const override {
    return {{.name = "penetration", .unit = "m", .limit = 1e-4, .stops = stops_,
             .cause = "beyond the contact margin"}};
  }
  void GetHealthValues(const ExternalForceWorkspace&, double* values) const override { values[0] = value_; }

 private:
  std::string name_ = "teeth";
  double value_;
  bool stops_;
};

std::shared_ptr<const Model> WithElement(double value, bool stops) {
  ModelBuilder b;
  const BodyIndex body = b.AddBody("body", 1.0, Vec3::Zero(), Mat3::Identity() * 0.01);
  b.AddJoint({.name = "spin", .type = JointType::kRevolute, .parent = kWorldBody, .child = body});
  b.AddExternalForce(std::make_shared<ReportingElement>(value, stops));
  return std::move(b).Finalize();
}

TEST(RunHealth, ForceElementsReportTheirOwnChecks) {
  SimulationOptions o;
  o.end_time = 0.01;
  o.output_interval = 1e-3;
  // Within the limit: nothing; beyond it: a warning naming the element, written to /health
  EXPECT_TRUE(Simulate(*WithElement(5e-5, false), o, nullptr).health.empty());
  const std::string path = ::testing::TempDir() + "orrery_run_health_" + std::to_string(::getpid()) + ".h5";
  {
    ResultFile out = ResultFile::Create(path);
    const SimulationReport r = Simulate(*WithElement(2e-3, false), o, &out);
    ASSERT_EQ(r.health.size(), 1u);
    EXPECT_EQ(r.health[0].element, "element 'teeth'");
    EXPECT_EQ(r.health[0].count, 11);  // every row
  }
  {
    const Hdf5Reader in(path);
    EXPECT_EQ(in.ReadStrings("/health/warnings/check"), std::vector<std::string>{"penetration"});
    EXPECT_EQ(in.ReadStrings("/health/warnings/element"), std::vector<std::string>{"element 'teeth'"});
    EXPECT_DOUBLE_EQ(in.ReadNumberAttribute("/health/elements/teeth/penetration", "max"), 2e-3);
    EXPECT_EQ(in.ReadIntAttribute("/health", "warnings"), 1);
    EXPECT_EQ(in.ReadMatrix("/health/energy_balance").rows(), 11);
  }
  std::filesystem::remove(path);
  // A check that stops, and any warning under --strict
  EXPECT_THROW(Simulate(*WithElement(2e-3, true), o, nullptr), RunHealthError);
  o.health.strict = true;
  EXPECT_THROW(Simulate(*WithElement(2e-3, false), o, nullptr), RunHealthError);
}

}  // namespace
}  // namespace orrery

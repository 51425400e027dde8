// Stability at the extremes (issue 16, docs/extremes.md), the short versions of the sweep
// (models/studies/extremes_*.yaml, tools/run_extremes.sh) through the `orrery` program: one case
// per family, each either meeting its accuracy check against a closed form or stopping with a
// message that names the time and the element and leaves a readable result file up to then.
//   - stiffness: the linear oscillator (models/scenes/oscillator.yaml) at k = 1e11 N/m, 10
//     periods, IDA and generalized-alpha: the end state within 1e-2 x0 of x0 (closed form);
//   - damping: critical damping (c = 2 sqrt(k m)) and none: x(t) = x0 (1 + w t) exp(-w t);
//   - step: w h = 10 > pi: without numerical damping the run warns naming the step and the
//     stiffest mode, --strict stops at t = 0; with rho_inf 0.9 the lost energy warns; at
//     w h = 0.5, 3 and 10 the end state is the generalized-alpha recurrence's (Chung & Hulbert
//     1993) to the Newton tolerance, far as it is from the continuous closed form;
//   - seed 003 lumped at a 1 ms generalized-alpha step (omega_max h = 62) meets Willis; in tooth
//     contact at a 20 ms step Newton stops naming the time and the joint;
//   - planet mass 1e-3 kg and speed 30,000 r/min: kinematic ratios (Willis; slider position);
//     1 r/min over 0.2 s: Willis over the settled second half;
//   - mesh stiffness 1e6 N/m under seed 003's load: stops naming the mesh (its teeth ratchet);
//     tooth contact at 1e6 N/m: stops naming the contact when the teeth have passed half the
//     thinner tooth (3.13 mm), the result file read up to then;
//   - the parallelogram four-bar through its singular position: IDA passes on the parallelogram
//     branch (rocker = crank); an output row at the singular time, or generalized-alpha, stops
//     naming the time and the closure row that loses its rank;
//   - drift: 10^4 generalized-alpha steps of the conservative four-bar (rho_inf 1), the energy
//     residual's growth bounded (theory in the test) and |Phi| at the Newton tolerance;
//   - load reversal across 100 um of backlash: the engaged flank changes side, the energy balance
//     closes, the carrier keeps Willis' speed.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "mbd/hdf5_reader.h"
#include "tests/common/cli_support.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using test_support::RunCommand;

const std::string kOrrery = std::string(ORRERY_BINARY_DIR) + "/bin/orrery";
constexpr double kPi = 3.14159265358979323846;
constexpr double kX0 = 1e-3;  // oscillator.yaml's initial displacement (m)
// Seed 003's carrier speed from Willis' equation: ring 80.6 rad/s (50 teeth), sun -10 rad/s (22).
constexpr double kWillis = (50 * 80.6 + 22 * -10.0) / 72;

// A number as the shortest text that reads back as the same double.
std::string Num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string Scene(const std::string& name) { return std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + name; }

std::string Out(const std::string& stem) {
  const fs::path dir = fs::temp_directory_path() / ("orrery_extremes_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / (stem + ".h5")).string();
}

// Last value of column `col` of a dataset.
double Last(const std::string& file, const std::string& dataset, int col = 0) {
  const Eigen::MatrixXd m = Hdf5Reader(file).ReadMatrix(dataset);
  return m(m.rows() - 1, col);
}

// Mean of column 0 over the rows with t >= from.
double MeanFrom(const std::string& file, const std::string& dataset, double from) {
  const Hdf5Reader r(file);
  const Eigen::MatrixXd t = r.ReadMatrix("/time"), x = r.ReadMatrix(dataset);
  double sum = 0;
  int n = 0;
  for (Eigen::Index i = 0; i < t.rows(); ++i)
    if (t(i, 0) >= from) sum += x(i, 0), ++n;
  return n > 0 ? sum / n : NAN;
}

// The mean of a joint's speed from its angle: (q(t_end) - q(t_0)) / (t_end - t_0), t_0 the first
// row at or after `from` (what the joint turned through, not a few sampled speeds).
double MeanSpeedFromAngle(const std::string& file, const std::string& joint, double from) {
  const Hdf5Reader r(file);
  std::string dataset = "/joints/";
  dataset += joint;
  dataset += "/q";
  const Eigen::MatrixXd t = r.ReadMatrix("/time"), q = r.ReadMatrix(dataset);
  Eigen::Index first = 0;
  while (first < t.rows() && t(first, 0) < from) ++first;
  const Eigen::Index last = t.rows() - 1;
  return first < last ? (q(last, 0) - q(first, 0)) / (t(last, 0) - t(first, 0)) : NAN;
}

// Runs the oscillator with k (N/m) for 10 periods and returns max(|x - x0|, |v| / w) / x0.
double OscillatorError(double k, const std::string& integrator, const std::string& stem) {
  const double w = std::sqrt(k), end = 20 * kPi / w;
  const std::string out = Out(stem);
  const auto [text, status] = RunCommand(
      kOrrery + " run " + Scene("oscillator.yaml") + " --quiet -o " + out + " --integrator " + integrator +
      " --set force_elements.spring.stiffness=" + Num(k) + " --set solver.end_time=" + Num(end) +
      " --set output.interval=" + Num(end / 200) + " --set solver.step=" + Num(end / 2000));
  EXPECT_EQ(status, 0) << text;
  const double t = Last(out, "/time");
  EXPECT_NEAR(t, end, 1e-12 * end);
  const double x = kX0 * std::cos(w * t), v = -kX0 * w * std::sin(w * t);
  return std::max(std::abs(Last(out, "/joints/slide/q") - x), std::abs(Last(out, "/joints/slide/v") - v) / w) / kX0;
}

TEST(Extremes, StiffnessOf1e11MeetsTheOscillatorsClosedForm) {
  // IDA at rtol 1e-9; generalized-alpha at 200 steps a period (w h = 0.0314): the trapezoidal
  // period error w t (w h)^2 / 12 = 5.2e-3 over 10 periods bounds it.
  EXPECT_LT(OscillatorError(1e11, "ida", "k_ida"), 1e-4);
  EXPECT_LT(OscillatorError(1e11, "generalized_alpha", "k_ga"), 6e-3);
}

TEST(Extremes, CriticalAndZeroDampingMeetTheirClosedForms) {
  const double w = 1000, end = 20 * kPi / w;
  for (const double zeta : {0.0, 1.0}) {
    const std::string out = Out("zeta" + std::to_string(static_cast<int>(zeta)));
    const auto [text, status] = RunCommand(kOrrery + " run " + Scene("oscillator.yaml") + " --quiet -o " + out +
                                           " --set force_elements.spring.damping=" + Num(2000 * zeta));
    ASSERT_EQ(status, 0) << text;
    const double t = Last(out, "/time");
    EXPECT_NEAR(t, end, 1e-12);
    const double x = zeta == 0 ? kX0 * std::cos(w * t) : kX0 * (1 + w * t) * std::exp(-w * t);
    EXPECT_NEAR(Last(out, "/joints/slide/q"), x, 1e-5 * kX0) << zeta;
    EXPECT_EQ(text.find("warning"), std::string::npos) << text;
  }
}

TEST(Extremes, AStepBeyondTheStabilityLimitWarnsOrStops) {
  // w h = 10: 1.6 periods a step. rho_inf 1: the warning names the step and the mode.
  const std::string base = kOrrery + " run " + Scene("oscillator.yaml") +
                           " --integrator generalized_alpha --set solver.step=0.01 --set solver.end_time=0.2"
                           " --set output.interval=0.01";
  {
    const auto [text, status] = RunCommand(base + " --set solver.rho_inf=1 -o " + Out("step1"));
    EXPECT_EQ(status, 0) << text;
    EXPECT_NE(text.find("t = 0 s: run: the step 0.01 s spans 1.59 periods of the stiffest mode (159.2 Hz"),
              std::string::npos) << text;
  }
  {
    const auto [text, status] = RunCommand(base + " --set solver.rho_inf=1 --strict -o " + Out("step_strict"));
    EXPECT_EQ(status, 1) << text;
    EXPECT_NE(text.find("run stopped: t = 0 s: run: the step 0.01 s spans"), std::string::npos) << text;
    EXPECT_TRUE(Hdf5Reader(Out("step_strict")).Exists("/health")) << text;
  }
  {
    // rho_inf 0.9 damps the unresolved mode: the energy it takes is unaccounted, and that warns.
    const auto [text, status] = RunCommand(base + " --set solver.rho_inf=0.9 -o " + Out("step09"));
    EXPECT_EQ(status, 0) << text;
    EXPECT_NE(text.find("run: the energy balance is off by"), std::string::npos) << text;
  }
}

// The generalized-alpha recurrence (Chung & Hulbert 1993, J. Appl. Mech. 60:371; the
// pseudo-acceleration form of Arnold & Bruls 2007, the same amplification matrix on linear
// problems) for x'' + w^2 x = 0 from (x0, 0), a_0 = x''_0, over n steps of h, solved exactly:
//   (1 - am) a_1 + am a_0 = (1 - af) xdd_1 + af xdd_0,  v_1 = v_0 + h ((1 - g) a_0 + g a_1),
//   x_1 = x_0 + h v_0 + h^2 ((1/2 - b) a_0 + b a_1),  xdd_1 = -w^2 x_1.
// Returns {x, v} at the end.
std::pair<double, double> AlphaOscillator(double w, double rho, double h, int n) {
  const double am = (2 * rho - 1) / (rho + 1), af = rho / (rho + 1), g = 0.5 + af - am;
  const double b = 0.25 * (g + 0.5) * (g + 0.5), r = (1 - af) / (1 - am);
  double x = kX0, v = 0, xdd = -w * w * x, a = xdd;
  for (int k = 0; k < n; ++k) {
    const double p = (af * xdd - am * a) / (1 - am);
    const double vp = v + h * (1 - g) * a + h * g * p, xp = x + h * v + h * h * ((0.5 - b) * a + b * p);
    const double xdd1 = -w * w * xp / (1 + w * w * h * h * b * r);
    a = p + r * xdd1, v = vp + h * g * r * xdd1, x = xp + h * h * b * r * xdd1, xdd = xdd1;
  }
  return {x, v};
}

TEST(Extremes, AnyStepDoesWhatItsSchemePredicts) {
  // 20 steps of w h = 0.5, 3 and 10 (rho_inf 0.9): the end state is the recurrence's to 20 Newton
  // tolerances (1e-8 each) of x0, while the continuous closed form is off by O(1) at the larger
  // steps (the period error the tradeoff study measures).
  const double w = 1000;
  for (const double wh : {0.5, 3.0, 10.0}) {
    const double h = wh / w, end = 20 * h;
    const std::string out = Out("alpha" + std::to_string(static_cast<int>(10 * wh)));
    const auto [text, status] = RunCommand(kOrrery + " run " + Scene("oscillator.yaml") +
                                           " --quiet --integrator generalized_alpha --set solver.rho_inf=0.9 -o " +
                                           out + " --set solver.step=" + Num(h) + " --set solver.end_time=" +
                                           Num(end) + " --set output.interval=" + Num(h));
    ASSERT_EQ(status, 0) << text;
    ASSERT_EQ(Hdf5Reader(out).ReadMatrix("/time").rows(), 21);
    const auto [x, v] = AlphaOscillator(w, 0.9, h, 20);
    EXPECT_NEAR(Last(out, "/joints/slide/q"), x, 20 * 1e-8 * kX0) << wh;
    EXPECT_NEAR(Last(out, "/joints/slide/v"), v, 20 * 1e-8 * kX0 * w) << wh;
    if (wh > 1) {
      EXPECT_GT(std::abs(x - kX0 * std::cos(w * end)), 0.1 * kX0) << wh;
    }
  }
}

TEST(Extremes, StepsFarTooLargeForTheGearsMeetWillisOrStop) {
  {
    // Lumped meshes at 1 ms (omega_max h = 62, damped by rho_inf 0.9): Willis over the second half
    const std::string out = Out("lumped_1ms");
    const auto [text, status] = RunCommand(kOrrery + " run " + Scene("seed003_lumped_healthy.yaml") +
                                           " --quiet --integrator generalized_alpha --end-time 0.05"
                                           " --set solver.step=1e-3 --set output.interval=1e-3 -o " + out);
    ASSERT_EQ(status, 0) << text;
    EXPECT_NEAR(MeanFrom(out, "/joints/S.carrier/v", 0.025), kWillis, 1e-2 * kWillis);
  }
  {
    // Tooth contact at 20 ms with the scene's Newton (measured ends, Broyden updates, refreshes at
    // a contraction of 0.01): the steps go through in halvings (down to 78 us) and the carrier
    // turns at Willis's speed. Measured by the angle it turns through from 0.02 s to 0.05 s: at
    // these steps the sampled speed swings by 5 to 15 % from row to row (0.04 s: 55.7 rad/s
    // with the smoothed flank normals, 52.95 with the facets'; 0.07 s: 59.0 with the facets'),
    // so a mean of three samples measures the swing, not the train.
    const std::string out = Out("contact_20ms_scene_newton");
    const auto [text, status] =
        RunCommand(kOrrery + " run " + Scene("seed003_contact_healthy.yaml") +
                   " --quiet --end-time 0.05 --set solver.step=2e-2"
                   " --set output.interval=1e-2 -o " +
                   out);
    ASSERT_EQ(status, 0) << text;
    EXPECT_NEAR(MeanSpeedFromAngle(out, "S.carrier", 0.02), kWillis, 1e-2 * kWillis);
  }
  {
    // Tooth contact at 20 ms with the contraction estimate and the matrix kept to a contraction
    // of 0.1: Newton fails through 8 halvings and stops naming time and joint
    const std::string out = Out("contact_20ms");
    const auto [text, status] =
        RunCommand(kOrrery + " run " + Scene("seed003_contact_healthy.yaml") +
                   " --end-time 0.05 --set solver.step=2e-2 --set output.interval=2e-2"
                   " --set solver.newton_estimate=true --set solver.matrix_refresh_rate=0.1 -o " +
                   out);
    EXPECT_EQ(status, 1) << text;
    EXPECT_NE(text.find("Newton did not converge at t = 0.00015625 s"), std::string::npos) << text;
    EXPECT_NE(text.find("joint 'S."), std::string::npos) << text;
    EXPECT_EQ(Hdf5Reader(out).ReadMatrix("/time").rows(), 1);
  }
}

TEST(Extremes, OneRpmMeetsWillisOverTheSettledSecondHalf) {
  // The suddenly applied 6000 N m leaves a torsional transient of a fixed size in rad/s: at
  // 0.069 rad/s it weighs 8 % over 0.01-0.02 s, 2.6e-3 over 0.1-0.2 s.
  const std::string out = Out("one_rpm");
  const auto [text, status] = RunCommand(kOrrery + " run " + Scene("seed003_lumped_healthy.yaml") +
                                         " --quiet --end-time 0.2 --set output.interval=2e-5"
                                         " --set 'gear_train.input_speeds=[0.10471976, -0.012992525]' -o " + out);
  ASSERT_EQ(status, 0) << text;
  const double willis = (50 * 0.10471976 + 22 * -0.012992525) / 72;
  EXPECT_NEAR(MeanFrom(out, "/joints/S.carrier/v", 0.1), willis, 1e-2 * willis);
}

TEST(Extremes, PlanetMassOf1e3AndOneGramKeepWillisSpeed) {
  for (const double m : {1e-3, 1e3}) {
    const std::string out = Out(m < 1 ? "mass_light" : "mass_heavy");
    const auto [text, status] = RunCommand(
        kOrrery + " run " + Scene("seed003_lumped_healthy.yaml") + " --quiet --end-time 0.01 -o " + out +
        " --set 'gear_train.dynamics.members={S.planet: {mass: " + Num(m) + ", inertia: " + Num(m * 3.92e-4) +
        "}}'");
    ASSERT_EQ(status, 0) << text;
    EXPECT_NEAR(MeanFrom(out, "/joints/S.carrier/v", 0.005), kWillis, 1e-2 * kWillis) << m;
  }
}

TEST(Extremes, SliderCrankAt30000RpmEndsOnItsKinematicPosition) {
  // 2.25 turns: crank at 90 degrees, slider at sqrt(L^2 - r^2) moving at -r w.
  const double w = 30000 * kPi / 30, end = 2.25 * 2 * kPi / w;
  const std::string out = Out("speed");
  const auto [text, status] = RunCommand(
      kOrrery + " run " + Scene("slider_crank.yaml") + " --quiet -o " + out +
      " --set 'drivers.motor.function={type: constant, value_rpm: 30000}' --set solver.end_time=0.0045"
      " --set output.interval=1e-5");
  ASSERT_EQ(status, 0) << text;
  EXPECT_NEAR(Last(out, "/time"), end, 1e-12);
  EXPECT_NEAR(Last(out, "/joints/slider_guide/q"), std::sqrt(0.09 - 0.01), 1e-6);
  EXPECT_NEAR(Last(out, "/joints/slider_guide/v"), -0.1 * w, 1e-4 * 0.1 * w);
}

TEST(Extremes, AMeshTooSoftForItsLoadStopsNamingTheMesh) {
  // 1e6 N/m under ~15 kN: a deflection beyond a quarter base pitch (2.9 mm).
  const std::string out = Out("soft");
  const auto [text, status] = RunCommand(kOrrery + " run " + Scene("seed003_lumped_healthy.yaml") +
                                         " --end-time 0.05 --set gear_train.dynamics.mesh_stiffness=1e6 -o " + out);
  EXPECT_EQ(status, 1) << text;
  EXPECT_NE(text.find("run stopped: t = "), std::string::npos) << text;
  EXPECT_NE(text.find("mesh 'S."), std::string::npos) << text;
  const Eigen::MatrixXd t = Hdf5Reader(out).ReadMatrix("/time");
  EXPECT_GT(t.rows(), 1);
  EXPECT_TRUE(t.allFinite());
}

TEST(Extremes, AToothContactTooSoftForItsLoadStopsNamingTheContact) {
  // 1e6 N/m, 100 times softer than ISO's c' b: the load needs ~15 mm of approach and the teeth
  // pass through each other; the contact stops when its penetration passes half the thinner
  // tooth (the sun's, thinned for 20 um of backlash: 3.13 mm; models/gear_contact.h).
  const std::string out = Out("soft_contact");
  const auto [text, status] =
      RunCommand(kOrrery + " run " + Scene("seed003_contact_healthy.yaml") +
                 " --end-time 0.002 --set gear_train.dynamics.tooth_contact.single_pair_stiffness=1e6 -o " + out);
  EXPECT_EQ(status, 1) << text;
  EXPECT_NE(text.find("run stopped: t = 0.0011 s: element 'S.sun-planet#1': penetration_limit = "), std::string::npos)
      << text;
  EXPECT_NE(text.find("exceeds 0.00313 m: the teeth have passed through each other"), std::string::npos) << text;
  EXPECT_NE(text.find("holds 12 rows (t = 0 to 0.0011 s)"), std::string::npos) << text;
  // The file up to then: the penetration below the limit until the last row, beyond it there
  const Hdf5Reader r(out);
  const Eigen::MatrixXd t = r.ReadMatrix("/time"), p = r.ReadMatrix("/external/S.sun-planet#1/max_penetration");
  ASSERT_EQ(t.rows(), 12);
  EXPECT_NEAR(t(11, 0), 0.0011, 1e-12);
  EXPECT_LT(p(10, 0), 3.13e-3);
  EXPECT_GT(p(11, 0), 3.13e-3);
  EXPECT_DOUBLE_EQ(r.ReadNumberAttribute("/health", "stopped"), 1);
}

TEST(Extremes, FourBarThroughItsSingularPosition) {
  const std::string base = kOrrery + " run " + Scene("four_bar_singular.yaml") + " --end-time 0.5";
  {
    // IDA steps through t = 0.25 s (links in line) and stays on the parallelogram branch.
    const std::string out = Out("fb_pass");
    const auto [text, status] = RunCommand(base + " --set output.interval=7e-4 -o " + out);
    ASSERT_EQ(status, 0) << text;
    EXPECT_NEAR(Last(out, "/joints/rocker_hinge/q"), Last(out, "/joints/crank_hinge/q"), 1e-6);
  }
  for (const std::string integrator : {"ida", "generalized_alpha"}) {
    // An output row at the singular time (IDA), or a step onto it (generalized-alpha), stops.
    const std::string out = Out("fb_" + integrator);
    const auto [text, status] = RunCommand(base + " --integrator " + integrator + " -o " + out);
    EXPECT_EQ(status, 1) << text;
    EXPECT_NE(text.find("t = 0.25 s"), std::string::npos) << text;
    EXPECT_NE(text.find("loses a rank"), std::string::npos) << text;
    EXPECT_NE(text.find("loop closure 'coupler_rocker' row 0"), std::string::npos) << text;
    EXPECT_NE(text.find("holds 250 rows (t = 0 to 0.249 s)"), std::string::npos) << text;
    EXPECT_EQ(Hdf5Reader(out).ReadMatrix("/time").rows(), 250);
  }
}

TEST(Extremes, EnergyAndConstraintDriftOver1e4StepsStayBounded) {
  // Generalized-alpha with rho_inf = 1 (alpha_m = alpha_f = 1/2, beta = 1/4, gamma = 1/2) is the
  // trapezoidal rule on linear problems, which conserves their energy; on this nonlinear swing
  // its energy error is O((w h)^2), oscillates with the motion and has no secular trend. So the
  // residual's growth rate, the slope of a least-squares line through |r(t)|, times the run's
  // length, must stay below the residual's own size (a linear drift would double it over the
  // run), and the peak over the second half below twice that over the first. The closure rows
  // are solved to the Newton tolerance (1e-8 on the accelerations, scaled by beta h^2) at every
  // step, so |Phi| does not grow at all: below 1e-12 m of a 0.4 m linkage.
  const std::string out = Out("drift");
  const auto [text, status] = RunCommand(kOrrery + " run " + Scene("four_bar.yaml") +
                                         " --quiet --integrator generalized_alpha --end-time 1 -o " + out);
  ASSERT_EQ(status, 0) << text;
  const Hdf5Reader r(out);
  const Eigen::MatrixXd t = r.ReadMatrix("/time"), e = r.ReadMatrix("/health/energy_balance");
  const Eigen::MatrixXd drift = r.ReadMatrix("/constraints/drift"), energy = r.ReadMatrix("/energy");
  ASSERT_EQ(t.rows(), 1001);
  EXPECT_EQ(r.ReadNumberAttribute("/solver", "steps"), 10000);
  double st = 0, sr = 0, stt = 0, str = 0, first = 0, second = 0;
  const double kinetic = energy.col(0).maxCoeff();
  const double n = static_cast<double>(t.rows());
  for (Eigen::Index i = 0; i < t.rows(); ++i) {
    const double ti = t(i, 0), ri = std::abs(e(i, 3));
    st += ti, sr += ri, stt += ti * ti, str += ti * ri;
    (ti < 0.5 ? first : second) = std::max(ti < 0.5 ? first : second, ri);
  }
  const double slope = (n * str - st * sr) / (n * stt - st * st);
  EXPECT_GT(kinetic, 0.01);
  EXPECT_LT(first, 1e-4 * kinetic);
  EXPECT_LT(second, 2 * first + 1e-12);
  EXPECT_LT(std::abs(slope) * 1.0, std::max(first, second));
  EXPECT_LT(drift.col(0).maxCoeff(), 1e-12);
}

TEST(Extremes, LoadReversalAcrossBacklashKeepsTheBalance) {
  const std::string out = Out("backlash");
  const auto [text, status] = RunCommand(
      kOrrery + " run " + Scene("seed003_lumped_healthy.yaml") + " --end-time 0.03 -o " + out +
      " --set 'gear_train.output_torque={type: sine, amplitude: 6000, frequency_hz: 40}'"
      " --set gear_train.dynamics.contact=two_sided --set gear_train.dynamics.backlash_um=100");
  ASSERT_EQ(status, 0) << text;
  EXPECT_NE(text.find("health              ok"), std::string::npos) << text;
  // The engaged flank: +1 drive, -1 coast (the load reversed across the gap).
  const Eigen::MatrixXd flank = Hdf5Reader(out).ReadMatrix("/gear_meshes/S.sun-planet#1/contact");
  EXPECT_EQ(flank.minCoeff(), -1);
  EXPECT_EQ(flank.maxCoeff(), 1);
  EXPECT_NEAR(MeanFrom(out, "/joints/S.carrier/v", 0.015), kWillis, 1e-2 * kWillis);
}

}  // namespace
}  // namespace orrery

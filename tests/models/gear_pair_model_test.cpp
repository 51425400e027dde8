// The parallel-axis gear pair scene: ideal ratio and tooth force against the kinematics and the
// torque balance; torsional natural frequency with the ISO 6336 stiffness against the closed
// form; a run with the time-varying stiffness whose mesh force averages to the transmitted load
// and fluctuates at the mesh frequency Z_1 w_1 / 2 pi.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/linearization.h"
#include "mbd/simulation.h"
#include "models/gear_pair_model.h"

namespace orrery::gears {
namespace {

constexpr double kPi = 3.14159265358979323846;

GearSpec Spec(int z, bool internal = false) {
  GearSpec s;
  s.teeth = z;
  s.normal_module_m = 2e-3;
  s.face_width_m = 20e-3;
  s.internal = internal;
  // A ring with the standard addendum reaches into the pinion's fillet (gear_geometry rejects
  // it); rings are made with a shorter addendum.
  if (internal) s.addendum_coef = 0.8;
  return s;
}

TEST(GearPairModel, KinematicRatioAndToothForce) {
  for (bool internal : {false, true}) {
    const GearPair pair(Gear(Spec(internal ? 24 : 20)), Gear(Spec(internal ? 96 : 40, internal)));
    GearPairModelOptions o;
    o.mesh_model = GearPairModelOptions::MeshModel::kKinematic;
    o.bore_radius1_m = 5e-3;
    o.bore_radius2_m = internal ? 0.11 : 10e-3;
    o.input_speed = TimeFunction::Constant(50.0);
    o.initial_speed1 = 50.0;
    const double T = 30;  // load torque on gear 2, opposing its rotation
    const double z1 = internal ? 24 : 20, z2 = internal ? 96 : 40;
    const double w2 = (internal ? 1 : -1) * 50.0 * z1 / z2;
    o.load_torque = TimeFunction::Constant(w2 > 0 ? -T : T);
    const GearPairModel m = BuildGearPairModel(pair, o);
    IntegratorOptions io;
    io.rtol = 1e-9;
    io.atol = 1e-11;
    auto integ = MakeIntegrator(*m.model, io);
    integ->Initialize(State::Initial(*m.model));
    integ->AdvanceTo(0.05);
    const State& s = integ->state();
    EXPECT_NEAR(s.v(1) / s.v(0), m.ratio, 1e-9);
    EXPECT_NEAR(m.ratio, (internal ? 1.0 : -1.0) * z1 / z2, 1e-15);
    // At constant speed the tooth force carries the load: F r_b2 = T; the motor gives T / |i|.
    const double F = integ->lambda()(m.model->gear_constraint_row[0]);
    EXPECT_NEAR(std::abs(F), T / pair.gear2().base_radius_m(), 1e-6 * T / pair.gear2().base_radius_m());
    const double effort = -integ->lambda()(m.model->driver_row[0]);
    EXPECT_NEAR(std::abs(effort), T * z1 / z2, 1e-6 * T);
  }
}

TEST(GearPairModel, TorsionalFrequencyWithIsoStiffness) {
  const GearPair pair(Gear(Spec(20)), Gear(Spec(40)));
  GearPairModelOptions o;
  o.stiffness = GearPairModelOptions::Stiffness::kIso6336;
  o.contact = GearMeshSpec::Contact::kLinearDrive;
  o.bore_radius1_m = 5e-3;
  o.bore_radius2_m = 10e-3;
  const GearPairModel m = BuildGearPairModel(pair, o);
  const double k = CalcIso6336Stiffness(pair).c_gamma_alpha_n_per_m;
  EXPECT_EQ(m.mesh_stiffness_mean_n_per_m, k);
  const ModalResult modes = CalcModes(Linearize(*m.model, State::Initial(*m.model)));
  const double rb1 = pair.gear1().base_radius_m(), rb2 = pair.gear2().base_radius_m();
  const double f = std::sqrt(k * (rb1 * rb1 / m.inertia1 + rb2 * rb2 / m.inertia2)) / (2 * kPi);
  ASSERT_EQ(modes.frequencies_hz.size(), 2u);
  EXPECT_NEAR(modes.frequencies_hz[1], f, 1e-7 * f);
}

TEST(GearPairModel, TimeVaryingStiffnessRunFluctuatesAtTheMeshFrequency) {
  const GearPair pair(Gear(Spec(20)), Gear(Spec(40)));
  GearPairModelOptions o;
  o.bore_radius1_m = 5e-3;
  o.bore_radius2_m = 10e-3;
  const double w1 = 100.0, T = 20.0;
  o.input_speed = TimeFunction::Constant(w1);
  o.initial_speed1 = w1;
  o.load_torque = TimeFunction::Constant(T);  // gear 2 turns -z: +T opposes it
  o.damping_ratio = 0.1;
  const GearPairModel m = BuildGearPairModel(pair, o);
  ASSERT_TRUE(m.tvms.has_value());
  // Static deflection at the start so the transient is small.
  State s0 = State::Initial(*m.model);
  const double F = T / pair.gear2().base_radius_m();
  s0.q(0) = F / m.mesh_stiffness_mean_n_per_m / pair.gear1().base_radius_m();
  IntegratorOptions io;
  io.rtol = 1e-8;
  io.atol = 1e-12;
  const double f_mesh = 20 * w1 / (2 * kPi);
  const int cycles = 40, per_cycle = 128;
  const double dt = 1.0 / (f_mesh * per_cycle);
  auto integ = MakeIntegrator(*m.model, io);
  integ->Initialize(s0);
  Data d(*m.model);
  std::vector<double> force, deflection;
  // Skip 20 cycles of transient (damping ratio 0.1 at the torsional mode), then record 40.
  for (int k = 1; k <= (20 + cycles) * per_cycle; ++k) {
    integ->AdvanceTo(k * dt);
    if (k <= 20 * per_cycle) continue;
    const State& s = integ->state();
    EvaluateDynamics(*m.model, s.t, s.q, s.v, integ->vdot(), d);
    force.push_back(d.mesh_force[0]);
    deflection.push_back(d.mesh_deflection[0]);
  }
  // Mean over whole mesh cycles: the transmitted force (gear 2's torque balance averaged over a
  // period of the steady state; the damper averages out). The samples are a rectangle rule on a
  // force that jumps with the stiffness at the single/double contact changes, twice a cycle: each
  // jump (k_max - k_min) delta costs at most jump / per_cycle of the mean.
  double mean = 0;
  for (double f : force) mean += f / force.size();
  const double jump = (m.tvms->max_n_per_m - m.tvms->min_n_per_m) / m.mesh_stiffness_mean_n_per_m * F;
  EXPECT_NEAR(mean, F, 2 * jump / per_cycle);
  // DFT of the mesh deflection (the transmission error): well below the torsional mode the force
  // stays near T / r_b2 and the deflection F / k(t) follows the stiffness, at the mesh frequency
  // and its harmonics and nowhere between them (whole cycles: no leakage).
  double mean_delta = 0;
  for (double x : deflection) mean_delta += x / deflection.size();
  auto amplitude = [&](double f) {
    std::complex<double> c = 0;
    for (size_t i = 0; i < deflection.size(); ++i)
      c += (deflection[i] - mean_delta) * std::exp(std::complex<double>(0, -2 * kPi * f * i * dt));
    return std::abs(c) * 2.0 / deflection.size();
  };
  const double a_mesh = amplitude(f_mesh), a_half = amplitude(1.5 * f_mesh);
  EXPECT_GT(a_mesh, 0.05 * mean_delta);  // k ripple of tens of percent
  EXPECT_LT(a_half, 1e-3 * a_mesh);
}

}  // namespace
}  // namespace orrery::gears

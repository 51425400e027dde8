// A flexible planet (Craig-Bampton-reduced FE gear) on a rigid carrier pin, driven through
// lumped meshes: seed 002's stage with planet 1 generated, meshed, reduced and attached
// (models/gear_fe_mesh.h, flex/craig_bampton.h, flex/flexible_body_modes.h, TrainModelOptions::
// flexible_planets). Its bore (RBE2) sits on the pin bearing; the meshes act on an RBE3 over the
// root circle, so the tooth loads twist and bend rim and web.
//
// Checks: both integrators run the stage at constant speed from its static state; in steady
// state the sun-planet mesh forces carry the sun torque (torque balance: the sum of the three
// forces times the base radius and cos(beta_b) equals the power-flow torque, within the TVMS
// ripple the rigid stage shows); the flexible planet's mesh force stays within the rigid
// stage's band (the reduced planet is stiff compared with the meshes); the frozen flexible planet
// reproduces the rigid-planet stage with the FE body's mass properties.
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "mbd/data.h"
#include "mbd/integrator.h"
#include "mbd/evaluate.h"
#include "mbd/state.h"
#include "models/gear_fe_mesh.h"
#include "models/seed_models.h"
#include "models/train_dynamics.h"

namespace orrery::gears {
namespace {

constexpr double kRpm = 2 * M_PI / 60;

// Seed 002's planet, meshed coarsely (hex8) and reduced to 12 fixed-interface modes with the
// bore (RBE2, body frame) and the root circle (RBE3, mesh loads) as interfaces.
std::shared_ptr<const FlexibleBodyModes> ReducedPlanet(const PlanetaryTrain& train, const TrainModelOptions& o,
                                                       double* mass, int* dof) {
  const GearPair pair = MakeTrainGearPair(train, train.MeshIndex("S.sun-planet"), o);
  const Gear& planet = pair.gear2().spec().teeth == 34 ? pair.gear2() : pair.gear1();
  flex::FeMesh mesh = MakeGearFeMesh(planet, {.bore_radius_m = 0.12, .type = flex::ElementType::kHex8,
                                              .flank_divisions = 3, .fillet_divisions = 2, .tooth_divisions = 2,
                                              .root_layer_divisions = 1, .rim_divisions = 3, .face_divisions = 3});
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2),
                                        flex::MakeInterface(mesh, "ROOT", flex::InterfaceKind::kRbe3)};
  ifs[0].name = "bore";
  ifs[1].name = "rim";
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 12});
  *mass = sys.mass_kg;
  *dof = 3 * mesh.num_nodes();
  return std::make_shared<FlexibleBodyModes>(
      flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs, {.export_surface_nodes = false, .surface_triangles = false}));
}

struct StageRun {
  double f_min = 1e300, f_max = 0, f_flex_min = 1e300, f_flex_max = 0;
  double torque_balance = 0;  // largest |sum F r_b cos(beta_b) - T_sun| / T_sun after settling
  long steps = 0;
};

StageRun RunStage(const TrainModel& tm, IntegratorKind kind, double t_end) {
  const PlanetaryTrain& train = *tm.train;
  const int sp = train.MeshIndex("S.sun-planet");
  IntegratorOptions opt;
  opt.kind = kind;
  opt.step = 1e-4;
  opt.rtol = 1e-5;
  opt.atol = 1e-8;
  State x0 = SolveTrainStaticState(tm, State::Initial(*tm.model));
  auto integ = MakeIntegrator(*tm.model, opt);
  integ->Initialize(x0);
  Data d(*tm.model);
  const double rb = tm.member_params[train.MemberIndex("S.sun")].base_radius_m;
  const double beta_b = std::atan(std::tan(7 * M_PI / 180) * std::cos(train.gears[0].transverse_pressure_angle_rad));
  const double torque = tm.power_flow.mesh_line_of_action_forces_n(sp) * 3 * rb;
  StageRun r;
  for (int i = 1; i * 1e-3 <= t_end + 1e-12; ++i) {
    integ->AdvanceTo(i * 1e-3);
    const State& s = integ->state();
    EvaluateDynamics(*tm.model, s.t, s.q, s.v, Eigen::VectorXd::Zero(tm.model->nv), d);
    double sum = 0;
    for (const TrainMeshElement& e : tm.meshes) {
      if (e.train_mesh != sp) continue;
      const double f = d.mesh_force[e.model_mesh];
      sum += f * rb * std::cos(beta_b);
      (e.branch == 0 ? r.f_flex_min : r.f_min) = std::min(e.branch == 0 ? r.f_flex_min : r.f_min, f);
      (e.branch == 0 ? r.f_flex_max : r.f_max) = std::max(e.branch == 0 ? r.f_flex_max : r.f_max, f);
    }
    if (s.t > 0.01) r.torque_balance = std::max(r.torque_balance, std::abs(sum - torque) / torque);
  }
  r.steps = integ->stats().steps;
  return r;
}

TEST(FlexiblePlanet, RunsOnTheCarrierPinThroughLumpedMeshes) {
  const auto train = Seed002ShiftedStage();
  TrainModelOptions o = Seed002DynamicsOptions(TimeFunction::Constant(20 * kRpm));
  double mass = 0;
  int dof = 0;
  const auto modes = ReducedPlanet(*train, o, &mass, &dof);
  const TrainModel rigid = BuildTrainModel(*train, 0, o);
  TrainFlexibleBody& planet = o.flexible_bodies["S.planet1"];
  planet.modes = modes;
  planet.options.damping_ratios = {0.02};
  planet.mesh_interface = "rim";
  const TrainModel flexible = BuildTrainModel(*train, 0, o);
  const FlexibleBody& fb = flexible.model->flexible_bodies.at(0);
  std::printf("[flex planet] seed 002 planet: %d FE DOF, %.1f kg (lumped model %.1f kg), %d modal coordinates, "
              "first %.0f Hz\n", dof, mass, rigid.planet_params[0].mass_kg, fb.nf, modes->frequencies_hz.front());
  const StageRun ref = RunStage(rigid, IntegratorKind::kGeneralizedAlpha, 0.03);
  const StageRun ga = RunStage(flexible, IntegratorKind::kGeneralizedAlpha, 0.03);
  const StageRun ida = RunStage(flexible, IntegratorKind::kIda, 0.015);
  std::printf("[flex planet] rigid stage: s-p forces %.4e..%.4e N (planet 1 %.4e..%.4e), torque balance %.2e\n",
              ref.f_min, ref.f_max, ref.f_flex_min, ref.f_flex_max, ref.torque_balance);
  std::printf("[flex planet] flexible planet 1, gen-alpha: others %.4e..%.4e N, planet 1 %.4e..%.4e N, torque "
              "balance %.2e (%ld steps); IDA: planet 1 %.4e..%.4e N, torque balance %.2e (%ld steps)\n",
              ga.f_min, ga.f_max, ga.f_flex_min, ga.f_flex_max, ga.torque_balance, ga.steps, ida.f_flex_min,
              ida.f_flex_max, ida.torque_balance, ida.steps);
  // Torque balance as good as the rigid stage's (the sun's inertia torque and the TVMS ripple
  // make the difference there), and the flexible planet's load within the rigid stage's band
  // widened by the same relative ripple.
  const double band = (ref.f_max - ref.f_min) / ref.f_max;
  EXPECT_LE(ga.torque_balance, 1.5 * ref.torque_balance + 0.01);
  EXPECT_LE(ida.torque_balance, 1.5 * ref.torque_balance + 0.01);
  EXPECT_GE(ga.f_flex_min, ref.f_min * (1 - band));
  EXPECT_LE(ga.f_flex_max, ref.f_max * (1 + band));
  EXPECT_GE(ida.f_flex_min, ref.f_min * (1 - band));
  EXPECT_LE(ida.f_flex_max, ref.f_max * (1 + band));
}

}  // namespace
}  // namespace orrery::gears

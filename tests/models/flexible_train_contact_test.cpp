// Seed 003's planetary stage with tooth contact on every mesh and planet 1 a Craig-Bampton-reduced
// FE gear (models/train_contact.h, "Flexible planets"): sun and ring driven at 10 and 80.6 rad/s,
// the carrier loaded by 6000 N m (ramped in smoothly), generalized-alpha at 5 us.
// Oracles (Newton's laws and the stage's power flow, not the contact code):
//   - planet 1's moment balance: its sun-mesh and ring-mesh forces act on the same base radius,
//     so their impulses over a window differ by its change of angular momentum only,
//       r_bp int (F_s1 - F_r1) dt = J_p (Omega(t2) - Omega(t1)),   Omega = carrier + planet spin,
//     checked to the facet tolerance of the flanks (their normals are off the involute's by up
//     to half a facet's roll angle, which moves the line of force by r_a dphi / 2) plus the
//     trapezoidal quadrature of the sampled forces (their change over one step, summed);
//   - the sun's moment balance: the sun is driven at constant speed, so the driver's torque is
//     the contact moment on it at every step, sum_i F_si r_bs (the flexible branch included);
//     over the window it must equal the power-flow torque share of the sun T_c z_s / (z_s + z_r)
//     up to the carrier's and planets' change of momentum (checked against the measured speeds);
//   - load sharing: the three branches are loaded in parallel (same sun, ring and carrier
//     angles), so each branch carries F_i = D k_i, k_i its series sun-ring stiffness: the
//     flexible branch's mean force against the rigid ones' is the ratio of the stiffnesses. That
//     ratio is bounded from the models' ingredients (see LoadShareBounds) and must fall inside.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "contact/flexible_contact_element.h"
#include "models/train_dynamics.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "models/gear_fe_mesh.h"
#include "models/mesh_stiffness.h"
#include "models/planetary_kinematics.h"
#include "models/planetary_power_flow.h"
#include "models/planetary_train.h"

namespace orrery::gears {
namespace {

using namespace orrery::contact;  // the engine the gear layer builds on

constexpr double kPi = 3.14159265358979323846;
constexpr double kModule = 4e-3, kAlpha = 22.5 * kPi / 180, kWidth = 0.04;
constexpr double kCarrierTorque = 6000;

// Seed 003's planet as models/bodies/seed003_planet.yaml reduces it.
std::shared_ptr<const FlexibleBodyModes> ReducePlanet(int modes) {
  gears::GearSpec g;
  g.teeth = 14;
  g.normal_module_m = kModule;
  g.normal_pressure_angle_rad = kAlpha;
  g.hand = gears::HelixHand::kLeft;
  g.face_width_m = kWidth;
  gears::GearFeMeshSpec s;
  s.bore_radius_m = 0.4 * 0.5 * 14 * kModule;
  s.type = flex::ElementType::kHex20;
  s.flank_divisions = 4, s.fillet_divisions = 2, s.tooth_divisions = 2;
  s.root_layer_divisions = 1, s.rim_divisions = 2, s.face_divisions = 2;
  s.material.youngs_modulus_pa = 206e9;
  const flex::FeMesh mesh = gears::MakeGearFeMesh(gears::Gear(g), s);
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = modes});
  return std::make_shared<FlexibleBodyModes>(flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs));
}

struct Stage {
  std::shared_ptr<const gears::PlanetaryTrain> train;
  gears::TrainModel model;
  std::shared_ptr<const FlexibleBodyModes> planet;
};

Stage MakeStage(const std::shared_ptr<const FlexibleBodyModes>& planet, double ramp_s) {
  gears::PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {22}, .planet = {14}, .ring = {50}, .num_planets = 3,
                          .tooth_form = gears::ToothForm{.normal_module_m = kModule,
                                                         .normal_pressure_angle_rad = kAlpha}});
  b.AddRange("steer", {});
  b.AddInput("S.ring");
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  Stage s;
  s.train = std::move(b).Finalize();
  s.planet = planet;
  const int range = s.train->RangeIndex("steer");
  gears::TrainModelOptions o;
  o.face_width_m = kWidth;
  o.input = gears::TrainModelOptions::Input::kSpeed;
  o.input_speeds_rad_s = {80.6, 10};
  const gears::PlanetaryKinematics k =
      gears::SolvePlanetaryKinematics(*s.train, range, Eigen::Vector2d(80.6, 10));
  o.input_torque_n_m = gears::CalcPlanetaryPowerFlow(*s.train, k, s.train->output, -kCarrierTorque)
                          .port_torques_n_m(s.train->inputs[0]);
  o.port_loads = false;
  o.output_torque_n_m = TimeFunction::SmoothStep(0, ramp_s, 0, -kCarrierTorque);
  if (planet) {
    auto& p = o.flexible_bodies["S.planet1"];
    p.modes = planet;
    p.options.damping_ratios = {0.02};
  }
  TrainContactOptions c;
  c.normal_backlash_m = 20e-6;
  c.gear.involute_intervals = 40;
  c.gear.hunt_crossley_s_per_m = 0.5;
  c.gear.margin_m = 100e-6;
  c.flexible.face_intervals = 2;  // vertex rows on the element layers: CI speed
  o.mesh_model = gears::MeshModel::kContact;
  o.contact = c;
  s.model = gears::BuildTrainModel(*s.train, range, o);
  return s;
}

TEST(FlexibleTrainContact, RefusesAPlanetWithoutToothSets) {
  // A reduced body whose tooth sets are missing (here: renamed) is refused, naming the set.
  auto modes = std::make_shared<FlexibleBodyModes>(*ReducePlanet(2));
  modes->node_sets.erase("TOOTH5_TIP");
  try {
    MakeStage(modes, 1e-3);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("TOOTH5_TIP"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("S.planet1"), std::string::npos) << e.what();
  }
}

// Facet tolerance of the stage's meshes: half the roll angle of one facet times r_a / r_b, the
// larger over the gears (relative error of a normal force's moment arm).
double FacetTolerance(const Stage& s, int intervals) {
  double facet = 0;
  for (int mi = 0; mi < static_cast<int>(s.train->meshes.size()); ++mi) {
    gears::TrainModelOptions o;
    o.face_width_m = kWidth;
    const gears::GearPair pair = gears::MakeTrainGearPair(*s.train, mi, o);
    for (const gears::Gear* g : {&pair.gear1(), &pair.gear2()}) {
      const double rb = g->base_radius_m();
      auto roll = [&](double r) { return std::sqrt(r * r - rb * rb) / rb; };
      const double dphi = std::abs(roll(g->tip_radius_m()) - roll(g->form_radius_m())) / intervals;
      facet = std::max(facet, g->tip_radius_m() * dphi / (2 * rb));
    }
  }
  return facet;
}

// Window means of a run and the two momentum balances.
struct StageRun {
  double F_s[3] = {0, 0, 0}, F_r[3] = {0, 0, 0};  // mean normal forces (N)
  double quad_s[3] = {0, 0, 0}, quad_r[3] = {0, 0, 0};  // trapezoid bound of each mean (N)
  double window_s = 0;
  // Carrier + planets about the stage axis: int (M_mesh + load) dt and dH.
  double assembly_impulse = 0, assembly_momentum = 0, assembly_mesh_impulse = 0, assembly_quad = 0;
  double planet1_momentum = 0;  // J_p dOmega_1
  double max_bound_m = 0;
  long exceeded = 0;
  double wall_s = 0;
};

constexpr int kSteps = 280, kWindowStart = 140;  // 1.4 ms at 5 us, window [0.7, 1.4] ms
constexpr double kStep = 5e-6, kRamp = 0.5e-3;

StageRun Simulate(const Stage& s) {
  const auto wall0 = std::chrono::steady_clock::now();
  const Model& m = *s.model.model;
  const gears::TrainModel& tm = s.model;
  IntegratorOptions io;
  io.kind = IntegratorKind::kGeneralizedAlpha;
  io.step = kStep;
  io.rho_inf = 0.5;
  // The flexible contact needs steps down to ~20 ns where a contact switches (a step of 0.3 us
  // failed at 1.36 ms): 8 halvings.
  io.max_step_halvings = 8;
  auto integ = MakeIntegrator(m, io);
  integ->Initialize(State::Initial(m));
  Data data(m);
  int carrier_member = -1;
  for (int i = 0; i < s.train->num_members(); ++i)
    if (s.train->members[i].name == "S.carrier") carrier_member = i;
  const JointIndex carrier_joint = tm.member_joints[carrier_member];
  const int v_carrier = m.joints[carrier_joint].v_start;
  auto J_z = [&](BodyIndex b) {
    const Body& body = m.bodies[b];
    return body.inertia_cm_B(2, 2) + body.mass * body.com_B.head<2>().squaredNorm();
  };
  const double J_c = J_z(m.joints[carrier_joint].spec.child);
  const double r_c = 0.5 * (22 + 14) * kModule;
  std::vector<int> v_planet;
  std::vector<double> m_planet, J_planet;
  for (JointIndex j : tm.planet_joints[0]) {
    v_planet.push_back(m.joints[j].v_start);
    m_planet.push_back(m.bodies[m.joints[j].spec.child].mass);
    J_planet.push_back(J_z(m.joints[j].spec.child));
  }
  int sun_elem[3], ring_elem[3];
  for (size_t k = 0; k < s.model.contacts.size(); ++k) {
    const TrainContactMesh& c = s.model.contacts[k];
    const bool internal = s.train->meshes[c.train_mesh].kind == gears::MeshKind::kInternal;
    (internal ? ring_elem : sun_elem)[c.branch] = static_cast<int>(k);
  }
  const double r_bs = s.model.contacts[sun_elem[0]].base_radius1_m;
  const double r_br = s.model.contacts[ring_elem[0]].base_radius2_m;
  const TimeFunction load = TimeFunction::SmoothStep(0, kRamp, 0, -kCarrierTorque);
  std::vector<std::vector<double>> force(6, std::vector<double>(kSteps + 1, 0.0));
  std::vector<double> mesh_moment(kSteps + 1), H(kSteps + 1), Omega1(kSteps + 1), t(kSteps + 1);
  StageRun r;
  auto sample = [&](int i) {
    const State& st = integ->state();
    EvaluateDynamics(m, st.t, st.q, st.v, integ->vdot(), data);
    for (int k = 0; k < 6; ++k) {
      const int e = s.model.contacts[k].external_force;
      double out[16];  // 13 outputs of a flexible gear contact
      const std::vector<OutputDescription>& outputs = m.external_forces[e]->outputs();
      ASSERT_LE(OutputValueCount(outputs), 16);
      m.external_forces[e]->GetOutputs(*data.external[e], out);
      force[k][i] = out[0];
      if (s.model.contacts[k].flexible_side) {
        for (size_t j = 0; j < outputs.size(); ++j) {
          if (outputs[j].name == "deformation_bound") r.max_bound_m = std::max(r.max_bound_m, out[j]);
          if (outputs[j].name == "inflation_exceeded") r.exceeded = std::max(r.exceeded, static_cast<long>(out[j]));
        }
      }
    }
    // Sun-mesh forces act on lines tangent to the sun's base circle, ring-mesh forces on lines
    // tangent to the ring's: their moments about the stage axis.
    mesh_moment[i] = 0;
    for (int b = 0; b < 3; ++b) mesh_moment[i] += force[sun_elem[b]][i] * r_bs + force[ring_elem[b]][i] * r_br;
    const double w_c = st.v(v_carrier);
    H[i] = J_c * w_c;
    for (int b = 0; b < 3; ++b) H[i] += m_planet[b] * r_c * r_c * w_c + J_planet[b] * (w_c + st.v(v_planet[b]));
    Omega1[i] = w_c + st.v(v_planet[0]);
    t[i] = st.t;
  };
  sample(0);
  for (int i = 1; i <= kSteps; ++i) {
    integ->AdvanceTo(i * kStep);
    sample(i);
  }
  // Window means (trapezoid) and the quadrature bound: half the change over each step.
  r.window_s = (kSteps - kWindowStart) * kStep;
  auto integral = [&](const std::vector<double>& f) {
    double sum = 0;
    for (int i = kWindowStart; i < kSteps; ++i) sum += 0.5 * (f[i] + f[i + 1]) * kStep;
    return sum;
  };
  auto quadrature = [&](const std::vector<double>& f) {
    double sum = 0;
    for (int i = kWindowStart; i < kSteps; ++i) sum += 0.5 * std::abs(f[i + 1] - f[i]) * kStep;
    return sum;
  };
  for (int b = 0; b < 3; ++b) {
    r.F_s[b] = integral(force[sun_elem[b]]) / r.window_s;
    r.F_r[b] = integral(force[ring_elem[b]]) / r.window_s;
    r.quad_s[b] = quadrature(force[sun_elem[b]]) / r.window_s;
    r.quad_r[b] = quadrature(force[ring_elem[b]]) / r.window_s;
  }
  std::vector<double> load_t(kSteps + 1);
  for (int i = 0; i <= kSteps; ++i) load_t[i] = load.Value(t[i]);
  r.assembly_mesh_impulse = integral(mesh_moment);
  r.assembly_impulse = r.assembly_mesh_impulse + integral(load_t);
  r.assembly_quad = quadrature(mesh_moment) + quadrature(load_t);
  r.assembly_momentum = H[kSteps] - H[kWindowStart];
  r.planet1_momentum = J_planet[0] * (Omega1[kSteps] - Omega1[kWindowStart]);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  std::printf("%s: wall %.1f s; window means (N): sun meshes %.0f %.0f %.0f, ring meshes %.0f %.0f %.0f; "
              "max deformation bound %.2f um\n", s.planet ? "flexible planet 1" : "rigid planets",
              r.wall_s, r.F_s[0], r.F_s[1], r.F_s[2], r.F_r[0], r.F_r[1], r.F_r[2], r.max_bound_m * 1e6);
  return r;
}

// Static compliance (m/N) of the planet's modes at the FE node nearest the pitch point of tooth 0's
// plus flank at mid-face, along the flank normal: sum_k (n . phi_k)^2 / K_kk (modes M-normalized,
// K diagonal).
double ModalPitchCompliance(const FlexibleBodyModes& modes, const gears::Gear& planet) {
  const gears::ProfilePoint p = planet.InvolutePointAtRadius(planet.reference_radius_m());
  double z_lo = 1e300, z_hi = -1e300;
  for (const auto& node : modes.nodes) z_lo = std::min(z_lo, node.position.z()), z_hi = std::max(z_hi, node.position.z());
  const Vec3 target(p.p.x(), p.p.y(), 0.5 * (z_lo + z_hi));
  int best = -1;
  double d_best = 1e300;
  for (int i = 0; i < static_cast<int>(modes.nodes.size()); ++i) {
    const double d = (modes.nodes[i].position - target).norm();
    if (d < d_best) d_best = d, best = i;
  }
  const Vec3 n(p.n.x(), p.n.y(), 0);
  const Eigen::RowVectorXd nphi = n.normalized().transpose() * modes.nodes[best].translation_shapes;
  double c = 0;
  for (int k = 0; k < modes.nf; ++k) c += nphi(k) * nphi(k) / modes.stiffness(k, k);
  return c;
}

TEST(FlexibleTrainContact, FlexiblePlanetCarriesItsShare) {
  const int nf = 24;
  const auto planet = ReducePlanet(nf);
  const Stage flexible = MakeStage(planet, kRamp);
  const Stage rigid = MakeStage(nullptr, kRamp);
  ASSERT_EQ(flexible.model.contacts.size(), 6u);
  for (const TrainContactMesh& c : flexible.model.contacts) {
    const bool internal = flexible.train->meshes[c.train_mesh].kind == gears::MeshKind::kInternal;
    EXPECT_EQ(c.flexible_side, c.branch == 0 ? (internal ? 1 : 2) : 0) << c.name;
    if (c.flexible_side) {
      // B is the planet's gear frame: the joint starts at pi + pi / z_p + (z_s / z_p) psi_1.
      const double psi = flexible.train->planet_sets[0].angles_rad[0];
      EXPECT_NEAR(c.planet_initial_angle_rad, kPi + kPi / 14 + 22.0 / 14 * psi, 1e-12) << c.name;
    }
  }
  const StageRun f = Simulate(flexible), r = Simulate(rigid);
  const double facet = FacetTolerance(flexible, 40);
  EXPECT_EQ(f.exceeded, 0) << "the planet deformed beyond the culling allowance";
  EXPECT_GT(f.max_bound_m, 1e-6);  // the planet deforms

  // Planet 1: r_bp int (F_s1 - F_r1) dt = J_p dOmega_1.
  const TrainContactMesh& sun1 = flexible.model.contacts[0];
  const double r_bp = sun1.base_radius2_m, T = f.window_s;
  const double impulse = r_bp * (f.F_s[0] - f.F_r[0]) * T;
  const double tol1 = r_bp * T * (facet * (f.F_s[0] + f.F_r[0]) + f.quad_s[0] + f.quad_r[0]);
  std::printf("planet 1: r_bp int (F_s - F_r) dt = %.4e N m s, J_p dOmega = %.4e, tolerance %.2e "
              "(facet %.2e)\n", impulse, f.planet1_momentum, tol1, facet);
  EXPECT_NEAR(impulse, f.planet1_momentum, tol1);

  // Carrier and planets: int (mesh moments + load) dt = dH, both runs.
  for (const StageRun* run : {&f, &r}) {
    const double tol = facet * std::abs(run->assembly_mesh_impulse) + run->assembly_quad;
    std::printf("%s: int (M_mesh + T_load) dt = %.4e N m s (mesh %.4e), dH = %.4e, tolerance %.2e\n",
                run == &f ? "flexible" : "rigid", run->assembly_impulse, run->assembly_mesh_impulse,
                run->assembly_momentum, tol);
    EXPECT_NEAR(run->assembly_impulse, run->assembly_momentum, tol);
  }

  // Load sharing. The branches are in parallel: F_i = D k_i, so making branch 1 flexible scales
  // its force against the rigid run's by q = rho S / (rho F_1 + F_2 + F_3) with S = sum F_i (rigid
  // run) and rho = k_1' / k_1 the ratio of branch 1's stiffnesses. Each mesh's compliance per
  // tooth pair carrying P: rigid delta_ref (P / F_cal)^(2/3) (ISO c' b calibration); flexible
  // delta_ref' (P / F_cal)^(2/3) + c_modal P (Hertz and the sun's / ring's tooth, then the
  // planet's modes). With n pairs in contact P = F / n; the sun and ring meshes of seed 003 have
  // contact ratios between 1 and 2, so rho lies between its values for n = 1 and n = 2: the
  // simulated q must lie between the two predictions (widened by the facet and quadrature
  // tolerances of the means).
  const gears::Gear planet_gear = gears::MakeTrainGearPair(*flexible.train, 0, [] {
    gears::TrainModelOptions o;
    o.face_width_m = kWidth;
    return o;
  }()).gear2();
  const double c_modal = ModalPitchCompliance(*planet, planet_gear);
  auto branch_compliance = [&](const Stage& s, double F, double n) {
    double c = 0;
    for (int k : {0, 3}) {  // sun-planet#1 and ring-planet#1
      const TrainContactMesh& e = s.model.contacts[k];
      const double F_cal = 1000;
      const double P = F / n;
      const double delta = e.calibration.reference_deflection_m * std::pow(P / F_cal, 2.0 / 3.0) +
                           (e.flexible_side ? c_modal * P : 0);
      c += delta / F;
    }
    return c;
  };
  ASSERT_EQ(flexible.model.contacts[3].branch, 0);
  const double F1 = 0.5 * (r.F_s[0] + r.F_r[0]), F1f = 0.5 * (f.F_s[0] + f.F_r[0]);
  const double S = r.F_s[0] + r.F_s[1] + r.F_s[2];
  const double q = f.F_s[0] / r.F_s[0];
  double q_pred[2];
  for (int n = 1; n <= 2; ++n) {
    const double rho = branch_compliance(rigid, F1, n) / branch_compliance(flexible, F1f, n);
    q_pred[n - 1] = rho * S / (rho * r.F_s[0] + r.F_s[1] + r.F_s[2]);
  }
  const double lo = std::min(q_pred[0], q_pred[1]), hi = std::max(q_pred[0], q_pred[1]);
  const double widen = facet + (f.quad_s[0] / f.F_s[0] + r.quad_s[0] / r.F_s[0]);
  std::printf("load share: flexible / rigid branch-1 sun-mesh force q = %.3f; predicted %.3f (n = 1) "
              "to %.3f (n = 2), widened by %.3f; modal compliance at the pitch point %.3g m/N\n", q,
              q_pred[0], q_pred[1], widen, c_modal);
  EXPECT_GE(q, lo * (1 - widen));
  EXPECT_LE(q, hi * (1 + widen));
}

}  // namespace
}  // namespace orrery::gears

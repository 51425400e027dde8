// Planetary train dynamic model (models/train_dynamics.h) against independent oracles: the
// Lagrangian of a one-planet torsional stage derived by hand (seed 001 eq. 7 with Willis-consistent
// deflections), the planar lumped stage of lumped_planetary.h (validated against Lin & Parker 1999
// Table 2) in the limit of rigid bearings, Parker & Lin's (2004) mesh phasing closed forms, the
// kinematics (mesh deflection rates vanish at the initial speeds) and the power flow's static mesh
// forces (seed 001 eq. 6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include "mbd/data.h"
#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"
#include "mbd/linearization.h"
#include "models/lumped_planetary.h"
#include "models/modal_analysis.h"
#include "models/planetary_scenes.h"
#include "models/train_dynamics.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// One single-planet stage of seed 001's gears (module 1.5 mm, 21.3 deg): ring held, sun in,
// carrier out.
std::shared_ptr<const PlanetaryTrain> OneStage(int zs, int zp, int zr, int planets) {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {zs}, .planet = {zp}, .ring = {zr}, .num_planets = planets,
                          .tooth_form = ToothForm{.normal_module_m = 0.0015,
                                                  .normal_pressure_angle_rad = 21.3 * kPi / 180}});
  b.AddBrake("B", "S.ring");
  b.AddRange("run", {"B"});
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  return std::move(b).Finalize();
}

TrainModelOptions Seed001Options() {
  TrainModelOptions o;
  o.face_width_m = 0.030;
  o.input = TrainModelOptions::Input::kNone;
  return o;
}

// Torsional one-planet stage vs its Lagrangian written out by hand: coordinates
// (th_s, th_r, th_c, th_pc), T = 1/2 [I_s th_s'^2 + I_r th_r'^2 + (I_c + m_p r_c^2) th_c'^2
// + I_p (th_c' + th_pc')^2], V = 1/2 [k_sp d_sp^2 + k_rp d_rp^2 + k_rg th_r^2] with
// d_sp = r_s (th_s - th_c) + r_p th_pc, d_rp = r_r (th_r - th_c) - r_p th_pc (base radii).
TEST(TrainDynamics, OnePlanetStageMatchesHandDerivedLagrangian) {
  const auto train = OneStage(34, 18, 70, 1);
  TrainModelOptions o = Seed001Options();
  o.meshes["S.sun-planet"].stiffness_n_per_m = 4.37e8;
  o.meshes["S.ring-planet"].stiffness_n_per_m = 5.26e8;
  o.brake_stiffness_n_m_per_rad = 3e6;
  const TrainModel tm = BuildTrainModel(*train, 0, o);
  ASSERT_EQ(tm.model->nv, 4);
  const TrainModes modes = CalcTrainModes(tm);

  const auto& mp = tm.member_params;
  const int s = train->MemberIndex("S.sun"), r = train->MemberIndex("S.ring"), c = train->MemberIndex("S.carrier");
  const TrainBodyParams& p = tm.planet_params[0];
  const double rs = mp[s].base_radius_m, rr = mp[r].base_radius_m, rp = p.base_radius_m;
  const double rc = train->planet_sets[0].center_radius_m;
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero(), K = Eigen::Matrix4d::Zero();
  M.diagonal() << mp[s].polar_inertia_kg_m2, mp[r].polar_inertia_kg_m2,
      mp[c].polar_inertia_kg_m2 + p.mass_kg * rc * rc + p.polar_inertia_kg_m2, p.polar_inertia_kg_m2;
  M(2, 3) = M(3, 2) = p.polar_inertia_kg_m2;
  const Eigen::Vector4d dsp(rs, 0, -rs, rp), drp(0, rr, -rr, -rp);
  K = 4.37e8 * dsp * dsp.transpose() + 5.26e8 * drp * drp.transpose();
  K(1, 1) += 3e6;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix4d> eig(K, M);
  // Relative eigenvalue accuracy of both solutions ~ n eps cond; allow 1e-8 on frequencies.
  ASSERT_EQ(modes.modes.size(), 4u);
  EXPECT_EQ(modes.num_rigid_body_modes, 1);
  for (int i = 1; i < 4; ++i) {
    const double f = std::sqrt(eig.eigenvalues()(i)) / (2 * kPi);
    EXPECT_NEAR(modes.modes[i].frequency_hz, f, 1e-8 * f) << "mode " << i;
  }
}

// Torsional train model vs the independent planar lumped stage (lumped_planetary.h, validated
// against Lin & Parker 1999) with the same parameters and bearings 1e6 times stiffer than the
// meshes: its N + 3 lowest modes tend to the torsional ones with a relative error O(k_m / k_b).
TEST(TrainDynamics, TorsionalModelIsTheRigidBearingLimitOfTheLumpedPlanarStage) {
  const int n = 3;
  const auto train = OneStage(34, 20, 74, n);  // concentric, (34 + 74) / 3 = 36: equally spaced
  TrainModelOptions o = Seed001Options();
  o.brake_stiffness_n_m_per_rad = 2e6;
  const TrainModel tm = BuildTrainModel(*train, 0, o);
  const TrainModes tor = CalcTrainModes(tm);

  LumpedStageParams lp;
  lp.dofs = LumpedStageParams::Dofs::kPlanar;
  lp.planets = n;
  const double kb = 1e6 * tm.meshes[0].stiffness_n_per_m;
  auto member = [&](const TrainBodyParams& p, double radius) {
    LumpedMember m;
    m.mass = p.mass_kg;
    m.inertia = p.polar_inertia_kg_m2;
    m.radius = radius;
    m.bearing_stiffness = kb;
    m.teeth = 1;
    return m;
  };
  const auto& mp = tm.member_params;
  lp.sun = member(mp[train->MemberIndex("S.sun")], mp[train->MemberIndex("S.sun")].base_radius_m);
  lp.ring = member(mp[train->MemberIndex("S.ring")], mp[train->MemberIndex("S.ring")].base_radius_m);
  lp.ring.torsional_stiffness = 2e6;
  lp.carrier = member(mp[train->MemberIndex("S.carrier")], train->planet_sets[0].center_radius_m);
  lp.planet = member(tm.planet_params[0], tm.planet_params[0].base_radius_m);
  lp.mesh_stiffness_sun = tm.meshes[0].stiffness_n_per_m;
  lp.mesh_stiffness_ring = tm.meshes[1].stiffness_n_per_m;
  lp.pressure_angle_sun = tm.meshes[0].working_pressure_angle_rad;
  lp.pressure_angle_ring = tm.meshes[1].working_pressure_angle_rad;
  lp.check_centre_distance = true;
  const LumpedStage stage = BuildLumpedStage(lp);
  const ModalResult planar = CalcModes(Linearize(*stage.model, State::Initial(*stage.model)));

  ASSERT_EQ(tor.modes.size(), size_t(n + 3));
  const double tol = 10 * tm.meshes[1].stiffness_n_per_m / kb;
  EXPECT_LT(std::abs(planar.frequencies_hz[0]), 1.0);
  for (int i = 1; i < n + 3; ++i)
    EXPECT_NEAR(planar.frequencies_hz[i], tor.modes[i].frequency_hz, tol * tor.modes[i].frequency_hz) << i;
  // The next planar mode is a bearing mode, far above.
  EXPECT_GT(planar.frequencies_hz[n + 3], 100 * tor.modes[n + 2].frequency_hz);
}

// Parker & Lin (2004): equally spaced planets, psi_n = 2 pi (n - 1) / N. Sun-planet phases
// -Z_s psi_n / 2 pi mod 1 in the mesh element's convention: all 0 (in phase) when Z_s / N is an
// integer, else the N values k / N in sequence; ring-planet phases -Z_r psi_n / 2 pi relative to
// ring-planet 1. Sun-ring phase of a planet for standard gears at the reference centre distance:
// a planet tooth whose flank touches the sun at the pitch point leaves the ring side facing a
// tooth (Z_p even) or a space (Z_p odd): phase_r1 + phase_s1 = (Z_p - 1) / 2 mod 1.
TEST(TrainDynamics, MeshPhasesFollowParkerLin) {
  struct Case { int zs, zp, zr, n; };
  for (const Case& k : {Case{24, 24, 72, 4}, Case{25, 23, 71, 4}, Case{34, 20, 74, 3}, Case{30, 21, 72, 6}}) {
    const auto train = OneStage(k.zs, k.zp, k.zr, k.n);
    TrainModelOptions o = Seed001Options();
    o.input_torque_n_m = 100;  // sun drives: sun-planet drive flank, ring-planet coast flank
    const TrainModel tm = BuildTrainModel(*train, 0, o);
    std::vector<double> sun, ring;
    for (const TrainMeshElement& e : tm.meshes) (e.train_mesh == 0 ? sun : ring).push_back(e.phase_cycles);
    ASSERT_EQ(sun.size(), size_t(k.n));
    auto mod1 = [](double x) { return x - std::floor(x); };
    auto near = [](double a, double b) { const double d = std::abs(a - b); return std::min(d, 1 - d); };
    const bool in_phase = k.zs % k.n == 0;
    for (int i = 0; i < k.n; ++i) {
      const double psi = 2 * kPi * i / k.n;
      EXPECT_LT(near(mod1(sun[i] - sun[0]), mod1(-k.zs * psi / (2 * kPi))), 1e-12) << k.zs << " planet " << i;
      EXPECT_LT(near(mod1(ring[i] - ring[0]), mod1(-k.zr * psi / (2 * kPi))), 1e-12) << k.zr << " planet " << i;
      if (in_phase) {
        EXPECT_LT(near(sun[i], sun[0]), 1e-12);
      }
    }
    // Sun-planet 1's phase: the sun's gear-frame tooth 0 on its body's +x at q = 0 (train_dynamics.h,
    // "Tooth faults"), planet 1 on +x; standard gears at the reference centre distance: a tooth
    // centred on the line of centres has its drive flank a quarter pitch past the pitch point.
    EXPECT_LT(near(sun[0], 0.25), 1e-9) << k.zs;
    if (!in_phase) {  // sequential: the phases are a permutation of k / N (gcd(Z_s, N) = 1 here)
      std::vector<double> sorted = sun;
      for (double& x : sorted) x = mod1(x - sun[0]);
      std::sort(sorted.begin(), sorted.end());
      for (int i = 0; i < k.n; ++i) EXPECT_LT(near(sorted[i], double(i) / k.n), 1e-12);
    }
    EXPECT_LT(near(mod1(sun[0] + ring[0]), mod1(0.5 * (k.zp - 1))), 1e-9) << "Z_p " << k.zp;
    // With the reference phase given as 0 (stage_phase_cycles), the absolute phases of Parker &
    // Lin's table, as before the default followed the body-frame teeth: sun-planet n at
    // -Z_s psi_n / 2 pi; the default shifts every sun-planet phase by sun[0] and every ring-planet
    // phase by -sun[0] (phase_r1 + phase_s1 is fixed by the planet's teeth).
    o.stage_phase_cycles = {0.0};
    const TrainModel given = BuildTrainModel(*train, 0, o);
    for (const TrainMeshElement& e : given.meshes) {
      const double psi = 2 * kPi * e.branch / k.n;
      const double default_phase = (e.train_mesh == 0 ? sun : ring)[e.branch];
      if (e.train_mesh == 0) {
        EXPECT_LT(near(e.phase_cycles, mod1(-k.zs * psi / (2 * kPi))), 1e-12) << k.zs << " planet " << e.branch;
      }
      const double shift = e.train_mesh == 0 ? sun[0] : -sun[0];
      EXPECT_LT(near(mod1(default_phase - e.phase_cycles), mod1(shift)), 1e-12) << k.zs << " mesh " << e.train_mesh;
    }
  }
}

// The initial state turns every member at its kinematic speed: no mesh deflects (its rate, the
// relative velocity of the two lever points along the line of action, vanishes). Seed 001 (three
// single-planet stages), seed 002 (helical), a double-planet and a Ravigneaux stage, every DOF set.
// Their 15-tooth planets are cut at 22.5 degrees (z_min = 2 / sin^2(22.5 deg) = 13.7; at 20 degrees
// they would be undercut, z_min = 17.1, which every assembly refuses).
std::vector<std::shared_ptr<const PlanetaryTrain>> KinematicTrains() {
  const ToothForm form{.normal_module_m = 0.002, .normal_pressure_angle_rad = 22.5 * std::numbers::pi / 180};
  PlanetaryTrainBuilder d;
  d.AddDoublePlanetStage({.name = "D", .sun = {30}, .inner_planet = {15}, .outer_planet = {15},
                          .ring = {78}, .num_planets = 3, .tooth_form = form});
  d.AddBrake("B", "D.ring");
  d.AddRange("run", {"B"});
  d.AddInput("D.sun");
  d.SetOutput("D.carrier");
  PlanetaryTrainBuilder r;
  r.AddRavigneauxStage({.name = "R", .small_sun = {30}, .large_sun = {36}, .short_planet = {15},
                        .long_planet = {21}, .ring = {78}, .num_planets = 3, .tooth_form = form});
  r.AddBrake("B", "R.ring");
  r.AddRange("run", {"B"});
  r.AddInput("R.sun1");
  r.SetOutput("R.carrier");
  return {MakeSeed001AutomaticTransmission(), MakeSeed002WindTurbineStage(), std::move(d).Finalize(),
          std::move(r).Finalize()};
}

TEST(TrainDynamics, InitialSpeedsAreKinematicallyConsistent) {
  for (const auto& train : KinematicTrains()) {
    for (TrainDofs dofs : {TrainDofs::kTorsional, TrainDofs::kPlanar, TrainDofs::kSpatial}) {
      TrainModelOptions o = Seed001Options();
      o.dofs = dofs;
      o.input = TrainModelOptions::Input::kSpeed;
      o.input_speeds_rad_s = {300.0};
      o.input_torque_n_m = 300;
      const TrainModel tm = BuildTrainModel(*train, 0, o);
      const Model& m = *tm.model;
      Data d(m);
      CalcPositionKinematics(m, m.q_initial, d);
      CalcVelocityKinematics(m, m.v_initial, d);
      for (const GearMesh& g : m.gear_meshes) {
        const MeshState s = CalcMeshState(g.geometry, d, g.spec.gear_a, g.spec.gear_b, g.spec.reference,
                                          g.spec.base_radius_a, g.spec.base_radius_b, 0.0);
        const double rate = CalcMeshRate(m, d, g.spec.gear_a, g.spec.gear_b, g.spec.reference, s, s.n_drive_W);
        // Pitch-line speeds are O(300 rad/s * 0.1 m); rounding of the speed solve and kinematics.
        EXPECT_NEAR(rate, 0.0, 1e-10) << g.spec.name;
      }
      // Lumped stages carry one mesh per branch and planet contact.
      size_t expected = 0;
      for (const Stage& st : train->stages) expected += st.meshes.size() * st.num_planets;
      EXPECT_EQ(m.gear_meshes.size(), expected);
    }
  }
}

// Static mesh forces of the linear model (K q = f under the input torque and the output load)
// equal the power flow's line-of-action forces per planet (seed 001 eq. 6, Table 2: stage 1 of
// the 1st gear 1429 N) and load the engaged flank (positive compression).
TEST(TrainDynamics, StaticMeshForcesMatchThePowerFlow) {
  const auto train = MakeSeed001AutomaticTransmission();
  TrainModelOptions o = Seed001Options();
  o.input = TrainModelOptions::Input::kTorque;
  o.input_torque_n_m = 300;
  const TrainModel tm = BuildTrainModel(*train, train->RangeIndex("1st"), o);
  const TrainModes modes = CalcTrainModes(tm);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(tm.model->nv);
  for (size_t i = 0; i < tm.model->joint_loads.size(); ++i)
    f(tm.model->joint_load_v_index[i]) += tm.model->joint_loads[i].function.Value(0);
  // Singular K (the rigid-body mode, which the balanced loads do not excite): minimum-norm solve.
  const Eigen::VectorXd q = modes.linear.K.completeOrthogonalDecomposition().solve(f);
  const Eigen::VectorXd force = modes.mesh_stiffness.cwiseProduct(modes.mesh_directions * q);
  for (const TrainMeshElement& e : tm.meshes) {
    const double expected = tm.power_flow.mesh_line_of_action_forces_n(e.train_mesh);
    // Conditioning: brakes 1e10 N m/rad against meshes ~1e5 N m/rad: cond(K) eps ~ 1e-10.
    EXPECT_NEAR(force(e.model_mesh), expected, 1e-6 * expected) << train->meshes[e.train_mesh].name;
  }
  // Table 2 (rounded to 1 N; the paper's tooth forces follow from 300 N m the same way).
  EXPECT_NEAR(tm.power_flow.mesh_tangential_forces_n(train->MeshIndex("S1.sun-planet")), 1429, 1.0);
}

}  // namespace
}  // namespace orrery::gears

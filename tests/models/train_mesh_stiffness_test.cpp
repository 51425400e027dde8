// Mesh stiffness from geometry in train models (train_dynamics.h, "Mesh stiffness from geometry"):
// the ISO 6336 and TVMS values of GearPairs built here by hand from GearSpecs (an independent
// construction of the same gears), the TVMS table's mean and phase convention (phase 0 = a pair at
// the pitch point), and a broken sun tooth whose stiffness dips, in a time-domain run, at the
// times the kinematics predict (SolvePlanetaryKinematics: once per sun turn relative to the
// carrier per planet, the fault frequency N f_m / Z_s over all planets).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/gear_mesh.h"
#include "mbd/integrator.h"
#include "models/mesh_stiffness.h"
#include "models/planetary_scenes.h"
#include "models/train_dynamics.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kAlpha = 21.3 * kPi / 180;

// Seed 001 stage 1 (34/18/70, module 1.5 mm, 21.3 deg, b = 30 mm), 4 planets, ring held, sun in.
std::shared_ptr<const PlanetaryTrain> Stage001() {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {34}, .planet = {18}, .ring = {70}, .num_planets = 4,
                          .tooth_form = ToothForm{.normal_module_m = 0.0015, .normal_pressure_angle_rad = kAlpha}});
  b.AddBrake("B", "S.ring");
  b.AddRange("run", {"B"});
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  return std::move(b).Finalize();
}

GearSpec Spec(int z, bool internal, double addendum = 1.0, double fillet = 0.38) {
  return GearSpec{.teeth = z, .normal_module_m = 0.0015, .normal_pressure_angle_rad = kAlpha,
                  .addendum_coef = addendum, .root_fillet_coef = fillet, .face_width_m = 0.030,
                  .internal = internal};
}

TrainModelOptions Options(MeshStiffnessSource source) {
  TrainModelOptions o;
  o.face_width_m = 0.030;
  o.input = TrainModelOptions::Input::kSpeed;
  o.input_speeds_rad_s = {100.0};
  o.input_torque_n_m = 300;
  o.mesh_stiffness_source = source;
  return o;
}

// ISO 6336 c_gamma_alpha b and the TVMS mean of the train's meshes equal those of the pairs
// built by hand (sun-planet; planet-ring with the documented ring defaults: addendum 0.85 m_n,
// rack fillet 0.25 m_n, the geometry every mesh level shares), and the
// model's mean stiffness (mbd's k_mean of the table) equals the TVMS mean: the table resamples
// the TVMS at shifted points, which keeps the mean of a periodic linear interpolant exactly.
TEST(TrainMeshStiffness, IsoAndTvmsMeansMatchHandBuiltPairs) {
  const auto train = Stage001();
  const GearPair sp(Gear(Spec(34, false)), Gear(Spec(18, false)));
  const GearPair rp(Gear(Spec(18, false)), Gear(Spec(70, true, 0.85, 0.25)));
  // A standard ring tip reaches the planet's fillet: the reason for a shorter ring addendum.
  EXPECT_THROW(GearPair(Gear(Spec(18, false)), Gear(Spec(70, true))), std::invalid_argument);
  const TrainModel iso = BuildTrainModel(*train, 0, Options(MeshStiffnessSource::kIso6336));
  const TrainModel tv = BuildTrainModel(*train, 0, Options(MeshStiffnessSource::kTvms));
  for (int k = 0; k < 2; ++k) {
    const GearPair& pair = k == 0 ? sp : rp;
    const int mesh = train->MeshIndex(k == 0 ? "S.sun-planet" : "S.ring-planet");
    const double k_iso = CalcIso6336Stiffness(pair).c_gamma_alpha_n_per_m;
    // Bores 0.4 r, ring rim r + 3.5 m_n (TrainModelOptions defaults).
    const Gear& g1 = pair.gear1();
    const Gear& g2 = pair.gear2();
    const Tvms t = CalcTvms(pair, {.bore_radius1_m = 0.4 * g1.reference_radius_m(),
                                   .rim_radius2_m = g2.internal() ? g2.reference_radius_m() + 3.5 * 0.0015
                                                                  : 0.4 * g2.reference_radius_m(),
                                   .samples_per_period = 64});
    for (const TrainMeshElement& e : iso.meshes)
      if (e.train_mesh == mesh) {
        EXPECT_NEAR(e.stiffness_n_per_m, k_iso, 1e-12 * k_iso);
      }
    for (const TrainMeshElement& e : tv.meshes) {
      if (e.train_mesh != mesh) continue;
      const GearMesh& gm = tv.model->gear_meshes[e.model_mesh];
      ASSERT_EQ(gm.spec.stiffness_table.size(), 64u);
      // Summation rounding of 64 terms.
      EXPECT_NEAR(e.stiffness_n_per_m, t.mean_n_per_m, 64 * 1e-16 * t.mean_n_per_m);
      EXPECT_NEAR(gm.k_mean, t.mean_n_per_m, 64 * 1e-16 * t.mean_n_per_m);
      // Linear interpolation between TVMS samples stays within their range.
      EXPECT_GE(e.stiffness_min_n_per_m, t.min_n_per_m * (1 - 1e-15));
      EXPECT_LE(e.stiffness_max_n_per_m, t.max_n_per_m * (1 + 1e-15));
      // Phase 0: a pair at the pitch point. The TVMS sample nearest to a pair at the pitch point
      // and its neighbours bracket the table's first entry.
      int best = 0;
      double dist = 1e30;
      for (size_t i = 0; i < t.contacts.size(); ++i)
        for (const ToothPairContact& c : t.contacts[i])
          if (std::abs(c.position_m - pair.pitch_point_m()) < dist) {
            dist = std::abs(c.position_m - pair.pitch_point_m());
            best = static_cast<int>(i);
          }
      const int n = static_cast<int>(t.stiffness_n_per_m.size());
      const double lo = std::min({t.stiffness_n_per_m[(best + n - 1) % n], t.stiffness_n_per_m[best], t.stiffness_n_per_m[(best + 1) % n]});
      const double hi = std::max({t.stiffness_n_per_m[(best + n - 1) % n], t.stiffness_n_per_m[best], t.stiffness_n_per_m[(best + 1) % n]});
      EXPECT_GE(gm.spec.stiffness_table[0], lo) << train->meshes[mesh].name;
      EXPECT_LE(gm.spec.stiffness_table[0], hi) << train->meshes[mesh].name;
    }
  }
}

// A sun tooth broken over half its face width (spur: its stiffness halves over its whole pass,
// from the start to the end of the contact path). With the sun driven at 100 rad/s, the sun-planet
// stiffness of branch n dips while that tooth passes planet n: centred at
//   t = (psi_n / 2 pi - 1 / (4 Z_s) + j) / f_rel + ((s_start + s_end) / 2 - s_P) / (p_b f_m),
// f_rel = (w_s - w_c) / 2 pi from SolvePlanetaryKinematics, f_m = Z_s f_rel. Tooth 0 is the
// gear-frame tooth centred on the sun body's +x at t = 0 (train_dynamics.h, "Tooth faults"): its
// drive flank reaches planet n's pitch point when its centre is half a tooth thickness at the
// pitch circle (a quarter pitch, standard gears at the reference centre distance) short of the
// line of centres psi_n. Over all planets the dips come at the sun's fault frequency N f_m / Z_s
// (gear_fault_frequencies_hz).
TEST(TrainMeshStiffness, BrokenSunToothDipsOncePerSunTurnPerPlanet) {
  const auto train = Stage001();
  TrainModelOptions o = Options(MeshStiffnessSource::kTvms);
  o.mesh_damping_ratio = 0.05;
  // Ring held by 1e8 N m/rad (18 times the four meshes' r_r^2 k): seed 001's 1e10 makes the ring a
  // ~0.4 MHz mode that IDA resolves at every TVMS kink (6e5 steps instead of 1e5 here).
  o.brake_stiffness_n_m_per_rad = 1e8;
  o.tooth_faults = {{.gear = "S.sun",
                     .spec = {.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0, .height_fraction = 1,
                              .face_fraction = 0.5}}};
  const TrainModel tm = BuildTrainModel(*train, 0, o);
  const TrainModel healthy = BuildTrainModel(*train, 0, Options(MeshStiffnessSource::kTvms));
  const Model& m = *tm.model;
  const int sp = train->MeshIndex("S.sun-planet");
  const int sun = train->MemberIndex("S.sun"), carrier = train->MemberIndex("S.carrier");
  for (const TrainMeshElement& e : tm.meshes)
    if (e.train_mesh == sp) {
      EXPECT_EQ(e.table_cycles, 34);
    }
  // Kinematics.
  const double f_rel = (tm.kinematics.speeds_rad_s(sun) - tm.kinematics.speeds_rad_s(carrier)) / (2 * kPi);
  const double f_m = tm.kinematics.stage_mesh_frequencies_hz(0);
  ASSERT_GT(f_rel, 0);
  EXPECT_NEAR(f_m, 34 * f_rel, 1e-9 * f_m);
  const double f_fault = tm.kinematics.gear_fault_frequencies_hz(train->members[sun].gear);
  EXPECT_NEAR(f_fault, 4 * f_rel, 1e-9 * f_fault);
  const GearPair pair(Gear(Spec(34, false)), Gear(Spec(18, false)));
  const double offset = ((pair.contact_start_m() + pair.contact_end_m()) / 2 - pair.pitch_point_m()) /
                        pair.transverse_base_pitch_m() / f_m;
  // Run 1.3 sun turns relative to the carrier; record the dips of each branch.
  const double t_end = 1.3 / f_rel, dt = 1e-5;
  IntegratorOptions io;
  // Absolute tolerance 1e-6 rad on the angles moves the phase of a 67 rad/s sun by 15 ns.
  io.rtol = 1e-5;
  io.atol = 1e-6;
  auto integ = MakeIntegrator(m, io);
  integ->Initialize(SolveTrainStaticState(tm, State::Initial(m)));
  Data d(m);
  std::vector<std::vector<double>> centres(4);
  std::vector<double> start(4, -1);
  double lag = 0;  // largest |carrier angle - kinematic angle|
  const int cv = m.joints[tm.member_joints[carrier]].q_start;
  const int n = static_cast<int>(t_end / dt);
  for (int i = 0; i <= n; ++i) {
    if (i > 0) integ->AdvanceTo(i * dt);
    const State& s = integ->state();
    EvaluateDynamics(m, s.t, s.q, s.v, integ->vdot(), d);
    lag = std::max(lag, std::abs(s.q(cv) - tm.kinematics.speeds_rad_s(carrier) * s.t));
    for (const TrainMeshElement& e : tm.meshes) {
      if (e.train_mesh != sp) continue;
      // Below the healthy mesh's stiffness at the same phase (one cycle of its table).
      const double k_ok = MeshStiffness(healthy.model->gear_meshes[e.model_mesh].spec, d.mesh_phase[e.model_mesh]);
      const bool dip = d.mesh_stiffness[e.model_mesh] < k_ok * (1 - 1e-9);
      if (dip && start[e.branch] < 0) start[e.branch] = s.t;
      if (!dip && start[e.branch] >= 0) {
        if (start[e.branch] > 0) centres[e.branch].push_back(0.5 * (start[e.branch] + s.t - dt));
        start[e.branch] = -1;
      }
    }
  }
  // Tolerance: half a table sample (1/64 cycle) of blur at each edge, the output step, and the
  // carrier's elastic lag behind its kinematic angle (sun driven exactly).
  const double tol = 0.5 / 64 / f_m + dt + lag / (2 * kPi * f_rel);
  std::printf("broken sun tooth: f_rel %.3f Hz, fault frequency %.3f Hz, tolerance %.3g s (IDA steps %ld)\n",
              f_rel, f_fault, tol, integ->stats().steps);
  int total = 0;
  const double quarter = 1.0 / (4 * 34);  // the tooth centre's lag behind its flank, in turns
  for (int b = 0; b < 4; ++b) {
    const double psi = train->planet_sets[0].angles_rad[b];
    for (double c : centres[b]) {
      const double j = std::round((c - offset) * f_rel - psi / (2 * kPi) + quarter);
      const double predicted = (psi / (2 * kPi) - quarter + j) / f_rel + offset;
      std::printf("  branch %d dip at %.6f s, predicted %.6f s\n", b, c, predicted);
      EXPECT_NEAR(c, predicted, tol) << "branch " << b;
    }
    // Once per relative sun turn, one turn apart: in 1.3 turns one complete dip, two for the
    // branches met within the first 0.3 turn (branch 0 is inside its dip at t = 0: not counted).
    const size_t expected = psi > 0 && psi / (2 * kPi) - quarter + offset * f_rel < 0.3 ? 2u : 1u;
    EXPECT_EQ(centres[b].size(), expected) << "branch " << b;
    for (size_t k = 1; k < centres[b].size(); ++k) EXPECT_NEAR(centres[b][k] - centres[b][k - 1], 1 / f_rel, 2 * tol);
    total += static_cast<int>(centres[b].size());
  }
  // All planets together: dips at the fault frequency N f_rel, centred at k / (N f_rel) + offset,
  // k = 1, 2, ... (k = 0, in progress at t = 0, is not counted).
  EXPECT_EQ(total, static_cast<int>(std::floor(f_fault * t_end)));
}

}  // namespace
}  // namespace orrery::gears

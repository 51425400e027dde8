// A broken tooth in a running spur pair with tooth contact (models/gear_contact.h: a tooth left
// out of the wheel's surface). Seed 001's 18/34 pair (m 1.5 mm, 21.3 deg, b 30 mm, contact ratio
// about 1.5) with 20 um normal backlash: the pinion driven at constant speed, the wheel braked by
// a torque that gives 1000 N along the line of action, generalized-alpha at a fixed step. The
// same run healthy and with wheel tooth 2 removed. Checks:
//   - load path: healthy, one or two tooth pairs carry, and the mean normal force is the load
//     (torque / base radius) within the faceting tolerance (the faceted flank's normal is off the
//     involute's by up to half a facet's roll angle: r_a dphi / 2 against r_b) and the mean of the
//     ringing; while the broken tooth would be in mesh only its neighbours carry (at the
//     hand-over from the leaving to the entering neighbour both may touch), and wherever it
//     would have shared with one of them, that one carries alone;
//   - no tooth-through-tooth penetration: the largest penetration of the broken run stays below
//     the contact margin (beyond it a penetration is not seen) and is reported against the
//     healthy run's;
//   - no lost contact detection: the largest motion of a tooth relative to the other gear between
//     consecutive evaluations (TrackedGapStats::max_motion_between_calls_m, over every evaluation
//     the integrator makes, Newton iterates included) is below the margin: a node skipped as out
//     of reach is evaluated at the first call after the surfaces have moved its distance, so it
//     is then at most one call's motion deep, where the margin still sees it (tracked_gaps.h);
//     the exact searches of the hierarchies are counted against node evaluations.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "contact/contact_element.h"
#include "models/gear_contact.h"
#include "mbd/data.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery::gears {
namespace {

using namespace orrery::contact;  // the engine the gear layer builds on

constexpr double kPi = 3.14159265358979323846;

// What the integrator's own evaluations saw (the element's workspaces live in its Data).
struct Observation {
  double max_motion_between_calls_m = 0;
  long searches = 0, calls = 0, node_evaluations = 0;
};

// A ContactElement that reports its search counters after every Apply().
class ObservedContact final : public ExternalForceElement {
 public:
  ObservedContact(ContactElementSpec spec, std::shared_ptr<Observation> obs)
      : element_(std::move(spec)), obs_(std::move(obs)) {}
  const std::string& name() const override { return element_.name(); }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model& m) const override {
    return element_.MakeWorkspace(m);
  }
  void Apply(const Model& m, double t, Data& data, ExternalForceWorkspace& ws) const override {
    element_.Apply(m, t, data, ws);
    const TrackedGapStats& s = static_cast<ContactWorkspace&>(ws).tracked.stats();
    obs_->max_motion_between_calls_m = std::max(obs_->max_motion_between_calls_m, s.max_motion_between_calls_m);
    obs_->searches = std::max(obs_->searches, s.seeds);
    obs_->node_evaluations = std::max(obs_->node_evaluations, s.node_evaluations);
    ++obs_->calls;
  }
  const std::vector<OutputDescription>& outputs() const override { return element_.outputs(); }
  void GetOutputs(const ExternalForceWorkspace& ws, double* values) const override {
    element_.GetOutputs(ws, values);
  }
  bool HasTangents() const override { return element_.HasTangents(); }
  void AddTangents(const Model& m, const Data& data, ExternalForceWorkspace& ws,
                   Eigen::Ref<Eigen::MatrixXd> K, Eigen::Ref<Eigen::MatrixXd> C) const override {
    element_.AddTangents(m, data, ws, K, C);
  }
  const ContactElement& element() const { return element_; }

 private:
  ContactElement element_;
  std::shared_ptr<Observation> obs_;
};

struct Sample {
  double roll_pitches = 0;      // pinion rotation in pitches
  double normal_force = 0, max_penetration = 0;
  unsigned long long wheel_teeth = 0;  // bit i: wheel tooth i has a pressed contact node
  int teeth() const { return __builtin_popcountll(wheel_teeth); }
};

struct PairRun {
  std::vector<Sample> samples;
  Observation obs;
  double load_n = 0, margin_m = 0, slack_m = 0, contact_ratio = 0;
  double facet_tolerance = 0;  // r_a dphi / 2 / r_b of the wheel (relative)
};

constexpr int kZ1 = 18, kZ2 = 34, kBroken = 2;

PairRun RunPair(bool broken) {
  const double deg = kPi / 180;
  gears::GearSpec s1{.teeth = kZ1, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * deg,
                     .face_width_m = 0.03};
  gears::GearSpec s2 = s1;
  s2.teeth = kZ2;
  const gears::GearPair pair = WithNormalBacklash(gears::GearPair{gears::Gear(s1), gears::Gear(s2)}, 20e-6, 0.0);
  GearContactOptions o;
  o.involute_intervals = 24;  // 0.5 um false TE (gear_contact.h), well below the 3 um deflection
  o.hunt_crossley_s_per_m = 1.3;  // about 5 % of critical at 1000 N (k_t = 1.5 c'b, wheel inertia)
  if (broken) o.missing_teeth2 = {kBroken};
  PairRun run;
  run.load_n = 1000;
  run.margin_m = o.margin_m;
  run.slack_m = o.slack_m;
  run.contact_ratio = pair.transverse_contact_ratio();
  {
    const gears::Gear& g = pair.gear2();
    const double ra = g.tip_radius_m(), rb = g.base_radius_m();
    const double dphi = std::sqrt(ra * ra - rb * rb) / rb / o.involute_intervals;
    run.facet_tolerance = ra * dphi / 2 / rb;
  }

  // Pinion on a revolute joint at the origin, driven; wheel at (a, 0, 0), a space facing pinion
  // tooth 0 at q = 0 (the sweep's frames), braked by T = F r_b2.
  const double w1 = 30;  // rad/s: one pitch in 11.6 ms, 8 um of roll per step
  const double rb2 = pair.gear2().base_radius_m();
  ModelBuilder b;
  const BodyIndex g1 = b.AddBody("pinion", 0.3, Vec3::Zero(), Mat3::Identity() * 2e-5);
  const BodyIndex g2 = b.AddBody("wheel", 0.8, Vec3::Zero(), Mat3::Identity() * 1.6e-4);
  JointSpec j1;
  j1.name = "j1", j1.type = JointType::kRevolute, j1.parent = kWorldBody, j1.child = g1;
  JointSpec j2 = j1;
  j2.name = "j2", j2.child = g2;
  j2.X_PF = Transform(AxisAngle(Vec3::UnitZ(), kPi * (1 + 1.0 / kZ2)), Vec3(pair.center_distance_m(), 0, 0));
  const JointIndex ji1 = b.AddJoint(j1);
  const JointIndex ji2 = b.AddJoint(j2);
  b.AddDriver({.name = "drive", .joint = ji1, .coordinate = 0, .mode = DriverSpec::Mode::kSpeed,
               .function = TimeFunction::Constant(w1)});
  // The wheel turns clockwise seen in its joint frame's z (= world z): the brake is +T.
  b.AddJointLoad({.name = "brake", .joint = ji2, .coordinate = 0,
                  .function = TimeFunction::SmoothStep(0, 5e-3, 0, run.load_n * rb2)});
  b.SetJointVelocity(ji1, Eigen::VectorXd::Constant(1, w1));
  b.SetJointVelocity(ji2, Eigen::VectorXd::Constant(1, -w1 * kZ1 / kZ2));
  auto obs = std::make_shared<Observation>();
  auto element = std::make_shared<ObservedContact>(MakeGearContactSpec("mesh", pair, g1, g2, o), obs);
  b.AddExternalForce(element);
  const std::shared_ptr<const Model> model = std::move(b).Finalize();

  IntegratorOptions io;
  io.kind = IntegratorKind::kGeneralizedAlpha;
  io.step = 2e-5;  // 6 steps per period of the wheel on the mesh (about 7.5 kHz)
  io.rho_inf = 0.8;
  auto integ = MakeIntegrator(*model, io);
  integ->Initialize(State::Initial(*model));
  // Samples at every step, evaluated again on a Data of our own (outputs and the teeth loaded).
  Data data(*model);
  auto ws = element->MakeWorkspace(*model);
  const ContactElement& ce = element->element();
  const ContactSurface& wheel_surface = *ce.spec().surface_b;
  const double pitch = 2 * kPi / kZ1;
  const double end = 3.8 * pitch / w1;  // past the broken tooth's window (1.9 .. 3.5 pitches)
  for (int k = 1; k * io.step <= end; ++k) {
    integ->AdvanceTo(k * io.step);
    const State& s = integ->state();
    CalcPositionKinematics(*model, s.q, data);
    CalcVelocityKinematics(*model, s.v, data);
    for (Vec6& f : data.f_ext) f.setZero();
    ce.Apply(*model, s.t, data, *ws);
    const auto& cw = static_cast<const ContactWorkspace&>(*ws);
    Sample x;
    x.roll_pitches = s.q(model->joints[ji1].q_start) / pitch;
    x.normal_force = cw.normal_force;
    x.max_penetration = cw.max_penetration;
    // Wheel teeth loaded: a penetrating wheel node, or a pinion node on a wheel face (parts are
    // the present teeth in order, MakeGearContactSurface). After Apply() a tooth whose rows
    // share one row's gaps lists that row alone (contact_element.h): the same teeth.
    auto tooth_of_part = [&](int part) { return broken && part >= kBroken ? part + 1 : part; };
    auto part_of = [](const std::vector<int>& start, int index) {
      return static_cast<int>(std::upper_bound(start.begin(), start.end(), index) - start.begin()) - 1;
    };
    for (const NodeGap& g : cw.gaps_b)
      if (g.on_surface && g.gap < 0)
        x.wheel_teeth |= 1ull << tooth_of_part(part_of(wheel_surface.part_vertex_start(), g.node));
    for (const NodeGap& g : cw.gaps_a)
      if (g.on_surface && g.gap < 0)
        x.wheel_teeth |= 1ull << tooth_of_part(part_of(wheel_surface.part_triangle_start(), g.face));
    run.samples.push_back(x);
  }
  run.obs = *obs;
  return run;
}

TEST(BrokenTooth, LoadMovesToTheNeighboursWithoutPenetratingOrLosingContact) {
  const PairRun healthy = RunPair(false), broken = RunPair(true);
  ASSERT_EQ(healthy.samples.size(), broken.samples.size());
  const unsigned long long bit = 1ull << kBroken;
  const unsigned long long neighbours = (1ull << (kBroken - 1)) | (1ull << (kBroken + 1));
  // After the load ramp (5 ms) and its ringing: the samples past one pitch.
  auto settled = [](const Sample& x) { return x.roll_pitches > 1.0; };
  // Healthy: one or two wheel teeth carry the load; the broken tooth's window is where it does.
  double healthy_pen = 0, broken_pen = 0, healthy_min_f = 1e30, healthy_max_f = 0, healthy_sum_f = 0;
  int healthy_n = 0;
  int window = 0, window_two_healthy = 0, window_single_broken = 0, window_unloaded = 0;
  double window_max_f = 0, window_from = 1e30, window_to = 0;
  for (size_t k = 0; k < healthy.samples.size(); ++k) {
    const Sample &h = healthy.samples[k], &x = broken.samples[k];
    EXPECT_FALSE(x.wheel_teeth & bit) << "the removed tooth carries load";
    if (!settled(h)) continue;
    healthy_pen = std::max(healthy_pen, h.max_penetration);
    broken_pen = std::max(broken_pen, x.max_penetration);
    healthy_min_f = std::min(healthy_min_f, h.normal_force);
    healthy_max_f = std::max(healthy_max_f, h.normal_force);
    healthy_sum_f += h.normal_force;
    ++healthy_n;
    EXPECT_GE(h.teeth(), 1) << "healthy pair out of contact at " << h.roll_pitches << " pitches";
    EXPECT_LE(h.teeth(), 2);
    if (!(h.wheel_teeth & bit)) continue;
    // The broken tooth would be in mesh: only its neighbours carry; where it would have shared
    // with one of them, that one carries alone (at the hand-over from the leaving to the
    // entering neighbour, both may touch).
    ++window;
    window_from = std::min(window_from, h.roll_pitches);
    window_to = std::max(window_to, h.roll_pitches);
    EXPECT_EQ(x.wheel_teeth & ~neighbours, 0ull) << "at " << x.roll_pitches << " pitches";
    if (h.teeth() == 2) ++window_two_healthy;
    if (h.teeth() == 2 && x.teeth() == 1) ++window_single_broken;
    if (x.teeth() == 0) ++window_unloaded;
    window_max_f = std::max(window_max_f, x.normal_force);
  }
  const double healthy_mean_f = healthy_sum_f / healthy_n;
  std::printf("contact ratio %.3f; load %.0f N; healthy normal force %.0f .. %.0f N, mean %.1f N\n",
              healthy.contact_ratio, healthy.load_n, healthy_min_f, healthy_max_f, healthy_mean_f);
  EXPECT_NEAR(healthy_mean_f, healthy.load_n,
              healthy.facet_tolerance * healthy.load_n + 0.5 * (healthy_max_f - healthy_min_f) / healthy_n);
  std::printf("broken tooth window: %.2f .. %.2f pitches, %d samples, %d with two healthy pairs (%d of "
              "them carried by one neighbour), %d without contact; largest force %.0f N\n",
              window_from, window_to, window, window_two_healthy, window_single_broken, window_unloaded,
              window_max_f);
  std::printf("max penetration: healthy %.2f um, broken %.2f um (margin %.0f um)\n", 1e6 * healthy_pen,
              1e6 * broken_pen, 1e6 * broken.margin_m);
  for (const PairRun* r : {&healthy, &broken})
    std::printf("%s: %ld evaluations, %.1f nodes evaluated and %.2f searched per evaluation, "
                "largest tooth motion between evaluations %.2f um (margin %.0f um)\n",
                r == &healthy ? "healthy" : "broken", r->obs.calls,
                static_cast<double>(r->obs.node_evaluations) / r->obs.calls,
                static_cast<double>(r->obs.searches) / r->obs.calls,
                1e6 * r->obs.max_motion_between_calls_m, 1e6 * r->margin_m);
  // The window is about (contact ratio) pitches long and was seen.
  EXPECT_GT(window, 0);
  EXPECT_GT(window_two_healthy, 0);
  EXPECT_EQ(window_single_broken, window_two_healthy);
  // No tooth through tooth: penetrations stay below the margin (where they would still be seen).
  EXPECT_LT(broken_pen, broken.margin_m);
  // Every evaluation moves the teeth by less than the margin: a node coming into reach is seen.
  for (const PairRun* r : {&healthy, &broken}) {
    EXPECT_LT(r->obs.max_motion_between_calls_m, r->margin_m);
    EXPECT_GT(r->obs.searches, 1);
    EXPECT_LT(r->obs.searches, r->obs.node_evaluations);
  }
}

}  // namespace
}  // namespace orrery::gears

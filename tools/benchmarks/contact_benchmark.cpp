// Cost of one contact evaluation for a rigid spur-gear pair in mesh (19/27 teeth, m = 2 mm,
// b = 10 mm, every tooth a part of its gear's surface, zero backlash so that both flanks touch),
// split by stage: broad phase (part spheres), triangle pairs (inflated-BVH traversal + exact
// distance), node-face lists (once per search), gaps (both passes), forces. The surfaces carry a
// slack of 50 um (candidate_pairs.h): BM_EvaluationWithinSlack alternates between two poses
// 1 nrad apart (what a step or a position column of a finite-difference Jacobian costs: no
// search), BM_EvaluationWithSearch forces a search every time, BM_SamePoseEvaluation repeats one
// pose (a velocity column).
// These use ContactGapMethod::kCandidatePairs; BM_Seed001Rolling* compare both gap methods on a
// rolling pair (tracked gaps are the elements' default).
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "contact/contact_element.h"
#include "models/gear_contact.h"
#include "models/gear_geometry.h"

namespace {

using namespace orrery;
using namespace orrery::contact;
using namespace orrery::gears;  // the gear layer's surfaces as workloads

struct GearPairContact {
  std::unique_ptr<ContactElement> element;
  std::unique_ptr<ContactWorkspace> ws;
  Transform X_W1[2], X_W2;
  Vec6 V1 = Vec6::Zero(), V2 = Vec6::Zero();
};

GearPairContact& Setup() {
  static GearPairContact* c = [] {
    auto* s = new GearPairContact;
    gears::Gear g1({.teeth = 19, .normal_module_m = 2e-3, .face_width_m = 0.01});
    gears::Gear g2({.teeth = 27, .normal_module_m = 2e-3, .face_width_m = 0.01});
    const double a = gears::GearPair(g1, g2).center_distance_m();
    std::vector<TriangleMesh> p1, p2;
    for (int i = 0; i < g1.teeth(); ++i) p1.push_back(gears::MakeToothSurfaceMesh(g1, i, {}, 10));
    for (int i = 0; i < g2.teeth(); ++i) p2.push_back(gears::MakeToothSurfaceMesh(g2, i, {}, 10));
    auto s1 = std::make_shared<const ContactSurface>(p1, 50e-6, 50e-6);
    auto s2 = std::make_shared<const ContactSurface>(p2, 50e-6, 50e-6);
    s->element = std::make_unique<ContactElement>(ContactElementSpec{
        .name = "mesh", .body_a = 1, .body_b = 2, .surface_a = s1, .surface_b = s2,
        .law = {.stiffness_per_area = 1e14, .hunt_crossley_s_per_m = 1,
                .friction_coefficient = 0.05},
        .gap_method = ContactGapMethod::kCandidatePairs});
    s->ws = std::make_unique<ContactWorkspace>(*s1, *s2);
    // Gear 1 turned into the zero-backlash mesh by ~10 um along the line of action.
    const double theta = 10e-6 / g1.base_radius_m();
    for (int k = 0; k < 2; ++k)
      s->X_W1[k] = Transform(AxisAngle(Vec3::UnitZ(), theta + 1e-9 * k), Vec3::Zero());
    s->X_W2 = Transform(AxisAngle(Vec3::UnitZ(), 3.14159265358979323846 * (1 + 1.0 / 27)),
                        Vec3(a, 0, 0));
    s->V1.head<3>() = Vec3(0, 0, 100);
    s->V2.head<3>() = Vec3(0, 0, -100 * 19.0 / 27);
    s->V2.tail<3>() = -Vec3(a, 0, 0).cross(s->V2.head<3>().eval());
    return s;
  }();
  return *c;
}

void Report(benchmark::State& state, const GearPairContact& c) {
  state.counters["triangles"] = c.element->spec().surface_a->num_triangles() +
                                c.element->spec().surface_b->num_triangles();
  state.counters["part_pairs"] = c.ws->search.stats().part_pairs;
  state.counters["leaf_tests"] = c.ws->search.stats().leaf_tests;
  state.counters["pairs"] = c.ws->search.stats().candidate_pairs;
  state.counters["node_faces"] = static_cast<double>(c.ws->node_faces_a.size() +
                                                     c.ws->node_faces_b.size());
  int contacts = 0;
  for (const auto* gaps : {&c.ws->gaps_a, &c.ws->gaps_b})
    for (const NodeGap& g : *gaps) contacts += g.gap < 0 && g.on_surface;
  state.counters["contact_nodes"] = contacts;
}

void BM_BroadPhase(benchmark::State& state) {
  GearPairContact& c = Setup();
  int k = 0;
  for (auto _ : state) c.ws->search.UpdateBroadPhase(c.X_W1[k ^= 1], c.X_W2);
  Report(state, c);
}
BENCHMARK(BM_BroadPhase)->Unit(benchmark::kMicrosecond);

void BM_TrianglePairs(benchmark::State& state) {
  GearPairContact& c = Setup();
  c.ws->search.UpdateBroadPhase(c.X_W1[0], c.X_W2);
  for (auto _ : state) c.ws->search.FindPairs(&c.ws->pairs);
  Report(state, c);
}
BENCHMARK(BM_TrianglePairs)->Unit(benchmark::kMicrosecond);

void BM_NodeFaceLists(benchmark::State& state) {
  GearPairContact& c = Setup();
  c.ws->search.UpdateBroadPhase(c.X_W1[0], c.X_W2);
  c.ws->search.FindPairs(&c.ws->pairs);
  const ContactSurface& a = *c.element->spec().surface_a;
  const ContactSurface& b = *c.element->spec().surface_b;
  for (auto _ : state) {
    ListNodeFaceCandidates(a, c.ws->pairs, true, &c.ws->scratch_a, &c.ws->node_faces_a);
    ListNodeFaceCandidates(b, c.ws->pairs, false, &c.ws->scratch_b, &c.ws->node_faces_b);
  }
  Report(state, c);
}
BENCHMARK(BM_NodeFaceLists)->Unit(benchmark::kMicrosecond);

void BM_Gaps(benchmark::State& state) {
  GearPairContact& c = Setup();
  c.ws->search.UpdateBroadPhase(c.X_W1[0], c.X_W2);
  c.ws->search.FindPairs(&c.ws->pairs);
  const ContactSurface& a = *c.element->spec().surface_a;
  const ContactSurface& b = *c.element->spec().surface_b;
  ListNodeFaceCandidates(a, c.ws->pairs, true, &c.ws->scratch_a, &c.ws->node_faces_a);
  ListNodeFaceCandidates(b, c.ws->pairs, false, &c.ws->scratch_b, &c.ws->node_faces_b);
  const double d = c.ws->search.search_distance_m();
  for (auto _ : state) {
    ComputeNodeGapsFromCandidates(a, c.X_W1[0], b, c.X_W2, c.ws->node_faces_a, d, &c.ws->gaps_a);
    ComputeNodeGapsFromCandidates(b, c.X_W2, a, c.X_W1[0], c.ws->node_faces_b, d, &c.ws->gaps_b);
  }
  Report(state, c);
}
BENCHMARK(BM_Gaps)->Unit(benchmark::kMicrosecond);

// The oracle pass straight from the triangle pairs (what every evaluation cost before the lists).
void BM_GapsFromPairs(benchmark::State& state) {
  GearPairContact& c = Setup();
  c.ws->search.UpdateBroadPhase(c.X_W1[0], c.X_W2);
  c.ws->search.FindPairs(&c.ws->pairs);
  const ContactSurface& a = *c.element->spec().surface_a;
  const ContactSurface& b = *c.element->spec().surface_b;
  const double d = c.ws->search.search_distance_m();
  for (auto _ : state) {
    ComputeNodeGaps(a, c.X_W1[0], b, c.X_W2, c.ws->pairs, true, d, &c.ws->scratch_a, &c.ws->gaps_a);
    ComputeNodeGaps(b, c.X_W2, a, c.X_W1[0], c.ws->pairs, false, d, &c.ws->scratch_b, &c.ws->gaps_b);
  }
  Report(state, c);
}
BENCHMARK(BM_GapsFromPairs)->Unit(benchmark::kMicrosecond);

void BM_Forces(benchmark::State& state) {
  GearPairContact& c = Setup();
  c.element->UpdateGaps(c.X_W1[0], c.X_W2, *c.ws);
  Vec6 fa, fb;
  double e, p;
  for (auto _ : state) {
    c.element->CalcForces(c.V1, c.V2, *c.ws, &fa, &fb, &e, &p);
    benchmark::DoNotOptimize(fa);
  }
  state.counters["normal_force_n"] = c.ws->normal_force;
  Report(state, c);
}
BENCHMARK(BM_Forces)->Unit(benchmark::kMicrosecond);

void BM_EvaluationWithinSlack(benchmark::State& state) {
  GearPairContact& c = Setup();
  Vec6 fa, fb;
  double e, p;
  int k = 0;
  const long searches = c.ws->search.stats().searches;
  for (auto _ : state) {
    c.element->UpdateGaps(c.X_W1[k ^= 1], c.X_W2, *c.ws);
    c.element->CalcForces(c.V1, c.V2, *c.ws, &fa, &fb, &e, &p);
    benchmark::DoNotOptimize(fa);
  }
  state.counters["searches"] = static_cast<double>(c.ws->search.stats().searches - searches);
  Report(state, c);
}
BENCHMARK(BM_EvaluationWithinSlack)->Unit(benchmark::kMicrosecond);

void BM_EvaluationWithSearch(benchmark::State& state) {
  GearPairContact& c = Setup();
  Vec6 fa, fb;
  double e, p;
  int k = 0;
  for (auto _ : state) {
    c.ws->search.Invalidate();
    c.element->UpdateGaps(c.X_W1[k ^= 1], c.X_W2, *c.ws);
    c.element->CalcForces(c.V1, c.V2, *c.ws, &fa, &fb, &e, &p);
    benchmark::DoNotOptimize(fa);
  }
  Report(state, c);
}
BENCHMARK(BM_EvaluationWithSearch)->Unit(benchmark::kMicrosecond);

void BM_SamePoseEvaluation(benchmark::State& state) {
  GearPairContact& c = Setup();
  Vec6 fa, fb;
  double e, p;
  for (auto _ : state) {
    c.element->UpdateGaps(c.X_W1[0], c.X_W2, *c.ws);
    c.element->CalcForces(c.V1, c.V2, *c.ws, &fa, &fb, &e, &p);
    benchmark::DoNotOptimize(fa);
  }
  Report(state, c);
}
BENCHMARK(BM_SamePoseEvaluation)->Unit(benchmark::kMicrosecond);

// Seed 001's 18/34 sun-planet pair with MakeGearContactSpec's defaults (100 involute intervals,
// 2 face intervals, margin 30 um, slack 100 um), gear 1 ahead by 3 um on the line of action:
// one evaluation within the slack (a step or a Jacobian column) and one with a search.
// Measured (one core, shared machine, CPU time): with a search 17 ms before the mesh-zone test
// (168 tooth pairs), 15.8 ms after (20 tooth pairs, 9 teeth in the zone): the part pairs were
// cheap root tests; the cost is the ~39k leaf tests of the ~30k candidate pairs that both flanks
// (zero backlash) within d + s = 130 um give on flanks faceted at 40 um. Backlash halves them.
struct Seed001Contact {
  std::unique_ptr<ContactElement> element;
  std::unique_ptr<ContactWorkspace> ws;
  Transform X_W1[2], X_W2;
};

// Seed 001's 18/34 sun-planet pair (m = 1.5 mm, 21.3 deg, b = 30 mm).
gears::GearPair Seed001Pair() {
  const double deg = 3.14159265358979323846 / 180;
  gears::GearSpec g1{.teeth = 18, .normal_module_m = 1.5e-3,
                     .normal_pressure_angle_rad = 21.3 * deg, .face_width_m = 0.03};
  gears::GearSpec g2 = g1;
  g2.teeth = 34;
  return gears::GearPair{gears::Gear(g1), gears::Gear(g2)};
}

Seed001Contact& SetupSeed001() {
  static Seed001Contact* c = [] {
    auto* s = new Seed001Contact;
    const gears::GearPair pair = Seed001Pair();
    ContactElementSpec spec = MakeGearContactSpec("mesh", pair, 1, 2, {});
    spec.gap_method = ContactGapMethod::kCandidatePairs;
    s->element = std::make_unique<ContactElement>(spec);
    s->ws = std::make_unique<ContactWorkspace>(*s->element->spec().surface_a,
                                               *s->element->spec().surface_b);
    const double theta = 3e-6 / pair.gear1().base_radius_m();
    for (int k = 0; k < 2; ++k)
      s->X_W1[k] = Transform(AxisAngle(Vec3::UnitZ(), theta + 1e-9 * k), Vec3::Zero());
    s->X_W2 = Transform(AxisAngle(Vec3::UnitZ(), 3.14159265358979323846 * (1 + 1.0 / 34)),
                        Vec3(pair.center_distance_m(), 0, 0));
    return s;
  }();
  return *c;
}

void BM_Seed001EvaluationWithinSlack(benchmark::State& state) {
  Seed001Contact& c = SetupSeed001();
  Vec6 fa, fb;
  double e, p;
  int k = 0;
  const Vec6 zero = Vec6::Zero();
  for (auto _ : state) {
    c.element->UpdateGaps(c.X_W1[k ^= 1], c.X_W2, *c.ws);
    c.element->CalcForces(zero, zero, *c.ws, &fa, &fb, &e, &p);
    benchmark::DoNotOptimize(fa);
  }
  state.counters["normal_force_n"] = c.ws->normal_force;
  state.counters["pairs"] = c.ws->search.stats().candidate_pairs;
  state.counters["node_faces"] = static_cast<double>(c.ws->node_faces_a.size() + c.ws->node_faces_b.size());
  state.counters["contact_nodes"] = c.ws->contact_points;
}
BENCHMARK(BM_Seed001EvaluationWithinSlack)->Unit(benchmark::kMicrosecond);

void BM_Seed001EvaluationWithSearch(benchmark::State& state) {
  Seed001Contact& c = SetupSeed001();
  Vec6 fa, fb;
  double e, p;
  int k = 0;
  const Vec6 zero = Vec6::Zero();
  for (auto _ : state) {
    c.ws->search.Invalidate();
    c.element->UpdateGaps(c.X_W1[k ^= 1], c.X_W2, *c.ws);
    c.element->CalcForces(zero, zero, *c.ws, &fa, &fb, &e, &p);
    benchmark::DoNotOptimize(fa);
  }
  state.counters["zone_teeth"] = c.ws->search.stats().zone_parts_a + c.ws->search.stats().zone_parts_b;
  state.counters["part_pairs"] = c.ws->search.stats().part_pairs;
  state.counters["leaf_tests"] = c.ws->search.stats().leaf_tests;
  state.counters["exact_tests"] = c.ws->search.stats().exact_tests;
  state.counters["pairs"] = c.ws->search.stats().candidate_pairs;
}
BENCHMARK(BM_Seed001EvaluationWithSearch)->Unit(benchmark::kMicrosecond);

// Seed 001's pair rolling: each evaluation turns gear 1 by 0.3 mrad (30 rad/s at a 10 us step)
// with gear 2 at its kinematic angle, 3 um ahead on the line of action, over many mesh periods:
// what a run pays per mesh evaluation, searches included, with each gap method.
void RollingSeed001(benchmark::State& state, ContactGapMethod method) {
  const double pi = 3.14159265358979323846;
  const gears::GearPair pair = Seed001Pair();
  ContactElementSpec spec = MakeGearContactSpec("mesh", pair, 1, 2, {});
  spec.gap_method = method;
  ContactElement element(spec);
  ContactWorkspace ws(*spec.surface_a, *spec.surface_b);
  const double ahead = 3e-6 / pair.gear1().base_radius_m();
  const Vec6 zero = Vec6::Zero();
  Vec6 fa, fb;
  double e, p, theta = 0, force = 0;
  long evaluations = 0;
  for (auto _ : state) {
    theta += 3e-4;
    const Transform X_W1(AxisAngle(Vec3::UnitZ(), theta + ahead), Vec3::Zero());
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), pi * (1 + 1.0 / 34) - theta * 18 / 34),
                         Vec3(pair.center_distance_m(), 0, 0));
    element.UpdateGaps(X_W1, X_W2, ws);
    element.CalcForces(zero, zero, ws, &fa, &fb, &e, &p);
    force += ws.normal_force;
    ++evaluations;
  }
  state.counters["mean_normal_force_n"] = force / std::max(1L, evaluations);
  state.counters["mesh_periods"] = theta / (2 * pi / 18);
  if (method == ContactGapMethod::kTracked) {
    const TrackedGapStats& t = ws.tracked.stats();
    state.counters["nodes_per_eval"] = static_cast<double>(t.node_evaluations) / t.updates;
    state.counters["searched_per_eval"] = static_cast<double>(t.seeds) / t.updates;
  } else {
    state.counters["searches_per_eval"] =
        static_cast<double>(ws.search.stats().searches) / std::max(1L, evaluations);
  }
}
void BM_Seed001RollingTracked(benchmark::State& state) {
  RollingSeed001(state, ContactGapMethod::kTracked);
}
void BM_Seed001RollingCandidatePairs(benchmark::State& state) {
  RollingSeed001(state, ContactGapMethod::kCandidatePairs);
}
BENCHMARK(BM_Seed001RollingTracked)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Seed001RollingCandidatePairs)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

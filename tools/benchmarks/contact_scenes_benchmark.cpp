// The tooth-contact rows of the performance table (docs/performance.md, issue 15): seed 003's
// stage run as `orrery run` runs it (generalized-alpha at the scene's step, the result recorder
// and the sensors writing to an in-memory result file, the run's health checks) for 20 ms of
// simulated time after a 5 ms start-up (the meshes taking up the load; run once, not timed).
//   ContactScene/0: rigid tooth contact on all 6 meshes (seed003_contact_healthy.yaml, 10 us);
//   ContactScene/1: planet 1 flexible (24 modes) with contact on its two meshes, planets 2 and 3
//                   on lumped TVMS meshes (seed003_flexible_healthy.yaml, 5 us; its reduced
//                   body is made on the first run).
// Counters: cpu_per_sim_s and wall_per_sim_s (process CPU and wall seconds per simulated second:
// the table's figures; CPU over all threads), steps, residuals, jacobians (the integrator's
// statistics), newton_failures (steps retried with a halved step), us_per_step, threads (the
// scene's solver.threads, else OMP_NUM_THREADS, else 1: the contacts of an evaluation in parallel).
// ListedNodeFloor: the least the tracked-gap scheme can do for one listed node of the rigid
// scene (docs/performance.md, "the floor"): transform the node into the face body's frame, one
// triangle distance on the face it is listed on, its gap (NodeGapFromClosest), its world point,
// normal and velocity, the contact law and the wrench summed: no sleep test, no walk, no search,
// no broad phase. Its nodes are the penetrating nodes of the six contact elements at the
// benchmark's start state (t = 5 ms). Counters: ns_per_node (CPU; printed with an "s"),
// listed_nodes (the six meshes together at that state), and floor_cpu_per_sim_s_r2 / _r315:
// ns_per_node times the steady listed nodes per evaluation (kListedPerEvaluation, counted over
// 5-15 ms) times the evaluations per simulated second at 10 us with 2 and with 3.15 residuals
// per step (the row's 5-15 ms), plus the recorder's 1e4 rows. Since the rows of a spur tooth
// share one row's evaluation (tracked_gaps.h, extruded parts; docs/performance.md
// "shared-rows"), a third of the listed nodes are evaluated: the scheme's floor is about a
// third of these figures, plus the shared entries' copies.
//   contact_scenes_benchmark --benchmark_filter=ListedNodeFloor
//   contact_scenes_benchmark --benchmark_filter=ContactScene/0
//   OMP_NUM_THREADS=2 contact_scenes_benchmark
#include <benchmark/benchmark.h>

#include <atomic>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "contact/contact_element.h"
#include "import/scene.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

constexpr const char* kFiles[] = {"seed003_contact_healthy.yaml", "seed003_flexible_healthy.yaml"};
constexpr double kStartUpS = 0.005;
constexpr double kSimulatedS = 0.02;

struct Row {
  Scene scene;
  State start;  // the state after the start-up
};

const Row& LoadRow(int i) {
  static std::map<int, std::unique_ptr<Row>> rows;
  auto& r = rows[i];
  if (r) return *r;
  Scene scene = LoadScene(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + kFiles[i],
                          {"solver.end_time=" + std::to_string(kStartUpS)},
                          {.make_reduced_bodies = true});
  const SimulationReport start_up = Simulate(*scene.model, scene.simulation, nullptr);
  scene.simulation.end_time = kStartUpS + kSimulatedS;
  r = std::make_unique<Row>(Row{.scene = std::move(scene), .start = start_up.final_state});
  return *r;
}

double ProcessCpuS() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void BM_ContactScene(benchmark::State& state) {
  const Row& row = LoadRow(int(state.range(0)));
  SimulationReport report;
  double wall_s = 0, cpu_s = 0;
  static std::atomic<long> files{0};
  for (auto _ : state) {
    ResultFile out = ResultFile::CreateInMemory("contact benchmark " + std::to_string(++files));
    const double cpu0 = ProcessCpuS();
    report = Simulate(*row.scene.model, row.scene.simulation, &out, {}, &row.start);
    cpu_s += ProcessCpuS() - cpu0;
    wall_s += report.wall_s;
  }
  const double runs = double(state.iterations());
  state.SetLabel(kFiles[state.range(0)]);
  state.counters["cpu_per_sim_s"] = cpu_s / runs / kSimulatedS;
  state.counters["wall_per_sim_s"] = wall_s / runs / kSimulatedS;
  state.counters["steps"] = double(report.stats.steps);
  state.counters["residuals"] = double(report.stats.residual_evaluations);
  state.counters["jacobians"] = double(report.stats.jacobian_evaluations);
  state.counters["newton_failures"] = double(report.stats.newton_failures);
  state.counters["us_per_step"] = 1e6 * wall_s / runs / double(report.stats.steps);
  state.counters["threads"] = ResolveThreads(row.scene.simulation.integrator.threads);
}

BENCHMARK(BM_ContactScene)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->Iterations(3);

// Listed nodes per evaluation of the rigid scene, its six meshes together, and its residuals per
// step, counted over 5-15 ms (docs/performance.md): 3 x (58.5 sun mesh + 78.2 ring mesh) in an
// instrumented build (perf-rigid5 stop); 4737 - 1586 residuals over 1000 steps (the solver's
// statistics of 15 and 5 ms runs; perf-newton2 stop: measured ends with Broyden updates, matrix
// refreshed at a contraction of 0.01; 3.89 before). Update both if the scene or its Newton changes.
constexpr double kListedPerEvaluation = 3 * (58.5 + 78.2);
constexpr double kResidualsPerStep = 3.15;

void BM_ListedNodeFloor(benchmark::State& state) {
  const Row& row = LoadRow(0);
  const Model& model = *row.scene.model;
  Data data(model);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(model.nv);
  EvaluateDynamics(model, row.start.t, row.start.q, row.start.v, vdot, data);
  // The listed gaps of each contact element at the start state, with what a node needs.
  struct Pass {
    const contact::ContactSurface* nodes;
    const contact::ContactSurface* faces;
    const contact::ContactLaw* law;
    Transform X_FN, X_WF;
    Vec6 V_N, V_F;
    std::vector<contact::NodeGap> gaps;  // the penetrating ones (the steady state's listed)
  };
  std::vector<Pass> passes;
  long listed = 0;
  for (size_t i = 0; i < model.external_forces.size(); ++i) {
    const auto* element =
        dynamic_cast<const contact::ContactElement*>(model.external_forces[i].get());
    if (!element) continue;
    auto& ws = static_cast<contact::ContactWorkspace&>(*data.external[i]);
    const auto& spec = element->spec();
    const Transform& X_WA = data.X_WB[spec.body_a];
    const Transform& X_WB = data.X_WB[spec.body_b];
    // Every listed node: the evaluation left a shared part's other rows pending
    // (contact_element.h), and UpdateGaps at its poses makes them.
    element->UpdateGaps(X_WA, X_WB, ws);
    const Vec6& V_A = data.V_WB[spec.body_a];
    const Vec6& V_B = data.V_WB[spec.body_b];
    passes.push_back({spec.surface_a.get(), spec.surface_b.get(), &spec.law,
                      X_WB.Inverse() * X_WA, X_WB, V_A, V_B, ws.gaps_a});
    passes.push_back({spec.surface_b.get(), spec.surface_a.get(), &spec.law,
                      X_WA.Inverse() * X_WB, X_WA, V_B, V_A, ws.gaps_b});
  }
  // A cold evaluation also lists the nodes within d that do not touch (a stepping one leaves
  // most of them asleep: 91 % of its listed nodes penetrate), so the floor is timed on the
  // penetrating nodes.
  for (Pass& pass : passes) {
    std::erase_if(pass.gaps,
                  [](const contact::NodeGap& g) { return !(g.gap < 0 && g.on_surface); });
    listed += long(pass.gaps.size());
  }
  Vec6 f_sum = Vec6::Zero();
  for (auto _ : state) {
    for (const Pass& pass : passes) {
      const auto& v = pass.faces->vertices();
      for (const contact::NodeGap& listed_gap : pass.gaps) {
        // The node in the face frame, one triangle distance on its face, its gap.
        const Vec3 p = pass.X_FN * pass.nodes->vertices()[listed_gap.node];
        const auto& t = pass.faces->triangles()[listed_gap.face];
        const contact::ClosestPoint c =
            contact::ClosestPointOnTriangle(p, v[t[0]], v[t[1]], v[t[2]]);
        contact::NodeGap g =
            contact::NodeGapFromClosest(*pass.faces, listed_gap.face, p, c.point, c.feature);
        g.p_W = pass.X_WF * p;
        g.q_W = pass.X_WF * c.point;
        g.n_W = pass.X_WF.R * pass.faces->face_normals()[g.face];
        if (!(g.gap < 0) || !g.on_surface) continue;
        // The law and the wrench, as ContactElement::CalcForces.
        const Vec3 v_rel = PointVelocity(pass.V_N, g.p_W) - PointVelocity(pass.V_F, g.p_W);
        const double area = 0.5 * g.weight * pass.nodes->vertex_areas()[listed_gap.node] *
                            pass.nodes->vertex_stiffness_scale()[listed_gap.node] *
                            pass.faces->face_stiffness_scale()[g.face];
        const contact::NodeForce f = contact::EvaluateContactLaw(
            *pass.law, -g.gap, -v_rel.dot(g.n_W), g.n_W, v_rel, area);
        f_sum += ForceAtPoint(g.p_W, f.f_W);
      }
    }
    benchmark::DoNotOptimize(f_sum);
  }
  // Inverted rates: the loop's time per node (ns), and that times the listed nodes per
  // simulated second (evaluations: 1e5 steps times the residuals, plus 1e4 recorder rows).
  const double nodes = double(state.iterations()) * double(listed);
  auto per = [&](double scale) {
    return benchmark::Counter(nodes * scale,
                              benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  };
  state.counters["listed_nodes"] = double(listed);
  state.counters["ns_per_node"] = per(1e-9);
  state.counters["floor_cpu_per_sim_s_r2"] = per(1 / (kListedPerEvaluation * (2e5 + 1e4)));
  state.counters["floor_cpu_per_sim_s_r315"] =
      per(1 / (kListedPerEvaluation * (kResidualsPerStep * 1e5 + 1e4)));
}
BENCHMARK(BM_ListedNodeFloor)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

// Seed 003's planetary stage with tooth contact on every mesh (models/scenes/
// seed003_contact_healthy.yaml) and with planet 1 flexible (seed003_flexible_healthy.yaml,
// 24 modes; its reduced body is made on the first run): what one step of the integrators pays.
//   *Residual: one evaluation of the dynamics (kinematics, the six contacts, inverse dynamics)
//     at the states of the scene's own run from 2 to 3 ms (every 5 us step, cycled);
//   *Tangents: the iteration matrix's tangents (DaeSystem::Tangents: finite differences of the
//     pipeline without the contacts, the contacts' analytic tangents);
//   FlexibleSunMesh*: the flexible planet's sun-mesh element alone (Apply after the kinematics),
//     and its tangents.
#include <benchmark/benchmark.h>

#include <map>
#include <stdexcept>
#include <memory>
#include <string>
#include <vector>

#include "import/scene.h"
#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"

namespace orrery {
namespace {

struct Stage {
  Scene scene;
  std::vector<State> states;       // the run's states from 2 to 3 ms, every 5 us
  Eigen::VectorXd vdot, lambda;    // at 2 ms
  const State& at(long k) const { return states[k % states.size()]; }
};

const Stage& LoadStage(const std::string& file) {
  static std::map<std::string, std::unique_ptr<Stage>> stages;
  auto& s = stages[file];
  if (s) return *s;
  s = std::make_unique<Stage>(
      Stage{.scene = LoadScene(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + file, {}, {.make_reduced_bodies = true})});
  IntegratorOptions o = s->scene.simulation.integrator;
  std::unique_ptr<Integrator> integ = MakeIntegrator(*s->scene.model, o);
  integ->Initialize(State::Initial(*s->scene.model));
  integ->AdvanceTo(0.002);
  s->vdot = integ->vdot();
  s->lambda = integ->lambda();
  for (int k = 0; k < 200; ++k) {
    s->states.push_back(integ->state());
    integ->AdvanceTo(0.002 + 5e-6 * (k + 1));
  }
  return *s;
}

void Residual(benchmark::State& state, const std::string& file) {
  const Stage& s = LoadStage(file);
  const Model& m = *s.scene.model;
  Data data(m);
  long k = 0;
  for (auto _ : state) {
    const State& st = s.at(k++);
    EvaluateDynamics(m, st.t, st.q, st.v, s.vdot, data);
    benchmark::DoNotOptimize(data.tau_id.data());
  }
}

void Tangents(benchmark::State& state, const std::string& file) {
  const Stage& s = LoadStage(file);
  const Model& m = *s.scene.model;
  DaeSystem dae(m);
  Eigen::MatrixXd K(m.nv + m.n_constraints, m.nv), C(m.nv, m.nv);
  long k = 0;
  for (auto _ : state) {
    const State& st = s.at(k++);
    dae.Tangents(st.t, st.q, st.v, s.vdot, s.lambda, K, C);
    benchmark::DoNotOptimize(K.data());
  }
  state.counters["nv"] = m.nv;
}

void BM_RigidStageResidual(benchmark::State& state) { Residual(state, "seed003_contact_healthy.yaml"); }
void BM_RigidStageTangents(benchmark::State& state) { Tangents(state, "seed003_contact_healthy.yaml"); }
void BM_FlexibleStageResidual(benchmark::State& state) {
  Residual(state, "seed003_flexible_healthy.yaml");
}
void BM_FlexibleStageTangents(benchmark::State& state) {
  Tangents(state, "seed003_flexible_healthy.yaml");
}
BENCHMARK(BM_RigidStageResidual)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RigidStageTangents)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FlexibleStageResidual)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FlexibleStageTangents)->Unit(benchmark::kMicrosecond);

// The flexible planet's sun mesh alone: its Apply after the kinematics (the kinematics timed
// apart: BM_StageKinematics), and its tangents; normal force and contact points at the last.
int ElementIndex(const Model& m, const std::string& name) {
  for (size_t e = 0; e < m.external_forces.size(); ++e)
    if (m.external_forces[e]->name() == name) return static_cast<int>(e);
  throw std::out_of_range("no external force element '" + name + "'");
}

// The kinematics at the run's states, then (apply) the flexible sun mesh's Apply.
void KinematicsThenSunMesh(benchmark::State& state, bool apply) {
  const Stage& s = LoadStage("seed003_flexible_healthy.yaml");
  const Model& m = *s.scene.model;
  const int e = ElementIndex(m, "S.sun-planet#1");
  Data data(m);
  long k = 0;
  for (auto _ : state) {
    const State& st = s.at(k++);
    CalcPositionKinematics(m, st.q, data);
    CalcVelocityKinematics(m, st.v, data);
    if (apply) m.external_forces[e]->Apply(m, st.t, data, *data.external[e]);
    benchmark::DoNotOptimize(data.V_WB.data());
  }
  if (!apply) return;
  std::vector<double> out(OutputValueCount(m.external_forces[e]->outputs()));
  m.external_forces[e]->GetOutputs(*data.external[e], out.data());
  state.counters["normal_force_n"] = out[0];
  state.counters["contact_points"] = out[2];
}
void BM_StageKinematics(benchmark::State& state) { KinematicsThenSunMesh(state, false); }
void BM_FlexibleSunMeshApply(benchmark::State& state) { KinematicsThenSunMesh(state, true); }
BENCHMARK(BM_StageKinematics)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FlexibleSunMeshApply)->Unit(benchmark::kMicrosecond);

void BM_FlexibleSunMeshTangents(benchmark::State& state) {
  const Stage& s = LoadStage("seed003_flexible_healthy.yaml");
  const Model& m = *s.scene.model;
  const int e = ElementIndex(m, "S.sun-planet#1");
  Data data(m);
  CalcPositionKinematics(m, s.at(0).q, data);
  CalcVelocityKinematics(m, s.at(0).v, data);
  m.external_forces[e]->Apply(m, s.at(0).t, data, *data.external[e]);
  CalcBodyJacobians(m, data);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m.nv, m.nv), C = K;
  for (auto _ : state) {
    m.external_forces[e]->AddTangents(m, data, *data.external[e], K, C);
    benchmark::DoNotOptimize(K.data());
  }
}
BENCHMARK(BM_FlexibleSunMeshTangents)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

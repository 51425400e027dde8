// Hot paths of the multibody core on a chain of rigid links (Google Benchmark, Release build).
//
//   chain_benchmark                       all
//   chain_benchmark --benchmark_filter=Residual
//
// Model: N links on revolute joints with axes alternating z and y (a 3-D chain), the free end
// closed to the world by a spherical loop closure (3 rows), gravity, a coordinate spring-damper on
// every joint. The reference case is N = 20 (17 DOF after the closure).
#include <benchmark/benchmark.h>

#include <memory>

#include "mbd/constraints.h"
#include "mbd/dae.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

std::shared_ptr<const Model> MakeChain(int n, bool closed) {
  ModelBuilder b;
  const double L = 0.1, m = 0.5;
  const Mat3 I = Vec3(m * L * L / 12, 1e-4, m * L * L / 12).asDiagonal();
  BodyIndex parent = kWorldBody;
  for (int k = 0; k < n; ++k) {
    const BodyIndex link = b.AddBody("link" + std::to_string(k), m, Vec3(L / 2, 0, 0), I);
    JointSpec j;
    j.name = "joint" + std::to_string(k);
    j.type = JointType::kRevolute;
    j.parent = parent;
    j.child = link;
    j.X_PF = Transform::Translation(Vec3(parent == kWorldBody ? 0.0 : L, 0, 0));
    j.axis = (k % 2 == 0) ? Vec3::UnitZ() : Vec3::UnitY();
    const JointIndex ji = b.AddJoint(j);
    b.SetJointPosition(ji, Eigen::VectorXd::Constant(1, k % 2 == 0 ? -0.12 : 0.05));
    b.AddCoordinateSpring({.name = "spring" + std::to_string(k), .joint = ji, .coordinate = 0,
                           .stiffness = 2.0, .damping = 0.01, .q0 = 0.0});
    parent = link;
  }
  if (closed) {
    // Close the loop where the tip sits in the initial configuration (assembled exactly later).
    const FrameIndex tip = b.AddFrame("tip", parent, Transform::Translation(Vec3(L, 0, 0)));
    auto draft = std::move(b);
    auto open = MakeChain(n, false);
    Data d(*open);
    CalcPositionKinematics(*open, open->q_initial, d);
    const Vec3 p = d.X_WB[open->body("link" + std::to_string(n - 1))] * Vec3(L, 0, 0);
    const FrameIndex anchor = draft.AddFrame("anchor", kWorldBody, Transform::Translation(p));
    draft.AddLoopClosure({.name = "closure", .type = JointType::kSpherical, .frame_a = anchor, .frame_b = tip});
    draft.SetGravity(Vec3(0, -9.81, 0));
    return std::move(draft).Finalize();
  }
  b.SetGravity(Vec3(0, -9.81, 0));
  return std::move(b).Finalize();
}

struct Fixture {
  explicit Fixture(int n) : model(MakeChain(n, true)), dae(*model) {
    State s = State::Initial(*model);
    s.v.setConstant(0.3);
    Data d(*model);
    AssembleState(*model, s, d);
    y.setZero(dae.size());
    yp.setZero(dae.size());
    r.setZero(dae.size());
    dae.ConsistentInitial(s, y, yp);
    J.setZero(dae.size(), dae.size());
  }
  std::shared_ptr<const Model> model;
  DaeSystem dae;
  Eigen::VectorXd y, yp, r;
  Eigen::MatrixXd J;
};

void BM_Residual(benchmark::State& st) {
  Fixture f(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    f.dae.Residual(0.0, f.y, f.yp, f.r);
    benchmark::DoNotOptimize(f.r.data());
  }
  st.counters["dof"] = f.model->nv - f.model->n_constraints;
  st.counters["residuals/s"] = benchmark::Counter(double(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Residual)->Arg(10)->Arg(20)->Arg(40)->Arg(60);

void BM_MassMatrix(benchmark::State& st) {
  Fixture f(static_cast<int>(st.range(0)));
  Data& d = f.dae.data();
  for (auto _ : st) {
    CalcMassMatrix(*f.model, d);
    benchmark::DoNotOptimize(d.M.data());
  }
}
BENCHMARK(BM_MassMatrix)->Arg(20)->Arg(60);

void BM_Jacobian(benchmark::State& st) {
  Fixture f(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    f.dae.Jacobian(0.0, 100.0, f.y, f.yp, f.J);
    benchmark::DoNotOptimize(f.J.data());
  }
}
BENCHMARK(BM_Jacobian)->Arg(20)->Arg(60);

// Wall time per simulated second: 1 s of the closed 20-link chain.
void BM_Simulate(benchmark::State& st) {
  auto model = MakeChain(20, true);
  SimulationOptions opt;
  opt.end_time = 1.0;
  opt.output_interval = 1e-3;
  opt.integrator.kind = st.range(0) == 0 ? IntegratorKind::kIda : IntegratorKind::kGeneralizedAlpha;
  opt.integrator.rtol = 1e-6;
  opt.integrator.atol = 1e-8;
  opt.integrator.step = 1e-3;
  SimulationReport rep;
  for (auto _ : st) rep = Simulate(*model, opt, nullptr);
  st.SetLabel(rep.integrator);
  st.counters["steps"] = double(rep.stats.steps);
  st.counters["residuals"] = double(rep.stats.residual_evaluations);
  st.counters["jacobians"] = double(rep.stats.jacobian_evaluations);
  st.counters["max|phi|"] = rep.stats.max_abs_phi;
  st.counters["max|phidot|"] = rep.stats.max_abs_phidot;
}
BENCHMARK(BM_Simulate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();

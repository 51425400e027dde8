#include "mbd/simulation.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include "mbd/evaluate.h"
#include "mbd/force_elements.h"
#include "mbd/output_schedule.h"
#include "mbd/result_recorder.h"

namespace orrery {
namespace {

void WriteStats(ResultFile& out, const IntegratorStats& s, const std::string& integrator,
                double wall_s, bool completed) {
  const std::string g = "/solver";
  out.WriteVector(g + "/statistics",
                  {double(s.steps), double(s.residual_evaluations), double(s.jacobian_evaluations),
                   double(s.newton_iterations), double(s.newton_failures),
                   double(s.error_test_failures), double(s.last_order), s.last_step,
                   s.max_abs_phi, s.max_abs_phidot, wall_s, double(s.newton_backtracks)},
                  "1");
  out.SetAttribute(g + "/statistics", "columns",
                   std::string("steps,residual_evaluations,jacobian_evaluations,newton_iterations,"
                               "newton_failures,error_test_failures,last_order,last_step_s,"
                               "max_abs_phi,max_abs_phidot,wall_time_s,newton_backtracks"));
  out.SetAttribute(g, "integrator", integrator);
  out.SetAttribute(g, "completed", std::int64_t(completed ? 1 : 0));
  out.SetAttribute(g, "steps", std::int64_t(s.steps));
  out.SetAttribute(g, "max_abs_phi", s.max_abs_phi);
  out.SetAttribute(g, "max_abs_phidot", s.max_abs_phidot);
  out.SetAttribute(g, "wall_time_s", wall_s);
}

// The sensors' sampler, observing the integrator's steps, when the model has sensors.
std::unique_ptr<SensorSampler> MakeSensorSampler(const Model& model, const SimulationOptions& options,
                                                 ResultFile& out, Integrator& integrator) {
  if (model.sensors.empty()) return nullptr;
  auto sampler = std::make_unique<SensorSampler>(model, options.sensors, options.integrator,
                                                 options.output_interval, options.end_time, out);
  integrator.set_step_observer(sampler.get());
  return sampler;
}

// After a failure: the sensors' rows up to the last /time row (an error there is dropped, the
// run's own is reported).
void FinishSensors(SensorSampler* sensors, double last_row_t) {
  if (!sensors) return;
  try {
    sensors->Finish(last_row_t);
  } catch (const std::exception&) {
  }
}

// One output row: room in the file, the recorder's row, then the row's health from the
// recorder's evaluation (or from an evaluation of its own without a file). Both evaluations
// start their contacts' tracking from the integrator's last evaluation (a step back), not
// from the last row (ExternalForceElement::WarmStart). When the integrator's last evaluation
// was at the row's state (Integrator::DataAtState: a generalized-alpha step that evaluated its
// accepted iterate, no constraints) both read it instead of evaluating.
void RecordRow(const Model& model, const Integrator& integrator, ResultFile* out, ResultRecorder* recorder,
               RunHealth& health, Data* own) {
  const State& s = integrator.state();
  if (recorder) {
    out->CheckRoom();
    recorder->Record(s, integrator.vdot(), integrator.lambda(), &integrator.data(),
                     integrator.DataAtState());
    health.OnOutput(s, integrator.lambda(), recorder->data(), integrator.stats().last_step);
    return;
  }
  if (const Data* at_state = integrator.DataAtState()) {
    health.OnOutput(s, integrator.lambda(), *at_state, integrator.stats().last_step);
    return;
  }
  WarmStartExternalWorkspaces(model, integrator.data(), *own);
  EvaluateDynamics(model, s.t, s.q, s.v, integrator.vdot(), *own);
  health.OnOutput(s, integrator.lambda(), *own, integrator.stats().last_step);
}

// Throws SimulationInterrupted when the flag was raised.
void CheckInterrupt(const std::atomic<int>* flag, double t) {
  if (flag == nullptr) return;
  if (const int signal = flag->load(std::memory_order_relaxed)) throw SimulationInterrupted(signal, t);
}

std::string InterruptedMessage(double t_s) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "interrupted at t = %g s", t_s);
  return buffer;
}

}  // namespace

SimulationInterrupted::SimulationInterrupted(int signal, double t_s)
    : std::runtime_error(InterruptedMessage(t_s)), signal_(signal), t_s_(t_s) {}

void CheckSimulationSettings(const Model& model, const SimulationOptions& options, const State* initial) {
  const OutputSchedule schedule = MakeOutputSchedule(initial ? initial->t : 0.0, options);
  ResolveThreads(options.integrator.threads);  // a bad OMP_NUM_THREADS before the file exists
  if (!(options.max_output_bytes > 0)) return;
  // The run's series laid out in memory, for the bytes of a row
  static std::atomic<long> count{0};
  ResultFile layout = ResultFile::CreateInMemory("in-memory layout " + std::to_string(++count));
  const ResultRecorder recorder(model, layout);
  RunHealth(model, options.integrator, options.health, options.output_interval).Declare(layout);
  CheckOutputSize(schedule, layout.bytes_per_row(), options.max_output_bytes);
}

SimulationReport Simulate(const Model& model, const SimulationOptions& options, ResultFile* out,
                          const std::function<void(const SimulationProgress&)>& progress,
                          const State* initial) {
  // Time bookkeeping checked before anything runs
  const State start_state = initial ? *initial : State::Initial(model);
  const OutputSchedule schedule = MakeOutputSchedule(start_state.t, options);
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto wall = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  std::unique_ptr<Integrator> integrator = MakeIntegrator(model, options.integrator);
  std::unique_ptr<ResultRecorder> recorder;
  std::unique_ptr<SensorSampler> sensors;
  RunHealth health(model, options.integrator, options.health, options.output_interval);
  if (out) {
    out->SetAttribute("/", "engine", std::string("orrery"));
    out->SetAttribute("/", "engine_version", std::string(ORRERY_VERSION));
    out->SetAttribute("/", "units", std::string("SI (m, kg, s, N, rad)"));
    out->SetAttribute("/", "scene", options.scene_text);
    out->SetAttribute("/", "scene_name", options.scene_name);
    out->SetAttribute("/", "integrator", integrator->name());
    out->SetAttribute("/", "end_time", options.end_time);
    out->SetAttribute("/", "output_interval", options.output_interval);
    recorder = std::make_unique<ResultRecorder>(model, *out);
    sensors = MakeSensorSampler(model, options, *out, *integrator);
    health.Declare(*out);
    CheckOutputSize(schedule, out->bytes_per_row(), options.max_output_bytes);
  }
  // Every accepted step: the interrupt flag, then the step's health (its gear angles from the
  // integrator's position kinematics at the state where it has them)
  integrator->SetStepCallback([&](double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& v) {
    CheckInterrupt(options.interrupt, t);
    health.OnStep(t, q, v, integrator->PositionKinematicsAtState());
  });
  std::unique_ptr<Data> own_data;  // the health's evaluations when there is no recorder
  if (!recorder) own_data = std::make_unique<Data>(model);
  SimulationReport report;
  report.integrator = integrator->name();
  double last_flush = 0;
  double last_row_t = 0;  // time of the last /time row (for the sensors' last rows)
  try {
    integrator->Initialize(start_state);
    health.Start(integrator->state());
    RecordRow(model, *integrator, out, recorder.get(), health, own_data.get());
    if (sensors) sensors->Start(integrator->state(), integrator->vdot());
    last_row_t = integrator->state().t;
    ++report.output_rows;
    for (std::int64_t k = 1; k < schedule.rows; ++k) {
      const double t = schedule.Time(k);
      integrator->AdvanceTo(t);
      CheckInterrupt(options.interrupt, integrator->state().t);
      RecordRow(model, *integrator, out, recorder.get(), health, own_data.get());
      if (sensors) sensors->Release(t);
      ++report.output_rows;
      last_row_t = t;
      const double w = wall();
      if (out && w - last_flush >= options.flush_interval_s) {
        out->Flush();
        last_flush = w;
      }
      if (progress) progress({integrator->state().t, options.end_time, integrator->stats().steps, w});
    }
  } catch (...) {
    // Statistics, health and sensors of the run so far; the error that stopped it is the one
    // passed on
    FinishSensors(sensors.get(), last_row_t);
    if (out) {
      try {
        WriteStats(*out, integrator->stats(), integrator->name(), wall(), false);
        health.Write(*out);
        out->Flush();
      } catch (const std::exception&) {
      }
    }
    throw;
  }
  try {
    health.Finish(integrator->state().t);
  } catch (...) {
    FinishSensors(sensors.get(), last_row_t);
    if (out) {
      WriteStats(*out, integrator->stats(), integrator->name(), wall(), false);
      health.Write(*out);
      out->Flush();
    }
    throw;
  }
  if (sensors) sensors->Finish(last_row_t);
  report.stats = integrator->stats();
  report.final_state = integrator->state();
  report.wall_s = wall();
  report.health = health.warnings();
  report.energy_residual_relative = health.energy_residual_relative();
  report.energy_quadrature_relative = health.energy_quadrature_relative();
  report.omega_max_h = health.omega_max_h();
  report.rho_infinity = health.rho_infinity();
  if (out) {
    WriteStats(*out, report.stats, integrator->name(), report.wall_s, true);
    health.Write(*out);
    out->Flush();
  }
  return report;
}

}  // namespace orrery

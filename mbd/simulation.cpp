#include "mbd/simulation.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

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

}  // namespace

SimulationReport Simulate(const Model& model, const SimulationOptions& options, ResultFile* out,
                          const std::function<void(const SimulationProgress&)>& progress,
                          const State* initial) {
  if (!(options.end_time > 0)) throw std::invalid_argument("end time must be > 0");
  if (!(options.output_interval > 0)) throw std::invalid_argument("output interval must be > 0");
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto wall = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  std::unique_ptr<Integrator> integrator = MakeIntegrator(model, options.integrator);
  std::unique_ptr<ResultRecorder> recorder;
  std::unique_ptr<SensorSampler> sensors;
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
  }
  SimulationReport report;
  report.integrator = integrator->name();
  double last_flush = 0;
  double last_row_t = 0;  // time of the last /time row (for the sensors' last rows)
  try {
    integrator->Initialize(initial ? *initial : State::Initial(model));
    const double t0 = integrator->state().t;
    if (recorder) recorder->Record(integrator->state(), integrator->vdot(), integrator->lambda());
    if (sensors) sensors->Start(integrator->state(), integrator->vdot());
    last_row_t = t0;
    ++report.output_rows;
    const long n_out = std::lround(std::ceil((options.end_time - t0) / options.output_interval - 1e-9));
    for (long k = 1; k <= n_out; ++k) {
      const double t = std::min(t0 + k * options.output_interval, options.end_time);
      integrator->AdvanceTo(t);
      if (recorder) recorder->Record(integrator->state(), integrator->vdot(), integrator->lambda());
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
    FinishSensors(sensors.get(), last_row_t);
    if (out) {
      WriteStats(*out, integrator->stats(), integrator->name(), wall(), false);
      out->Flush();
    }
    throw;
  }
  if (sensors) sensors->Finish(last_row_t);
  report.stats = integrator->stats();
  report.final_state = integrator->state();
  report.wall_s = wall();
  if (out) {
    WriteStats(*out, report.stats, integrator->name(), report.wall_s, true);
    out->Flush();
  }
  return report;
}

}  // namespace orrery

#pragma once
// The simulation loop: integrate a model to an end time, record results at a fixed output
// interval into a result file, report progress, and return the solver statistics.
//
// Usage:
//   SimulationOptions opt;  opt.end_time = 2.0;  opt.output_interval = 1e-3;
//   ResultFile out = ResultFile::Create("run.h5");
//   SimulationReport rep = Simulate(*model, opt, &out);
#include <functional>
#include <string>

#include "mbd/integrator.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/sensor_sampler.h"
#include "mbd/state.h"

namespace orrery {

struct SimulationOptions {
  double end_time = 1.0;          // s, > 0
  double output_interval = 1e-3;  // s, > 0: rows written every this much simulated time
  double flush_interval_s = 1.0;  // wall-clock seconds between flushes of the result file
  IntegratorOptions integrator;
  SensorSamplingOptions sensors;  // how the model's sensors are sampled (sensor_sampler.h)
  std::string scene_text;         // stored as attribute "scene" of the result file
  std::string scene_name;
};

struct SimulationProgress {
  double t = 0, end_time = 0;  // simulated time reached, end time (s)
  long steps = 0;              // integrator steps so far
  double wall_s = 0;           // wall-clock time so far (s)
};

struct SimulationReport {
  IntegratorStats stats;
  State final_state;
  long output_rows = 0;
  double wall_s = 0;
  std::string integrator;
};

// Runs the model from its initial state (or `initial` if given) to options.end_time. Writes to
// `out` if non-null (series declared by RecordingLayout, flushed every flush_interval_s and at the
// end, statistics written at the end, also when the run fails; the model's sensors through a
// SensorSampler, one row per /time row). Throws std::runtime_error with
// the reason if the integrator stops; rows written until then stay in the file.
SimulationReport Simulate(const Model& model, const SimulationOptions& options, ResultFile* out,
                          const std::function<void(const SimulationProgress&)>& progress = {},
                          const State* initial = nullptr);

}  // namespace orrery

#pragma once
// The simulation loop: integrate a model to an end time, record results at a fixed output
// interval into a result file, report progress, and return the solver statistics.
//
// Before anything runs, the time settings are checked (output_schedule.h: rows counted without
// overflow, times distinct, the result file's size estimated against max_output_bytes). While it
// runs, the run's health is watched (run_health.h) after every step and at every row, and the
// interrupt flag is polled after every integrator step, so a stop request is honoured within one
// step however coarse the output interval. A result file that runs out of room
// (ResultFile::CheckRoom) ends the run with every row recorded until then.
//
// Usage:
//   SimulationOptions opt;  opt.end_time = 2.0;  opt.output_interval = 1e-3;
//   ResultFile out = ResultFile::Create("run.h5");
//   SimulationReport rep = Simulate(*model, opt, &out);
#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbd/integrator.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/sensor_sampler.h"
#include "mbd/run_health.h"
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
  // Estimated size of the result file (rows x bytes per row) above which the run is refused
  // before it starts (bytes; 0: no bound). An end time of 1e20 s wrote tens of GB before.
  double max_output_bytes = 10e9;
  HealthOptions health;           // run_health.h
  // Polled after every integrator step and output row; non-zero: the run stops with
  // SimulationInterrupted (a signal handler sets it; nullptr: never).
  const std::atomic<int>* interrupt = nullptr;
};

// Thrown by Simulate when options.interrupt was raised: what() is "interrupted at t = <t> s".
class SimulationInterrupted : public std::runtime_error {
 public:
  SimulationInterrupted(int signal, double t_s);
  int signal() const { return signal_; }
  double t() const { return t_s_; }

 private:
  int signal_;
  double t_s_;
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
  std::vector<HealthWarning> health;    // warnings of the run (run_health.h)
  double energy_residual_relative = 0;  // energy-balance residual / energy scale at the end
  double energy_quadrature_relative = 0;  // what the rows' quadrature cannot resolve, same scale
  double omega_max_h = -1;              // generalized-alpha: stiffest mode x step (-1: not estimated)
  double rho_infinity = 1;              // generalized-alpha: damping of unresolved modes (1: none)
};

// The checks Simulate makes before it runs, for a caller that wants them before it creates the
// result file (so that a refused run leaves an existing file alone): the time settings
// (MakeOutputSchedule) and the estimated file size against options.max_output_bytes (the series
// laid out in memory) and the thread count (ResolveThreads: solver.threads, OMP_NUM_THREADS).
// Throws std::invalid_argument naming the setting and the numbers.
void CheckSimulationSettings(const Model& model, const SimulationOptions& options, const State* initial = nullptr);

// Runs the model from its initial state (or `initial` if given) to options.end_time. Writes to
// `out` if non-null (series declared by RecordingLayout, flushed every flush_interval_s and at the
// end, statistics and /health written at the end, also when the run fails; the model's sensors
// through a SensorSampler, one row per /time row). Throws std::invalid_argument for absurd time
// settings or an estimated file beyond max_output_bytes (before the run), std::runtime_error with
// the reason if the integrator stops, RunHealthError when a health check stops the run,
// ResultFileFullError when the file has no room left, SimulationInterrupted on
// options.interrupt; rows written until then stay in the file.
SimulationReport Simulate(const Model& model, const SimulationOptions& options, ResultFile* out,
                          const std::function<void(const SimulationProgress&)>& progress = {},
                          const State* initial = nullptr);

}  // namespace orrery

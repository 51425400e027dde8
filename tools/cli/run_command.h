#pragma once
// `orrery run SCENE`: load a scene, simulate it, write the result file, print a summary.
//
// Steps: LoadScene(scene_path, overrides) where --end-time, --integrator and --threads become the
// overrides "solver.end_time=T", "solver.integrator=NAME" and "solver.threads=N" (applied after
// every --set, so they win);
// ResultFile::Create(output_path, else the scene's output path); Simulate with a progress
// callback that draws a ProgressBar on `err` and stops the run on SIGINT/SIGTERM; a summary of
// the run and the solver statistics on `out`.
//
// Failures print one line "orrery: error: <reason>" on `err` and return kExitFailure (1); an
// interrupted run flushes the result file and returns 128 + the signal number (130 for Ctrl-C),
// within one integrator step of the signal. After a failure the message says what the file holds
// (rows and times, read back from the disk). The result file is created only once the scene has
// loaded and the run's settings passed their checks (CheckSimulationSettings), and never at the
// path of the scene or of a file the scene reads. The summary ends with the run's health
// (run_health.h): "ok", or one line per warning; --strict stops at the first warning.
//
// Usage:
//   RunArgs args;  args.scene_path = "pendulum.yaml";  args.end_time = 2.0;
//   int code = RunCommand(args, std::cout, std::cerr);
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "mbd/simulation.h"

namespace orrery::cli {

struct RunArgs {
  std::string scene_path;                // SCENE
  std::string output_path;               // -o: "" for the scene's output path
  std::optional<double> end_time;        // --end-time (s)
  std::vector<std::string> overrides;    // --set key.path=value, in command-line order
  std::string integrator;                // --integrator: "" for the scene's, "ida", "generalized_alpha"
  std::optional<int> threads;            // --threads: solver.threads (tooth contacts in parallel)
  bool quiet = false;                    // --quiet: no progress output
  bool err_is_terminal = false;          // progress as a redrawn bar (else a line every 10 %)
  // --study-attribute key=value (hidden; `orrery study` sets them): attributes of the result
  // file's /study group, numbers where the value reads as one (integers as integers)
  std::vector<std::string> study_attributes;
  bool strict = false;                   // --strict: stop at the first health warning
  std::optional<double> max_output_gb;   // --max-output-gb: bound on the estimated result file
  // Called after every output row, before the interrupt check (tests use it to raise a signal).
  std::function<void(const SimulationProgress&)> observer;
};

// The overrides given to LoadScene: args.overrides, then solver.end_time, solver.integrator and
// solver.threads.
std::vector<std::string> SceneOverrides(const RunArgs& args);

// Runs the command; returns the process exit code.
int RunCommand(const RunArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

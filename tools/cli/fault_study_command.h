#pragma once
// `orrery fault-study SCENE -o DIR [--end-time T] [--t0 T0] [--signal PATH] [--set key=value ...]
//                     [--force] [--quiet]`
// One scene with its tooth faults and the same scene without them (its healthy twin: the scene
// loaded with SceneLoadOptions::without_faults, everything else as written), both run, compared
// on one signal, and left in one folder (docs/fault_study.md):
//
//   DIR/healthy.h5, DIR/faulty.h5        the two result files (`orrery run`'s content)
//   DIR/overlay.png                      both spectra, mesh harmonics and sidebands marked
//   DIR/faulty_spectrum.png, DIR/healthy_spectrum.png   each spectrum, peaks labelled
//   DIR/faulty_signal.png                the faulty record over time
//   DIR/stress_<body>.png                hot-spot stress over time of each flexible body (faulty)
//   DIR/summary.json, DIR/summary.md     the numbers (fault_study_analysis.h), summary.md also
//                                        printed on stdout
//
// Simulated time: --end-time, else 0.30 s; the analysed records start at --t0, else 0.03 s (the
// start transient skipped: on seed 003's stage the response is steady from 0.02 s on), so 0.27 s
// are analysed: a Hann spectrum's lines must lie more than 4 bins apart for the sideband energy
// ratio (sideband_energy_ratio.h: T > 2 B / f_x), which for seed 003's f_p^H = 15.74 Hz needs
// T > 0.254 s. The output interval is the scene's (docs/fault_study.md says why and what it costs).
// Signal: --signal PATH, else the scene's first sensor (/sensors/<name>/<quantity>).
// Progress: one bar (or a line every 10 %) over both runs (simulated time of both).
//
// Failures print one line "orrery: error: ..." and return kExitFailure: a scene that does not load
// or declares no tooth faults, DIR holding a study's results (healthy.h5, faulty.h5, summary.json
// or summary.md) without --force, a DIR that cannot be made, a failed run (the other run's file
// stays), an analysis that cannot be made (no sensor and no --signal, a record too short for the
// sidebands). An interrupted study returns 128 + the signal number.
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "import/scene.h"

namespace orrery::cli {

inline constexpr double kFaultStudyEndTime = 0.30;  // s
inline constexpr double kFaultStudyT0 = 0.03;       // s

struct FaultStudyArgs {
  std::string scene_path;              // SCENE
  std::string output_dir;              // -o DIR
  std::optional<double> end_time;      // --end-time (s)
  std::optional<double> t0;            // --t0 (s)
  std::string signal;                  // --signal: dataset ("" : the scene's first sensor)
  std::vector<std::string> overrides;  // --set key.path=value
  bool force = false;                  // --force: replace DIR's results
  bool plots = true;                   // --no-plots: skip the PNG files
  bool quiet = false;                  // --quiet: no progress
  bool err_is_terminal = false;        // progress as a redrawn bar
};

int FaultStudyCommand(const FaultStudyArgs& args, std::ostream& out, std::ostream& err);

// The study on scenes already loaded (what FaultStudyCommand does after loading SCENE twice; a C++
// user or a test can hand in scenes built in code): `faulty` a gear-train scene with tooth faults,
// `healthy` its twin. args.scene_path names the scene in the summary only.
int RunFaultStudy(const Scene& faulty, const Scene& healthy, const FaultStudyArgs& args, std::ostream& out,
                  std::ostream& err);

}  // namespace orrery::cli

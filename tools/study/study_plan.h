#pragma once
// The runs of a study: its description (import/study_file.h) expanded into a numbered list of
// runs, each a list of parameter values, and the scene overrides each run is started with.
//
// Runs are the cartesian product of the study's blocks (axes, zipped groups, random blocks) in
// file order, the last block varying fastest: for blocks of sizes n_0 .. n_{B-1}, run r takes
// entry (r / prod_{b' > b} n_b') mod n_b of block b. A study without axes has one run.
//
// Random blocks draw their samples from a 64-bit Mersenne Twister (std::mt19937_64, fully
// specified by the C++ standard) seeded with the block's seed: sample s draws its keys in file
// order, one number each, u = (x >> 11) 2^-53 in [0, 1) from the engine's output x:
//   uniform      low + (high - low) u
//   log_uniform  exp(ln low + (ln high - ln low) u)
//   choice       choices[floor(u n)]
// Drawn numbers are written as the shortest text that reads back as the same double, so the
// same study file gives the same runs on every machine (and every MPI rank).
//
// A run's overrides are the study's settings (end_time, output_interval, settings:) followed by
// its parameters, each "key=value" as `orrery run --set` takes it.
//
// Usage:
//   StudyPlan plan = MakeStudyPlan(LoadStudyFile("quick.yaml"));
//   CheckStudyScene(plan);                          // the base scene knows every key
//   for (const RunSpec& run : plan.runs) Start(plan.Overrides(run));
#include <string>
#include <vector>

#include "import/study_file.h"

namespace orrery::study {

struct RunSpec {
  int index = 0;                    // 0 .. runs-1
  std::vector<std::string> values;  // one per StudyPlan::parameters, YAML text
};

struct StudyPlan {
  StudyDescription study;
  std::vector<std::string> parameters;    // scene keys of the blocks, in file order
  std::vector<std::string> parameter_at;  // "FILE:LINE: axes[i].key" of each
  std::vector<RunSpec> runs;

  // settings, then the run's parameters, as "key=value"
  std::vector<std::string> Overrides(const RunSpec& run) const;
};

// The most runs a study may have.
inline constexpr long long kMaxStudyRuns = 10'000'000;

// Expands the blocks. Throws std::runtime_error "FILE: axes: ..." when the product exceeds
// kMaxStudyRuns.
StudyPlan MakeStudyPlan(StudyDescription study);

// Loads the base scene with the overrides of the first run (which sets every key of the study),
// so that a key the scene does not have is found before anything runs. Throws std::runtime_error
// naming the study file, the line and key of the setting or axis and the scene's own message
// ("quick.yaml:7: axes[0].key: seed002.yaml: --set gear_train.input_speed.alfa1: unknown key
// 'alfa1'; did you mean 'alpha1'?"), or the study file's scene key for a scene that does not load
// at all. A value that fails only in a later run fails that run, not the study.
void CheckStudyScene(const StudyPlan& plan);

}  // namespace orrery::study

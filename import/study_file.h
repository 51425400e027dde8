#pragma once
// Study files (YAML) for `orrery study`: a base scene, parameter axes over scene keys, the
// outputs to extract from each run's result file, and where to write. Read with the scene rules
// (docs/scene_format.md: strict keys with suggestions, errors "FILE:LINE: KEY: reason" as
// SceneError) into a plain description; tools/study/ expands it into runs, runs them and extracts
// the outputs. The format is documented in docs/studies.md.
//
//   name: quick
//   scene: ../scenes/seed002_alpha1_ramp.yaml       # relative to the study file
//   folder: results/studies/quick                   # relative to the working directory
//   end_time: 0.1                                   # solver.end_time of every run
//   output_interval: 1e-3                           # output.interval of every run
//   settings: {solver.step: 1e-4}                   # further scene keys of every run
//   axes:                                           # runs: the cartesian product of the entries
//     - {key: gear_train.input_speed.alpha1, values: [0.02, 0.04]}
//     - {key: solver.rho_inf, range: {start: 0.6, stop: 1.0, step: 0.2}}
//     - zip: [{key: a, values: [1, 2]}, {key: b, values: [3, 4]}]
//     - random: {samples: 8, seed: 1, keys: [{key: c, log_uniform: [1e6, 1e9]}]}
//   outputs:
//     - {name: force_rms, type: rms, dataset: /gear_meshes/S.sun-planet#1/force, from: 0.05}
//   jobs: 4                                         # runs at a time on one machine (default:
//   cores) limits: {wall_time_s: 600, memory_mib: 4096}    # per run (default: none)
//
// Scene keys are checked only for their form here (a key path as `--set` takes it); whether the
// base scene has them is checked by loading it (tools/study/study_plan.h), which needs the scene
// reader, so every key keeps its place (`at`, "FILE:LINE: PATH") for that message.
//
// Usage:
//   StudyDescription study = LoadStudyFile("models/studies/quick.yaml");
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace orrery {

// A scene setting of every run: key as `--set` takes it, value as YAML text.
struct StudySetting {
  std::string key;    // "solver.end_time"
  std::string value;  // "0.1"
  std::string at;     // "quick.yaml:4: end_time", for errors found later
};

// range: {start, stop, step} or {start, stop, count[, spacing: linear|log]}
struct StudyRange {
  double start = 0, stop = 0;
  double step = 0;   // != 0, pointing from start toward stop; 0 when count is given
  int count = 0;     // >= 1; 0 when step is given
  bool log = false;  // geometric spacing (count only; start and stop > 0)
};

// The values of a range: with a step, start + i step for i = 0, 1, ... up to stop (included
// when within 1e-9 of a step of it); with a count, `count` values from start to stop, both
// included, evenly spaced (linear) or in geometric progression (log).
std::vector<double> ExpandStudyRange(const StudyRange& range);
// A range value as scene text: 15 significant digits, so 0.1 + 2 * 0.1 is written "0.3".
std::string RangeValueText(double value);

// One parameter: a scene key and its values (an explicit list or a range).
struct StudyAxis {
  std::string key;                  // scene key path
  std::string at;                   // "FILE:LINE: axes[0].key"
  std::vector<std::string> values;  // values: as YAML text (flow style for lists and maps); a
                                    // range's values as RangeValueText(ExpandStudyRange(range))
  std::optional<StudyRange> range;  // how the values were given, when by range:
};

enum class StudyDistribution { kUniform, kLogUniform, kChoice };

// One key of a random block: uniform: [low, high], log_uniform: [low, high] or choice: [...].
struct StudyRandomKey {
  std::string key, at;
  StudyDistribution distribution = StudyDistribution::kUniform;
  double low = 0, high = 0;          // low < high (log_uniform: low > 0)
  std::vector<std::string> choices;  // choice: YAML text, at least one
};

// An entry of `axes:`. The runs are the cartesian product of the blocks in file order (the first
// varies slowest).
struct StudyBlock {
  enum class Kind { kAxis, kZip, kRandom };
  Kind kind = Kind::kAxis;
  std::vector<StudyAxis> axes;       // kAxis: one; kZip: two or more of equal length
  int samples = 0;                   // kRandom: >= 1
  std::uint64_t seed = 0;            // kRandom
  std::vector<StudyRandomKey> keys;  // kRandom: at least one
  std::string at;                    // "FILE:LINE: axes[2]"
};

enum class StudyOutputKind {
  kPeak,
  kRms,
  kMean,
  kMin,
  kMax,
  kFinal,                // statistics of a column over a time window
  kAmplitude,            // spectral amplitude at a frequency or line
  kSidebandEnergyRatio,  // SER around the mesh harmonics
  kIndicator,            // condition indicator (record or TSA)
  kMaxStress,            // largest von Mises stress of a flexible body
};

struct StudyOutput {
  std::string name;  // column of the index: letters, digits, '_', '.', '-'; starts with a letter
  std::string at;    // "FILE:LINE: outputs[name]"
  StudyOutputKind kind = StudyOutputKind::kPeak;
  std::string type;  // as written ("peak", "sideband_energy_ratio", ...)

  std::string dataset;  // dataset path (max_stress: /flexible_bodies/<body>/von_mises_max)
  std::string column;   // 0-based index or name from the dataset's "columns"; "" for the first
  double from_s = -std::numeric_limits<double>::infinity();  // time window [from, to]
  double to_s = std::numeric_limits<double>::infinity();
  // >= 0 (instead of from_s): the window starts this fraction of the way through the run's
  // recorded time, t0 + f (t_end - t0) (runs of different lengths: their second half is 0.5).
  double from_fraction = -1;

  // Spectral outputs (amplitude, sideband_energy_ratio)
  std::string window = "hann";  // hann | flattop | rect
  // amplitude: frequency_hz, or line (a kinematic line of the result file) times harmonic, plus
  // sideband n times modulation (a line) or modulation_hz
  double frequency_hz = 0;
  std::string line;
  int harmonic = 1;
  int sideband = 0;
  // amplitude (sideband) and sideband_energy_ratio: the modulation line or frequency
  std::string modulation;
  double modulation_hz = 0;
  // sideband_energy_ratio and the mesh order of TSA indicators: mesh line or frequency
  std::string mesh;
  double mesh_hz = 0;
  int harmonics = 3;  // sideband_energy_ratio: K mesh harmonics
  int sidebands = 6;  // sideband_energy_ratio: N sideband pairs

  // indicator: rms | peak | crest_factor | kurtosis | fm0 | fm4 | na4, of the record or of its
  // time-synchronous average over `tsa` (a joint name or an angle dataset; fm0, fm4 and na4
  // need it) with mesh_order teeth per revolution (or from mesh / mesh_hz)
  std::string indicator;
  std::string tsa;
  int mesh_order = 0;
  int samples_per_revolution = 0;  // 0: DefaultSamplesPerRevolution of the record
};

// Per-run limits; 0 for none.
struct StudyLimits {
  double wall_time_s =
      0;                  // a run taking longer is stopped (SIGTERM, SIGKILL 10 s later) and failed
  double memory_mib = 0;  // address-space limit of a run's process (RLIMIT_AS)
};

struct StudyDescription {
  std::string file;                    // the study file as given
  std::string name;                    // name: (default: the file's stem)
  std::string scene_path;              // scene:, resolved against the study file's folder
  std::string scene_at;                // "FILE:LINE: scene"
  std::string folder;                  // folder: as written ("" when not given)
  std::vector<StudySetting> settings;  // end_time, output_interval, then settings: in file order
  std::vector<StudyBlock> blocks;      // axes: (may be empty: one run)
  std::vector<StudyOutput> outputs;    // outputs: (may be empty: wall time and memory only)
  int jobs = 0;                        // jobs: (0: not given)
  StudyLimits limits;
};

// Throws SceneError "FILE:LINE: KEY: reason" for a missing or unknown key, a wrong type, a value
// out of range, an empty axis, a key given twice across settings and axes, zipped axes of
// different lengths or a duplicate output name; "FILE: cannot open ..." for an unreadable file.
StudyDescription LoadStudyFile(const std::string& path);
// The same from text; `file` names it in messages and relative scene paths are resolved against
// its folder.
StudyDescription ParseStudyFile(const std::string& text, const std::string& file);

}  // namespace orrery

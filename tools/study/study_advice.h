#pragma once
// Advice from measured studies (`orrery advise`, docs/tradeoff.md): given study indexes (the
// index.h5 that `orrery study` writes), one output and an error bound, the cheapest measured
// setting whose output lies within the bound of the reference setting's.
//
// Math: for each run r that finished (status ok, output and cost not NaN) the error against the
// reference run ref is e_r = |x_r - x_ref| / |x_ref| (relative, the default) or |x_r - x_ref|
// (absolute, in the output's unit); its cost c_r is a measured column of the index
// (cpu_time_s by default: user + system time of the run's process; wall_time_s;
// peak_memory_mib). A run is on the Pareto front when no other run has c <= c_r and e <= e_r with
// one of them strict. The advice is the run of least cost with e_r <= bound (ties: the smaller
// error, then the first listed), which is always on the front; it is the reference itself when no
// other run meets the bound (its own error is then not measured: only as good as the reference's
// convergence, which the study's author states).
//
// Usage:
//   AdviceRequest q;  q.studies = {"results/studies/tradeoff/seed003_contact_healthy"};
//   q.output = "mesh_force_peak";  q.error_bound = 0.01;
//   Advice a = AdviseSetting(q);   // a.settings[a.chosen] is the advice
#include <string>
#include <vector>

namespace orrery::study {

// One measured setting: a run of one of the studies
struct MeasuredSetting {
  std::string study;       // the study's label: its folder's name
  int run = -1;            // run index within its study
  std::string parameters;  // "key=value key=value" (the index's parameter columns)
  double value = 0;        // the output
  double error = 0;        // against the reference (relative or absolute, as asked)
  double cost = 0;         // the cost column
  bool on_front = false;   // on the Pareto front of (cost, error)
  bool reference = false;  // the reference run
};

struct AdviceRequest {
  // Study folders (holding index.h5) or index.h5 files; the runs of all are compared
  std::vector<std::string> studies;
  std::string output;               // an output name of every study
  double error_bound = 0;           // > 0: fraction (relative) or the output's unit (absolute)
  bool relative = true;             // relative error |x - x_ref| / |x_ref|
  std::string cost = "cpu_time_s";  // cpu_time_s | wall_time_s | peak_memory_mib
  // The reference: "RUN" (a run of the last study), "STUDY:RUN" (STUDY: a folder's name among
  // `studies`); "" for the last run of the last study
  std::string reference;
};

struct Advice {
  std::vector<MeasuredSetting> settings;  // the usable runs, cost ascending (ties: error)
  int reference = -1;                     // index into settings
  int chosen = -1;                        // index into settings: the advice
  int skipped = 0;                        // runs not ok, or with a NaN output or cost
  std::string unit;                       // the output's unit (index.h5 attribute), may be ""
};

// The advice. Throws std::invalid_argument with one line naming the argument (an empty study
// list, a bound that is not a positive finite number, an unknown cost column, an output missing
// from a study, a reference that does not name a usable run, a zero reference value with a
// relative error) and std::runtime_error naming the file when an index cannot be read.
Advice AdviseSetting(const AdviceRequest& request);

// Pareto front of the points (cost[i], error[i]): true where no other point is at most as costly
// and at most as wrong, and strictly better in one. Sizes equal (else std::invalid_argument).
std::vector<bool> ParetoFront(const std::vector<double>& cost, const std::vector<double>& error);

}  // namespace orrery::study

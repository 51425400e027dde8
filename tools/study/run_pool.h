#pragma once
// The runs one process of a study (the only one, or one MPI rank) has going at a time: up to
// `slots` child processes (run_process.h), each `orrery run` on the base scene with the run's
// overrides, writing the run's result file in the study folder.
//
// When a run's process ends, the pool makes its record (run_record.h):
//   exit 0                 outputs extracted from its result file (output_extraction.h): status
//                          ok, or output_failed naming the first output that could not be read
//   exit != 0              failed; reason: the run's "orrery: error: ..." line from its log (the
//                          last such line), else its last line
//   ended by a signal      failed; reason "killed by signal N (name)" (a crash, the OOM killer)
//   over the wall limit    stopped (SIGTERM, SIGKILL 10 s later) and failed, reason naming it
// (with a memory limit, a failure's reason ends with "(memory limit N MiB)": running out of it
// shows as std::bad_alloc, a failed mapping or a signal, whichever comes first)
// and writes the record as the run's completion marker (study_folder.h) before handing it out.
// Runs stopped by StopAll (the study interrupted) get no record and no marker: they are run
// again when the study resumes.
//
// The child command line:
//   orrery run SCENE -o DIR/runs/run_00003.h5 --quiet --set KEY=VALUE ...
//         --study-attribute run=3 --study-attribute study=NAME --study-attribute KEY=VALUE ...
// (the attributes land on the result file's /study group: the run index, the study's name and
// each parameter by its scene key).
//
// Usage:
//   RunPool pool(plan, folder, {.executable = SelfExecutable(), .slots = 2});
//   pool.Start(0);
//   for (const RunRecord& r : pool.Poll()) collect(r);
#include <optional>
#include <string>
#include <vector>

#include "import/study_file.h"
#include "tools/study/run_process.h"
#include "tools/study/run_record.h"
#include "tools/study/study_folder.h"
#include "tools/study/study_plan.h"

namespace orrery::study {

struct RunPoolOptions {
  std::string executable;    // the orrery program (SelfExecutable())
  int slots = 1;             // runs at a time, >= 1
  double kill_grace_s = 10;  // from SIGTERM to SIGKILL for a run over its wall-time limit
  int rank = 0;              // MPI rank of this process, for the records
};

class RunPool {
 public:
  RunPool(const StudyPlan& plan, const StudyFolder& folder, RunPoolOptions options);

  int slots() const { return options_.slots; }
  int running() const { return static_cast<int>(active_.size()); }
  int free_slots() const { return options_.slots - running(); }
  std::vector<int> Running() const;

  // Starts run `run` (0 <= run < runs). A run that cannot start is failed at once: its record
  // comes with the next Poll.
  void Start(int run);

  // The records of the runs that ended since the last call, their markers written. Enforces the
  // wall-time limit of the running ones. Non-blocking.
  std::vector<RunRecord> Poll();

  // Stops every running run (`signal`, then SIGKILL after `grace_s`) and waits for them; they
  // get no record.
  void StopAll(int signal, double grace_s);

  // The command line of run `run` (for tests and --dry-run).
  std::vector<std::string> CommandLine(int run) const;

 private:
  struct Active {
    int run = 0;
    RunProcess process;
    bool over_limit = false;  // stopped for the wall-time limit
    double stop_sent_s = 0;   // ElapsedSeconds when SIGTERM was sent
  };
  RunRecord Finish(const Active& active, const ProcessExit& exit) const;
  void EnforceLimit(Active& active) const;

  const StudyPlan& plan_;
  const StudyFolder& folder_;
  RunPoolOptions options_;
  std::string host_;
  std::vector<Active> active_;
  std::vector<RunRecord> failed_to_start_;
};

// The failure line of a run's log: the text after the last "orrery: error: ", else the last
// non-empty line, else "".
std::string FailureLine(const std::string& log_path);

}  // namespace orrery::study

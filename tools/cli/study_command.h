#pragma once
// `orrery study STUDY.yaml`: a parameter study over a base scene (docs/studies.md).
//
// Steps: LoadStudyFile and MakeStudyPlan (import/study_file.h, tools/study/study_plan.h); the base
// scene loaded once with the first run's settings (CheckStudyScene: an unknown key stops here);
// the study folder prepared or reopened (-o DIR, else the file's folder:, else
// results/studies/<name>; a folder of another study is refused); the unfinished runs run as
// child processes, `jobs` at a time (-j, else the file's jobs:, else the cores), with a progress
// line on `err`; the index written; a summary on `out`.
//
// Under an MPI launcher (mpirun -n N, srun --mpi=pmix; or --mpi for a singleton) the ranks share
// the runs (tools/study/study_runner.h): rank 0 prepares the folder, hands out runs, collects
// the records and writes the index and the summary; every rank runs its runs as child
// processes.
//
// Exit codes: 0 when every run has a record (failed runs included: they are in the index with
// their reason), 1 when the study cannot run (bad study file, unknown scene key, refused folder,
// no MPI when asked for), 128 + signal when interrupted (the runs going are run again on the next
// start). --dry-run checks the study and lists its runs without running anything.
//
// Usage:
//   StudyArgs args;  args.study_path = "models/studies/quick.yaml";
//   int code = StudyCommand(args, std::cout, std::cerr);
#include <ostream>
#include <string>

namespace orrery::cli {

struct StudyArgs {
  std::string study_path;        // STUDY.yaml
  std::string folder;            // -o: "" for the file's folder: (or results/studies/<name>)
  int jobs = 0;                  // -j: runs at a time per machine or rank; 0: file's, else cores
  bool retry_failed = false;     // --retry-failed: run failed runs again
  bool mpi = false;              // --mpi: use MPI even without a launcher (singleton)
  bool dry_run = false;          // --dry-run: check and list the runs
  bool quiet = false;            // --quiet: no progress
  bool err_is_terminal = false;  // progress as a redrawn line (else lines)
};

int StudyCommand(const StudyArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

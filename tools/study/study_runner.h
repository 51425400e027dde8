#pragma once
// Runs the runs of a study that are not finished yet: on one machine, or over the ranks of an
// MPI job.
//
// One machine (RunStudyLocal): the runs without a completion marker (study_folder.h) go into a
// queue in index order; a RunPool (run_pool.h) keeps `jobs` of them going as child processes;
// each record is kept, its failure reported; the index (study_index.h) is rewritten every
// `index_interval_s` and at the end.
//
// MPI (RunStudyMpi), dynamic scheduling through MPI messages only:
//   every rank      reads the study file and expands it (the same runs on every rank), tells
//                   rank 0 whether that worked (kTagReady)
//   rank 0          checks the base scene and prepares the folder, answers every rank go or
//                   stop (kTagStart), reads the markers, keeps the queue, starts runs in its own
//                   pool and hands out run indices to the ranks that ask (kTagRequest ->
//                   kTagAssign; an empty assignment: nothing left), collects their records
//                   (kTagResult) into the index
//   other ranks     ask for as many runs as they have free slots, run them in their own pool
//                   (child processes, markers written), send each record to rank 0, and say
//                   kTagFinished when told nothing is left and their runs have ended
// Rank 0 stopped by a signal tells the others (kTagStop); every rank stops its runs (they are
// run again when the study resumes) and rank 0 writes the index of what it has.
// Records travel as text with hexadecimal doubles (run_record.h): the index of an MPI study holds
// the same numbers, to the last bit, as that of the same study run on one machine.
//
// Usage:
//   StudyOutcome o = RunStudyLocal(plan, folder, hash, options, std::cerr);
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "tools/study/mpi_session.h"
#include "tools/study/run_record.h"
#include "tools/study/study_folder.h"
#include "tools/study/study_plan.h"
#include "tools/study/study_progress.h"

namespace orrery::study {

enum StudyTag : int {
  kTagReady = 1,     // rank -> 0: "ok" or "error <reason>"
  kTagStart = 2,     // 0 -> rank: "go" or "stop"
  kTagRequest = 3,   // rank -> 0: number of free slots
  kTagAssign = 4,    // 0 -> rank: run indices separated by blanks ("" for none left)
  kTagResult = 5,    // rank -> 0: an encoded RunRecord
  kTagFinished = 6,  // rank -> 0: "" or "interrupted <signal>"
  kTagStop = 7,      // 0 -> rank: stop the runs and finish
};

struct StudyRunOptions {
  std::string executable;     // the orrery program (SelfExecutable())
  int jobs = 1;               // runs at a time in this process (>= 1)
  bool retry_failed = false;  // run again the runs whose marker says failed or output_failed
  StudyProgress::Style progress = StudyProgress::Style::kNone;
  std::function<int()> interrupted;  // the signal asking to stop (SIGINT, SIGTERM), 0 if none
  double index_interval_s = 30;      // rewrite the index this often while runs go
  double stop_grace_s = 10;          // from SIGTERM to SIGKILL when stopping runs
};

struct StudyOutcome {
  // per run (rank 0; empty on other ranks)
  std::vector<std::optional<RunRecord>> records;
  int done_before = 0;         // runs finished before this session
  int run_now = 0;             // runs finished in this session (all ranks' on rank 0)
  int interrupted_signal = 0;  // the signal that stopped the study, 0 if it completed
  double wall_s = 0;           // of this session
};

// The records of finished runs from their markers (failed ones left out when `retry_failed`).
std::vector<std::optional<RunRecord>> ReadMarkers(const StudyPlan& plan, const StudyFolder& folder,
                                                  bool retry_failed);

// Runs what is left of the study in this process; writes the index. Throws std::runtime_error
// when a marker or the index cannot be written.
StudyOutcome RunStudyLocal(const StudyPlan& plan, const StudyFolder& folder,
                           const std::string& study_hash, const StudyRunOptions& options,
                           std::ostream& err);

// Rank 0's and the other ranks' parts of an MPI study, after the handshake (the command does it,
// study_command.h). Rank 0 writes the index.
StudyOutcome CoordinateStudyMpi(const StudyPlan& plan, const StudyFolder& folder,
                                const std::string& study_hash, const StudyRunOptions& options,
                                const MpiSession& mpi, std::ostream& err);
StudyOutcome WorkStudyMpi(const StudyPlan& plan, const StudyFolder& folder,
                          const StudyRunOptions& options, const MpiSession& mpi);

// Runs at a time by default: the cores this process may use (its CPU affinity), shared among the
// `ranks_on_node` ranks of an MPI job on this node; at least 1.
int DefaultJobs(int ranks_on_node);

}  // namespace orrery::study

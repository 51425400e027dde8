#include "tools/study/study_runner.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <deque>
#include <set>
#include <sstream>

#include "tools/study/run_pool.h"
#include "tools/study/study_index.h"

namespace orrery::study {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// The pending runs of `records`, in index order
std::deque<int> PendingRuns(const std::vector<std::optional<RunRecord>>& records) {
  std::deque<int> queue;
  for (std::size_t i = 0; i < records.size(); ++i)
    if (!records[i]) queue.push_back(static_cast<int>(i));
  return queue;
}

// Recorded runs and those among them that did not go well
struct Tally {
  int done = 0, failed = 0;
};
Tally Count(const std::vector<std::optional<RunRecord>>& records) {
  Tally t;
  for (const std::optional<RunRecord>& r : records)
    if (r) {
      ++t.done;
      if (r->status != RunStatus::kOk) ++t.failed;
    }
  return t;
}

// Keeps a record and reports a failure
void Collect(RunRecord record, std::vector<std::optional<RunRecord>>& records,
             StudyProgress& progress, int& run_now) {
  if (record.status != RunStatus::kOk) progress.RunFailed(record);
  const auto i = static_cast<std::size_t>(record.run);
  if (i < records.size()) records[i] = std::move(record);
  ++run_now;
}

// Rewrites the index every `interval` seconds
class IndexWriter {
 public:
  IndexWriter(const StudyPlan& plan, const StudyFolder& folder, std::string hash, double interval)
      : plan_(plan),
        folder_(folder),
        hash_(std::move(hash)),
        interval_(interval),
        last_(Clock::now()) {}
  void MaybeWrite(const std::vector<std::optional<RunRecord>>& records) {
    if (Since(last_) >= interval_) Write(records);
  }
  void Write(const std::vector<std::optional<RunRecord>>& records) {
    WriteStudyIndex(plan_, folder_, records, hash_);
    last_ = Clock::now();
  }

 private:
  const StudyPlan& plan_;
  const StudyFolder& folder_;
  std::string hash_;
  double interval_;
  Clock::time_point last_;
};

int Interrupted(const StudyRunOptions& options) {
  return options.interrupted ? options.interrupted() : 0;
}

std::string Join(const std::vector<int>& runs) {
  std::string s;
  for (int r : runs) {
    if (!s.empty()) s += ' ';
    s += std::to_string(r);
  }
  return s;
}

std::vector<int> ParseRuns(const std::string& text) {
  std::vector<int> runs;
  std::istringstream in(text);
  int r = 0;
  while (in >> r) runs.push_back(r);
  return runs;
}

}  // namespace

std::vector<std::optional<RunRecord>> ReadMarkers(const StudyPlan& plan, const StudyFolder& folder,
                                                  bool retry_failed) {
  std::vector<std::optional<RunRecord>> records(plan.runs.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    std::optional<RunRecord> r = folder.ReadMarker(static_cast<int>(i));
    if (r && !(retry_failed && r->status != RunStatus::kOk)) records[i] = std::move(r);
  }
  return records;
}

int DefaultJobs(int ranks_on_node) {
  cpu_set_t set;
  CPU_ZERO(&set);
  int affinity = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 1;
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  affinity = std::max(1, affinity);
  const int shared = static_cast<int>(std::max(1L, online) / std::max(1, ranks_on_node));
  return std::max(1, std::min(affinity, std::max(1, shared)));
}

StudyOutcome RunStudyLocal(const StudyPlan& plan, const StudyFolder& folder,
                           const std::string& study_hash, const StudyRunOptions& options,
                           std::ostream& err) {
  const auto start = Clock::now();
  StudyOutcome o;
  o.records = ReadMarkers(plan, folder, options.retry_failed);
  std::deque<int> queue = PendingRuns(o.records);
  o.done_before = static_cast<int>(o.records.size() - queue.size());
  StudyProgress progress(err, options.progress, plan.study.name, static_cast<int>(plan.runs.size()),
                         o.done_before);
  IndexWriter index(plan, folder, study_hash, options.index_interval_s);
  RunPool pool(plan, folder,
               {.executable = options.executable,
                .slots = options.jobs,
                .kill_grace_s = options.stop_grace_s});
  for (;;) {
    // Stop on a signal: the runs going are run again on resume
    if (const int signal = Interrupted(options)) {
      progress.Abandon();
      pool.StopAll(SIGTERM, options.stop_grace_s);
      o.interrupted_signal = signal;
      break;
    }
    // Collect, then fill the free slots
    for (RunRecord& r : pool.Poll()) Collect(std::move(r), o.records, progress, o.run_now);
    while (pool.free_slots() > 0 && !queue.empty()) {
      pool.Start(queue.front());
      queue.pop_front();
    }
    const Tally t = Count(o.records);
    progress.Update(t.done, t.failed, pool.running());
    if (queue.empty() && pool.running() == 0) {
      // Runs that failed to start are reported by the next Poll
      for (RunRecord& r : pool.Poll()) Collect(std::move(r), o.records, progress, o.run_now);
      if (pool.running() == 0) break;
    }
    index.MaybeWrite(o.records);
    WaitForChildExit(0.1);
  }
  const Tally t = Count(o.records);
  if (o.interrupted_signal == 0) progress.Finish(t.done, t.failed);
  index.Write(o.records);
  o.wall_s = Since(start);
  return o;
}

StudyOutcome CoordinateStudyMpi(const StudyPlan& plan, const StudyFolder& folder,
                                const std::string& study_hash, const StudyRunOptions& options,
                                const MpiSession& mpi, std::ostream& err) {
  const auto start = Clock::now();
  StudyOutcome o;
  o.records = ReadMarkers(plan, folder, options.retry_failed);
  std::deque<int> queue = PendingRuns(o.records);
  o.done_before = static_cast<int>(o.records.size() - queue.size());
  StudyProgress progress(err, options.progress, plan.study.name, static_cast<int>(plan.runs.size()),
                         o.done_before);
  IndexWriter index(plan, folder, study_hash, options.index_interval_s);
  RunPool pool(plan, folder,
               {.executable = options.executable,
                .slots = options.jobs,
                .kill_grace_s = options.stop_grace_s,
                .rank = 0});
  std::set<int> handed_out;  // runs given to other ranks, no record yet
  std::set<int> finished;    // ranks that said kTagFinished
  bool stopping = false;
  Clock::time_point stop_time;
  for (;;) {
    // A signal: stop the own runs and tell the other ranks
    if (const int signal = Interrupted(options); signal != 0 && !stopping) {
      progress.Abandon();
      stopping = true;
      stop_time = Clock::now();
      o.interrupted_signal = signal;
      for (int rank = 1; rank < mpi.size(); ++rank)
        if (finished.count(rank) == 0) mpi.Send(rank, kTagStop, "");
      pool.StopAll(SIGTERM, options.stop_grace_s);
    }
    // Own runs
    for (RunRecord& r : pool.Poll()) Collect(std::move(r), o.records, progress, o.run_now);
    if (!stopping)
      while (pool.free_slots() > 0 && !queue.empty()) {
        pool.Start(queue.front());
        queue.pop_front();
      }
    // Messages of the other ranks
    while (std::optional<MpiMessage> m = mpi.TryReceive()) {
      if (m->tag == kTagRequest) {
        std::vector<int> runs;
        const int wanted = std::max(1, std::atoi(m->data.c_str()));
        while (!stopping && static_cast<int>(runs.size()) < wanted && !queue.empty()) {
          runs.push_back(queue.front());
          handed_out.insert(queue.front());
          queue.pop_front();
        }
        mpi.Send(m->source, kTagAssign, Join(runs));
      } else if (m->tag == kTagResult) {
        RunRecord r = DecodeRunRecord(m->data);
        handed_out.erase(r.run);
        Collect(std::move(r), o.records, progress, o.run_now);
      } else if (m->tag == kTagFinished) {
        finished.insert(m->source);
      }
    }
    // Progress; the end when every rank has finished (or, stopping, has had its time)
    const Tally t = Count(o.records);
    progress.Update(t.done, t.failed, pool.running() + static_cast<int>(handed_out.size()));
    const bool others_done = static_cast<int>(finished.size()) == mpi.size() - 1;
    if (pool.running() == 0 && (queue.empty() || stopping) && others_done) break;
    if (stopping && Since(stop_time) > options.stop_grace_s + 20) break;
    index.MaybeWrite(o.records);
    WaitForChildExit(0.01);
  }
  const Tally t = Count(o.records);
  if (o.interrupted_signal == 0) progress.Finish(t.done, t.failed);
  index.Write(o.records);
  o.wall_s = Since(start);
  return o;
}

StudyOutcome WorkStudyMpi(const StudyPlan& plan, const StudyFolder& folder,
                          const StudyRunOptions& options, const MpiSession& mpi) {
  const auto start = Clock::now();
  StudyOutcome o;
  RunPool pool(plan, folder,
               {.executable = options.executable,
                .slots = options.jobs,
                .kill_grace_s = options.stop_grace_s,
                .rank = mpi.rank()});
  bool asked = false, nothing_left = false, stopping = false;
  for (;;) {
    // Stop on a signal or when rank 0 says so
    if (const int signal = Interrupted(options); signal != 0 && !stopping) {
      o.interrupted_signal = signal;
      stopping = nothing_left = true;
      pool.StopAll(SIGTERM, options.stop_grace_s);
    }
    // Records of ended runs go to rank 0
    for (const RunRecord& r : pool.Poll()) {
      mpi.Send(0, kTagResult, EncodeRunRecord(r));
      ++o.run_now;
    }
    // Assignments and stops
    while (std::optional<MpiMessage> m = mpi.TryReceive()) {
      if (m->tag == kTagAssign) {
        asked = false;
        const std::vector<int> runs = ParseRuns(m->data);
        if (runs.empty()) nothing_left = true;
        if (!stopping)
          for (int r : runs) pool.Start(r);
      } else if (m->tag == kTagStop && !stopping) {
        stopping = nothing_left = true;
        pool.StopAll(SIGTERM, options.stop_grace_s);
      }
    }
    // Ask for work while slots are free; finish when nothing is left and nothing runs
    if (!nothing_left && !asked && pool.free_slots() > 0) {
      mpi.Send(0, kTagRequest, std::to_string(pool.free_slots()));
      asked = true;
    }
    if (nothing_left && !asked && pool.running() == 0) {
      for (const RunRecord& r : pool.Poll()) mpi.Send(0, kTagResult, EncodeRunRecord(r));
      mpi.Send(0, kTagFinished, stopping ? "interrupted" : "");
      break;
    }
    WaitForChildExit(0.01);
  }
  o.wall_s = Since(start);
  return o;
}

}  // namespace orrery::study

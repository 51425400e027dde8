#include "tools/cli/study_command.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "import/study_file.h"
#include "tools/cli/error_message.h"
#include "tools/cli/interrupt.h"
#include "tools/study/mpi_session.h"
#include "tools/study/run_process.h"
#include "tools/study/study_folder.h"
#include "tools/study/study_index.h"
#include "tools/study/study_plan.h"
#include "tools/study/study_runner.h"

namespace orrery::cli {
namespace {

using namespace orrery::study;

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// "1 run", "2 runs"
std::string Count(int n, const std::string& what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

void SummaryLine(std::ostream& out, const char* label, const std::string& value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%-20s", label);
  out << buffer << value << '\n';
}

// A study ready to run: the plan, its folder and the study file's hash
struct PreparedStudy {
  StudyPlan plan;
  std::optional<StudyFolder> folder;
  std::string hash;
};

StudyPlan LoadPlan(const StudyArgs& args) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(args.study_path, ec))
    throw std::runtime_error("study file " + args.study_path + ": no such file");
  return MakeStudyPlan(LoadStudyFile(args.study_path));
}

std::string FolderOf(const StudyArgs& args, const StudyPlan& plan) {
  if (!args.folder.empty()) return args.folder;
  if (!plan.study.folder.empty()) return plan.study.folder;
  return (std::filesystem::path("results") / "studies" / plan.study.name).string();
}

// The scene check and the folder (the process that owns the folder: the only one, or rank 0)
void Prepare(const StudyArgs& args, PreparedStudy& s, std::ostream& err) {
  CheckStudyScene(s.plan);
  const std::string text = ReadText(args.study_path);
  s.hash = HashText(text);
  s.folder = StudyFolder::Prepare(FolderOf(args, s.plan), args.study_path, text,
                                  ReadText(s.plan.study.scene_path),
                                  static_cast<int>(s.plan.runs.size()), err);
}

StudyRunOptions RunOptions(const StudyArgs& args, const StudyPlan& plan, int ranks_on_node) {
  StudyRunOptions o;
  o.executable = SelfExecutable();
  o.jobs = args.jobs > 0         ? args.jobs
           : plan.study.jobs > 0 ? plan.study.jobs
                                 : DefaultJobs(ranks_on_node);
  o.retry_failed = args.retry_failed;
  o.progress = args.quiet             ? StudyProgress::Style::kNone
               : args.err_is_terminal ? StudyProgress::Style::kBar
                                      : StudyProgress::Style::kLines;
  o.interrupted = [] { return PendingInterrupt(); };
  return o;
}

int Summary(const StudyArgs& args, const PreparedStudy& s, const StudyOutcome& o,
            const std::string& execution, std::ostream& out, std::ostream& err) {
  const StudyCounts c = CountRecords(o.records);
  const int runs = static_cast<int>(s.plan.runs.size());
  SummaryLine(out, "study", s.plan.study.name + " (" + args.study_path + ")");
  SummaryLine(out, "scene", s.plan.study.scene_path);
  SummaryLine(out, "folder", s.folder->path());
  SummaryLine(out, "runs",
              std::to_string(runs) + ": " + std::to_string(c.ok) + " ok, " +
                  std::to_string(c.failed) + " failed, " + std::to_string(c.output_failed) +
                  " output_failed, " + std::to_string(c.pending) + " pending (" +
                  std::to_string(o.done_before) + " done before, " + std::to_string(o.run_now) +
                  " now)");
  SummaryLine(out, "index", s.folder->IndexHdf5Path() + ", " + s.folder->IndexCsvPath());
  char wall[64];
  std::snprintf(wall, sizeof wall, "%.3g s", o.wall_s);
  SummaryLine(out, "wall time", std::string(wall) + ", " + execution);
  out << std::flush;
  if (o.interrupted_signal != 0) {
    ReportError(err, "study interrupted by signal " + std::to_string(o.interrupted_signal) + "; " +
                         std::to_string(c.pending) +
                         " runs left, run the same command again to resume");
    return kExitSignalBase + o.interrupted_signal;
  }
  return kExitSuccess;
}

// --dry-run: the runs and their settings
int DryRun(const PreparedStudy& s, std::ostream& out) {
  out << "study " << s.plan.study.name << ": " << s.plan.runs.size() << " runs of "
      << s.plan.study.scene_path << "\n";
  for (const StudySetting& setting : s.plan.study.settings)
    out << "  every run: " << setting.key << "=" << setting.value << "\n";
  for (const RunSpec& run : s.plan.runs) {
    out << "run " << run.index;
    for (std::size_t i = 0; i < run.values.size(); ++i)
      out << "  " << s.plan.parameters[i] << "=" << run.values[i];
    out << "\n";
  }
  return kExitSuccess;
}

int RunLocal(const StudyArgs& args, std::ostream& out, std::ostream& err) {
  PreparedStudy s;
  try {
    s.plan = LoadPlan(args);
    if (args.dry_run) {
      CheckStudyScene(s.plan);
      return DryRun(s, out);
    }
    Prepare(args, s, err);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  InterruptGuard guard;
  BlockChildSignal();
  const StudyRunOptions options = RunOptions(args, s.plan, 1);
  const StudyOutcome o = RunStudyLocal(s.plan, *s.folder, s.hash, options, err);
  return Summary(args, s, o, Count(options.jobs, "run") + " at a time", out, err);
}

// Every rank reads the study; rank 0 also prepares it and tells the others whether to go
std::optional<PreparedStudy> Handshake(const StudyArgs& args, const MpiSession& mpi,
                                       std::ostream& err) {
  PreparedStudy s;
  std::string error;
  try {
    s.plan = LoadPlan(args);
    if (mpi.rank() == 0) Prepare(args, s, err);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (mpi.rank() != 0) {
    mpi.Send(0, kTagReady, error.empty() ? "ok" : "error " + error);
    for (;;) {
      const MpiMessage m = mpi.Receive();
      if (m.tag == kTagStart)
        return m.data == "go" ? std::optional<PreparedStudy>(std::move(s)) : std::nullopt;
    }
  }
  // Rank 0: its own error first, else the first rank's
  for (int ready = 1; ready < mpi.size();) {
    const MpiMessage m = mpi.Receive();
    if (m.tag != kTagReady) continue;
    ++ready;
    if (error.empty() && m.data != "ok")
      error = "rank " + std::to_string(m.source) + ": " + m.data.substr(6);
  }
  for (int rank = 1; rank < mpi.size(); ++rank)
    mpi.Send(rank, kTagStart, error.empty() ? "go" : "stop");
  if (!error.empty()) {
    ReportError(err, error);
    return std::nullopt;
  }
  return s;
}

int RunMpi(const StudyArgs& args, std::ostream& out, std::ostream& err) {
  // Children's ends wake the loops; MPI's threads (started by MPI_Init) inherit the mask
  BlockChildSignal();
  std::unique_ptr<MpiSession> mpi;
  try {
    mpi = MpiSession::Start();
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  std::optional<PreparedStudy> s = Handshake(args, *mpi, err);
  if (!s) return kExitFailure;
  InterruptGuard guard;
  const StudyRunOptions options = RunOptions(args, s->plan, mpi->local_size());
  // A failure past the handshake (a marker or the index not written) ends every rank
  try {
    if (mpi->rank() != 0) {
      const StudyFolder folder =
          StudyFolder::Open(FolderOf(args, s->plan), static_cast<int>(s->plan.runs.size()));
      const StudyOutcome o = WorkStudyMpi(s->plan, folder, options, *mpi);
      return o.interrupted_signal != 0 ? kExitSignalBase + o.interrupted_signal : kExitSuccess;
    }
    const StudyOutcome o = CoordinateStudyMpi(s->plan, *s->folder, s->hash, options, *mpi, err);
    return Summary(args, *s, o,
                   "MPI, " + Count(mpi->size(), "rank") + " x " + Count(options.jobs, "run") +
                       " at a time (" + mpi->library() + ")",
                   out, err);
  } catch (const std::exception& e) {
    ReportError(err, "rank " + std::to_string(mpi->rank()) + ": " + e.what());
    mpi->Abort(kExitFailure);
  }
}

}  // namespace

int StudyCommand(const StudyArgs& args, std::ostream& out, std::ostream& err) {
  try {
    if (const std::optional<std::string> refused = MisconfiguredLaunch()) {
      ReportError(err, *refused);
      return kExitFailure;
    }
    const bool mpi = (args.mpi || MpiLaunchDetected(nullptr)) && !args.dry_run;
    return mpi ? RunMpi(args, out, err) : RunLocal(args, out, err);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli

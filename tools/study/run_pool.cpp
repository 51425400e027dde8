#include "tools/study/run_pool.h"

#include <unistd.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "tools/study/output_extraction.h"

namespace orrery::study {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

std::string Seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", s);
  return buffer;
}

}  // namespace

std::string FailureLine(const std::string& log_path) {
  std::ifstream in(log_path);
  std::string line, error, last;
  const std::string prefix = "orrery: error: ";
  while (std::getline(in, line)) {
    // A progress bar's carriage returns leave the last redraw
    if (const std::size_t cr = line.find_last_of('\r'); cr != std::string::npos)
      line = line.substr(cr + 1);
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    last = line;
    if (const std::size_t at = line.find(prefix); at != std::string::npos)
      error = line.substr(at + prefix.size());
  }
  return error.empty() ? last : error;
}

RunPool::RunPool(const StudyPlan& plan, const StudyFolder& folder, RunPoolOptions options)
    : plan_(plan), folder_(folder), options_(std::move(options)) {
  if (options_.slots < 1) options_.slots = 1;
  char host[256] = {0};
  if (gethostname(host, sizeof host - 1) == 0) host_ = host;
}

std::vector<int> RunPool::Running() const {
  std::vector<int> runs;
  for (const Active& a : active_) runs.push_back(a.run);
  return runs;
}

std::vector<std::string> RunPool::CommandLine(int run) const {
  const RunSpec& spec = plan_.runs[static_cast<std::size_t>(run)];
  std::vector<std::string> argv{options_.executable,
                                "run",
                                Absolute(plan_.study.scene_path),
                                "-o",
                                Absolute(folder_.ResultPath(run)),
                                "--quiet"};
  for (const std::string& o : plan_.Overrides(spec)) argv.insert(argv.end(), {"--set", o});
  argv.insert(argv.end(), {"--study-attribute", "run=" + std::to_string(run)});
  argv.insert(argv.end(), {"--study-attribute", "study=" + plan_.study.name});
  for (std::size_t i = 0; i < plan_.parameters.size(); ++i)
    argv.insert(argv.end(), {"--study-attribute", plan_.parameters[i] + "=" + spec.values[i]});
  return argv;
}

void RunPool::Start(int run) {
  try {
    active_.push_back({.run = run,
                       .process = RunProcess::Start(CommandLine(run), folder_.LogPath(run),
                                                    plan_.study.limits.memory_mib)});
  } catch (const std::exception& e) {
    RunRecord r;
    r.run = run;
    r.status = RunStatus::kFailed;
    r.exit_status = -1;
    r.wall_time_s = r.cpu_time_s = r.peak_memory_mib = 0;
    r.reason = e.what();
    r.rank = options_.rank;
    r.host = host_;
    r.outputs.assign(plan_.study.outputs.size(), kNaN);
    r.units.assign(plan_.study.outputs.size(), "");
    failed_to_start_.push_back(r);
  }
}

RunRecord RunPool::Finish(const Active& active, const ProcessExit& exit) const {
  RunRecord r;
  r.run = active.run;
  r.exit_status = exit.exit_status;
  r.wall_time_s = exit.wall_time_s;
  r.cpu_time_s = exit.cpu_time_s;
  r.peak_memory_mib = exit.peak_memory_mib;
  r.rank = options_.rank;
  r.host = host_;
  r.outputs.assign(plan_.study.outputs.size(), kNaN);
  r.units.assign(plan_.study.outputs.size(), "");
  // A failed run: the reason from its log or its signal
  if (active.over_limit || exit.exit_status != 0) {
    r.status = RunStatus::kFailed;
    if (active.over_limit) {
      r.reason =
          "stopped after the wall-time limit of " + Seconds(plan_.study.limits.wall_time_s) + " s";
    } else if (exit.signal != 0) {
      r.reason =
          "killed by signal " + std::to_string(exit.signal) + " (" + strsignal(exit.signal) + ")";
    } else {
      r.reason = FailureLine(folder_.LogPath(active.run));
      if (r.reason.empty()) r.reason = "exit status " + std::to_string(exit.exit_status);
    }
    if (plan_.study.limits.memory_mib > 0)
      r.reason += " (memory limit " + Seconds(plan_.study.limits.memory_mib) + " MiB)";
    return r;
  }
  // A finished run: its outputs
  ExtractedOutputs x = ExtractOutputs(folder_.ResultPath(active.run), plan_.study.outputs);
  r.outputs = std::move(x.values);
  r.units = std::move(x.units);
  r.status = x.error.empty() ? RunStatus::kOk : RunStatus::kOutputFailed;
  r.reason = x.error;
  return r;
}

void RunPool::EnforceLimit(Active& a) const {
  const double limit = plan_.study.limits.wall_time_s;
  if (!(limit > 0)) return;
  const double elapsed = a.process.ElapsedSeconds();
  if (!a.over_limit && elapsed > limit) {
    a.over_limit = true;
    a.stop_sent_s = elapsed;
    a.process.Signal(SIGTERM);
  } else if (a.over_limit && elapsed > a.stop_sent_s + options_.kill_grace_s) {
    a.process.Signal(SIGKILL);
  }
}

std::vector<RunRecord> RunPool::Poll() {
  std::vector<RunRecord> done = std::move(failed_to_start_);
  failed_to_start_.clear();
  for (std::size_t i = 0; i < active_.size();) {
    const std::optional<ProcessExit> exit = active_[i].process.Poll();
    if (!exit) {
      EnforceLimit(active_[i]);
      ++i;
      continue;
    }
    done.push_back(Finish(active_[i], *exit));
    active_.erase(active_.begin() + static_cast<std::ptrdiff_t>(i));
  }
  // Markers, once the records are complete
  for (const RunRecord& r : done) {
    const RunSpec& spec = plan_.runs[static_cast<std::size_t>(r.run)];
    std::vector<std::string> parameters;
    for (std::size_t k = 0; k < plan_.parameters.size(); ++k)
      parameters.push_back(plan_.parameters[k] + "=" + spec.values[k]);
    folder_.WriteMarker(r, parameters);
  }
  return done;
}

void RunPool::StopAll(int signal, double grace_s) {
  for (Active& a : active_) a.process.Signal(signal);
  // Wait for them, then kill what is left
  for (Active& a : active_) {
    while (!a.process.Poll()) {
      if (grace_s <= 0) {
        a.process.Signal(SIGKILL);
        a.process.Wait();
        break;
      }
      WaitForChildExit(0.05);
      grace_s -= 0.05;
    }
  }
  active_.clear();
}

}  // namespace orrery::study

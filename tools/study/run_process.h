#pragma once
// One run of a study as a child process: the own binary started with `orrery run ...`
// (posix_spawn, the fork/exec that does not copy the parent's memory: safe beside MPI's
// registered memory), its standard output and error sent to a log file, its end collected with
// wait4 so that the run's own resource use is known: wall time from start to exit, and peak
// memory as its maximum resident set size (ru_maxrss).
//
// A run cannot take the study down: a crash, an abort or a memory blow-up ends only the child.
// Each child leads its own process group, so a Ctrl-C at the terminal reaches the study alone,
// which then stops its runs itself (and knows that it did).
// The child dies with the study: at its start it asks the kernel to kill it when its parent
// exits (PR_SET_PDEATHSIG, armed by PrepareStudyChild from environment variables the parent
// sets), so a study killed with SIGKILL leaves no orphan runs. An address-space limit
// (RLIMIT_AS) can be set per run the same way.
//
// Usage:
//   RunProcess p = RunProcess::Start({exe, "run", scene, "-o", out, "--quiet"}, "run.log", 0);
//   while (!(exit = p.Poll())) sleep();
//   exit->exit_status, exit->peak_memory_mib, exit->wall_time_s
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace orrery::study {

struct ProcessExit {
  int exit_status = 0;         // exit code; 128 + signal number when a signal ended it
  int signal = 0;              // the signal that ended it, 0 when it exited
  double wall_time_s = 0;      // from Start to the moment Poll saw it end
  double cpu_time_s = 0;       // user + system time of the child (ru_utime + ru_stime)
  double peak_memory_mib = 0;  // ru_maxrss of the child (KiB on Linux) / 1024
};

class RunProcess {
 public:
  // Starts argv[0] with `argv`, stdin from /dev/null, stdout and stderr to `log_path`
  // (truncated). `memory_mib` > 0 limits the child's address space. Throws std::runtime_error
  // naming the program when it cannot start.
  static RunProcess Start(const std::vector<std::string>& argv, const std::string& log_path,
                          double memory_mib);

  RunProcess(RunProcess&& other) noexcept;
  RunProcess& operator=(RunProcess&& other) noexcept;
  RunProcess(const RunProcess&) = delete;
  RunProcess& operator=(const RunProcess&) = delete;
  // Kills (SIGKILL) and reaps a child still running.
  ~RunProcess();

  pid_t pid() const { return pid_; }
  double ElapsedSeconds() const;
  // The exit once the child has ended (non-blocking); reaps it.
  std::optional<ProcessExit> Poll();
  // Waits for the end (blocking).
  ProcessExit Wait();
  // Sends `signal` to the child if it still runs.
  void Signal(int signal) const;

 private:
  RunProcess(pid_t pid, std::chrono::steady_clock::time_point start) : pid_(pid), start_(start) {}
  std::optional<ProcessExit> Reap(bool block);
  pid_t pid_ = -1;
  std::chrono::steady_clock::time_point start_;
};

// Blocks SIGCHLD in the calling thread (and the threads it starts later), so that
// WaitForChildExit wakes as soon as a child ends: call before starting threads (MPI_Init).
void BlockChildSignal();
// Returns when a child has ended (SIGCHLD, if blocked), a signal handler ran, or after
// `timeout_s`, whichever comes first.
void WaitForChildExit(double timeout_s);

// The path of the running program (/proc/self/exe). Throws std::runtime_error when unknown.
std::string SelfExecutable();

// Called first thing by `orrery` (main): when started as a study's run (the environment names
// the parent), arms PR_SET_PDEATHSIG = SIGKILL, exits at once if the parent is already gone,
// applies the run's memory limit, and removes the variables so that nothing below inherits them.
void PrepareStudyChild();

}  // namespace orrery::study

#pragma once
// Simulations run at once in forked child processes, one per core, with their progress and their
// end reported to the parent through a pipe (what `orrery fault-study` does with its healthy and
// faulty runs).
//
// Why processes and not threads: HDF5 as Debian builds it is not thread-safe, and every run
// writes its own result file. Why fork and not `orrery run` children (as `orrery study` starts
// them, tools/study/run_process.h): the scenes are loaded (and their reduced bodies made) once,
// in the parent, and scenes built in C++ can be run the same way; the child inherits the loaded
// model copy-on-write. The engine starts no threads, so the child may go on with everything the
// parent had (the precondition of fork in a program that uses more than async-signal-safe calls).
//
// Protocol: the child sends fixed-size messages (ChildMessage, smaller than PIPE_BUF, so that each
// write is atomic and a read never sees half of one): progress at most every 50 ms of wall time,
// then one final message (done, failed with the exception's text, or interrupted with the
// signal), and ends with _exit (no atexit handlers, no stdio flush: nothing of the parent's is
// done twice). A child that dies without a final message (a crash, the OOM killer) is reported
// with the signal that ended it.
//
// Signals: each child leads its own process group, so a Ctrl-C at the terminal reaches the
// parent alone; the parent (an InterruptGuard living, interrupt.h) forwards the first SIGINT or
// SIGTERM to the children once, which stop within one integrator step (the handler they inherit
// sets the flag Simulate polls) and keep what their files hold. A child dies with the parent
// (PR_SET_PDEATHSIG = SIGKILL): a study killed with SIGKILL leaves no orphan runs. When one run
// fails the others are stopped the same way (the study needs them all).
//
// Usage:
//   InterruptGuard guard;
//   std::vector<ForkedWork> works{{[&](const ProgressFn& p) { return Simulate(m1, o1, &f1, p); }, 0.3}, ...};
//   std::vector<ChildOutcome> r = RunForked(works, [&](const SimulationProgress& sum) { bar.Update(sum); });
#include <functional>
#include <string>
#include <vector>

#include "mbd/simulation.h"

namespace orrery::cli {

using ProgressFn = std::function<void(const SimulationProgress&)>;
// What a child does: a run, reporting its progress through the callback; throws on failure
// (SimulationInterrupted when stopped by a signal).
using ChildWork = std::function<SimulationReport(const ProgressFn&)>;

struct ForkedWork {
  ChildWork run;
  double end_time_s = 0;  // the run's end time, for the progress before its first report
};

struct ChildOutcome {
  enum class Status { kDone, kFailed, kInterrupted, kStopped };
  Status status = Status::kFailed;  // kStopped: stopped by the parent because another run failed
  std::string reason;               // kFailed: the exception's text, or how the child died
  int signal = 0;                   // kInterrupted: the signal that stopped it
  SimulationProgress last;          // the run's last progress (kDone: end time, steps, wall time)
  double cpu_time_s = 0;            // user + system time of the child (wait4)
  double peak_memory_mib = 0;       // the child's maximum resident set size
};

// Runs every work in its own child at once; calls `on_progress` in the parent with the sum of the
// children's latest progress (t, end_time and steps added up, wall_s the wall time since the
// start) whenever one reports; returns when all have ended, one outcome per work in order.
// `interrupted` (empty: PendingInterrupt) is polled every 0.2 s; its first nonzero signal is
// forwarded to the children. Throws std::runtime_error when a pipe or a child cannot be made (the
// children already started are killed and reaped).
std::vector<ChildOutcome> RunForked(const std::vector<ForkedWork>& works, const ProgressFn& on_progress,
                                    const std::function<int()>& interrupted = {});

}  // namespace orrery::cli

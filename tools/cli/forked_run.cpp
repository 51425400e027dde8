#include "tools/cli/forked_run.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <type_traits>

#include "tools/cli/interrupt.h"

namespace orrery::cli {
namespace {

// One message from a child; fixed size below PIPE_BUF so that a write is atomic
struct ChildMessage {
  enum Kind : int { kProgress, kDone, kFailed, kInterrupted } kind = kProgress;
  SimulationProgress progress;
  int signal = 0;
  char text[480] = {};
};
static_assert(sizeof(ChildMessage) <= PIPE_BUF && std::is_trivially_copyable_v<ChildMessage>);

void Send(int fd, const ChildMessage& m) {
  // A short write cannot happen below PIPE_BUF; EINTR (a signal while the pipe is full) retried
  while (::write(fd, &m, sizeof m) < 0 && errno == EINTR) {
  }
}

ChildMessage Final(ChildMessage::Kind kind, const SimulationProgress& last, const char* text, int signal = 0) {
  ChildMessage m{.kind = kind, .progress = last, .signal = signal};
  std::snprintf(m.text, sizeof m.text, "%s", text);
  return m;
}

// The child: own process group, dies with the parent, runs the work, reports, _exit
[[noreturn]] void ChildMain(const ChildWork& work, int fd, pid_t parent) {
  ::setpgid(0, 0);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(1);
  SimulationProgress last;
  double sent_wall_s = -1;
  int code = 0;
  try {
    const SimulationReport r = work([&](const SimulationProgress& p) {
      last = p;
      if (p.wall_s - sent_wall_s < 0.05) return;
      sent_wall_s = p.wall_s;
      Send(fd, {.kind = ChildMessage::kProgress, .progress = p});
    });
    last = {.t = r.final_state.t, .end_time = last.end_time, .steps = r.stats.steps, .wall_s = r.wall_s};
    Send(fd, Final(ChildMessage::kDone, last, ""));
  } catch (const SimulationInterrupted& e) {
    last.t = e.t();
    Send(fd, Final(ChildMessage::kInterrupted, last, e.what(), e.signal()));
    code = 128 + e.signal();
  } catch (const std::exception& e) {
    Send(fd, Final(ChildMessage::kFailed, last, e.what()));
    code = 1;
  } catch (...) {
    Send(fd, Final(ChildMessage::kFailed, last, "unknown exception"));
    code = 1;
  }
  ::_exit(code);
}

// A child seen from the parent
struct Child {
  pid_t pid = -1;
  int fd = -1;                 // read end, -1 once closed
  bool final_seen = false;     // its final message arrived
  bool stopped_for_failure = false;  // signalled by the parent because another run failed
  bool signalled = false;            // signalled by the parent
  bool died = false;                 // its pipe closed without a final message
  ChildOutcome outcome;
};

// Reads one message of `c` (poll said readable); false at the end of the pipe
bool ReadMessage(Child& c) {
  ChildMessage m;
  ssize_t n;
  while ((n = ::read(c.fd, &m, sizeof m)) < 0 && errno == EINTR) {
  }
  if (n != static_cast<ssize_t>(sizeof m)) return false;
  c.outcome.last = m.progress;
  if (m.kind == ChildMessage::kProgress) return true;
  c.final_seen = true;
  c.outcome.status = m.kind == ChildMessage::kDone        ? ChildOutcome::Status::kDone
                     : m.kind == ChildMessage::kInterrupted ? ChildOutcome::Status::kInterrupted
                                                            : ChildOutcome::Status::kFailed;
  c.outcome.signal = m.signal;
  c.outcome.reason = m.text;
  return true;
}

// Waits for the child's end; resource use, and how it died when it sent no final message
void Reap(Child& c) {
  int status = 0;
  struct rusage usage {};
  while (::wait4(c.pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  c.outcome.cpu_time_s = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
                         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  c.outcome.peak_memory_mib = usage.ru_maxrss / 1024.0;
  if (c.final_seen) {
    if (c.stopped_for_failure && c.outcome.status == ChildOutcome::Status::kInterrupted)
      c.outcome.status = ChildOutcome::Status::kStopped;
    return;
  }
  c.outcome.status = ChildOutcome::Status::kFailed;
  c.outcome.reason = WIFSIGNALED(status) ? std::string("the process was killed by signal ") +
                                               std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")"
                                         : "the process exited with code " + std::to_string(WEXITSTATUS(status)) +
                                               " without a report";
}

void Stop(Child& c, int signal, bool for_failure) {
  if (c.final_seen || c.died || c.signalled) return;
  ::kill(c.pid, signal);
  c.signalled = true;
  c.stopped_for_failure = for_failure;
}

// Forks one child for `work`; the parent keeps the read end
Child StartChild(const ChildWork& work) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot make a pipe: ") + std::strerror(errno));
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(std::string("cannot start a run process (fork): ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    ChildMain(work, fds[1], parent);
  }
  ::close(fds[1]);
  return {.pid = pid, .fd = fds[0]};
}

SimulationProgress Sum(const std::vector<Child>& children, double wall_s) {
  SimulationProgress sum{.wall_s = wall_s};
  for (const Child& c : children) {
    sum.t += c.outcome.last.t;
    sum.end_time += c.outcome.last.end_time;
    sum.steps += c.outcome.last.steps;
  }
  return sum;
}

// Until every pipe has closed: messages read, progress passed on, a signal or a failure forwarded
void Watch(std::vector<Child>& children, const ProgressFn& on_progress, const std::function<int()>& interrupted) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    std::vector<pollfd> fds;
    for (const Child& c : children)
      if (c.fd >= 0) fds.push_back({.fd = c.fd, .events = POLLIN, .revents = 0});
    if (fds.empty()) return;
    ::poll(fds.data(), fds.size(), 200);  // EINTR: a signal, looked at below
    bool updated = false;
    for (Child& c : children) {
      const auto it = std::find_if(fds.begin(), fds.end(), [&](const pollfd& p) { return p.fd == c.fd; });
      if (it == fds.end() || it->revents == 0) continue;
      if (ReadMessage(c)) {
        updated = true;
        continue;
      }
      ::close(c.fd);
      c.fd = -1;
      c.died = !c.final_seen;
    }
    if (updated && on_progress)
      on_progress(Sum(children, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
    // A signal to the parent, or a failed run: the others stop
    const int signal = interrupted ? interrupted() : PendingInterrupt();
    const bool failed = std::any_of(children.begin(), children.end(), [](const Child& c) {
      return c.died || (c.final_seen && c.outcome.status == ChildOutcome::Status::kFailed);
    });
    if (signal != 0 || failed)
      for (Child& c : children) Stop(c, signal != 0 ? signal : SIGTERM, signal == 0);
  }
}

}  // namespace

std::vector<ChildOutcome> RunForked(const std::vector<ForkedWork>& works, const ProgressFn& on_progress,
                                    const std::function<int()>& interrupted) {
  std::vector<Child> children;
  try {
    for (const ForkedWork& w : works) {
      children.push_back(StartChild(w.run));
      children.back().outcome.last.end_time = w.end_time_s;
    }
  } catch (...) {
    for (Child& c : children) {
      ::kill(c.pid, SIGKILL);
      ::close(c.fd);
      Reap(c);
    }
    throw;
  }
  Watch(children, on_progress, interrupted);
  std::vector<ChildOutcome> outcomes;
  for (Child& c : children) {
    Reap(c);
    outcomes.push_back(c.outcome);
  }
  return outcomes;
}

}  // namespace orrery::cli

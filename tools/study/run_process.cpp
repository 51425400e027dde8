#include "tools/study/run_process.h"

#include <fcntl.h>
#include <pthread.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <utility>

extern char** environ;

namespace orrery::study {
namespace {

constexpr const char* kParentVariable = "ORRERY_STUDY_PARENT_PID";
constexpr const char* kMemoryVariable = "ORRERY_STUDY_MEMORY_MIB";

// The parent's environment without the study's own variables, plus `extra`
std::vector<std::string> ChildEnvironment(const std::vector<std::string>& extra) {
  std::vector<std::string> env;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string entry(*e);
    if (entry.rfind(std::string(kParentVariable) + "=", 0) == 0 ||
        entry.rfind(std::string(kMemoryVariable) + "=", 0) == 0)
      continue;
    env.push_back(entry);
  }
  env.insert(env.end(), extra.begin(), extra.end());
  return env;
}

std::vector<char*> Pointers(std::vector<std::string>& strings) {
  std::vector<char*> p;
  for (std::string& s : strings) p.push_back(s.data());
  p.push_back(nullptr);
  return p;
}

}  // namespace

RunProcess RunProcess::Start(const std::vector<std::string>& argv, const std::string& log_path,
                             double memory_mib) {
  // Standard streams: stdin from /dev/null, stdout and stderr to the log
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  // Default signal handling and an empty mask in the child (the study may block or catch some)
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, all;
  sigemptyset(&none);
  sigfillset(&all);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &all);
  // Its own process group: a Ctrl-C at the terminal reaches the study, which stops its runs
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr,
                           POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETPGROUP);
  // Arguments and environment
  std::vector<std::string> args = argv;
  std::vector<std::string> extra{std::string(kParentVariable) + "=" + std::to_string(getpid())};
  if (memory_mib > 0)
    extra.push_back(std::string(kMemoryVariable) + "=" + std::to_string(memory_mib));
  std::vector<std::string> env = ChildEnvironment(extra);
  std::vector<char*> arg_pointers = Pointers(args), env_pointers = Pointers(env);
  pid_t pid = -1;
  const auto start = std::chrono::steady_clock::now();
  const int rc = posix_spawn(&pid, args.front().c_str(), &actions, &attr, arg_pointers.data(),
                             env_pointers.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw std::runtime_error("cannot start " + args.front() + ": " + std::strerror(rc));
  return RunProcess(pid, start);
}

RunProcess::RunProcess(RunProcess&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)), start_(other.start_) {}

RunProcess& RunProcess::operator=(RunProcess&& other) noexcept {
  if (this != &other) {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      Reap(true);
    }
    pid_ = std::exchange(other.pid_, -1);
    start_ = other.start_;
  }
  return *this;
}

RunProcess::~RunProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    Reap(true);
  }
}

double RunProcess::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::optional<ProcessExit> RunProcess::Reap(bool block) {
  if (pid_ <= 0) return std::nullopt;
  int status = 0;
  struct rusage usage {};
  pid_t r;
  do {
    r = ::wait4(pid_, &status, block ? 0 : WNOHANG, &usage);
  } while (r < 0 && errno == EINTR);
  if (r == 0) return std::nullopt;
  ProcessExit e;
  e.wall_time_s = ElapsedSeconds();
  pid_ = -1;
  if (r < 0) {  // not our child any more: nothing to report but a failure
    e.exit_status = -1;
    return e;
  }
  e.peak_memory_mib = static_cast<double>(usage.ru_maxrss) / 1024.0;
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  e.cpu_time_s = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  if (WIFSIGNALED(status)) {
    e.signal = WTERMSIG(status);
    e.exit_status = 128 + e.signal;
  } else {
    e.exit_status = WEXITSTATUS(status);
  }
  return e;
}

std::optional<ProcessExit> RunProcess::Poll() { return Reap(false); }

ProcessExit RunProcess::Wait() { return *Reap(true); }

void RunProcess::Signal(int signal) const {
  if (pid_ > 0) ::kill(pid_, signal);
}

void BlockChildSignal() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGCHLD);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

void WaitForChildExit(double timeout_s) {
  sigset_t set, blocked;
  sigemptyset(&set);
  sigaddset(&set, SIGCHLD);
  pthread_sigmask(SIG_BLOCK, nullptr, &blocked);
  struct timespec timeout {};
  timeout.tv_sec = static_cast<time_t>(timeout_s);
  timeout.tv_nsec = static_cast<long>((timeout_s - static_cast<double>(timeout.tv_sec)) * 1e9);
  if (sigismember(&blocked, SIGCHLD) == 1)
    sigtimedwait(&set, nullptr, &timeout);  // EAGAIN on timeout, EINTR for a handler: both return
  else
    nanosleep(&timeout, nullptr);
}

std::string SelfExecutable() {
  std::string path(4096, '\0');
  const ssize_t n = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (n <= 0)
    throw std::runtime_error(std::string("cannot find the orrery program (/proc/self/exe): ") +
                             std::strerror(errno));
  path.resize(static_cast<std::size_t>(n));
  return path;
}

void PrepareStudyChild() {
  const char* parent = std::getenv(kParentVariable);
  if (parent == nullptr) return;
  // Die with the study; a study already gone leaves nothing to do
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (std::to_string(::getppid()) != parent) std::_Exit(128 + SIGKILL);
  // Memory limit of the run
  if (const char* mib = std::getenv(kMemoryVariable)) {
    const double limit = std::strtod(mib, nullptr);
    if (limit > 0) {
      struct rlimit r {};
      r.rlim_cur = r.rlim_max = static_cast<rlim_t>(limit * 1024.0 * 1024.0);
      ::setrlimit(RLIMIT_AS, &r);
    }
  }
  ::unsetenv(kParentVariable);
  ::unsetenv(kMemoryVariable);
}

}  // namespace orrery::study

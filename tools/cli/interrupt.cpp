#include "tools/cli/interrupt.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace orrery::cli {
namespace {

// Written by the signal handler, read by the computation; lock-free, so safe in a handler
std::atomic<int> g_pending_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void RecordSignal(int signal) {
  int none = 0;
  g_pending_signal.compare_exchange_strong(none, signal);
}

void Install(int signal, struct sigaction* previous) {
  struct sigaction action {};
  action.sa_handler = RecordSignal;
  sigemptyset(&action.sa_mask);
  // One-shot: a second signal gets the default action (terminate)
  action.sa_flags = SA_RESETHAND;
  if (sigaction(signal, &action, previous) != 0)
    throw std::runtime_error(std::string("cannot install a handler for signal ") + std::to_string(signal) +
                             ": " + std::strerror(errno));
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_pending_signal.store(0);
  Install(SIGINT, &previous_int_);
  try {
    Install(SIGTERM, &previous_term_);
  } catch (...) {
    sigaction(SIGINT, &previous_int_, nullptr);
    throw;
  }
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGTERM, &previous_term_, nullptr);
  sigaction(SIGINT, &previous_int_, nullptr);
}

int PendingInterrupt() { return g_pending_signal.load(std::memory_order_relaxed); }

const std::atomic<int>* InterruptFlag() { return &g_pending_signal; }

}  // namespace orrery::cli

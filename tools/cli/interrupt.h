#pragma once
// Graceful interruption of long runs by SIGINT (Ctrl-C) and SIGTERM (kill, batch schedulers).
//
// While an `InterruptGuard` lives, the first SIGINT or SIGTERM only records the signal in an
// atomic flag; Simulate polls the flag after every integrator step (SimulationOptions::interrupt)
// and throws SimulationInterrupted, so the result file is flushed on the way out within one step
// of the signal, however coarse the output interval. The handler is installed with SA_RESETHAND:
// a second Ctrl-C terminates the process the default way, for a run stuck inside a step. The
// destructor restores the previous handlers.
//
// Usage:
//   InterruptGuard guard;
//   options.interrupt = InterruptFlag();
//   Simulate(model, options, &out);   // throws SimulationInterrupted after a signal
#include <atomic>
#include <csignal>

namespace orrery::cli {

class InterruptGuard {
 public:
  // Clears any earlier request and installs the handlers. Throws std::runtime_error if the
  // system refuses. Guards must not nest.
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

// The signal number received since the current guard was installed, 0 if none.
int PendingInterrupt();

// The flag the handler sets (the signal number), for SimulationOptions::interrupt.
const std::atomic<int>* InterruptFlag();

}  // namespace orrery::cli

#pragma once
// Graceful interruption of long runs by SIGINT (Ctrl-C) and SIGTERM (kill, batch schedulers).
//
// While an `InterruptGuard` lives, the first SIGINT or SIGTERM only records the signal in an
// atomic flag; the computation polls `PendingInterrupt()` at a safe point (the progress callback
// of Simulate) and throws `Interrupted`, so the result file is flushed on the way out. The handler
// is installed with SA_RESETHAND: a second Ctrl-C terminates the process the default way, for a
// run stuck between two safe points. The destructor restores the previous handlers.
//
// Usage:
//   InterruptGuard guard;
//   Simulate(model, options, &out, [](const SimulationProgress& p) {
//     if (const int sig = PendingInterrupt()) throw Interrupted(sig, p.t);
//   });
#include <csignal>
#include <stdexcept>

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

// Thrown from a progress callback when a signal asked the run to stop; what() is
// "interrupted at t = <t> s".
class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, double t_s);
  int signal() const { return signal_; }
  double t() const { return t_s_; }

 private:
  int signal_;
  double t_s_;
};

}  // namespace orrery::cli

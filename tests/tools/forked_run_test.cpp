// RunForked (tools/cli/forked_run.h): works run at once in child processes. Oracles are the
// works themselves: what each reports (its end, its exception's text, the signal that killed it)
// must come back to the parent unchanged, and two works that each sleep 0.3 s end together in
// well under the 0.6 s they would take one after the other.
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "tools/cli/forked_run.h"
#include "tools/cli/interrupt.h"

namespace orrery::cli {
namespace {

using Status = ChildOutcome::Status;

// A "run" of `steps` steps of `step_s` wall time each, reporting after every step
ChildWork Sleeper(int steps, double step_s, double end_time) {
  return [=](const ProgressFn& progress) {
    SimulationReport r;
    for (int k = 1; k <= steps; ++k) {
      std::this_thread::sleep_for(std::chrono::duration<double>(step_s));
      if (const int s = InterruptFlag()->load()) throw SimulationInterrupted(s, end_time * (k - 1) / steps);
      progress({.t = end_time * k / steps, .end_time = end_time, .steps = k, .wall_s = k * step_s});
    }
    r.final_state.t = end_time;
    r.stats.steps = steps;
    r.wall_s = steps * step_s;
    return r;
  };
}

TEST(ForkedRun, TwoRunsGoAtOnceAndReportTheirEndsAndProgress) {
  SimulationProgress last;
  int updates = 0;
  const auto start = std::chrono::steady_clock::now();
  const std::vector<ChildOutcome> r =
      RunForked({{Sleeper(6, 0.05, 0.2), 0.2}, {Sleeper(6, 0.05, 0.3), 0.3}}, [&](const SimulationProgress& p) {
        last = p;
        ++updates;
      });
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.size(), 2u);
  for (const ChildOutcome& o : r) {
    EXPECT_EQ(o.status, Status::kDone) << o.reason;
    EXPECT_EQ(o.last.steps, 6);
    EXPECT_GE(o.cpu_time_s, 0);
  }
  EXPECT_DOUBLE_EQ(r[0].last.t, 0.2);
  EXPECT_DOUBLE_EQ(r[1].last.t, 0.3);
  // The last progress is the sum of both ends; sequential runs would take 0.6 s
  EXPECT_GT(updates, 1);
  EXPECT_DOUBLE_EQ(last.t, 0.5);
  EXPECT_DOUBLE_EQ(last.end_time, 0.5);
  EXPECT_EQ(last.steps, 12);
  EXPECT_LT(wall_s, 0.55);
}

TEST(ForkedRun, AFailureComesBackWithItsReasonAndStopsTheOtherRun) {
  InterruptGuard guard;
  const ChildWork fails = [](const ProgressFn&) -> SimulationReport {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    throw std::runtime_error("step size below 1e-12 s at t = 0.01 s");
  };
  const std::vector<ChildOutcome> r = RunForked({{Sleeper(200, 0.05, 1), 1}, {fails, 1}}, {});
  EXPECT_EQ(r[1].status, Status::kFailed);
  EXPECT_EQ(r[1].reason, "step size below 1e-12 s at t = 0.01 s");
  // The long run (10 s) was stopped within a step of the failure
  EXPECT_EQ(r[0].status, Status::kStopped);
  EXPECT_LT(r[0].last.t, 0.1);
}

TEST(ForkedRun, AChildKilledBySignalIsReportedWithTheSignal) {
  const ChildWork dies = [](const ProgressFn&) -> SimulationReport {
    ::raise(SIGKILL);
    return {};
  };
  const std::vector<ChildOutcome> r = RunForked({{dies, 1}}, {});
  EXPECT_EQ(r[0].status, Status::kFailed);
  EXPECT_NE(r[0].reason.find("killed by signal 9"), std::string::npos) << r[0].reason;
}

TEST(ForkedRun, AnInterruptOfTheParentIsForwardedToTheRuns) {
  InterruptGuard guard;
  const auto start = std::chrono::steady_clock::now();
  // The parent "receives" SIGTERM 0.2 s in
  const std::vector<ChildOutcome> r = RunForked({{Sleeper(200, 0.05, 1), 1}, {Sleeper(200, 0.05, 1), 1}}, {}, [&] {
    return std::chrono::steady_clock::now() - start > std::chrono::milliseconds(200) ? SIGTERM : 0;
  });
  for (const ChildOutcome& o : r) {
    EXPECT_EQ(o.status, Status::kInterrupted);
    EXPECT_EQ(o.signal, SIGTERM);
    EXPECT_LT(o.last.t, 0.1);
  }
}

}  // namespace
}  // namespace orrery::cli

// Child processes of a study: exit codes, signals, peak memory against a known allocation, the
// memory limit, logs and their failure line.
#include "tools/study/run_process.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tools/study/run_pool.h"

namespace orrery::study {
namespace {

namespace fs = std::filesystem;

class RunProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("orrery_run_process_" + std::to_string(getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Log() const { return (dir_ / "log").string(); }
  std::string ReadLog() const {
    std::ifstream in(Log());
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  static ProcessExit RunShell(const std::string& script, const std::string& log,
                              double memory_mib = 0) {
    return RunProcess::Start({"/bin/sh", "-c", script}, log, memory_mib).Wait();
  }
  fs::path dir_;
};

TEST_F(RunProcessTest, ExitCodesSignalsAndLogs) {
  ProcessExit e = RunShell("echo out; echo err >&2; exit 3", Log());
  EXPECT_EQ(e.exit_status, 3);
  EXPECT_EQ(e.signal, 0);
  EXPECT_EQ(ReadLog(), "out\nerr\n");
  e = RunShell("kill -SEGV $$", Log());
  EXPECT_EQ(e.signal, 11);
  EXPECT_EQ(e.exit_status, 128 + 11);
  // The study's variables reach the child only for PrepareStudyChild, which removes them
  RunShell("echo ${ORRERY_STUDY_PARENT_PID:-none}", Log());
  EXPECT_EQ(ReadLog(), std::to_string(getpid()) + "\n");
  EXPECT_THROW(RunProcess::Start({"/nonexistent/program"}, Log(), 0), std::runtime_error);
}

TEST_F(RunProcessTest, PeakMemoryIsTheChildsOwn) {
  // python3 holding 200 MiB of touched memory: its maximum resident set is at least that, and
  // the study's own does not count
  const std::string script = "python3 -c 'x = bytearray(200 * 2**20); print(len(x))'";
  const ProcessExit e = RunShell(script, Log());
  ASSERT_EQ(e.exit_status, 0) << ReadLog();
  EXPECT_GE(e.peak_memory_mib, 200);
  EXPECT_LT(e.peak_memory_mib, 400);
  const ProcessExit small = RunShell("exit 0", Log());
  EXPECT_LT(small.peak_memory_mib, 50);
  EXPECT_GE(e.cpu_time_s, 0);
  EXPECT_GT(e.wall_time_s, 0);
}

TEST_F(RunProcessTest, MemoryLimitEndsOnlyTheRun) {
  // The limit applies in the child only when it is the orrery program (PrepareStudyChild reads
  // it), so a shell run is not limited; the orrery binary is tested through `orrery study`
  // (tests/tools/study/study_cli_test.cpp). Here: the variable is handed over.
  RunShell("echo ${ORRERY_STUDY_MEMORY_MIB:-none}", Log(), 300);
  EXPECT_EQ(ReadLog().substr(0, 3), "300");
}

TEST_F(RunProcessTest, FailureLineIsTheLastErrorLine) {
  std::ofstream(Log()) << "progress\r  50 %\rorrery: error: first\nsummary\norrery: error: "
                          "scene.yaml:3: mass: must be > 0\n\n";
  EXPECT_EQ(FailureLine(Log()), "scene.yaml:3: mass: must be > 0");
  std::ofstream(Log()) << "a line\nthe last words\n  \n";
  EXPECT_EQ(FailureLine(Log()), "the last words");
  std::ofstream(Log()) << "";
  EXPECT_EQ(FailureLine(Log()), "");
}

}  // namespace
}  // namespace orrery::study

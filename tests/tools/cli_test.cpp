// Tests of the `orrery` command-line program: the command functions called in-process
// (tools/cli/run_command.h, inspect_command.h, progress_bar.h, error_message.h) and the built
// binary called through the shell for argument errors and --version.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "tools/cli/error_message.h"
#include "tools/cli/inspect_command.h"
#include "tools/cli/progress_bar.h"
#include "tools/cli/run_command.h"

namespace orrery::cli {
namespace {

namespace fs = std::filesystem;

// A pendulum released at 1 rad, 0.2 s at 0.01 s output interval: 21 rows
constexpr const char* kPendulum =
    "name: p\n"
    "gravity: [0,-9.81,0]\n"
    "bodies:\n"
    "  - {name: bob, mass: 1, inertia: [0.01,0.01,0.01]}\n"
    "joints:\n"
    "  - {name: hinge, type: revolute, parent: world, child: bob, child_frame: {position: [0,1,0]}, "
    "axis: [0,0,1], initial_position: 1.0}\n"
    "solver: {end_time: 0.2}\n"
    "output: {interval: 0.01}\n";

std::size_t CountLines(const std::string& text) { return std::count(text.begin(), text.end(), '\n'); }

// Exactly one line, "orrery: error: ...", mentioning `reason`
::testing::AssertionResult IsOneErrorLine(const std::string& err, const std::string& reason) {
  if (CountLines(err) != 1 || err.back() != '\n')
    return ::testing::AssertionFailure() << "not exactly one line: \"" << err << "\"";
  if (err.rfind("orrery: error: ", 0) != 0) return ::testing::AssertionFailure() << "no prefix: " << err;
  if (err.find(reason) == std::string::npos)
    return ::testing::AssertionFailure() << "\"" << reason << "\" not in: " << err;
  return ::testing::AssertionSuccess();
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("orrery_cli_test_" + std::to_string(getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Runs `args` quietly unless told otherwise; fills out_ and err_
  int Run(RunArgs args) {
    out_.str("");
    err_.str("");
    return RunCommand(args, out_, err_);
  }
  RunArgs PendulumArgs(const std::string& output = "out.h5") {
    RunArgs args;
    args.scene_path = Write("pendulum.yaml", kPendulum);
    args.output_path = Path(output);
    args.quiet = true;
    return args;
  }

  fs::path dir_;
  std::ostringstream out_, err_;
};

TEST_F(CliTest, RunWritesEveryOutputRow) {
  RunArgs args = PendulumArgs();
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  EXPECT_EQ(err_.str(), "");  // --quiet
  // 0, 0.01, ..., 0.2
  const Hdf5Reader reader(args.output_path);
  const Eigen::MatrixXd t = reader.ReadMatrix("/time");
  ASSERT_EQ(t.rows(), 21);
  EXPECT_DOUBLE_EQ(t(0, 0), 0.0);
  EXPECT_NEAR(t(20, 0), 0.2, 1e-12);
  EXPECT_EQ(reader.ReadMatrix("/joints/hinge/q").rows(), 21);
  // The summary names the file, the rows and the statistics
  const std::string out = out_.str();
  EXPECT_NE(out.find(args.output_path), std::string::npos) << out;
  EXPECT_NE(out.find("rows written        21\n"), std::string::npos) << out;
  for (const char* label : {"wall time", "wall per sim. s", "integrator", "steps", "residual evals",
                            "jacobian evals", "newton failures", "error-test fails", "max |Phi|",
                            "max |Phi-dot|"})
    EXPECT_NE(out.find(label), std::string::npos) << label << " missing in\n" << out;
}

TEST_F(CliTest, RunWritesToTheScenesOutputFileWithoutDashO) {
  RunArgs args;
  args.scene_path = Write("pendulum.yaml", kPendulum);
  args.quiet = true;
  args.overrides = {"output.file=" + Path("from_scene.h5")};
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  EXPECT_EQ(Hdf5Reader(Path("from_scene.h5")).ReadMatrix("/time").rows(), 21);
}

TEST_F(CliTest, EndTimeOverridesTheScene) {
  RunArgs args = PendulumArgs();
  args.end_time = 0.1;
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  const Hdf5Reader reader(args.output_path);
  EXPECT_EQ(reader.ReadMatrix("/time").rows(), 11);
  EXPECT_DOUBLE_EQ(std::stod(reader.ReadAttributeText("/", "end_time")), 0.1);
}

TEST_F(CliTest, SetOverridesTheSceneAndEndTimeWinsOverSet) {
  // --set alone
  RunArgs args = PendulumArgs();
  args.overrides = {"output.interval=0.02", "bodies.bob.mass=2"};
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  EXPECT_EQ(Hdf5Reader(args.output_path).ReadMatrix("/time").rows(), 11);
  // --end-time comes after every --set
  args.overrides = {"solver.end_time=0.1"};
  args.end_time = 0.3;
  EXPECT_EQ(SceneOverrides(args), (std::vector<std::string>{"solver.end_time=0.1", "solver.end_time=0.3"}));
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  EXPECT_EQ(Hdf5Reader(args.output_path).ReadMatrix("/time").rows(), 31);
}

TEST_F(CliTest, IntegratorOverridesTheScene) {
  RunArgs args = PendulumArgs();
  args.integrator = "generalized_alpha";
  EXPECT_EQ(SceneOverrides(args).back(), "solver.integrator=generalized_alpha");
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  const std::string written = Hdf5Reader(args.output_path).ReadAttributeText("/", "integrator");
  EXPECT_NE(written.find("alpha"), std::string::npos) << written;
  EXPECT_NE(out_.str().find(written), std::string::npos) << out_.str();
}

TEST_F(CliTest, ProgressIsALineEvery10PercentWhenNotATerminal) {
  RunArgs args = PendulumArgs();
  args.quiet = false;
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  // 20 output steps of 5 %: one line at each of the 10 marks, the last at 100 %
  const std::string err = err_.str();
  EXPECT_EQ(CountLines(err), 10u) << err;
  EXPECT_EQ(err.find('\r'), std::string::npos);
  EXPECT_NE(err.find("progress 100%  t = 0.2 / 0.2 s"), std::string::npos) << err;
}

TEST_F(CliTest, InspectListsDatasetsAndFileAttributes) {
  RunArgs args = PendulumArgs();
  ASSERT_EQ(Run(args), kExitSuccess) << err_.str();
  std::ostringstream out, err;
  ASSERT_EQ(InspectCommand({args.output_path}, out, err), kExitSuccess) << err.str();
  EXPECT_EQ(err.str(), "");
  const std::string listing = out.str();
  // Groups, datasets with shape and unit
  EXPECT_NE(listing.find("\n  bodies/\n"), std::string::npos) << listing;
  EXPECT_NE(listing.find("\n    bob/"), std::string::npos) << listing;
  // The time series: its line holds the shape and ends with the unit
  const std::size_t time_at = listing.find("\n  time ");
  ASSERT_NE(time_at, std::string::npos) << listing;
  const std::string time_line = listing.substr(time_at + 1, listing.find('\n', time_at + 1) - time_at - 1);
  EXPECT_NE(time_line.find(" 21 x 1 "), std::string::npos) << time_line;
  EXPECT_TRUE(time_line.ends_with(" s")) << time_line;
  EXPECT_NE(listing.find("hinge/"), std::string::npos) << listing;
  // Each dataset the reader lists is on a line of its own
  for (const Hdf5Reader::Entry& e : Hdf5Reader(args.output_path).List()) {
    const std::string name = e.path.substr(e.path.rfind('/') + 1);
    EXPECT_NE(listing.find(name), std::string::npos) << e.path << " missing in\n" << listing;
  }
  // File attributes; the scene as its first line and its line count
  EXPECT_NE(listing.find("engine_version"), std::string::npos) << listing;
  EXPECT_NE(listing.find("scene_name"), std::string::npos) << listing;
  EXPECT_NE(listing.find("end_time"), std::string::npos) << listing;
  EXPECT_NE(listing.find("name: p  (8 lines)\n"), std::string::npos) << listing;
  EXPECT_EQ(listing.find("gravity:"), std::string::npos) << listing;
}

TEST_F(CliTest, AttributeSummaryShortensLongValues) {
  EXPECT_EQ(AttributeSummary("ida"), "ida");
  EXPECT_EQ(AttributeSummary("a\nb\nc\n"), "a  (3 lines)");
  EXPECT_EQ(AttributeSummary("a\nb\nc"), "a  (3 lines)");
  EXPECT_EQ(AttributeSummary("abcdefghij", 6), "abc...");
}

TEST_F(CliTest, MissingSceneFileIsOneErrorLine) {
  RunArgs args = PendulumArgs();
  args.scene_path = Path("no_such_scene.yaml");
  EXPECT_EQ(Run(args), kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(err_.str(), "no_such_scene.yaml"));
  EXPECT_EQ(out_.str(), "");
  EXPECT_FALSE(fs::exists(args.output_path));
}

TEST_F(CliTest, SceneErrorIsOneErrorLineAndCreatesNoFile) {
  std::string text = kPendulum;
  text.replace(text.find("mass: 1"), 7, "mass: -1");
  RunArgs args = PendulumArgs();
  args.scene_path = Write("bad.yaml", text);
  EXPECT_EQ(Run(args), kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(err_.str(), "mass"));
  EXPECT_NE(err_.str().find("bad.yaml"), std::string::npos) << err_.str();
  EXPECT_FALSE(fs::exists(args.output_path));
}

TEST_F(CliTest, BadOverrideIsOneErrorLine) {
  RunArgs args = PendulumArgs();
  args.overrides = {"solver.no_such_key=1"};
  EXPECT_EQ(Run(args), kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(err_.str(), "no_such_key"));
}

TEST_F(CliTest, UnwritableOutputPathIsOneErrorLine) {
  RunArgs args = PendulumArgs();
  args.output_path = Path("no_such_dir/out.h5");
  EXPECT_EQ(Run(args), kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(err_.str(), args.output_path));
  EXPECT_EQ(out_.str(), "");
}

TEST_F(CliTest, InspectOfAMissingOrForeignFileIsOneErrorLine) {
  std::ostringstream out, err;
  EXPECT_EQ(InspectCommand({Path("missing.h5")}, out, err), kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(err.str(), "missing.h5"));
  std::ostringstream out2, err2;
  EXPECT_EQ(InspectCommand({Write("text.h5", "not hdf5\n")}, out2, err2), kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(err2.str(), "text.h5"));
}

TEST_F(CliTest, SigintStopsTheRunAndKeepsTheRowsWritten) {
  RunArgs args = PendulumArgs();
  struct sigaction before {};
  sigaction(SIGINT, nullptr, &before);
  // The signal arrives after the row at t = 0.1 s (rows 0 .. 10)
  args.observer = [](const SimulationProgress& p) {
    if (p.t > 0.1 - 1e-9 && p.t < 0.1 + 1e-9) std::raise(SIGINT);
  };
  EXPECT_EQ(Run(args), kExitSignalBase + SIGINT);
  // Honoured at the next integrator step, before the row at 0.11 s
  EXPECT_TRUE(IsOneErrorLine(err_.str(), "interrupted at t = 0.1"));
  EXPECT_TRUE(IsOneErrorLine(err_.str(), args.output_path + " holds 11 rows (t = 0 to 0.1 s)"));
  EXPECT_EQ(out_.str(), "");
  // The file was flushed and closed: every row up to the interruption is readable
  const Hdf5Reader reader(args.output_path);
  EXPECT_EQ(reader.ReadMatrix("/time").rows(), 11);
  EXPECT_EQ(reader.ReadMatrix("/joints/hinge/q").rows(), 11);
  EXPECT_EQ(reader.ReadAttributeText("/solver", "completed"), "0");
  // The previous handler is back
  struct sigaction after {};
  sigaction(SIGINT, nullptr, &after);
  EXPECT_EQ(after.sa_handler, before.sa_handler);
}

TEST(ProgressBarTest, BarIsRedrawnInPlaceAtMostTenTimesASecond) {
  std::ostringstream err;
  ProgressBar bar(err, ProgressBar::Style::kBar);
  // 100 updates within 0.5 s of wall time: 5 or 6 redraws
  for (int k = 1; k <= 100; ++k) bar.Update({0.01 * k, 1.0, 10L * k, 0.005 * k});
  const std::string drawn = err.str();
  const auto redraws = std::count(drawn.begin(), drawn.end(), '\r');
  EXPECT_GE(redraws, 5);
  EXPECT_LE(redraws, 6);
  EXPECT_EQ(CountLines(drawn), 0u);
  // Finish draws 100 % and ends the line
  bar.Finish();
  EXPECT_EQ(CountLines(err.str()), 1u);
  EXPECT_NE(err.str().find("100%"), std::string::npos);
}

TEST(ProgressBarTest, AbandonErasesTheBar) {
  std::ostringstream err;
  ProgressBar bar(err, ProgressBar::Style::kBar);
  bar.Update({0.5, 1.0, 7, 2.0});
  bar.Abandon();
  const std::string drawn = err.str();
  const std::string line = FormatProgressBar({0.5, 1.0, 7, 2.0});
  EXPECT_EQ(drawn, "\r" + line + "\r" + std::string(line.size(), ' ') + "\r");
}

TEST(ProgressBarTest, FormatShowsTimePercentStepsWallAndTimeLeft) {
  // Half way after 2 s of wall time: 2 s left
  EXPECT_EQ(FormatProgressBar({0.5, 1.0, 42, 2.0}, 10),
            "[#####.....]  50%  t 0.5 / 1 s  42 steps  wall 2.00 s  left 2.00 s");
  EXPECT_EQ(FormatProgressLine({0.25, 1.0, 3, 30.0}),
            "progress  25%  t = 0.25 / 1 s, 3 steps, wall 30.0 s, left 1 min 30 s");
  EXPECT_EQ(FormatDuration(7500), "2 h 05 min");
  // Nothing simulated yet: time left unknown
  EXPECT_NE(FormatProgressLine({0, 1.0, 0, 0.1}).find("left ?"), std::string::npos);
}

TEST(ProgressBarTest, QuietPrintsNothing) {
  std::ostringstream err;
  ProgressBar bar(err, ProgressBar::Style::kNone);
  for (int k = 1; k <= 10; ++k) bar.Update({0.1 * k, 1.0, k, 0.5 * k});
  bar.Finish();
  EXPECT_EQ(err.str(), "");
}

TEST(ErrorMessageTest, ReasonIsFoldedOntoOneLine) {
  std::ostringstream err;
  ReportError(err, "  IDA failed\n  at t = 0.3:\tcorrector\r\n did not converge\n");
  EXPECT_EQ(err.str(), "orrery: error: IDA failed at t = 0.3: corrector did not converge\n");
  EXPECT_EQ(OneLine(" \n "), "unknown error");
}

// The built program, through the shell: exit code and the lines it printed
struct Process {
  int code = -1;
  std::string out, err;
};

Process RunBinary(const std::string& arguments) {
  const fs::path dir = fs::temp_directory_path() / ("orrery_cli_test_bin_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string out = (dir / "out.txt").string(), err = (dir / "err.txt").string();
  const std::string command = std::string("\"") + ORRERY_BINARY_DIR + "/bin/orrery\" " + arguments + " >" + out +
                              " 2>" + err + " </dev/null";
  const int status = std::system(command.c_str());
  Process p;
  p.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::stringstream o, e;
  o << std::ifstream(out).rdbuf();
  e << std::ifstream(err).rdbuf();
  p.out = o.str();
  p.err = e.str();
  fs::remove_all(dir);
  return p;
}

class BinaryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(std::string(ORRERY_BINARY_DIR) + "/bin/orrery"))
        << "build the `orrery` target before running these tests";
  }
};

TEST_F(BinaryTest, BadArgumentsAreOneLineAndExitCode2) {
  // An integrator CLI11 does not accept
  Process p = RunBinary("run --integrator rk4 scene.yaml");
  EXPECT_EQ(p.code, kExitUsage);
  EXPECT_TRUE(IsOneErrorLine(p.err, "rk4"));
  EXPECT_EQ(p.out, "");
  // A misspelt command is named
  p = RunBinary("rnu scene.yaml");
  EXPECT_EQ(p.code, kExitUsage);
  EXPECT_TRUE(IsOneErrorLine(p.err, "unknown command 'rnu'"));
  // An unknown option, a missing positional, no command at all
  for (const char* arguments : {"run scene.yaml --frobnicate", "run", "inspect", ""}) {
    p = RunBinary(arguments);
    EXPECT_EQ(p.code, kExitUsage) << arguments;
    EXPECT_TRUE(IsOneErrorLine(p.err, "")) << arguments;
  }
}

TEST_F(BinaryTest, RuntimeErrorIsOneLineAndExitCode1) {
  const Process p = RunBinary("run /nonexistent/orrery_scene.yaml");
  EXPECT_EQ(p.code, kExitFailure);
  EXPECT_TRUE(IsOneErrorLine(p.err, "/nonexistent/orrery_scene.yaml"));
}

TEST_F(BinaryTest, VersionAndHelpGoToStdout) {
  Process p = RunBinary("--version");
  EXPECT_EQ(p.code, 0);
  EXPECT_EQ(p.out, std::string("orrery ") + ORRERY_VERSION + "\n");
  EXPECT_EQ(p.err, "");
  p = RunBinary("run --help");
  EXPECT_EQ(p.code, 0);
  EXPECT_NE(p.out.find("--end-time"), std::string::npos) << p.out;
}

}  // namespace
}  // namespace orrery::cli

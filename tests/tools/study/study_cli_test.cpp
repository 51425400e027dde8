// `orrery study` end to end through the built program: a study with a failing run completes and
// records the failure, a run over its wall-time limit is stopped, a killed study resumes without
// redoing finished runs (and leaves no run behind), bad study files are one line naming the file
// and key, a folder of another study is refused, and MPI asked for without its plugin is one line.
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <chrono>
#include <map>
#include <thread>

#include "mbd/hdf5_reader.h"
#include "tests/tools/study/study_cli_support.h"

extern char** environ;

namespace orrery::study::test {
namespace {

// Exactly one line "orrery: error: ..." holding every one of `parts`
::testing::AssertionResult IsOneErrorLine(const std::string& err,
                                          const std::vector<std::string>& parts) {
  if (std::count(err.begin(), err.end(), '\n') != 1 || err.back() != '\n')
    return ::testing::AssertionFailure() << "not exactly one line: \"" << err << "\"";
  if (err.rfind("orrery: error: ", 0) != 0)
    return ::testing::AssertionFailure() << "no prefix: " << err;
  for (const std::string& part : parts)
    if (err.find(part) == std::string::npos)
      return ::testing::AssertionFailure() << "\"" << part << "\" not in: " << err;
  return ::testing::AssertionSuccess();
}

TEST_F(StudyCliTest, FailingRunIsRecordedAndTheStudyCompletes) {
  const std::string study =
      Write("s.yaml",
            "scene: pendulum.yaml\n"
            "axes:\n  - {key: bodies.bob.mass, values: [1, -1, 2]}\n"
            "outputs:\n  - {name: angle_peak, type: peak, dataset: /joints/hinge/q}\n");
  const CommandResult r = Study(study + " -o " + Path("out") + " -j 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("3: 2 ok, 1 failed, 0 output_failed, 0 pending"), std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("run 1 failed: "), std::string::npos) << r.err;
  const auto csv = ReadCsv(Path("out/index.csv"));
  ASSERT_EQ(csv.size(), 4u);
  EXPECT_EQ(csv[0][3], "angle_peak");
  EXPECT_EQ(csv[1][1], "ok");
  EXPECT_EQ(csv[2][1], "failed");
  EXPECT_EQ(csv[3][1], "ok");
  EXPECT_EQ(csv[2][3], "nan");
  EXPECT_NEAR(std::stod(csv[1][3]), 1.0, 1e-6);  // released at rest at 1 rad: the peak angle
  EXPECT_EQ(csv[2][7], "1");                     // exit status of the failed run
  EXPECT_EQ(csv[2][8], Path("pendulum.yaml") +
                           ": --set bodies.bob.mass: mass must be positive, got -1.000000");
  // Done is done: nothing runs again, unless the failed runs are asked for
  CommandResult again = Study(study + " -o " + Path("out"));
  EXPECT_NE(again.out.find("(3 done before, 0 now)"), std::string::npos) << again.out;
  again = Study(study + " -o " + Path("out") + " --retry-failed");
  EXPECT_NE(again.out.find("(2 done before, 1 now)"), std::string::npos) << again.out;
}

TEST_F(StudyCliTest, OutputThatCannotBeReadIsRecordedBesideTheOthers) {
  const std::string study = Write("s.yaml",
                                  "scene: pendulum.yaml\nend_time: 0.05\n"
                                  "outputs:\n  - {name: a, type: peak, dataset: /joints/hinge/q}\n"
                                  "  - {name: b, type: peak, dataset: /joints/hinge/qq}\n");
  const CommandResult r = Study(study + " -o " + Path("out"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto csv = ReadCsv(Path("out/index.csv"));
  ASSERT_EQ(csv.size(), 2u);
  EXPECT_EQ(csv[1][1], "output_failed");
  EXPECT_NEAR(std::stod(csv[1][2]), 1.0, 1e-6);  // a: read
  EXPECT_EQ(csv[1][3], "nan");                   // b: not
  EXPECT_EQ(csv[1][7], "0");                     // the run itself went well
  EXPECT_EQ(csv[1][8],
            "output 'b': " + Path("out/runs/run_00000.h5") + ": /joints/hinge/qq: no such dataset");
}

TEST_F(StudyCliTest, RunOverItsWallTimeLimitIsStopped) {
  const std::string study = Write("s.yaml",
                                  "scene: pendulum.yaml\nend_time: 1e6\noutput_interval: 1\n"
                                  "limits: {wall_time_s: 1}\n");
  const auto start = std::chrono::steady_clock::now();
  const CommandResult r = Study(study + " -o " + Path("out"));
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.status, 0) << r.err;
  const auto csv = ReadCsv(Path("out/index.csv"));
  ASSERT_EQ(csv.size(), 2u);
  EXPECT_EQ(csv[1][1], "failed");
  EXPECT_EQ(csv[1][5], "143");  // SIGTERM: the run flushed its file and exited 128 + 15
  EXPECT_EQ(csv[1][6], "stopped after the wall-time limit of 1 s");
  EXPECT_EQ(csv[1][7], "0");  // rank
  EXPECT_LT(took, 30);
  // The stopped run's file holds what it simulated until then
  EXPECT_GT(Hdf5Reader(Path("out/runs/run_00000.h5")).ReadVector("/time").size(), 1u);
}

TEST_F(StudyCliTest, MemoryLimitFailsTheRunNotTheStudy) {
  // 20 MiB of address space: the run cannot get what it needs (its resident set alone is ~25 MiB)
  const std::string study =
      Write("s.yaml", "scene: pendulum.yaml\nend_time: 0.1\nlimits: {memory_mib: 20}\n");
  const CommandResult r = Study(study + " -o " + Path("out"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto csv = ReadCsv(Path("out/index.csv"));
  ASSERT_EQ(csv.size(), 2u);
  EXPECT_EQ(csv[1][1], "failed");
  EXPECT_NE(csv[1][6].find("(memory limit 20 MiB)"), std::string::npos) << csv[1][6];
}

// (inode, modification time) of a file: a file rewritten or replaced differs
std::pair<ino_t, long long> Identity(const std::string& path) {
  struct stat s {};
  if (::stat(path.c_str(), &s) != 0) return {0, 0};
  return {s.st_ino, static_cast<long long>(s.st_mtim.tv_sec) * 1000000000LL + s.st_mtim.tv_nsec};
}

// Processes whose command line mentions `text` (the runs of a study name its folder)
int ProcessesMentioning(const std::string& text) {
  int n = 0;
  for (const fs::directory_entry& e : fs::directory_iterator("/proc")) {
    const std::string cmdline = ReadFile(e.path() / "cmdline");
    if (cmdline.find(text) != std::string::npos) ++n;
  }
  return n;
}

TEST_F(StudyCliTest, KilledStudyResumesWithoutRedoingFinishedRuns) {
  // Six runs of about a quarter of a second each, one at a time
  const std::string study = Write(
      "s.yaml",
      "scene: pendulum.yaml\nend_time: 300\n"
      "axes:\n  - {key: joints.hinge.initial_position, range: {start: 0.1, stop: 0.6, count: 6}}\n"
      "outputs:\n  - {name: peak, type: peak, dataset: /joints/hinge/q}\n");
  const std::string folder = Path("out");
  // Start it, wait for two completion markers, kill it hard
  std::vector<std::string> args{Binary(), "study", study, "-o", folder, "-j", "1", "--quiet"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  ASSERT_EQ(posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ), 0);
  const auto done = [&] {
    int n = 0;
    for (int i = 0; i < 6; ++i)
      n += fs::exists(folder + "/runs/run_0000" + std::to_string(i) + ".done");
    return n;
  };
  for (int waited = 0; done() < 2 && waited < 120000; waited += 10)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const int finished = done();
  ASSERT_GE(finished, 2);
  ASSERT_LT(finished, 6) << "the study ended before it could be killed";
  // Its run died with it (PR_SET_PDEATHSIG): nothing mentions the folder a moment later
  int left = 1;
  for (int waited = 0; (left = ProcessesMentioning(folder)) > 0 && waited < 5000; waited += 10)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(left, 0);
  // Finished runs as they are; unfinished ones get a half-written result file where they have none
  std::map<int, std::pair<ino_t, long long>> markers, results;
  for (int i = 0; i < 6; ++i) {
    const std::string run = folder + "/runs/run_0000" + std::to_string(i);
    if (fs::exists(run + ".done")) {
      markers[i] = Identity(run + ".done");
      results[i] = Identity(run + ".h5");
    } else if (!fs::exists(run + ".h5")) {
      std::ofstream(run + ".h5") << "half a file";
    }
  }
  // Resume: only the unfinished runs run
  const CommandResult r = Study(study + " -o " + folder + " -j 1");
  ASSERT_EQ(r.status, 0) << r.err;
  std::string counts = "(";
  counts += std::to_string(finished) + " done before, " + std::to_string(6 - finished) + " now)";
  EXPECT_NE(r.out.find(counts), std::string::npos) << r.out;
  for (const auto& [i, identity] : markers) {
    const std::string run = folder + "/runs/run_0000" + std::to_string(i);
    EXPECT_EQ(Identity(run + ".done"), identity) << "run " << i << " was redone";
    EXPECT_EQ(Identity(run + ".h5"), results[i]) << "run " << i << " was redone";
  }
  const auto csv = ReadCsv(folder + "/index.csv");
  ASSERT_EQ(csv.size(), 7u);
  for (int i = 1; i <= 6; ++i) {
    EXPECT_EQ(csv[i][1], "ok") << "run " << i - 1;
    // The peak angle of a pendulum released at rest is its release angle
    EXPECT_NEAR(std::stod(csv[i][3]), 0.1 * i, 1e-6) << "run " << i - 1;
  }
  EXPECT_GT(Hdf5Reader(folder + "/runs/run_00005.h5").ReadVector("/time").size(), 100u);
}

TEST_F(StudyCliTest, BadStudyFilesAreOneLineNamingFileAndKey) {
  struct Case {
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases{
      {"scene: pendulum.yaml\naxes:\n  - {key: bodies.bob.mass, valuse: [1]}\n",
       {"s.yaml:3: axes[0].valuse: unknown key 'valuse'; did you mean 'values'?"}},
      {"scene: pendulum.yaml\naxes:\n  - {key: bodies.bob.mas, values: [1, 2]}\n",
       {"s.yaml:3: axes[0].key: ",
        "pendulum.yaml: --set bodies.bob.mas: unknown key 'mas'; did you mean 'mass'?"}},
      {"scene: pendulum.yaml\naxes:\n  - {key: bodies.bob.mass, values: []}\n",
       {"s.yaml:3: axes[0].values: an axis needs at least one value, got an empty list"}},
      {"scene: pendulum.yml\n", {"s.yaml:1: scene: no scene file ", "pendulum.yml"}},
      {"scene: pendulum.yaml\nfolder: x\nfolder: y\n",
       {"s.yaml:3: folder: duplicate key 'folder' (first at line 2)"}},
  };
  for (const Case& c : cases) {
    const std::string study = Write("s.yaml", c.text);
    const CommandResult r = Study(study + " -o " + Path("out"));
    EXPECT_EQ(r.status, 1) << c.text;
    EXPECT_TRUE(IsOneErrorLine(r.err, c.parts)) << c.text;
    EXPECT_FALSE(fs::exists(Path("out"))) << "a folder was made for: " << c.text;
  }
  const CommandResult missing = Study(Path("none.yaml"));
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(IsOneErrorLine(missing.err, {"none.yaml: no such file"}));
}

TEST_F(StudyCliTest, FolderOfAnotherStudyIsRefused) {
  const std::string study = Write("s.yaml", "scene: pendulum.yaml\nend_time: 0.1\n");
  ASSERT_EQ(Study(study + " -o " + Path("out") + " -q").status, 0);
  const std::string before = ReadFile(Path("out/study.yaml"));
  const std::string index = ReadFile(Path("out/index.csv"));
  Write("s.yaml", "scene: pendulum.yaml\nend_time: 0.2\n");
  const CommandResult r = Study(study + " -o " + Path("out"));
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(IsOneErrorLine(
      r.err, {Path("out") + ": holds another study (study file hash ", "choose another folder"}));
  EXPECT_EQ(ReadFile(Path("out/study.yaml")), before);
  EXPECT_EQ(ReadFile(Path("out/index.csv")), index);
  // A folder that is no study's
  fs::create_directories(Path("mine"));
  Write("mine/notes.txt", "keep");
  const CommandResult mine = Study(study + " -o " + Path("mine"));
  EXPECT_EQ(mine.status, 1);
  EXPECT_TRUE(IsOneErrorLine(mine.err, {"not empty and not a study folder"}));
  EXPECT_EQ(ReadFile(Path("mine/notes.txt")), "keep");
}

TEST_F(StudyCliTest, DryRunListsTheRunsAndWritesNothing) {
  const std::string study = Write(
      "s.yaml",
      "scene: pendulum.yaml\nend_time: 0.1\naxes:\n  - {key: bodies.bob.mass, values: [1, 2]}\n"
      "  - random: {samples: 2, seed: 3, keys: [{key: solver.rtol, log_uniform: [1e-9, 1e-6]}]}\n");
  const CommandResult r = Study(study + " -o " + Path("out") + " --dry-run");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("study s: 4 runs of "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("every run: solver.end_time=0.1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("run 3  bodies.bob.mass=2  solver.rtol="), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(Path("out")));
}

TEST_F(StudyCliTest, MpiAskedForWithoutItsPluginIsOneLine) {
  const std::string study = Write("s.yaml", "scene: pendulum.yaml\nend_time: 0.1\n");
  const CommandResult r = Shell("ORRERY_STUDY_MPI_PLUGIN=" + Path("no_plugin.so") + " '" +
                                Binary() + "' study " + study + " -o " + Path("out") + " --mpi");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(
      IsOneErrorLine(r.err, {"MPI asked for, but the MPI plugin", "no_plugin.so", "libopenmpi3"}));
  // srun with several tasks but no MPI: refused rather than run twice
  const CommandResult srun =
      Shell("SLURM_STEP_NUM_TASKS=4 '" + Binary() + "' study " + study + " -o " + Path("out"));
  EXPECT_EQ(srun.status, 1);
  EXPECT_TRUE(IsOneErrorLine(srun.err,
                             {"started by srun as one of 4 tasks without MPI", "srun --mpi=pmix"}));
}

}  // namespace
}  // namespace orrery::study::test

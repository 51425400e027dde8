// `orrery advise` (tools/study/study_advice.h, tools/cli/advise_command.h): on a synthetic index
// whose answers are worked out by hand below, on bad arguments, and on the real quick study
// (models/studies/quick.yaml run here) against a brute-force search of its index.csv.
#include "tools/study/study_advice.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "mbd/result_file.h"
#include "tests/tools/study/study_cli_support.h"

namespace orrery::study::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Six runs: (cpu s, wall s, value) = (1, 9, 110), (2, 8, 101), (3, 7, 104), (4, 6, 100.5),
// (10, 5, 100: the last run, the reference), and run 5 failed. Relative errors against 100:
// 10 %, 1 %, 4 %, 0.5 %, 0. Run 2 (3 s, 4 %) is dominated by run 1 (2 s, 1 %): the front on CPU
// time is runs 0, 1, 3, 4. Run 5 (failed) is listed last, so the reference is named explicitly.
void WriteSyntheticIndex(const std::string& path) {
  ResultFile f = ResultFile::Create(path);
  f.WriteStrings("/runs/status", {"ok", "ok", "ok", "ok", "ok", "failed"});
  f.WriteVector("/runs/cpu_time_s", {1, 2, 3, 4, 10, 0.5}, "s");
  f.WriteVector("/runs/wall_time_s", {9, 8, 7, 6, 5, kNaN}, "s");
  f.WriteVector("/runs/peak_memory_mib", {30, 30, 30, 30, 30, 30}, "MiB");
  f.WriteStrings("/parameters/keys", {"solver.step", "solver.integrator"});
  f.WriteVector("/parameters/solver.step", {1e-3, 5e-4, 2e-4, 1e-4, 1e-5, 1e-6}, "");
  f.WriteStrings("/parameters/solver.integrator", {"a", "b", "c", "d", "e", "f"});
  f.WriteStrings("/outputs/names", {"force", "zero"});
  f.WriteVector("/outputs/force", {110, 101, 104, 100.5, 100, kNaN}, "N");
  f.WriteVector("/outputs/zero", {1, 1, 1, 1, 0, kNaN}, "N");
  f.Close();
}

class StudyAdviceTest : public StudyCliTest {
 protected:
  void SetUp() override {
    StudyCliTest::SetUp();
    fs::create_directories(dir_ / "synthetic");
    WriteSyntheticIndex(Path("synthetic/index.h5"));
  }
  AdviceRequest Request(double bound) const {
    AdviceRequest q;
    q.studies = {Path("synthetic")};
    q.output = "force";
    q.error_bound = bound;
    q.reference = "4";
    return q;
  }
  CommandResult Advise(const std::string& arguments) const {
    return Shell("'" + Binary() + "' advise " + arguments);
  }
};

TEST(ParetoFront, KeepsThePointsNoOtherBeatsInBothCostAndError) {
  // (1, 5) (2, 3) (2, 4) (3, 3) (4, 1) (4, 1): (2, 4) loses to (2, 3), (3, 3) to (2, 3); equal
  // points do not dominate each other
  const std::vector<bool> front = ParetoFront({1, 2, 2, 3, 4, 4}, {5, 3, 4, 3, 1, 1});
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, false, true, true}));
  EXPECT_THROW(ParetoFront({1, 2}, {1}), std::invalid_argument);
}

TEST_F(StudyAdviceTest, NamesTheCheapestRunWithinTheBoundOnTheSyntheticIndex) {
  // 2 %: runs 1 (1 %), 3, 4 qualify; run 1 costs least
  Advice a = AdviseSetting(Request(0.02));
  ASSERT_EQ(a.settings.size(), 5u);
  EXPECT_EQ(a.skipped, 1);
  EXPECT_EQ(a.unit, "N");
  EXPECT_EQ(a.settings[a.chosen].run, 1);
  EXPECT_DOUBLE_EQ(a.settings[a.chosen].error, 0.01);
  EXPECT_EQ(a.settings[a.chosen].parameters, "solver.step=5e-04 solver.integrator=b");
  EXPECT_EQ(a.settings[a.reference].run, 4);
  std::vector<int> front;
  for (const MeasuredSetting& m : a.settings)
    if (m.on_front) front.push_back(m.run);
  EXPECT_EQ(front, (std::vector<int>{0, 1, 3, 4}));
  // 0.6 %: run 3 (0.5 %); 0.1 %: only the reference
  EXPECT_EQ(AdviseSetting(Request(0.006)).settings[AdviseSetting(Request(0.006)).chosen].run, 3);
  a = AdviseSetting(Request(0.001));
  EXPECT_EQ(a.chosen, a.reference);
  // Absolute 1.5 N: run 1 (1 N off)
  AdviceRequest q = Request(1.5);
  q.relative = false;
  a = AdviseSetting(q);
  EXPECT_EQ(a.settings[a.chosen].run, 1);
  // On wall time the order reverses: run 4 (5 s) is the cheapest and the reference
  q = Request(0.02);
  q.cost = "wall_time_s";
  a = AdviseSetting(q);
  EXPECT_EQ(a.settings[a.chosen].run, 4);
  EXPECT_EQ(a.chosen, a.reference);
  // The same study given twice: the reference as STUDY:RUN
  q = Request(0.02);
  q.studies = {Path("synthetic"), Path("synthetic/index.h5")};
  q.reference = "synthetic:4";
  a = AdviseSetting(q);
  EXPECT_EQ(a.settings.size(), 10u);
  EXPECT_EQ(a.settings[a.chosen].run, 1);
}

TEST_F(StudyAdviceTest, RefusesBadArgumentsInOneLine) {
  auto message = [](const AdviceRequest& q) {
    try {
      AdviseSetting(q);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  AdviceRequest q = Request(0.01);
  q.reference = "5";
  EXPECT_NE(message(q).find("--reference: synthetic run 5 is not usable (status failed"),
            std::string::npos)
      << message(q);
  q.reference = "";  // the last run (5), failed
  EXPECT_NE(message(q).find("run 5 is not usable"), std::string::npos);
  q.reference = "7";
  EXPECT_EQ(message(q), "--reference 7: not a run of study synthetic (0 to 5)");
  q.reference = "other:1";
  EXPECT_NE(message(q).find("--reference other:1: no study 'other'"), std::string::npos);
  q = Request(0.01);
  q.output = "zero";
  EXPECT_NE(message(q).find("is 0, so a relative error has no meaning; use --absolute"),
            std::string::npos)
      << message(q);
  q = Request(0.01);
  q.output = "torque";
  EXPECT_NE(message(q).find("--output torque: not an output of"), std::string::npos);
  EXPECT_NE(message(q).find("(outputs: force, zero)"), std::string::npos);
  q = Request(0);
  EXPECT_EQ(message(q), "--error 0: the bound must be a positive number");
  q = Request(0.01);
  q.cost = "energy";
  EXPECT_NE(message(q).find("--cost energy: one of"), std::string::npos);
  q = Request(0.01);
  q.studies = {Path("nothing")};
  EXPECT_NE(message(q).find("no study index"), std::string::npos);

  // Through the program: exit 2, one line
  for (const std::string& args :
       {std::string("--error 1 --output force"),  // no --study
        "--study " + Path("synthetic") + " --output force --error 1x",
        "--study " + Path("synthetic") + " --output force --error 1% --absolute",
        "--study " + Path("synthetic") + " --output force --error 1% --cost joules"}) {
    const CommandResult r = Advise(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("orrery: error: ", 0), 0u) << r.err;
  }
  const CommandResult r =
      Advise("--study " + Path("synthetic") + " --output force --error 2% --reference 4");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("advice     synthetic run 1 (solver.step=5e-04 solver.integrator=b): force "
                       "= 101 N, error 1 %, cpu 2 s (bound 2 %)"),
            std::string::npos)
      << r.out;
}

// The quick study (six runs of seed 002's ramp, about 3 s of CPU), advised on the peak mesh force
// against run 5; the oracle: the cheapest row of index.csv within the bound, searched here
TEST_F(StudyAdviceTest, AdviceOnTheQuickStudyIsTheCheapestRowWithinTheBound) {
  const std::string study = std::string(ORRERY_SOURCE_DIR) + "/models/studies/quick.yaml";
  const CommandResult run = Study(study + " -o " + Path("quick") + " -j 2 --quiet");
  ASSERT_EQ(run.status, 0) << run.err;
  const auto rows = ReadCsv(Path("quick/index.csv"));
  ASSERT_EQ(rows.size(), 7u);
  auto column = [&](const std::string& name) {
    const auto it = std::find(rows[0].begin(), rows[0].end(), name);
    EXPECT_NE(it, rows[0].end()) << name;
    return static_cast<std::size_t>(it - rows[0].begin());
  };
  const std::size_t value = column("sun_mesh_force_peak"), cost = column("cpu_time_s");
  const double reference = std::stod(rows[6][value]);
  for (double bound : {0.5, 0.1, 0.03, 0.01, 1e-9}) {
    int best = -1;
    for (int r = 1; r <= 6; ++r) {
      const bool within =
          std::abs(std::stod(rows[r][value]) - reference) <= bound * std::abs(reference);
      const double c = std::stod(rows[r][cost]);
      if (within && (best < 0 || c < std::stod(rows[best][cost]))) best = r;
    }
    AdviceRequest q;
    q.studies = {Path("quick")};
    q.output = "sun_mesh_force_peak";
    q.error_bound = bound;
    const Advice a = AdviseSetting(q);
    EXPECT_EQ(a.settings[a.chosen].run, best - 1) << "bound " << bound;
    EXPECT_EQ(a.settings[a.reference].run, 5);
    EXPECT_TRUE(a.settings[a.chosen].on_front);
  }
  const CommandResult json = Shell("'" + Binary() + "' advise --study " + Path("quick") +
                                   " --output sun_mesh_force_peak --error 1% --json");
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_NE(json.out.find("\"unit\": \"N\""), std::string::npos) << json.out;
  EXPECT_NE(json.out.find("\"front\": ["), std::string::npos);
}

}  // namespace
}  // namespace orrery::study::test

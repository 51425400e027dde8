// Runs of a study: the cartesian product in its order, zipped axes, random samples from the
// standard's Mersenne Twister, overrides, and the base-scene check naming the study's key.
#include "tools/study/study_plan.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace orrery::study {
namespace {

namespace fs = std::filesystem;

StudyPlan Plan(const std::string& text) { return MakeStudyPlan(ParseStudyFile(text, "s.yaml")); }

TEST(StudyPlanTest, GridRunsWithTheLastAxisFastest) {
  const StudyPlan p =
      Plan("scene: a.yaml\naxes:\n  - {key: a, values: [1, 2]}\n  - {key: b, values: [x, y, z]}\n");
  ASSERT_EQ(p.runs.size(), 6u);
  EXPECT_EQ(p.parameters, (std::vector<std::string>{"a", "b"}));
  const std::vector<std::vector<std::string>> expected{{"1", "x"}, {"1", "y"}, {"1", "z"},
                                                       {"2", "x"}, {"2", "y"}, {"2", "z"}};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(p.runs[i].index, static_cast<int>(i));
    EXPECT_EQ(p.runs[i].values, expected[i]) << "run " << i;
  }
}

TEST(StudyPlanTest, ZippedAxesMoveTogether) {
  const StudyPlan p = Plan(
      "scene: a.yaml\naxes:\n  - {key: c, values: [0, 1]}\n"
      "  - zip: [{key: a, values: [1, 2, 3]}, {key: b, range: {start: 10, stop: 30, step: 10}}]\n");
  ASSERT_EQ(p.runs.size(), 6u);
  EXPECT_EQ(p.runs[4].values, (std::vector<std::string>{"1", "2", "20"}));
  EXPECT_EQ(p.runs[2].values, (std::vector<std::string>{"0", "3", "30"}));
}

TEST(StudyPlanTest, NoAxesIsOneRun) {
  const StudyPlan p = Plan("scene: a.yaml\nend_time: 2\n");
  ASSERT_EQ(p.runs.size(), 1u);
  EXPECT_EQ(p.Overrides(p.runs[0]), (std::vector<std::string>{"solver.end_time=2"}));
}

TEST(StudyPlanTest, OverridesAreTheSettingsThenTheParameters) {
  const StudyPlan p = Plan(
      "scene: a.yaml\nend_time: 2\nsettings: {x.y: [1, 2]}\naxes:\n  - {key: a, values: [{type: "
      "constant, value: 3}]}\n");
  EXPECT_EQ(p.Overrides(p.runs[0]), (std::vector<std::string>{"solver.end_time=2", "x.y=[1, 2]",
                                                              "a={type: constant, value: 3}"}));
}

TEST(StudyPlanTest, RandomSamplesFollowTheStandardMersenneTwister) {
  // The first output of std::mt19937_64 with the default seed 5489 is 14514284786278117030
  // (the C++ standard fixes the engine; [rand.predef] gives its 10000th output 9981545732273789042)
  std::mt19937_64 reference;
  reference.discard(9999);
  ASSERT_EQ(reference(), 9981545732273789042ULL);
  const std::uint64_t first = 14514284786278117030ULL;
  const double u = static_cast<double>(first >> 11) * 0x1.0p-53;
  const StudyPlan p = Plan(
      "scene: a.yaml\naxes:\n  - random: {samples: 200, seed: 5489, keys: [{key: a, uniform: [2, "
      "4]}, "
      "{key: b, log_uniform: [1e-6, 1e-2]}, {key: c, choice: [p, q, r]}]}\n");
  ASSERT_EQ(p.runs.size(), 200u);
  // The first draw, exactly as the header states it
  EXPECT_EQ(std::stod(p.runs[0].values[0]), 2 + 2 * u);
  // Bounds, spread over decades, every choice taken
  std::set<std::string> choices;
  int low_decade = 0;
  for (const RunSpec& r : p.runs) {
    const double a = std::stod(r.values[0]), b = std::stod(r.values[1]);
    EXPECT_GE(a, 2);
    EXPECT_LT(a, 4);
    EXPECT_GE(b, 1e-6);
    EXPECT_LT(b, 1e-2);
    low_decade += b < 1e-5;
    choices.insert(r.values[2]);
  }
  EXPECT_EQ(choices, (std::set<std::string>{"p", "q", "r"}));
  EXPECT_GT(low_decade,
            25);  // a quarter of log-uniform samples lie in the lowest of 4 decades (50 expected)
  // The same seed gives the same runs; another seed others
  EXPECT_EQ(Plan("scene: a.yaml\naxes:\n  - random: {samples: 3, seed: 7, keys: [{key: a, uniform: "
                 "[0, 1]}]}\n")
                .runs[2]
                .values,
            Plan("scene: a.yaml\naxes:\n  - random: {samples: 3, seed: 7, keys: [{key: a, uniform: "
                 "[0, 1]}]}\n")
                .runs[2]
                .values);
  EXPECT_NE(Plan("scene: a.yaml\naxes:\n  - random: {samples: 3, seed: 8, keys: [{key: a, uniform: "
                 "[0, 1]}]}\n")
                .runs[2]
                .values,
            Plan("scene: a.yaml\naxes:\n  - random: {samples: 3, seed: 7, keys: [{key: a, uniform: "
                 "[0, 1]}]}\n")
                .runs[2]
                .values);
}

TEST(StudyPlanTest, TooManyRunsIsAnError) {
  try {
    Plan(
        "scene: a.yaml\naxes:\n  - {key: a, range: {start: 0, stop: 1, count: 100000}}\n"
        "  - {key: b, range: {start: 0, stop: 1, count: 1000}}\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "s.yaml: axes: the study has more than 10000000 runs");
  }
}

class StudySceneCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("orrery_study_plan_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "p.yaml")
        << "name: p\ngravity: [0,-9.81,0]\n"
           "bodies:\n  - {name: bob, mass: 1, inertia: [0.01,0.01,0.01]}\n"
           "joints:\n  - {name: hinge, type: revolute, parent: world, child: bob, "
           "axis: [0,0,1], initial_position: 1.0}\n"
           "solver: {end_time: 0.2}\noutput: {interval: 0.01}\n";
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string CheckError(const std::string& text) {
    const fs::path study = dir_ / "s.yaml";
    std::ofstream(study) << text;
    try {
      CheckStudyScene(MakeStudyPlan(LoadStudyFile(study.string())));
    } catch (const std::runtime_error& e) {
      std::string m = e.what();
      const std::string prefix = dir_.string() + "/";
      for (std::size_t at; (at = m.find(prefix)) != std::string::npos;) m.erase(at, prefix.size());
      return m;
    }
    return "no error";
  }
  fs::path dir_;
};

TEST_F(StudySceneCheckTest, UnknownSceneKeysNameTheStudyFileAndKey) {
  EXPECT_EQ(CheckError("scene: p.yaml\naxes:\n  - {key: bodies.bob.mass, values: [1, 2]}\n"),
            "no error");
  EXPECT_EQ(CheckError("scene: p.yaml\naxes:\n  - {key: bodies.bob.mas, values: [1, 2]}\n"),
            "s.yaml:3: axes[0].key: p.yaml: --set bodies.bob.mas: unknown key 'mas'; did you mean "
            "'mass'?");
  EXPECT_EQ(CheckError("scene: p.yaml\nsettings: {bodies.bobb.mass: 2}\n"),
            "s.yaml:2: settings.bodies.bobb.mass: p.yaml: --set bodies.bobb.mass: no item named "
            "'bobb' in 'bodies' (line 3); did you mean 'bob'?");
  EXPECT_EQ(
      CheckError("scene: p.yaml\nend_time: 1\naxes:\n  - zip: [{key: a, values: [1]}, {key: "
                 "solver.rtol, values: [1e-6]}]\n")
          .rfind("s.yaml:4: axes[0].zip[0].key: p.yaml: --set a: unknown key 'a' (allowed: name, ",
                 0),
      0u);
  // The first run's values are checked too; later runs' values fail their own runs
  EXPECT_EQ(
      CheckError("scene: p.yaml\naxes:\n  - {key: bodies.bob.mass, values: [-1, 2]}\n"),
      "s.yaml:3: axes[0].key: p.yaml: --set bodies.bob.mass: mass must be positive, got -1.000000");
  EXPECT_EQ(CheckError("scene: p.yaml\naxes:\n  - {key: bodies.bob.mass, values: [1, -2]}\n"),
            "no error");
  // A missing scene
  EXPECT_EQ(CheckError("scene: q.yaml\n"), "s.yaml:1: scene: no scene file q.yaml");
}

}  // namespace
}  // namespace orrery::study

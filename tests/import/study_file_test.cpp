// Study files: every entry kind read into the description, ranges expanded, and one test per class
// of error (file, line and key path in every message).
#include "import/study_file.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "import/scene.h"

namespace orrery {
namespace {

constexpr const char* kEverything = R"(name: sweep
scene: ../scenes/pendulum.yaml
folder: out/sweep
end_time: 0.5
output_interval: 1e-3
settings:
  solver.rtol: 1e-9
  joints.hinge.initial_velocity: 0
axes:
  - {key: bodies.rod.mass, values: [1, 2.5, "3"]}
  - {key: solver.atol, range: {start: 1e-9, stop: 1e-6, count: 4, spacing: log}}
  - zip:
      - {key: joints.hinge.initial_position, range: {start: 0.1, stop: 0.3, step: 0.1}}
      - {key: gravity, values: [[0, -9.81, 0], [0, -1.62, 0], [0, -3.71, 0]]}
  - random:
      samples: 5
      seed: 42
      keys:
        - {key: bodies.rod.com.0, uniform: [-0.1, 0.1]}
        - {key: solver.max_step, log_uniform: [1e-4, 1e-2]}
        - {key: solver.integrator, choice: [ida, generalized_alpha]}
outputs:
  - {name: angle_peak, type: peak, dataset: /joints/hinge/q, from: 0.1, to: 0.4}
  - {name: ke_mean, type: mean, dataset: /energy, column: kinetic}
  - {name: line, type: amplitude, dataset: /joints/hinge/q, line: f_m, harmonic: 2, sideband: -1, modulation: f_c, window: flattop}
  - {name: ser, type: sideband_energy_ratio, dataset: /joints/hinge/q, mesh_hz: 220.3, modulation_hz: 15.74, harmonics: 2}
  - {name: fm4, type: indicator, dataset: /joints/hinge/q, indicator: fm4, tsa: hinge, mesh_order: 14}
  - {name: stress, type: max_stress, body: S.planet1}
jobs: 3
limits: {wall_time_s: 60, memory_mib: 2048}
)";

TEST(StudyFileTest, ReadsEveryEntryKind) {
  const StudyDescription s = ParseStudyFile(kEverything, "studies/sweep.yaml");
  EXPECT_EQ(s.name, "sweep");
  EXPECT_EQ(s.scene_path, "scenes/pendulum.yaml");  // relative to the study file's folder
  EXPECT_EQ(s.folder, "out/sweep");
  // end_time and output_interval become scene settings, before settings:
  ASSERT_EQ(s.settings.size(), 4u);
  EXPECT_EQ(s.settings[0].key, "solver.end_time");
  EXPECT_EQ(s.settings[0].value, "0.5");
  EXPECT_EQ(s.settings[1].key, "output.interval");
  EXPECT_EQ(s.settings[2].key, "solver.rtol");
  EXPECT_EQ(s.settings[2].value, "1e-9");
  EXPECT_EQ(s.settings[3].at, "studies/sweep.yaml:8: settings.joints.hinge.initial_velocity");
  ASSERT_EQ(s.blocks.size(), 4u);
  // Values as written, quoted strings kept quoted, ranges expanded
  EXPECT_EQ(s.blocks[0].axes[0].values, (std::vector<std::string>{"1", "2.5", "\"3\""}));
  EXPECT_EQ(s.blocks[0].axes[0].at, "studies/sweep.yaml:10: axes[0].key");
  EXPECT_EQ(s.blocks[1].axes[0].values,
            (std::vector<std::string>{"1e-09", "1e-08", "1e-07", "1e-06"}));
  EXPECT_EQ(s.blocks[2].kind, StudyBlock::Kind::kZip);
  EXPECT_EQ(s.blocks[2].axes[0].values, (std::vector<std::string>{"0.1", "0.2", "0.3"}));
  EXPECT_EQ(s.blocks[2].axes[1].values[1], "[0, -1.62, 0]");
  EXPECT_EQ(s.blocks[3].kind, StudyBlock::Kind::kRandom);
  EXPECT_EQ(s.blocks[3].samples, 5);
  EXPECT_EQ(s.blocks[3].seed, 42u);
  ASSERT_EQ(s.blocks[3].keys.size(), 3u);
  EXPECT_EQ(s.blocks[3].keys[1].distribution, StudyDistribution::kLogUniform);
  EXPECT_EQ(s.blocks[3].keys[2].choices, (std::vector<std::string>{"ida", "generalized_alpha"}));
  // Outputs
  ASSERT_EQ(s.outputs.size(), 6u);
  EXPECT_EQ(s.outputs[0].kind, StudyOutputKind::kPeak);
  EXPECT_DOUBLE_EQ(s.outputs[0].from_s, 0.1);
  EXPECT_DOUBLE_EQ(s.outputs[0].to_s, 0.4);
  EXPECT_EQ(s.outputs[1].column, "kinetic");
  EXPECT_EQ(s.outputs[2].line, "f_m");
  EXPECT_EQ(s.outputs[2].harmonic, 2);
  EXPECT_EQ(s.outputs[2].sideband, -1);
  EXPECT_EQ(s.outputs[2].modulation, "f_c");
  EXPECT_EQ(s.outputs[2].window, "flattop");
  EXPECT_DOUBLE_EQ(s.outputs[3].mesh_hz, 220.3);
  EXPECT_EQ(s.outputs[3].harmonics, 2);
  EXPECT_EQ(s.outputs[3].sidebands, 6);
  EXPECT_EQ(s.outputs[4].tsa, "hinge");
  EXPECT_EQ(s.outputs[4].mesh_order, 14);
  EXPECT_EQ(s.outputs[5].dataset, "/flexible_bodies/S.planet1/von_mises_max");
  EXPECT_EQ(s.jobs, 3);
  EXPECT_DOUBLE_EQ(s.limits.wall_time_s, 60);
  EXPECT_DOUBLE_EQ(s.limits.memory_mib, 2048);
}

TEST(StudyFileTest, NameDefaultsToTheFileStem) {
  const StudyDescription s = ParseStudyFile("scene: a.yaml\n", "dir/my_study.yaml");
  EXPECT_EQ(s.name, "my_study");
  EXPECT_TRUE(s.blocks.empty());
  EXPECT_TRUE(s.outputs.empty());
}

TEST(StudyFileTest, RangesWithStepIncludeTheStopAndRoundTo15Digits) {
  // 0.1 + 2 * 0.1 = 0.30000000000000004 in doubles; the text is "0.3"
  EXPECT_EQ(RangeValueText(0.1 + 2 * 0.1), "0.3");
  const std::vector<double> v = ExpandStudyRange({.start = 0.1, .stop = 0.7, .step = 0.2});
  ASSERT_EQ(v.size(), 4u);  // (0.7 - 0.1) / 0.2 = 2.9999999999999996: the stop still counts
  EXPECT_EQ(RangeValueText(v.back()), "0.7");
  EXPECT_EQ(ExpandStudyRange({.start = 5, .stop = 1, .step = -2}), (std::vector<double>{5, 3, 1}));
  EXPECT_EQ(ExpandStudyRange({.start = 0, .stop = 1, .step = 0.4}).size(), 3u);  // 0, 0.4, 0.8
  // Counts: both ends exact, geometric when log
  const std::vector<double> lin = ExpandStudyRange({.start = 1, .stop = 2, .count = 5});
  EXPECT_EQ(lin, (std::vector<double>{1, 1.25, 1.5, 1.75, 2}));
  const std::vector<double> log =
      ExpandStudyRange({.start = 1e-3, .stop = 1e3, .count = 7, .log = true});
  ASSERT_EQ(log.size(), 7u);
  for (int i = 0; i < 7; ++i)
    EXPECT_NEAR(log[i], std::pow(10.0, i - 3), 1e-12 * std::pow(10.0, i - 3));
  EXPECT_EQ(ExpandStudyRange({.start = 4, .stop = 9, .count = 1}), (std::vector<double>{4}));
}

// The SceneError of `text` (read as "s.yaml")
std::string ErrorOf(const std::string& text) {
  try {
    ParseStudyFile(text, "s.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(StudyFileTest, ErrorsNameFileLineAndKey) {
  const std::string head = "scene: a.yaml\n";
  // Unknown keys, with a suggestion
  EXPECT_EQ(ErrorOf(head + "axis: []\n"),
            "s.yaml:2: axis: unknown key 'axis'; did you mean 'axes'?");
  EXPECT_EQ(ErrorOf(head + "axes:\n  - {key: a.b, vales: [1]}\n"),
            "s.yaml:3: axes[0].vales: unknown key 'vales'; did you mean 'values'?");
  EXPECT_EQ(
      ErrorOf(head + "axes:\n  - {key: a.b, uniform: [0, 1]}\n"),
      "s.yaml:3: axes[0].uniform: key not allowed here: random values belong in a 'random:' entry");
  // A window from a fraction of the run: in [0, 1), not with from
  const std::string out = "outputs:\n  - {name: m, type: mean, dataset: /x, ";
  EXPECT_EQ(ParseStudyFile(head + out + "from_fraction: 0.5}\n", "s.yaml").outputs[0].from_fraction, 0.5);
  EXPECT_EQ(ErrorOf(head + out + "from_fraction: 1}\n"),
            "s.yaml:3: outputs[m].from_fraction: from_fraction must be in [0, 1), got 1");
  EXPECT_EQ(ErrorOf(head + out + "from: 0.1, from_fraction: 0.5}\n"),
            "s.yaml:3: outputs[m].from_fraction: give either from or from_fraction, not both");
  // Empty axes
  EXPECT_EQ(ErrorOf(head + "axes:\n  - {key: a.b, values: []}\n"),
            "s.yaml:3: axes[0].values: an axis needs at least one value, got an empty list");
  EXPECT_EQ(ErrorOf(head + "axes:\n  - {key: a.b, range: {start: 0, stop: 1, count: 0}}\n"),
            "s.yaml:3: axes[0].range.count: an axis needs at least one value, got count 0");
  EXPECT_EQ(ErrorOf(head + "axes:\n  - {key: a.b, range: {start: 0, stop: 1, step: -0.1}}\n"),
            "s.yaml:3: axes[0].range.step: the step must be non-zero and point from start toward "
            "stop, got -0.1");
  EXPECT_EQ(ErrorOf(head + "axes:\n  - {key: a.b}\n"),
            "s.yaml:3: axes[0]: give either 'values' or 'range'");
  EXPECT_EQ(
      ErrorOf(head +
              "axes:\n  - random: {samples: 0, seed: 1, keys: [{key: a, uniform: [0, 1]}]}\n"),
      "s.yaml:3: axes[0].random.samples: needs at least one sample, got 0");
  // Keys
  EXPECT_EQ(ErrorOf(head + "axes:\n  - {key: \"a b\", values: [1]}\n"),
            "s.yaml:3: axes[0].key: 'a b' is not a scene key path (a.b.c or a[name].c, no blanks "
            "or '=')");
  EXPECT_EQ(
      ErrorOf(head + "end_time: 1\naxes:\n  - {key: solver.end_time, values: [1]}\n"),
      "s.yaml:4: axes[0].key: scene key 'solver.end_time' is already set at s.yaml:2: end_time");
  // Zip lengths, random bounds
  EXPECT_EQ(
      ErrorOf(head +
              "axes:\n  - zip:\n    - {key: a, values: [1, 2]}\n    - {key: b, values: [1]}\n"),
      "s.yaml:5: axes[0].zip[1]: zipped axes need equal lengths: 1 values here, 2 in the first");
  EXPECT_EQ(
      ErrorOf(head +
              "axes:\n  - random: {samples: 2, seed: 1, keys: [{key: a, log_uniform: [0, 1]}]}\n"),
      "s.yaml:3: axes[0].random.keys[0].log_uniform: log_uniform needs low > 0");
  // Outputs
  EXPECT_EQ(ErrorOf(head + "outputs:\n  - {name: x, type: pek, dataset: /a}\n"),
            "s.yaml:3: outputs[x].type: unknown type 'pek'; did you mean 'peak'?");
  EXPECT_EQ(ErrorOf(head + "outputs:\n  - {name: x, type: peak}\n"),
            "s.yaml:3: outputs[x].dataset: missing required key 'dataset'");
  EXPECT_EQ(ErrorOf(head + "outputs:\n  - {name: 2x, type: peak, dataset: /a}\n"),
            "s.yaml:3: outputs[2x].name: '2x' is not an output name (a letter, then letters, "
            "digits, '_', '.', '-')");
  EXPECT_EQ(ErrorOf(head + "outputs:\n  - {name: x, type: peak, dataset: /a}\n  - {name: x, type: "
                           "rms, dataset: /b}\n"),
            "s.yaml:4: outputs[x]: duplicate output name 'x'");
  EXPECT_EQ(
      ErrorOf(head + "outputs:\n  - {name: wall_time_s, type: peak, dataset: /a}\n"),
      "s.yaml:3: outputs[wall_time_s]: output name 'wall_time_s' is a column of the index already");
  EXPECT_EQ(
      ErrorOf(head + "outputs:\n  - {name: x, type: indicator, dataset: /a, indicator: fm4}\n"),
      "s.yaml:3: outputs[x].tsa: fm4 is an indicator of a time-synchronous average: name the "
      "member in 'tsa'");
  EXPECT_EQ(ErrorOf(head + "outputs:\n  - {name: x, type: amplitude, dataset: /a}\n"),
            "s.yaml:3: outputs[x].line: missing required key 'line' (a kinematic line of the "
            "result file) or 'frequency_hz'");
  EXPECT_EQ(ErrorOf(head + "outputs:\n  - {name: x, type: peak, dataset: /a, from: 2, to: 1}\n"),
            "s.yaml:3: outputs[x].to: the window needs from < to, got from 2 s, to 1 s");
  // Missing scene, empty file
  EXPECT_EQ(ErrorOf("name: x\n"), "s.yaml:1: scene: missing required key 'scene'");
  EXPECT_EQ(ErrorOf(""), "s.yaml: the study file is empty");
  EXPECT_EQ(ErrorOf("scene: [a\n").rfind("s.yaml:2: YAML syntax error: ", 0), 0u);
}

}  // namespace
}  // namespace orrery

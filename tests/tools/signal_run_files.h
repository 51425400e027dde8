#pragma once
// Result files of a synthetic planet vibration for the tests of `orrery spectrum | compare |
// octave | plot`, written with mbd's ResultFile in the recorder's layout (mbd/result_recorder.h)
// plus the kinematic lines (tools/signal/kinematic_lines.h), as a gear scene's run would hold them.
//
// The planet turns at f_p^H = 16 Hz relative to the carrier (its joint angle /joints/S.planet1/q),
// Z = 14 teeth, so f_m = 224 Hz; its angular acceleration (column z) is the mesh and its second
// harmonic, amplitude-modulated once per planet revolution with index m:
//   x(t) = (1 + m cos θ) (cos 14θ + 0.3 cos 28θ),   θ = 2π 16 t
// Sampled at 51.2 kHz for 2 s (102401 rows: 3200 samples per planet revolution, the FFT length
// 102400 makes every line a bin of 0.5 Hz).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mbd/result_file.h"

namespace orrery::test_support {

struct GearRun {
  double modulation = 0.05;  // m
  bool lines = true;         // write /kinematics/lines
  bool fault_line = true;    // include f_fault S.planet among them
  double unit_scale = 1.0;   // multiplies x (levels)
};

inline constexpr double kPlanetHz = 16.0, kMeshHz = 224.0, kSampleRateHz = 51200.0;

inline double GearRunValue(double theta, double m) {
  return (1 + m * std::cos(theta)) * (std::cos(14 * theta) + 0.3 * std::cos(28 * theta));
}

inline void WriteGearRun(const std::string& path, const GearRun& run = {}) {
  ResultFile out = ResultFile::Create(path);
  const auto t = out.AddSeries("/time", 1, "s");
  const auto a = out.AddSeries("/bodies/S.planet1/angular_acceleration", 3, "rad/s^2", {"x", "y", "z"});
  const auto q = out.AddSeries("/joints/S.planet1/q", 1, "rad");
  for (int i = 0; i <= 102400; ++i) {
    const double time = i / kSampleRateHz;
    const double theta = 2 * std::numbers::pi * kPlanetHz * time;
    const double z = run.unit_scale * GearRunValue(theta, run.modulation);
    const double row[3] = {0.0, 0.0, z};
    out.Append(t, &time);
    out.Append(a, row);
    out.Append(q, &theta);
  }
  if (run.lines) {
    std::vector<std::string> names = {"f_m", "f_c", "f_p^H"}, kinds = {"mesh", "shaft", "shaft"};
    std::vector<double> hz = {kMeshHz, 8.42, kPlanetHz};
    if (run.fault_line) {
      names.push_back("f_fault S.planet");
      kinds.push_back("fault");
      hz.push_back(kPlanetHz);
    }
    out.WriteStrings("/kinematics/lines/name", names);
    out.WriteVector("/kinematics/lines/frequency_hz", hz, "Hz");
    out.WriteStrings("/kinematics/lines/kind", kinds);
  }
  out.Close();
}

}  // namespace orrery::test_support

namespace orrery::test_support {

// Exactly one line "orrery: error: ..." containing every one of `parts`
inline ::testing::AssertionResult IsOneErrorLine(const std::string& err, const std::vector<std::string>& parts) {
  if (std::count(err.begin(), err.end(), '\n') != 1 || err.back() != '\n')
    return ::testing::AssertionFailure() << "not exactly one line: \"" << err << "\"";
  if (err.rfind("orrery: error: ", 0) != 0) return ::testing::AssertionFailure() << "no prefix: " << err;
  for (const std::string& part : parts)
    if (err.find(part) == std::string::npos) return ::testing::AssertionFailure() << "\"" << part << "\" not in: " << err;
  return ::testing::AssertionSuccess();
}

// Whether `path` is a PNG file (its 8-byte signature) of some size
inline bool IsPng(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  in.read(head, 8);
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return in.gcount() == 8 && std::equal(head, head + 8, reinterpret_cast<const char*>(signature)) &&
         std::filesystem::file_size(path) > 10000;
}

// A fresh directory per test, removed afterwards
class SignalCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("orrery_signal_cli_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  std::string Run(const GearRun& run, const std::string& name) {
    WriteGearRun(Path(name), run);
    return Path(name);
  }
  // The built binary with `arguments`, output and status (tests/common/cli_support.h)
  static std::string Binary() { return std::string("\"") + ORRERY_BINARY_DIR + "/bin/orrery\" "; }

  std::filesystem::path dir_;
};

}  // namespace orrery::test_support

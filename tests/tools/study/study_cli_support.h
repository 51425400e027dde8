#pragma once
// Helpers of the tests that run `orrery study` through the built program: a fresh folder per
// test, a pendulum base scene, commands with their stdout, stderr and exit status, and the
// CSV index read back.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace orrery::study::test {

namespace fs = std::filesystem;

struct CommandResult {
  int status = -1;  // exit code, -1 when it did not exit normally
  std::string out, err;
};

// A pendulum released at 1 rad (a few milliseconds per simulated second of run time)
inline constexpr const char* kPendulumScene =
    "name: p\n"
    "gravity: [0, -9.81, 0]\n"
    "bodies:\n"
    "  - {name: bob, mass: 1, inertia: [0.01, 0.01, 0.01]}\n"
    "joints:\n"
    "  - {name: hinge, type: revolute, parent: world, child: bob, child_frame: {position: [0, 1, "
    "0]}, "
    "axis: [0, 0, 1], initial_position: 1.0}\n"
    "solver: {end_time: 0.2, rtol: 1e-10, atol: 1e-12}\n"
    "output: {interval: 0.01}\n";

inline std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rows of a CSV file (RFC 4180: quoted fields may hold commas and doubled quotes)
inline std::vector<std::vector<std::string>> ReadCsv(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(ReadFile(path));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string>& row = rows.emplace_back(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"')
        row.back() += '"', ++i;
      else if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted)
        row.emplace_back();
      else
        row.back() += c;
    }
  }
  return rows;
}

class StudyCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("orrery_study_cli_" + std::to_string(getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Write("pendulum.yaml", kPendulumScene);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string Binary() { return std::string(ORRERY_BINARY_DIR) + "/bin/orrery"; }

  // `command` through the shell, stdout and stderr kept apart
  CommandResult Shell(const std::string& command) const {
    const std::string out = Path("stdout.txt"), err = Path("stderr.txt");
    const int status = std::system((command + " >'" + out + "' 2>'" + err + "'").c_str());
    CommandResult r;
    r.status = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = ReadFile(out);
    r.err = ReadFile(err);
    return r;
  }
  // orrery study with `arguments`
  CommandResult Study(const std::string& arguments) const {
    std::string command = "'";
    command += Binary();
    command += "' study ";
    command += arguments;
    return Shell(command);
  }

  fs::path dir_;
};

}  // namespace orrery::study::test

// A generated planet reduced, attached and simulated from the command line: `orrery reduce` on
// models/scenes/seed002_planet_reduce.yaml, then `orrery run` on seed002_flexible_planet.yaml
// (shortened), in a scratch directory. Checks: both succeed; the result file holds the planet's
// modal coordinates, its von Mises hot spot and its surface, with an .xdmf beside it; the scene
// refuses a missing body file with the command that makes it, and a stale one (the reduce input
// changed since) with the reason.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include "mbd/hdf5_reader.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

// Runs `orrery ARGS` and returns (exit code, stdout + stderr).
std::pair<int, std::string> Orrery(const std::string& args) {
  const std::string command = std::string("\"") + ORRERY_BINARY_DIR + "/bin/orrery\" " + args + " 2>&1";
  FILE* p = popen(command.c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(FlexiblePlanetCli, ReduceThenRunWritesModesStressAndAnimation) {
  const fs::path dir = fs::path(::testing::TempDir()) / "flexible_planet_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path scenes = fs::path(ORRERY_SOURCE_DIR) / "models" / "scenes";
  fs::copy_file(scenes / "seed002_planet_reduce.yaml", dir / "seed002_planet_reduce.yaml");
  fs::copy_file(scenes / "seed002_flexible_planet.yaml", dir / "seed002_flexible_planet.yaml");
  const std::string scene = (dir / "seed002_flexible_planet.yaml").string();

  // No body file yet: the error names the command that makes it.
  auto [code, text] = Orrery("run " + scene + " --end-time 0.005 -o " + (dir / "run.h5").string());
  EXPECT_EQ(code, 1) << text;
  EXPECT_NE(text.find("orrery reduce"), std::string::npos) << text;
  EXPECT_NE(text.find("reduced_body"), std::string::npos) << text;

  std::tie(code, text) = Orrery("reduce " + (dir / "seed002_planet_reduce.yaml").string() + " -o " +
                                (dir / "seed002_planet.h5").string() + " --json");
  ASSERT_EQ(code, 0) << text;
  EXPECT_NE(text.find("reduced_frequencies_hz"), std::string::npos);

  std::tie(code, text) = Orrery("run " + scene + " --end-time 0.01 -o " + (dir / "run.h5").string());
  ASSERT_EQ(code, 0) << text;
  EXPECT_NE(text.find("max von Mises"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(dir / "run.xdmf"));
  const Hdf5Reader r((dir / "run.h5").string());
  EXPECT_EQ(r.ReadMatrix("/flexible_bodies/S.planet1/modal_q").rows(), 11);
  EXPECT_EQ(r.ReadMatrix("/flexible_bodies/S.planet1/von_mises_max").rows(), 11);
  const auto surface = r.Shape("/flexible_bodies/S.planet1/surface/positions");
  ASSERT_EQ(surface.size(), 2u);
  EXPECT_EQ(surface[0], 11);
  EXPECT_NE(Slurp(dir / "run.xdmf").find("S.planet1"), std::string::npos);

  // The reduce input changes (more modes): the body file is stale and the run refuses it.
  std::string input = Slurp(dir / "seed002_planet_reduce.yaml");
  const std::string from = "modes: 12", to = "modes: 10";
  ASSERT_NE(input.find(from), std::string::npos);
  input.replace(input.find(from), from.size(), to);
  std::ofstream(dir / "seed002_planet_reduce.yaml") << input;
  std::tie(code, text) = Orrery("run " + scene + " --end-time 0.005 -o " + (dir / "stale.h5").string());
  EXPECT_EQ(code, 1) << text;
  EXPECT_NE(text.find("modes kept"), std::string::npos) << text;
  EXPECT_NE(text.find("orrery reduce"), std::string::npos) << text;
}

}  // namespace
}  // namespace orrery

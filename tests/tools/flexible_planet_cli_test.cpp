// A generated planet reduced, attached and simulated from the command line, in a scratch copy of
// models/scenes/seed002_flexible_planet.yaml and models/bodies/seed002_planet.yaml:
// - without its reduce input, a scene with a missing body file is refused with the command that
//   makes it;
// - `orrery reduce` makes the file (JSON keys of the issue), `orrery run` attaches and runs it: the
//   result file holds the planet's modal coordinates, its von Mises hot spot and its surface, with
//   an .xdmf beside it;
// - with its reduce input, a missing file is made by the run itself;
// - once the reduce input changes, the file is stale and the run refuses it with the reason.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include "mbd/hdf5_reader.h"
#include "tests/common/cli_support.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

// Runs `orrery ARGS` and returns (exit code, stdout + stderr).
std::pair<int, std::string> Orrery(const std::string& args) {
  std::string command = "\"";
  command += ORRERY_BINARY_DIR;
  command += "/bin/orrery\" ";
  command += args;
  auto [out, code] = test_support::RunCommand(command);
  return {code, out};
}

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(FlexiblePlanetCli, ReduceAttachRunAndRefuseStaleBodies) {
  const fs::path dir = fs::path(::testing::TempDir()) / "flexible_planet_cli";
  fs::remove_all(dir);
  fs::create_directories(dir / "scenes");
  fs::create_directories(dir / "bodies");
  const fs::path models = fs::path(ORRERY_SOURCE_DIR) / "models";
  fs::copy_file(models / "bodies" / "seed002_planet.yaml", dir / "bodies" / "seed002_planet.yaml");
  const std::string scene_text = Slurp(models / "scenes" / "seed002_flexible_planet.yaml");
  const std::string scene = (dir / "scenes" / "seed002_flexible_planet.yaml").string();
  const std::string body = (dir / "bodies" / "seed002_planet.h5").string();
  const std::string input = (dir / "bodies" / "seed002_planet.yaml").string();

  // Without reduce_input, a missing file is an error naming the command that makes it.
  std::string no_input = scene_text;
  const std::string input_line = "        reduce_input: ../bodies/seed002_planet.yaml\n";
  ASSERT_NE(no_input.find(input_line), std::string::npos);
  no_input.erase(no_input.find(input_line), input_line.size());
  std::ofstream(scene) << no_input;
  auto [code, text] = Orrery("run " + scene + " --end-time 0.005 -o " + (dir / "run.h5").string());
  EXPECT_EQ(code, 1) << text;
  EXPECT_NE(text.find("orrery reduce INPUT -o"), std::string::npos) << text;
  EXPECT_NE(text.find("reduced_body"), std::string::npos) << text;

  // orrery reduce, then the run attaches the body.
  std::tie(code, text) = Orrery("reduce " + input + " -o " + body + " --json");
  ASSERT_EQ(code, 0) << text;
  EXPECT_NE(text.find("\"full_frequencies_hz\""), std::string::npos);
  EXPECT_NE(text.find("\"reduced_frequencies_hz\""), std::string::npos);
  std::tie(code, text) = Orrery("run " + scene + " --end-time 0.01 -o " + (dir / "run.h5").string());
  ASSERT_EQ(code, 0) << text;
  EXPECT_NE(text.find("max von Mises"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(dir / "run.xdmf"));
  {
    const Hdf5Reader r((dir / "run.h5").string());
    EXPECT_EQ(r.ReadMatrix("/flexible_bodies/S.planet1/modal_q").rows(), 11);
    EXPECT_EQ(r.ReadMatrix("/flexible_bodies/S.planet1/von_mises_max").rows(), 11);
    const auto surface = r.Shape("/flexible_bodies/S.planet1/surface/positions");
    ASSERT_EQ(surface.size(), 2u);
    EXPECT_EQ(surface[0], 11);
  }
  EXPECT_NE(Slurp(dir / "run.xdmf").find("S.planet1"), std::string::npos);

  // With reduce_input (the scene as shipped), a missing file is made by the run.
  std::ofstream(scene) << scene_text;
  fs::remove(body);
  std::tie(code, text) = Orrery("run " + scene + " --end-time 0.005 -o " + (dir / "made.h5").string());
  ASSERT_EQ(code, 0) << text;
  EXPECT_TRUE(fs::exists(body));

  // The reduce input changes (fewer modes): the file is stale and the run refuses it.
  std::string changed = Slurp(input);
  const std::string from = "modes: 12", to = "modes: 10";
  ASSERT_NE(changed.find(from), std::string::npos);
  changed.replace(changed.find(from), from.size(), to);
  std::ofstream(input) << changed;
  std::tie(code, text) = Orrery("run " + scene + " --end-time 0.005 -o " + (dir / "stale.h5").string());
  EXPECT_EQ(code, 1) << text;
  EXPECT_NE(text.find("modes kept"), std::string::npos) << text;
  EXPECT_NE(text.find("orrery reduce"), std::string::npos) << text;
}

}  // namespace
}  // namespace orrery

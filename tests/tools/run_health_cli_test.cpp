// The reproductions of issue 17's classes 3 and 4 through the `orrery` program, as a user meets
// them:
//   - class 3 (plausibility while running, mbd/run_health.h): seed 003's lumped stage at a 0.05 s
//     generalized-alpha step (the issue's run ended silently with the carrier at -8793 rad/s
//     instead of 59 rad/s) stops naming the mesh whose teeth the step skips; a mesh so soft that
//     the teeth ratchet stops naming the mesh; tooth contact loaded 100 times over (penetrations
//     of 0.3-0.5 mm against the scene's 100 um margin) warns per contact element, and --strict
//     stops at the first warning, while the scene as shipped reports a healthy run;
//   - class 4 (one gear geometry validation for every command): an undercut planet, a 2-tooth
//     planet with a negative root radius, pointed teeth and a 1 mm sun tip diameter on the contact
//     scene are refused by run, kinematics, modes and mesh-stiffness with the same line, at the
//     scene key of the gear (its tip key for the tip).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "tests/common/cli_support.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using test_support::RunCommand;

const std::string kOrrery = std::string(ORRERY_BINARY_DIR) + "/bin/orrery";

std::string ScenePath(const std::string& name) { return std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + name; }

fs::path TempDir() {
  const fs::path dir = fs::temp_directory_path() / ("orrery_run_health_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// The shipped scene `name` with `from` replaced by `to`, written as dir/<stem>.yaml.
std::string Variant(const std::string& name, const std::string& from, const std::string& to, const std::string& stem) {
  std::ifstream in(ScenePath(name));
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  const fs::path path = TempDir() / (stem + ".yaml");
  std::ofstream(path) << s;
  return path.string();
}

int CountOf(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(RunHealthCli, AStepThatSkipsTeethStopsTheIssuesReproduction) {
  const std::string out = (TempDir() / "step.h5").string();
  const auto [text, status] = RunCommand(kOrrery + " run " + ScenePath("seed003_lumped_healthy.yaml") +
                                         " --integrator generalized_alpha --set solver.step=5e-2"
                                         " --set output.interval=5e-2 -o " + out);
  EXPECT_EQ(status, 1) << text;
  EXPECT_NE(text.find("run stopped: t = 0.05 s: mesh 'S.sun-planet#1': the gears roll"), std::string::npos) << text;
  EXPECT_NE(text.find("the step skips teeth"), std::string::npos) << text;
  EXPECT_NE(text.find("holds 2 rows (t = 0 to 0.05 s)"), std::string::npos) << text;
}

TEST(RunHealthCli, AMeshSoSoftTheTeethRatchetStops) {
  const std::string out = (TempDir() / "soft.h5").string();
  const auto [text, status] = RunCommand(kOrrery + " run " + ScenePath("seed003_lumped_healthy.yaml") +
                                         " --end-time 0.05 --set gear_train.dynamics.mesh_stiffness=1e4 -o " + out);
  EXPECT_EQ(status, 1) << text;
  EXPECT_NE(text.find("run stopped"), std::string::npos) << text;
  EXPECT_NE(text.find("the teeth ratchet past each other"), std::string::npos) << text;
}

TEST(RunHealthCli, ToothPenetrationFarBeyondTheMarginWarnsPerContact) {
  const std::string scene = ScenePath("seed003_contact_healthy.yaml");
  // As shipped: healthy
  const auto [healthy, healthy_status] =
      RunCommand(kOrrery + " run " + scene + " --end-time 5e-4 -o " + (TempDir() / "healthy.h5").string());
  EXPECT_EQ(healthy_status, 0) << healthy;
  EXPECT_NE(healthy.find("health              ok"), std::string::npos) << healthy;
  // 100 times the load: every contact warns, the run ends (a warning, not a stop)
  const std::string overload = " --end-time 5e-4 --set gear_train.output_torque=-600000";
  const auto [text, status] = RunCommand(kOrrery + " run " + scene + overload + " -o " + (TempDir() / "over.h5").string());
  EXPECT_EQ(status, 0) << text;
  EXPECT_EQ(CountOf(text, "penetration beyond the contact margin"), 6) << text;
  EXPECT_NE(text.find("element 'S.sun-planet#1': penetration = "), std::string::npos) << text;
  EXPECT_NE(text.find("exceeds 0.0001 m"), std::string::npos) << text;
  // --strict stops at the first
  const auto [strict, strict_status] =
      RunCommand(kOrrery + " run " + scene + overload + " --strict -o " + (TempDir() / "strict.h5").string());
  EXPECT_EQ(strict_status, 1) << strict;
  EXPECT_NE(strict.find("--strict: stopped at the first warning"), std::string::npos) << strict;
}

TEST(RunHealthCli, GearGeometryIsRefusedAlikeByEveryCommand) {
  const std::string gears = "sun: 22, planet: 14, ring: 50, module_mm: 4,";
  struct Case {
    std::string scene, gears, stem, line, message;
  };
  const std::vector<Case> cases{
      {"seed003_lumped_healthy.yaml", "sun: 40, planet: 5, ring: 50, module_mm: 4,", "undercut", "17",
       "gear_train.stages[S].planet: gear 'S.planet': gear geometry: undercut: z = 5"},
      {"seed003_lumped_healthy.yaml", "sun: 46, planet: 2, ring: 50, module_mm: 4,", "two_teeth", "17",
       "gear_train.stages[S].planet: gear 'S.planet': gear geometry: root radius r_f = -0.001 m is not positive"},
      {"seed003_lumped_healthy.yaml", gears + " addendum_coefficient: 1.6,", "pointed", "17",
       "gear_train.stages[S].sun: gear 'S.sun': gear geometry: pointed tip"},
      {"seed003_contact_healthy.yaml", "sun: {teeth: 22, tip_diameter_mm: 1}, planet: 14, ring: 50, module_mm: 4,",
       "tip", "18", "gear_train.stages[S].sun.tip_diameter_mm: gear 'S.sun': gear geometry: tip radius r_a = 0.0005 m"}};
  for (const Case& c : cases) {
    const std::string path = Variant(c.scene, gears, c.gears, c.stem);
    for (const std::string command : {"run", "kinematics", "modes", "mesh-stiffness --mesh S.sun-planet"}) {
      const std::string extra = command == "run" ? " --end-time 1e-3 -o " + (TempDir() / (c.stem + ".h5")).string() : "";
      const auto [text, status] = RunCommand(kOrrery + " " + command + " " + path + extra);
      EXPECT_EQ(status, 1) << c.stem << ", " << command << ": " << text;
      EXPECT_NE(text.find("orrery: error: " + path + ":" + c.line + ": " + c.message), std::string::npos)
          << c.stem << ", " << command << ": " << text;
    }
  }
}

}  // namespace
}  // namespace orrery

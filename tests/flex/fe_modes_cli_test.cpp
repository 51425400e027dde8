// `orrery fe-modes` end to end (tools/cli/fe_modes_command.cpp; it lives here because the CLI
// test folder does not link flex/): a box mesh written by WriteInp, modes by the built `orrery`
// program, compared with CalcFeModes on the same mesh; one-line errors. Skipped when the
// program has not been built.
#include <gtest/gtest.h>

#include "tests/common/cli_support.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "flex/box_mesher.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"
#include "flex/inp_file.h"

namespace orrery::flex {
namespace {

using test_support::RunCommand;


// `orrery fe-modes <mesh> <args>` (built by appending: GCC 12 warns falsely (-Wrestrict) about
// chains of string operator+).
std::string FeModesCommandLine(const std::filesystem::path& orrery, const std::filesystem::path& mesh, const char* args) {
  std::string c = "'";
  c += orrery.string();
  c += "' fe-modes '";
  c += mesh.string();
  c += "' ";
  c += args;
  return c;
}

TEST(FeModesCliTest, FrequenciesMatchLibraryAndErrorsAreOneLine) {
  const std::filesystem::path orrery = std::filesystem::path(ORRERY_BINARY_DIR) / "bin" / "orrery";
  if (!std::filesystem::exists(orrery)) GTEST_SKIP() << "orrery program not built: " << orrery;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("orrery_fe_modes_cli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  FeMesh mesh = MakeBoxMesh({.size_m = {0.4, 0.05, 0.05}, .divisions = {6, 1, 1}, .type = ElementType::kHex20});
  WriteInpFile(dir / "beam.inp", mesh);
  const auto [json, status] = RunCommand(FeModesCommandLine(orrery, dir / "beam.inp", "--E 7e10 --nu 0.33 --rho 2700 --fix XMIN --modes 4 --json"));
  ASSERT_EQ(status, 0) << json;
  mesh.AssignMaterialToAll({.name = "AL", .youngs_modulus_pa = 7e10, .poissons_ratio = 0.33, .density_kg_m3 = 2700});
  const FeModes ref = CalcFeModes(AssembleFeSystem(mesh), NodeDofs(mesh.NodeSet("XMIN")), {.num_modes = 4});
  const std::size_t at = json.find("\"frequencies_hz\": [");
  ASSERT_NE(at, std::string::npos) << json;
  const char* p = json.c_str() + at + 19;
  for (int i = 0; i < 4; ++i) {
    char* end = nullptr;
    const double f = std::strtod(p, &end);
    EXPECT_NEAR(f, ref.frequencies_hz[i], 1e-9 * ref.frequencies_hz[i]) << json;
    p = end + 1;
  }
  // Free-free: six zeros first
  const auto [free_json, free_status] = RunCommand(FeModesCommandLine(orrery, dir / "beam.inp", "--E 7e10 --nu 0.33 --rho 2700 --modes 7 --json"));
  EXPECT_EQ(free_status, 0);
  EXPECT_NE(free_json.find("\"rigid_body_modes\": 6"), std::string::npos) << free_json;
  // Errors: one line each
  const auto [bad_set, s1] = RunCommand(FeModesCommandLine(orrery, dir / "beam.inp", "--E 7e10 --nu 0.33 --rho 2700 --fix HUB --modes 3"));
  EXPECT_EQ(s1, 1);
  EXPECT_EQ(bad_set.rfind("orrery: error: no node set 'HUB'", 0), 0u) << bad_set;
  EXPECT_EQ(std::count(bad_set.begin(), bad_set.end(), '\n'), 1);
  const auto [no_mat, s2] = RunCommand(FeModesCommandLine(orrery, dir / "beam.inp", "--modes 3"));
  EXPECT_EQ(s2, 1);
  EXPECT_NE(no_mat.find("has no *MATERIAL"), std::string::npos) << no_mat;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace orrery::flex

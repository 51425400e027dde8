// `orrery mesh-stiffness --flexible` (tools/cli/flexible_mesh_stiffness.cpp) on seed 001's
// sun-planet mesh at Table 2's 1429 N, 6 roll angles: the wiring (scene, blanks, JSON) of the sweep
// whose physics tests/contact/flexible_gear_mesh_test.cpp checks. Oracles: the teeth in contact
// are the pairs the unloaded path of contact holds, or one more at the end of the path; two pairs
// are stiffer than one; the mean lies within 15 % of ISO 6336 c_gamma_alpha b (the coarse mesh's
// discretization, 4.5 % between fe levels 1 and 2, plus the FE-lumped difference).
#include "tools/cli/flexible_mesh_stiffness.h"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/common/cli_support.h"

#include "tools/cli/error_message.h"

namespace orrery::cli {
namespace {

constexpr auto Array = test_support::JsonArray;
constexpr auto Number = test_support::JsonNumber;


TEST(FlexibleMeshStiffnessCli, Seed001SunPlanet) {
  MeshStiffnessArgs args;
  args.scene_path = std::string(ORRERY_SOURCE_DIR) + "/models/scenes/seed001_sun_planet_contact.yaml";
  args.mesh = "S1.sun-planet";
  args.load_n = 1429;
  args.points = 6;
  args.json = true;
  args.flexible = true;
  std::ostringstream out, err;
  ASSERT_EQ(MeshStiffnessCommand(args, out, err), kExitSuccess) << err.str();
  const std::string json = out.str();
  const std::vector<double> k = Array(json, "stiffness_n_per_m");
  const std::vector<double> teeth = Array(json, "teeth_in_contact");
  const std::vector<double> path = Array(json, "predicted_pairs");
  ASSERT_EQ(k.size(), 6u);
  ASSERT_EQ(teeth.size(), 6u);
  ASSERT_EQ(path.size(), 6u);
  for (size_t i = 0; i < teeth.size(); ++i)
    EXPECT_TRUE(teeth[i] == path[i] || teeth[i] == path[i] + 1) << "point " << i;
  const double single = Number(json, "single_zone_stiffness_n_per_m");
  const double twice = Number(json, "double_zone_stiffness_n_per_m");
  EXPECT_GT(single, 0);
  EXPECT_GT(twice, 1.2 * single);
  const double c_ga = Number(json, "iso6336_c_gamma_alpha_n_per_m");
  EXPECT_NEAR(Number(json, "mean_stiffness_n_per_m"), c_ga, 0.15 * c_ga);
  EXPECT_GT(Number(json, "modes_gear1"), 0);
}

TEST(FlexibleMeshStiffnessCli, RefusesAnFeLevelBelowOne) {
  MeshStiffnessArgs args;
  args.scene_path = std::string(ORRERY_SOURCE_DIR) + "/models/scenes/seed001_sun_planet_contact.yaml";
  args.mesh = "S1.sun-planet";
  args.flexible = true;
  args.fe_level = 0;
  std::ostringstream out, err;
  EXPECT_EQ(MeshStiffnessCommand(args, out, err), kExitFailure);
  EXPECT_NE(err.str().find("--fe-level"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace orrery::cli

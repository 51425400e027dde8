// Tests for models/train_bodies.cpp: the gear checks every assembly makes first (issue 17).
//   - CheckTrainGearGeometry: a gear that cannot be cut is refused even when no mesh uses its
//     geometry (seed 003's stage with kinematic meshes; the same Gear checks as
//     models/gear_geometry.h, whose closed forms tests/models/gear_geometry_test.cpp holds);
//   - CheckFlexibleGearBodies: a flexible planet must be the planet (class 5): a body whose
//     reduce input was another gear (its provenance source names z, m_n and b), or whose FE
//     surface does not reach the planet's tip circle r_a = m (z / 2 + 1) (ISO 21771 with x = 0), is
//     refused naming both gears.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "models/planetary_scenes.h"
#include "models/train_description.h"

namespace orrery::gears {
namespace {

std::string ErrorOf(const GearTrainDescription& d) {
  try {
    AssembleGearTrain(d);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// A surface ring of radius r (m) about B's z axis: 12 triangles between z = 0 and 0.04 m.
std::shared_ptr<const FlexibleBodyModes> RingSurface(double r) {
  auto m = std::make_shared<FlexibleBodyModes>();
  const int n = 12;
  for (int k = 0; k < 2 * n; ++k) {
    const double phi = 2 * std::numbers::pi * (k / 2) / n;
    m->nodes.push_back({.id = k + 1, .position = Vec3(r * std::cos(phi), r * std::sin(phi), 0.04 * (k % 2))});
  }
  for (int k = 0; k < n; ++k) m->surface_triangles.push_back({2 * k, 2 * k + 1, (2 * k + 2) % (2 * n)});
  return m;
}

TEST(TrainBodies, AGearThatCannotBeCutIsRefusedWhateverItsMeshModel) {
  GearTrainDescription d = MakeSeed003StageDescription();
  d.options.mesh_model = MeshModel::kKinematic;
  // Kinematic meshes and two speed inputs: one planet leaves the stage exactly determined (three
  // would repeat the same constraint rows: over-constrained)
  std::get<SinglePlanetStageSpec>(d.train.stages[0]).num_planets = 1;
  EXPECT_EQ(ErrorOf(d), "");
  // Pressure angle 17 deg: z_min about 2 / sin^2(17 deg) = 23.4 (less the rack's tip fillet) > 22
  // and 14 (the sun, the first gear, is named)
  std::get<SinglePlanetStageSpec>(d.train.stages[0]).tooth_form->normal_pressure_angle_rad = 17 * std::numbers::pi / 180;
  const std::string e = ErrorOf(d);
  EXPECT_EQ(e.rfind("train model: gear 'S.sun': gear geometry: undercut: z = 22 < z_min = ", 0), 0u) << e;
}

TEST(TrainBodies, AFlexiblePlanetReducedFromAnotherGearIsRefused) {
  GearTrainDescription d = MakeSeed003StageDescription();
  // Planet: z = 14, m = 4 mm: r_a = 0.004 (7 + 1) = 0.032 m; face width 40 mm
  const std::string planet = "is not the gear 'S.planet' (z = 14, m_n = 0.004 m, b = 0.04 m): ";
  d.options.flexible_bodies["S.planet1"] = {.modes = RingSurface(0.032),
                                            .source = "gear z=15, m_n=0.004 m, alpha_n=22.5 deg, beta=0 deg, b=0.04 m"};
  std::string e = ErrorOf(d);
  EXPECT_NE(e.find("flexible body 'S.planet1' (gear z=15, m_n=0.004 m"), std::string::npos) << e;
  EXPECT_NE(e.find(planet + "its tooth count is 15"), std::string::npos) << e;
  d.options.flexible_bodies["S.planet1"].source = "gear z=14, m_n=0.004 m, alpha_n=22.5 deg, beta=0 deg, b=0.03 m";
  e = ErrorOf(d);
  EXPECT_NE(e.find(planet + "its face width is 0.03 m"), std::string::npos) << e;
  d.options.flexible_bodies["S.planet1"].source = "gear z=14, m_n=0.005 m, alpha_n=22.5 deg, beta=0 deg, b=0.04 m";
  e = ErrorOf(d);
  EXPECT_NE(e.find(planet + "its normal module is 0.005 m"), std::string::npos) << e;
  // A source that names no gear (a mesh file): the surface decides; one tooth more reaches
  // r_a + m / 2 = 0.034 m, beyond a quarter module
  d.options.flexible_bodies["S.planet1"] = {.modes = RingSurface(0.034), .source = "planet.inp"};
  e = ErrorOf(d);
  EXPECT_NE(e.find(planet + "its surface reaches radius 0.034 m, the gear's tip circle is at 0.032 m"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace orrery::gears

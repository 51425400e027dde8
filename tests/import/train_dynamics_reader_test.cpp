// Tests for import/train_dynamics_reader.cpp: every numeric key of a gear_train's `dynamics:` map
// acts on the model it is read for (issue 17, class 7: keys accepted and ignored).
//
// The oracle is the model itself, as in lumped_stage_reader_test.cpp: seed 001's three-stage train
// (models/scenes/seed001_three_stage.yaml: two connections, three clutches, three brakes) in its
// 2nd range (clutch K1, brakes B2 and B3: stage 1 turns as a block, its meshes unloaded), in the
// spatial DOF set, every dynamics value set; each number is changed by 30 % in turn and the
// linearization at the start (mass, stiffness, damping) or the generalized forces at rest must
// change.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "import/scene.h"
#include "tests/common/model_fingerprint.h"

namespace orrery {
namespace {

std::string Number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// Seed 001's scene up to its `dynamics:` map, with the range and drive replaced.
std::string TrainText() {
  std::ifstream in(std::string(ORRERY_SOURCE_DIR) + "/models/scenes/seed001_three_stage.yaml");
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  text = text.substr(0, text.find("  dynamics:"));
  const std::size_t range = text.find("  range: 1st");
  text.replace(range, std::string("  range: 1st").size(), "  range: 2nd");
  return text;
}

// `values`: "key" -> number under dynamics (a "members." or "housing." prefix puts it in that map).
std::string SceneText(const std::map<std::string, double>& values) {
  std::ostringstream s;
  s << TrainText() << "  dynamics:\n    dofs: spatial\n";
  std::ostringstream members, housing;
  for (const auto& [key, value] : values) {
    if (key.rfind("members.", 0) == 0) members << key.substr(8) << ": " << Number(value) << ", ";
    else if (key.rfind("housing.", 0) == 0) housing << key.substr(8) << ": " << Number(value) << ", ";
    else s << "    " << key << ": " << Number(value) << "\n";
  }
  std::string m = members.str(), h = housing.str();
  if (!m.empty()) s << "    members: {S2.planet: {" << m.substr(0, m.size() - 2) << "}}\n";
  if (!h.empty()) s << "    housing: {" << h.substr(0, h.size() - 2) << "}\n";
  s << "solver: {end_time: 0.01}\noutput: {interval: 0.001}\n";
  return s.str();
}

// Each value 1.3 times its base must change the model; the planet's and the housing's moments stay
// a real mass distribution either way (I_polar <= 2 I_transverse).
TEST(TrainDynamicsReader, EveryNumericDynamicsKeyChangesTheModel) {
  const std::map<std::string, double> base{
      {"connection_stiffness", 1e8}, {"clutch_stiffness", 2e8}, {"brake_stiffness", 1e10},
      {"mesh_damping_ratio", 0.05}, {"mesh_stiffness_per_face_width", 1.5e10},
      {"unloaded_mesh_stiffness_factor", 1e-3}, {"density", 7850}, {"bore_to_pitch_ratio", 0.4},
      {"ring_rim_modules", 5}, {"stage_spacing_mm", 120}, {"bearing_stiffness", 1e8},
      {"axial_bearing_stiffness", 2e8}, {"tilt_bearing_stiffness", 3e6}, {"bearing_damping", 300},
      {"members.mass", 0.3}, {"members.inertia", 2e-4}, {"members.transverse_inertia", 1.5e-4},
      {"members.bearing_stiffness", 4e8}, {"members.axial_bearing_stiffness", 5e8},
      {"members.tilt_bearing_stiffness", 6e6}, {"members.bearing_damping", 500},
      {"members.face_width_mm", 25}, {"housing.mass", 50}, {"housing.polar_inertia", 2},
      {"housing.transverse_inertia", 1.5}, {"housing.mount_radial_stiffness", 1e8},
      {"housing.mount_axial_stiffness", 2e8}, {"housing.mount_torsional_stiffness", 1e7},
      {"housing.mount_tilt_stiffness", 3e7}, {"housing.mount_damping_ratio", 0.02}};
  const Eigen::VectorXd reference = test_support::ModelFingerprint(LoadSceneFromString(SceneText(base), "base.yaml"));
  for (const auto& [key, value] : base) {
    std::map<std::string, double> changed = base;
    changed[key] = 1.3 * value;
    const Eigen::VectorXd f = test_support::ModelFingerprint(LoadSceneFromString(SceneText(changed), "changed.yaml"));
    ASSERT_EQ(f.size(), reference.size()) << key;
    EXPECT_GT((f - reference).norm(), 1e-12 * reference.norm()) << key << " is read and changes nothing";
  }
}

}  // namespace
}  // namespace orrery

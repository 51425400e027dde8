// Tests for import/lumped_stage_reader.cpp: every numeric key the `lumped_stage:` reader accepts
// acts on the model (issue 17, class 7: a planet's torsional_stiffness was accepted and changed
// nothing), and a key that cannot act in the chosen DOF set is refused with the reason.
//
// The oracle is the model itself: each numeric value of a scene that sets every key the DOF set
// allows is changed by 30 %, one at a time, and the model's linearization at the start (mass,
// stiffness and damping matrices) or its generalized forces at rest must change; the tooth counts
// (which must agree with the base radii) are checked to reach the meshes. A key that is read and dropped leaves all of them equal to the last bit.
#include <gtest/gtest.h>

#include <map>
#include <utility>
#include <sstream>
#include <string>
#include <vector>

#include "import/scene.h"
#include "tests/common/model_fingerprint.h"

namespace orrery {
namespace {

// The numbers of one scene: "sun.mass" -> 0.4, "mesh_stiffness_sun" -> 5e8, ...
using Values = std::map<std::string, double>;

// Every numeric key a member of `kind` takes in `dofs` (the reader's IdleMemberKeys refuse the
// others), with values of Lin & Parker's example (docs/validation/lin_parker_1999.md) or of that
// order.
Values MemberValues(const std::string& kind, const std::string& dofs) {
  Values v;
  const std::map<std::string, std::vector<double>> base{
      {"sun", {0.4, 1e-3, 77.4}}, {"ring", {2.35, 0.05, 275}},
      {"carrier", {5.43, 0.05, 176.8}}, {"planet", {0.66, 1e-3, 100.3}}};
  const std::vector<double>& b = base.at(kind);
  if (kind == "planet" || dofs != "torsional") v["mass"] = b[0];  // the torsional set refuses the others'
  v["inertia"] = b[1];
  v[kind == "carrier" ? "planet_circle_diameter_mm" : "base_diameter_mm"] = b[2];
  if (kind != "planet") {
    v["torsional_stiffness"] = 2e5;
    v["torsional_damping"] = 3;
  }
  if (dofs != "torsional") {
    v["bearing_stiffness"] = 1e8;
    v["bearing_damping"] = 200;
  }
  if (dofs == "spatial") {
    v["axial_stiffness"] = 2e8;
    v["tilt_stiffness"] = 4e6;
  }
  return v;
}

Values SceneValues(const std::string& dofs) {
  Values v;
  for (const std::string kind : {"sun", "ring", "carrier", "planet"})
    for (const auto& [key, value] : MemberValues(kind, dofs)) v[kind + "." + key] = value;
  v["mesh_stiffness_sun"] = 5e8;
  v["mesh_stiffness_ring"] = 6e8;
  if (dofs != "torsional") {  // refused by the torsional set (directions act through translations)
    v["pressure_angle_sun_deg"] = 24.6;
    v["pressure_angle_ring_deg"] = 22.1;
  }
  v["mesh_damping_ratio"] = 0.05;
  v["input.torque"] = 100;
  v["load.torque"] = -300;
  v["helix_angle_deg"] = 12;
  return v;
}

std::string Number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

std::string SceneText(const std::string& dofs, const Values& v) {
  std::ostringstream s;
  s << "lumped_stage:\n  dofs: " << dofs << "\n  planets: 3\n";
  for (const std::string kind : {"sun", "ring", "carrier", "planet"}) {
    s << "  " << kind << ": {";
    const char* sep = "";
    for (const auto& [key, value] : v)
      if (key.rfind(kind + ".", 0) == 0) s << sep << key.substr(kind.size() + 1) << ": " << Number(value), sep = ", ";
    s << "}\n";
  }
  for (const auto& [key, value] : v) {
    if (key.find('.') != std::string::npos) continue;
    s << "  " << key << ": " << Number(value) << "\n";
  }
  s << "  input: {member: sun, torque: " << Number(v.at("input.torque")) << "}\n";
  s << "  load: {member: carrier, torque: " << Number(v.at("load.torque")) << "}\n";
  s << "solver: {end_time: 0.01}\noutput: {interval: 0.001}\n";
  return s.str();
}

TEST(LumpedStageReader, EveryNumericKeyChangesTheModel) {
  for (const std::string dofs : {"torsional", "planar", "spatial"}) {
    const Values base = SceneValues(dofs);
    const Eigen::VectorXd reference = test_support::ModelFingerprint(LoadSceneFromString(SceneText(dofs, base), "base.yaml"));
    for (const auto& [key, value] : base) {
      Values changed = base;
      changed[key] = 1.3 * value;
      const Eigen::VectorXd f = test_support::ModelFingerprint(LoadSceneFromString(SceneText(dofs, changed), "changed.yaml"));
      ASSERT_EQ(f.size(), reference.size()) << dofs << ": " << key;
      EXPECT_GT((f - reference).norm(), 1e-12 * reference.norm()) << "dofs " << dofs << ": " << key
                                                                   << " is read and changes nothing";
    }
  }
}

// `teeth` (not in the scenes above: tooth counts must agree with the base radii) set the meshes'
// tooth counts, which their base pitch and phase come from.
TEST(LumpedStageReader, TeethReachTheMeshes) {
  Values v = SceneValues("planar");
  // 27 / 35 / 96 teeth on base diameters in the same ratio
  const double per_tooth_mm = 100.3 / 35;
  v["sun.base_diameter_mm"] = 27 * per_tooth_mm, v["ring.base_diameter_mm"] = 96 * per_tooth_mm;
  std::string text = SceneText("planar", v);
  const std::vector<std::pair<std::string, int>> teeth{{"sun", 27}, {"planet", 35}, {"ring", 96}};
  for (const auto& [kind, z] : teeth) {
    const std::string at = "  " + kind + ": {";
    text.insert(text.find(at) + at.size(), "teeth: " + std::to_string(z) + ", ");
  }
  const Scene scene = LoadSceneFromString(text, "teeth.yaml");
  ASSERT_EQ(scene.model->gear_meshes.size(), 6u);
  EXPECT_EQ(scene.model->gear_meshes[0].spec.teeth_a, 27);  // sun_planet1: sun, planet
  EXPECT_EQ(scene.model->gear_meshes[0].spec.teeth_b, 35);
  EXPECT_EQ(scene.model->gear_meshes[1].spec.teeth_b, 96);  // ring_planet1: planet, ring
}

std::string ErrorOf(const std::string& text) {
  try {
    LoadSceneFromString(text, "t.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(LumpedStageReader, KeysThatCannotActAreRefusedWithTheReason) {
  // A planet's torsional spring (the reproduction: 1e9 N m/rad changed no frequency)
  Values v = SceneValues("planar");
  v["planet.torsional_stiffness"] = 1e9;
  EXPECT_NE(ErrorOf(SceneText("planar", v)).find("lumped_stage.planet.torsional_stiffness: key not allowed here: a "
                                                 "planet turns freely on its pin"),
            std::string::npos)
      << ErrorOf(SceneText("planar", v));
  // Bearings without translations; axial and tilt stiffness outside the spatial set
  v = SceneValues("torsional");
  v["sun.bearing_stiffness"] = 1e8;
  EXPECT_NE(ErrorOf(SceneText("torsional", v)).find("lumped_stage.sun.bearing_stiffness: key not allowed here: not "
                                                    "used with dofs: torsional"),
            std::string::npos)
      << ErrorOf(SceneText("torsional", v));
  v = SceneValues("planar");
  v["ring.tilt_stiffness"] = 1e6;
  EXPECT_NE(ErrorOf(SceneText("planar", v)).find("lumped_stage.ring.tilt_stiffness: key not allowed here: not used "
                                                 "with dofs: planar"),
            std::string::npos)
      << ErrorOf(SceneText("planar", v));
  // Without translations the sun's, ring's and carrier's masses and the lines of action's
  // directions do not act (a planet's mass does, through the carrier)
  v = SceneValues("torsional");
  v["carrier.mass"] = 5.43;
  EXPECT_NE(ErrorOf(SceneText("torsional", v)).find("lumped_stage.carrier.mass: key not allowed here: not used "
                                                    "with dofs: torsional"),
            std::string::npos)
      << ErrorOf(SceneText("torsional", v));
  v = SceneValues("torsional");
  v["pressure_angle_ring_deg"] = 22.1;
  EXPECT_NE(ErrorOf(SceneText("torsional", v)).find("lumped_stage.pressure_angle_ring_deg: key not allowed here: "
                                                    "not used with dofs: torsional"),
            std::string::npos)
      << ErrorOf(SceneText("torsional", v));
}

}  // namespace
}  // namespace orrery

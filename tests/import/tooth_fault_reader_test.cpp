// Tooth faults from YAML (import/tooth_fault_reader.h) and in reduce inputs (import/reduce_input.h
// `fault:`): every field with its unit, the kind's own keys only, file:line errors, the faulty
// mesh, and the provenance that keeps a healthy reduced body from standing in for a faulty one.
#include "import/tooth_fault_reader.h"

#include <gtest/gtest.h>

#include <string>

#include "flex/reduced_body_file.h"
#include "import/reduce_input.h"

namespace orrery {
namespace {

using gears::ToothFaultSpec;

std::vector<ToothFaultSpec> Read(const std::string& text) {
  const YAML::Node root = YAML::Load(text);
  const scene_reader::Context ctx("f.yaml");
  return ReadToothFaults(ctx, scene_reader::Item{root, "fault", root.Mark()});
}

std::string ErrorOf(const std::string& text) {
  try {
    Read(text);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(ToothFaultReader, ReadsEveryKindWithUnits) {
  const std::vector<ToothFaultSpec> f = Read(R"(
- {kind: broken_tooth, tooth: 3, height_fraction: 0.5, face_fraction: 0.25, from_face: zmax}
- {kind: root_crack, tooth: 4, crack_depth_mm: 0.8, crack_angle_deg: 45, crack_face_fraction: 0.5,
   crack_end_depth_um: 0, flank: minus}
- {kind: spall, tooth: 5, flank: plus, roll_start_mm: 5.2, roll_end_mm: 6, axial_start: 0.01, axial_end_mm: 20,
   depth_um: 20})");
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].kind, ToothFaultSpec::Kind::kBrokenTooth);
  EXPECT_EQ(f[0].tooth, 3);
  EXPECT_EQ(f[0].height_fraction, 0.5);
  EXPECT_EQ(f[0].face_fraction, 0.25);
  EXPECT_EQ(f[0].from_face, ToothFaultSpec::FromFace::kZmax);
  EXPECT_EQ(f[1].kind, ToothFaultSpec::Kind::kRootCrack);
  EXPECT_NEAR(f[1].crack_depth_m, 0.8e-3, 1e-18);
  EXPECT_NEAR(f[1].crack_angle_rad, std::numbers::pi / 4, 1e-15);
  ASSERT_TRUE(f[1].crack_end_depth_m.has_value());
  EXPECT_EQ(*f[1].crack_end_depth_m, 0.0);
  EXPECT_EQ(f[1].flank, ToothFaultSpec::Flank::kMinus);
  EXPECT_EQ(f[2].kind, ToothFaultSpec::Kind::kSpall);
  EXPECT_NEAR(f[2].roll_start_m, 5.2e-3, 1e-18);
  EXPECT_NEAR(f[2].axial_end_m, 0.02, 1e-18);
  EXPECT_NEAR(f[2].depth_m, 20e-6, 1e-20);
  // A single map is one fault; defaults: a whole tooth broken at the root.
  const std::vector<ToothFaultSpec> one = Read("{kind: broken_tooth, tooth: 0}");
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].height_fraction, 1.0);
  EXPECT_EQ(one[0].face_fraction, 1.0);
}

TEST(ToothFaultReader, ErrorsNameFileLineAndKey) {
  EXPECT_NE(ErrorOf("{kind: spall, tooth: 1, crack_depth_mm: 1}").find("'crack_depth_mm' does not apply to a spall"),
            std::string::npos);
  EXPECT_NE(ErrorOf("{kind: pitting, tooth: 1}").find("unknown value 'pitting'"), std::string::npos);
  EXPECT_NE(ErrorOf("{kind: root_crack, tooth: 1, crack_angle_deg: 45}").find("crack_depth"), std::string::npos);
  EXPECT_NE(ErrorOf("{kind: spall, tooth: 1, roll_start_mm: 5, roll_end_mm: 6, axial_start: 0, axial_end: 0.01}")
                .find("f.yaml:1: fault.depth: missing required key 'depth'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("{kind: broken_tooth, tooth: 1, hieght_fraction: 0.5}").find("did you mean 'height_fraction'"),
            std::string::npos);
}

constexpr const char* kPlanet = R"(gear: {teeth: 18, module_mm: 1.5, pressure_angle_deg: 21.3, face_width_mm: 30,
       bore_diameter_mm: 14}
mesh: {element: hex20, flank_divisions: 3, fillet_divisions: 2, tooth_divisions: 4, root_layer_divisions: 1,
       rim_divisions: 1, face_divisions: 2}
material: {name: steel, E: 210e9, nu: 0.3, rho: 7850}
interfaces:
  - {name: bore, node_set: BORE}
reduction: {modes: 4}
)";

TEST(ToothFaultReader, ReduceInputFaultChangesMeshAndProvenance) {
  const ReduceInput healthy = ParseReduceInput(kPlanet, "planet.yaml");
  const ReduceInput broken =
      ParseReduceInput(std::string(kPlanet) + "fault: {kind: broken_tooth, tooth: 2, height_fraction: 0.5}\n",
                       "planet.yaml");
  ASSERT_EQ(broken.mesh.faults.size(), 1u);
  const GearReduction h = PrepareGearReduction(healthy), b = PrepareGearReduction(broken);
  EXPECT_EQ(h.faults, "none");
  EXPECT_EQ(b.faults, "broken_tooth tooth=2 height_fraction=0.5 face_fraction=1 from_face=zmin");
  EXPECT_LT(b.mesh.num_elements(), h.mesh.num_elements());
  // Provenance: the scene's expectation against a file's record.
  const flex::ReducedBodyProvenance ph =
      flex::MakeReducedBodyProvenance(h.mesh, h.cb_options, h.interfaces, h.outputs, h.source, h.faults);
  flex::ReducedBodyProvenance pb =
      flex::MakeReducedBodyProvenance(b.mesh, b.cb_options, b.interfaces, b.outputs, b.source, b.faults);
  EXPECT_THROW(flex::CheckReducedBodyMatches(ph, pb), flex::StaleReducedBodyError);
  EXPECT_THROW(flex::CheckReducedBodyMatches(pb, ph), flex::StaleReducedBodyError);
  EXPECT_NO_THROW(flex::CheckReducedBodyMatches(pb, pb));
  // Only the fault record differs (a spall leaves the FE mesh as it is): still stale.
  flex::ReducedBodyProvenance spalled = ph;
  spalled.faults = "spall tooth=2 ...";
  try {
    flex::CheckReducedBodyMatches(ph, spalled, "planet.h5");
    ADD_FAILURE() << "a healthy body passed for a spalled one";
  } catch (const flex::StaleReducedBodyError& e) {
    EXPECT_NE(std::string(e.what()).find("tooth faults differ: file none, the scene asks spall"), std::string::npos)
        << e.what();
  }
  // A file written before faults were recorded counts as healthy.
  flex::ReducedBodyProvenance old = ph;
  old.faults.clear();
  EXPECT_NO_THROW(flex::CheckReducedBodyMatches(old, ph));
  EXPECT_THROW(flex::CheckReducedBodyMatches(old, spalled), flex::StaleReducedBodyError);
  // A fault the gear cannot carry is refused at its line.
  try {
    ParseReduceInput(std::string(kPlanet) + "fault: {kind: broken_tooth, tooth: 18}\n", "planet.yaml");
    ADD_FAILURE() << "tooth 18 of 18 accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("planet.yaml:9: fault: tooth fault: broken_tooth: tooth = 18"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace orrery

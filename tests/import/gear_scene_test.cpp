// The gear model sections of scene files (import/gear_scene.cpp): every scene shipped in
// models/scenes loads, the two gear sections build the models they describe (checked against the
// C++ factories they spell out), and errors in them name file:line: key.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "import/scene.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/lumped_planetary.h"
#include "models/planetary_scenes.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

std::string ScenePath(const std::string& name) {
  return std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + name;
}

// The message of the SceneError that loading `text` throws ("" if none).
std::string ErrorOf(const std::string& text) {
  try {
    LoadSceneFromString(text, "t.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// Loaded from a scratch copy of models/scenes and models/bodies (inputs only): a scene with a
// flexible body makes its missing reduced-body file, which must not land in the source tree.
TEST(GearScene, EverySceneInModelsScenesLoads) {
  const fs::path copy = fs::path(::testing::TempDir()) / "every_scene";
  fs::remove_all(copy);
  for (const char* folder : {"scenes", "bodies"}) {
    fs::create_directories(copy / folder);
    for (const auto& entry : fs::directory_iterator(fs::path(ORRERY_SOURCE_DIR) / "models" / folder))
      if (entry.path().extension() == ".yaml") fs::copy_file(entry.path(), copy / folder / entry.path().filename());
  }
  int count = 0;
  for (const auto& entry : fs::directory_iterator(copy / "scenes")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    Scene scene;
    ASSERT_NO_THROW(scene = LoadScene(entry.path().string(), {}, {.make_reduced_bodies = true}));
    EXPECT_TRUE(scene.model);
    ++count;
  }
  EXPECT_GE(count, 9);
}

TEST(GearScene, LinParkerScenesMatchTheCxxExample) {
  for (int n : {3, 4, 5}) {
    const Scene s = LoadScene(ScenePath("lin_parker_1999_n" + std::to_string(n) + ".yaml"));
    ASSERT_EQ(s.kind, SceneKind::kLumpedStage);
    const LumpedStageParams a = s.lumped_stage->params, b = LinParker1999Example(n);
    EXPECT_EQ(a.planets, n);
    for (const auto& [x, y] : {std::pair{a.sun, b.sun}, {a.ring, b.ring}, {a.carrier, b.carrier}, {a.planet, b.planet}}) {
      EXPECT_DOUBLE_EQ(x.mass, y.mass);
      EXPECT_NEAR(x.inertia, y.inertia, 1e-15 * y.inertia);
      EXPECT_NEAR(x.radius, y.radius, 1e-15);
      EXPECT_DOUBLE_EQ(x.bearing_stiffness, y.bearing_stiffness);
      EXPECT_NEAR(x.torsional_stiffness, y.torsional_stiffness, 1e-12 * (1 + y.torsional_stiffness));
    }
    EXPECT_DOUBLE_EQ(a.pressure_angle_sun, b.pressure_angle_sun);
    EXPECT_EQ(a.lines_of_action_on_carrier, b.lines_of_action_on_carrier);
    EXPECT_EQ(s.model->nv, 3 * (3 + n));
  }
}

TEST(GearScene, Seed001SceneIsTheFactoryTrain) {
  const Scene s = LoadScene(ScenePath("seed001_three_stage.yaml"));
  ASSERT_EQ(s.kind, SceneKind::kGearTrain);
  const auto& t = *s.gear_train->train;
  const auto f = gears::MakeSeed001AutomaticTransmission();
  ASSERT_EQ(t.members.size(), f->members.size());
  for (size_t i = 0; i < t.members.size(); ++i) EXPECT_EQ(t.members[i].name, f->members[i].name);
  for (size_t i = 0; i < t.planet_sets.size(); ++i)
    for (size_t k = 0; k < t.planet_sets[i].angles_rad.size(); ++k)
      EXPECT_NEAR(t.planet_sets[i].angles_rad[k], f->planet_sets[i].angles_rad[k], 1e-12);
  EXPECT_EQ(t.ranges.size(), 4u);
  EXPECT_EQ(t.ranges[s.gear_train->range].name, "1st");
  EXPECT_EQ(t.members[t.inputs[0]].name, "S1.ring");
  EXPECT_EQ(t.members[t.output].name, "S2.carrier");
  EXPECT_DOUBLE_EQ(s.gear_train->input_torque_n_m, 300.0);
}

TEST(GearScene, Seed002SpeedFollowsTheTrapezoid) {
  const Scene s = LoadScene(ScenePath("seed002_alpha1_ramp.yaml"));
  ASSERT_EQ(s.kind, SceneKind::kGearTrain);
  ASSERT_EQ(s.model->drivers.size(), 1u);
  const TimeFunction& w = s.model->drivers[0].spec.function;
  const double w1 = 20 * 2 * 3.14159265358979323846 / 60;
  EXPECT_NEAR(w.Value(0.0), 0.0, 1e-15);
  EXPECT_NEAR(w.Value(0.05), w1, 1e-12);   // plateau between t1 = 8 ms and t2 = 112 ms
  EXPECT_NEAR(w.Value(0.15), 0.0, 1e-15);  // at rest after t3 = 120 ms
  EXPECT_NEAR(s.gear_train->input_speeds_rad_s[0], w1, 1e-12);  // operating point: the peak
}

TEST(GearScene, Seed003OutputTorqueBecomesTheRingTorque) {
  const Scene s = LoadScene(ScenePath("seed003_lumped_healthy.yaml"));
  // T_r = 6000 Z_r / (Z_s + Z_r) on the ring for a 6000 N m carrier load.
  EXPECT_NEAR(s.gear_train->input_torque_n_m, 6000.0 * 50 / 72, 1e-9);
}

constexpr const char* kLumped =
    "lumped_stage:\n"                                                          // 1
    "  planets: 3\n"                                                           // 2
    "  sun: {mass: 0.4, inertia: 1e-4, base_diameter_mm: 77.4}\n"              // 3
    "  ring: {mass: 2.35, inertia: 0.05, base_diameter_mm: 275}\n"             // 4
    "  carrier: {mass: 5.4, inertia: 0.05, planet_circle_diameter_mm: 176.8}\n"  // 5
    "  planet: {mass: 0.66, inertia: 1e-3, base_diameter_mm: 100.3}\n"         // 6
    "  mesh_stiffness_sun: 5e8\n"                                              // 7
    "  mesh_stiffness_ring: 5e8\n"                                             // 8
    "  pressure_angle_sun_deg: 24.6\n"                                         // 9
    "  pressure_angle_ring_deg: 24.6\n"                                        // 10
    "solver: {end_time: 0.01}\n"                                               // 11
    "output: {interval: 0.001}\n";                                             // 12

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(GearScene, LumpedStageErrorsNameFileLineKey) {
  EXPECT_EQ(ErrorOf(kLumped), "");
  EXPECT_EQ(ErrorOf(Replace(kLumped, "mass: 0.4,", "mas: 0.4,")),
            "t.yaml:3: lumped_stage.sun.mas: unknown key 'mas'; did you mean 'mass'?");
  EXPECT_EQ(ErrorOf(Replace(kLumped, "mass: 2.35", "mass: -1")),
            "t.yaml:4: lumped_stage.ring.mass: must be > 0, got -1");
  EXPECT_NE(ErrorOf(Replace(kLumped, "planet_circle_diameter_mm", "base_diameter_mm"))
                .find("t.yaml:5: lumped_stage.carrier.base_diameter_mm: key not allowed here: the carrier has no base circle"),
            std::string::npos);
  EXPECT_EQ(ErrorOf(Replace(kLumped, "  mesh_stiffness_ring: 5e8\n", "")),
            "t.yaml:1: lumped_stage.mesh_stiffness_ring: missing required key (one of 'mesh_stiffness_ring')");
  EXPECT_EQ(ErrorOf(Replace(kLumped, "  planets: 3\n", "  planets: 3\n  input: {member: son, speed: 10}\n")),
            "t.yaml:3: lumped_stage.input.member: unknown value 'son'; did you mean 'sun'?");
  // One model section only.
  EXPECT_NE(ErrorOf(std::string(kLumped) + "bodies: []\n").find("t.yaml:13: bodies: key not allowed with lumped_stage"),
            std::string::npos);
}

constexpr const char* kTrain =
    "gear_train:\n"                                                                       // 1
    "  stages:\n"                                                                         // 2
    "    - {name: S, type: single_planet, planets: 3, sun: 19, planet: 34, ring: 89,\n"   // 3
    "       module_mm: 16, face_width_mm: 100}\n"                                         // 4
    "  brakes:\n"                                                                         // 5
    "    - {name: B, member: S.ring}\n"                                                   // 6
    "  ranges:\n"                                                                         // 7
    "    run: [B]\n"                                                                      // 8
    "  inputs: [S.carrier]\n"                                                             // 9
    "  output: S.sun\n"                                                                   // 10
    "  input_speed_rpm: 20\n"                                                             // 11
    "  dynamics: {dofs: planar, meshes: {S.sun-planet: {stiffness: 1e9}}}\n"              // 12
    "solver: {end_time: 0.01}\n"                                                          // 13
    "output: {interval: 0.001}\n";                                                        // 14

TEST(GearScene, GearTrainErrorsNameFileLineKey) {
  EXPECT_EQ(ErrorOf(kTrain), "");
  EXPECT_EQ(ErrorOf(Replace(kTrain, "planets: 3,", "planet_count: 3,")),
            "t.yaml:3: gear_train.stages[S].planet_count: unknown key 'planet_count' (allowed: name, "
            "type, planets, planet_angles, planet_angles_deg, planet_spacing, addendum_coefficient, "
            "module, module_mm, pressure_angle, pressure_angle_deg, helix_angle, helix_angle_deg, "
            "face_width, face_width_mm, sun, planet, ring, pin_circle_diameter, pin_circle_diameter_mm, "
            "pin_circle_radius, pin_circle_radius_mm)");
  EXPECT_EQ(ErrorOf(Replace(kTrain, "type: single_planet", "type: single_plant")),
            "t.yaml:3: gear_train.stages[S].type: unknown type 'single_plant'; did you mean 'single_planet'?");
  EXPECT_EQ(ErrorOf(Replace(kTrain, "member: S.ring", "member: S.rign")),
            "t.yaml:6: gear_train.brakes[B].member: no member named 'S.rign'; did you mean 'S.ring'?");
  EXPECT_EQ(ErrorOf(Replace(kTrain, "run: [B]", "run: [C]")),
            "t.yaml:8: gear_train.ranges.run[0]: no clutch or brake named 'C'; did you mean 'B'?");
  EXPECT_EQ(ErrorOf(Replace(kTrain, "S.sun-planet:", "S.sun-planit:")),
            "t.yaml:12: gear_train.dynamics.meshes[S.sun-planit]: no mesh named 'S.sun-planit'; did you "
            "mean 'S.sun-planet'?");
  EXPECT_EQ(ErrorOf(Replace(kTrain, "  output: S.sun\n", "  output: S.sun\n  range: rn\n")),
            "t.yaml:11: gear_train.range: no gear range named 'rn'; did you mean 'run'?");
  EXPECT_NE(ErrorOf(Replace(kTrain, "  output: S.sun\n", "  output: S.sun\n  seed: 2\n"))
                .find("t.yaml:11: gear_train.seed: key not allowed here: scenes spell the train out"),
            std::string::npos);
  // Equal spacing needs (Z_s + Z_r) / n integer: reported at the planet count.
  EXPECT_NE(ErrorOf(Replace(kTrain, "planets: 3,", "planets: 5,")).find("t.yaml:3: gear_train.stages[S].planets: "),
            std::string::npos);
  // An override names the key (no line).
  try {
    LoadSceneFromString(kTrain, "t.yaml", {"gear_train.dynamics.dofs=plane"});
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "t.yaml: --set gear_train.dynamics.dofs: unknown value 'plane'; did you mean 'planar'?");
  }
}

// Member overrides of the stiffness geometry (profile_shift, ISO 21771 sign; addendum_coefficient)
// reach TrainModelOptions; output_torque as a function (a load taken up gradually, seed 000's load
// case) is applied as written and its largest value sets the power flow; with a torque-driven
// input it is refused (the input's constant torque would not follow it).
TEST(GearScene, MemberProfileShiftAndAnOutputTorqueFunction) {
  const std::string shifted = Replace(kTrain, "meshes: {S.sun-planet: {stiffness: 1e9}}",
                                      "members: {S.sun: {profile_shift: 0.3, addendum_coefficient: 0.9}}");
  const Scene s = LoadSceneFromString(shifted, "t.yaml");
  const gears::TrainMemberOverride& sun = s.gear_train->description.options.members.at("S.sun");
  EXPECT_EQ(sun.profile_shift, 0.3);
  EXPECT_EQ(sun.addendum_coefficient, 0.9);
  EXPECT_EQ(ErrorOf(Replace(shifted, "addendum_coefficient: 0.9", "addendum_coefficient: -1")).rfind("t.yaml:12: ", 0), 0u);

  const std::string ramp = Replace(kTrain, "  input_speed_rpm: 20\n",
                                   "  input_speed_rpm: 20\n  output_torque: {type: smooth_step, t0: 0, t1: 0.005, "
                                   "v0: 0, v1: -1000}\n");
  const Scene r = LoadSceneFromString(ramp, "t.yaml");
  const gears::TrainModelOptions& o = r.gear_train->description.options;
  ASSERT_TRUE(o.output_torque_n_m.has_value());
  EXPECT_EQ(o.output_torque_n_m->Value(0.0), 0.0);
  EXPECT_EQ(o.output_torque_n_m->Value(0.005), -1000.0);
  EXPECT_EQ(o.output_port_torque_n_m, -1000.0);
  EXPECT_EQ(ErrorOf(Replace(ramp, "  input_speed_rpm: 20\n", "  input_speed_rpm: 20\n  drive: torque\n")),
            "t.yaml:13: gear_train.output_torque: 'output_torque' as a function needs 'drive: speed' (a "
            "torque-driven input keeps its constant torque)");
}

// dynamics.mesh_model: contact (models/train_contact.h through the scene): seed 003's stage with
// tooth contact on its six mesh branches runs its 5 ms, the contact outputs are recorded per
// branch, and in the mean over the last half (after the load taken up at t = 0 has rung down to
// a few percent) the meshes balance the driven members' power-flow torques: sun
// sum_i F_si r_bs = T_c z_s / (z_s + z_r), ring sum_i F_ri r_br = T_c z_r / (z_s + z_r) with
// T_c = 6000 N m. Tolerance: the faceted flank's normal is off the involute normal by up to half
// a facet's roll angle, r_a dphi / 2 of moment arm against r_b (planetary_contact_test.cpp), plus
// the mean of the ringing left over the window, bounded by its amplitude over the cycles seen.
TEST(GearScene, ContactMeshModelRunsSeed003WithTorqueBalanceInTheMean) {
  const Scene scene = LoadScene(ScenePath("seed003_contact_healthy.yaml"), {"solver.end_time=0.005"});
  ASSERT_EQ(scene.kind, SceneKind::kGearTrain);
  EXPECT_EQ(scene.gear_train->options.mesh_model, gears::MeshModel::kContact);
  const std::vector<std::string> expected{"S.sun-planet#1", "S.sun-planet#2", "S.sun-planet#3",
                                          "S.ring-planet#1", "S.ring-planet#2", "S.ring-planet#3"};
  ASSERT_EQ(scene.gear_train->contact_meshes, expected);
  EXPECT_TRUE(scene.gear_train->model->meshes.empty());  // no lumped mesh left
  const fs::path file = fs::path(::testing::TempDir()) / "seed003_contact_healthy.h5";
  {
    ResultFile out = ResultFile::Create(file.string());
    const SimulationReport r = Simulate(*scene.model, scene.simulation, &out);
    out.Close();
    std::printf("%ld steps, %ld residual evaluations, %.1f s wall\n", r.stats.steps,
                r.stats.residual_evaluations, r.wall_s);
  }
  const Hdf5Reader in(file.string());
  const int rows = static_cast<int>(in.ReadMatrix("/time").rows());
  ASSERT_GE(rows, 40);
  // Base radii and tip radii of the stage (module 4 mm, 22.5 deg, standard gears).
  const double m = 4e-3, alpha = 22.5 * std::numbers::pi / 180;
  const double rbs = 0.5 * m * 22 * std::cos(alpha), rbr = 0.5 * m * 50 * std::cos(alpha);
  const double Tc = 6000, Ts = Tc * 22 / 72, Tr = Tc * 50 / 72;
  Eigen::VectorXd sun = Eigen::VectorXd::Zero(rows), ring = Eigen::VectorXd::Zero(rows);
  double max_penetration = 0;
  for (const std::string& name : expected) {
    const Eigen::MatrixXd f = in.ReadMatrix("/external/" + name + "/normal_force");
    const Eigen::MatrixXd pen = in.ReadMatrix("/external/" + name + "/max_penetration");
    ASSERT_EQ(f.rows(), rows);
    EXPECT_TRUE(in.Exists("/external/" + name + "/contact_points"));
    EXPECT_GT(f.col(0).tail(rows / 2).minCoeff(), 0) << name << " lost contact";
    max_penetration = std::max(max_penetration, pen.maxCoeff());
    (name.starts_with("S.sun") ? sun : ring) += f.col(0) * (name.starts_with("S.sun") ? rbs : rbr);
  }
  const Eigen::VectorXd sun_late = sun.tail(rows / 2), ring_late = ring.tail(rows / 2);
  // Facet error: 40 involute intervals over the roll angle to the tip of the sun (ring: the
  // planet's, the larger roll per interval), r_a dphi / 2 against r_b.
  auto facet = [&](double z, double ra) {
    const double rb = 0.5 * m * z * std::cos(alpha);
    const double roll = std::sqrt(ra * ra - rb * rb) / rb;
    return ra * (roll / 40) / 2 / rb;
  };
  const double facet_sun = facet(22, 0.5 * m * 22 + m), facet_ring = facet(14, 0.5 * m * 14 + m);
  // Ringing: half the peak to peak over the window, over the number of samples (its mean over
  // samples of an oscillation that alternates sign every sample or two).
  auto ringing = [&](const Eigen::VectorXd& x) {
    return 0.5 * (x.maxCoeff() - x.minCoeff()) / x.size();
  };
  std::printf("sun %.0f N m (%.0f), ring %.0f N m (%.0f); largest penetration %.1f um\n", sun_late.mean(),
              Ts, ring_late.mean(), Tr, 1e6 * max_penetration);
  EXPECT_NEAR(sun_late.mean(), Ts, facet_sun * Ts + ringing(sun_late));
  EXPECT_NEAR(ring_late.mean(), Tr, facet_ring * Tr + ringing(ring_late));
  // Below the scene's contact margin (100 um), where a penetration is still seen.
  EXPECT_LT(max_penetration, 100e-6);
}

TEST(GearScene, ContactMeshModelErrors) {
  const std::string head = R"(
gear_train:
  stages:
    - {name: S, type: single_planet, planets: 3, sun: 22, planet: 14, ring: 50, module_mm: 4,
       pressure_angle_deg: 22.5, face_width_mm: 40}
  ranges: {steer: []}
  inputs: [S.ring, S.sun]
  output: S.carrier
  input_speeds: [80.6, 10]
  output_torque: -6000
solver: {end_time: 0.001}
output: {interval: 0.001}
)";
  auto with = [&](const std::string& dynamics) { return head.substr(0, head.find("solver")) + "  dynamics: " + dynamics + "\n" + head.substr(head.find("solver")); };
  EXPECT_EQ(ErrorOf(with("{mesh_model: contact}")), "");
  EXPECT_NE(ErrorOf(with("{tooth_contact: {hunt_crossley: 1}}")).find("tooth_contact needs a contact mesh"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_model: rigid}")).find("mesh_model"), std::string::npos);
  EXPECT_NE(ErrorOf(with("{meshes: {S.sun-planat: {model: contact}}}")).find("no mesh named 'S.sun-planat'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_model: contact, tooth_contact: {missing_teeth: [{gear: S.planet, branch: 4, teeth: [0]}]}}"))
                .find("must be in 1..3"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_model: contact, tooth_contact: {missing_teeth: [{gear: S.sun, teeth: [22]}]}}"))
                .find("0..21"),
            std::string::npos);
  // A broken planet tooth loads (the removal itself is tests/contact/broken_tooth_test.cpp).
  const Scene s = LoadSceneFromString(
      with("{mesh_model: contact, tooth_contact: {missing_teeth: [{gear: S.planet, branch: 2, teeth: [0]}]}}"), "t.yaml");
  EXPECT_EQ(s.gear_train->contact_meshes.size(), 6u);
  // The flexible planets' surface options.
  EXPECT_NE(ErrorOf(with("{mesh_model: contact, tooth_contact: {flexible: {face_intervals: 0}}}"))
                .find("face_intervals: must be >= 1"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_model: contact, tooth_contact: {flexible: {embed_tolerance_um: -1}}}"))
                .find("embed_tolerance_um"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_model: contact, tooth_contact: {flexible: {face_interval: 2}}}"))
                .find("face_intervals"),
            std::string::npos);
  // Recorded contact points: a count, named when wrong; recorded as n x 3 and n columns.
  EXPECT_NE(ErrorOf(with("{mesh_model: contact, tooth_contact: {record_points: -2}}"))
                .find("record_points: must be in 0..1000"),
            std::string::npos);
  const Scene r = LoadSceneFromString(with("{mesh_model: contact, tooth_contact: {record_points: 4}}"), "t.yaml");
  const auto& e = *r.model->external_forces[0];
  const std::vector<OutputDescription>& outputs = e.outputs();
  ASSERT_EQ(outputs.back().name, "point_normal_forces");
  EXPECT_EQ(outputs.back().columns, 4);
  EXPECT_EQ(outputs[outputs.size() - 2].columns, 12);
}

// dynamics.faults: errors at the entry (gear, branch, tooth, the kind's keys, the gear's geometry,
// a lumped mesh without TVMS); a broken planet tooth at the lumped (TVMS over the planet's 14
// teeth on its two meshes, branch 2 only) and contact levels.
TEST(GearScene, TrainFaultsFromYaml) {
  const std::string head = R"(
gear_train:
  stages:
    - {name: S, type: single_planet, planets: 3, sun: 22, planet: 14, ring: 50, module_mm: 4,
       pressure_angle_deg: 22.5, face_width_mm: 40}
  ranges: {steer: []}
  inputs: [S.ring, S.sun]
  output: S.carrier
  input_speeds: [80.6, -10]
  output_torque: -6000
solver: {end_time: 0.001}
output: {interval: 0.001}
)";
  auto with = [&](const std::string& dynamics) { return head.substr(0, head.find("solver")) + "  dynamics: " + dynamics + "\n" + head.substr(head.find("solver")); };
  const std::string broken = "kind: broken_tooth, tooth: 3, height_fraction: 0.5, face_fraction: 1";
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.planit, branch: 1, " + broken + "}]}"))
                .find("no gear named 'S.planit'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.planet, " + broken + "}]}")).find("needs 'branch'"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.planet, branch: 4, " + broken + "}]}"))
                .find("must be in 1..3"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.sun, branch: 1, " + broken + "}]}"))
                .find("a branch is for planets"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.planet, branch: 1, kind: broken_tooth, tooth: 14}]}"))
                .find("0..13"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.planet, branch: 1, " + broken + ", depth_um: 20}]}"))
                .find("does not apply to a broken_tooth"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{faults: [{gear: S.planet, branch: 1, " + broken + "}]}")).find("mesh_stiffness: tvms"),
            std::string::npos);
  EXPECT_NE(ErrorOf(with("{mesh_stiffness: tvms, faults: [{gear: S.planet, branch: 1, kind: broken_tooth, tooth: 3, "
                         "height_fraction: 1.5}]}"))
                .find("height_fraction"),
            std::string::npos);
  // Lumped: the planet's two meshes on branch 2 span its 14 teeth, the others one mesh cycle.
  const Scene lumped =
      LoadSceneFromString(with("{mesh_stiffness: tvms, faults: [{gear: S.planet, branch: 2, " + broken + "}]}"), "t.yaml");
  ASSERT_EQ(lumped.gear_train->options.tooth_faults.size(), 1u);
  EXPECT_EQ(lumped.gear_train->options.tooth_faults[0].branch, 1);
  std::map<std::pair<int, int>, double> lowest;  // (train mesh, branch): the table's minimum
  auto low = [&](int mesh, int branch) { return lowest[std::pair{mesh, branch}]; };
  for (const gears::TrainMeshElement& e : lumped.gear_train->model->meshes) {
    EXPECT_EQ(e.table_cycles, 14) << e.train_mesh << "#" << e.branch;
    const auto& table = lumped.model->gear_meshes[e.model_mesh].spec.stiffness_table;
    ASSERT_EQ(table.size(), 14u * 64);
    lowest[std::pair{e.train_mesh, e.branch}] = *std::min_element(table.begin(), table.end());
  }
  // Where the lost tip would carry the load alone, branch 2's stiffness falls below the healthy
  // branches' single-pair minimum.
  for (int mesh : {0, 1}) {
    EXPECT_LT(low(mesh, 1), 0.9 * low(mesh, 0)) << "mesh " << mesh;
    EXPECT_NEAR(low(mesh, 2), low(mesh, 0), 1e-9 * low(mesh, 0)) << "mesh " << mesh;
  }
  // Contact: the same entry loads with faulty surfaces.
  const Scene contact = LoadSceneFromString(
      with("{mesh_model: contact, faults: [{gear: S.planet, branch: 2, " + broken + "}]}"), "t.yaml");
  EXPECT_EQ(contact.gear_train->contact_meshes.size(), 6u);
}

// A flexible planet in tooth contact whose reduced body is not the train's planet (15 teeth for
// the stage's 14) is refused, naming the planet.
TEST(GearScene, ContactMeshModelRefusesAFlexiblePlanetOfAnotherGear) {
  const fs::path dir = fs::path(::testing::TempDir()) / "flexible_contact_planet";
  fs::remove_all(dir);
  fs::create_directories(dir);
  {
    std::ofstream in(dir / "planet15.yaml");
    in << "gear: {teeth: 15, module_mm: 4, pressure_angle_deg: 22.5, face_width_mm: 40, bore_diameter_mm: 20}\n"
          "mesh: {element: hex8, flank_divisions: 2, fillet_divisions: 1, tooth_divisions: 2,\n"
          "       root_layer_divisions: 1, rim_divisions: 1, face_divisions: 1}\n"
          "material: {E: 206e9, nu: 0.3, rho: 7850}\n"
          "interfaces: [{name: bore, node_set: BORE}]\n"
          "reduction: {modes: 4}\n"
          "outputs: {stress_modes: false, geometric_stiffness: false}\n";
  }
  const std::string text = R"(
gear_train:
  stages:
    - {name: S, type: single_planet, planets: 3, sun: 22, planet: 14, ring: 50, module_mm: 4,
       pressure_angle_deg: 22.5, face_width_mm: 40}
  ranges: {steer: []}
  inputs: [S.ring, S.sun]
  output: S.carrier
  input_speeds: [80.6, 10]
  output_torque: -6000
  dynamics:
    mesh_model: contact
    flexible_bodies:
      S.planet1: {reduced_body: planet15.h5, reduce_input: planet15.yaml}
solver: {end_time: 0.001}
output: {interval: 0.001}
)";
  {
    std::ofstream scene(dir / "scene.yaml");
    scene << text;
  }
  std::string error;
  try {
    LoadScene((dir / "scene.yaml").string(), {}, {.make_reduced_bodies = true});
  } catch (const SceneError& e) {
    error = e.what();
  }
  // Refused by the assembler's identity check of flexible gears (models/train_bodies.cpp, before
  // any mesh is built: every mesh model), from the reduce input's provenance
  EXPECT_NE(error.find("flexible body 'S.planet1' (gear z=15"), std::string::npos) << error;
  EXPECT_NE(error.find("is not the gear 'S.planet' (z = 14, m_n = 0.004 m, b = 0.04 m): its tooth count is 15"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("scene.yaml"), std::string::npos) << error;
}

}  // namespace
}  // namespace orrery

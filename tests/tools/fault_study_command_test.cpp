// The fault study (tools/cli/fault_study_command.h) on seed 003's stage with lumped TVMS meshes
// (22/14/50, 3 planets, ring +80.6 rad/s, sun -10 rad/s: f_m = 220.3 Hz, f_p^H = 15.74 Hz,
// docs/validation/scenarios.md), planet 1 with half the face width of a tooth broken off
// (the potential-energy TVMS of that tooth halved over its engagement).
// Oracles:
// - the mesh line at the kinematic f_m (seed 003: 220.3 Hz) within the spectrum's resolution;
// - a broken planet tooth meets the sun and the ring once per planet turn relative to the carrier,
//   so its mesh force is modulated at f_p^H: sidebands at k f_m +- n f_p^H which the healthy run
//   (a TVMS periodic in one mesh cycle) lacks; they must grow by more than 20 dB. A healthy
//   periodic record leaves only the mesh line's window leakage there, and a sideband's level sums
//   the bins within 2 of it (LinePower), so its nearest bin lies f_p^H T - 2 bins from the mesh
//   line: for the study's default record (0.27 s, 4.25 bins) that is 2.25 bins, the Hann
//   window's first sidelobe (-31.5 dB), while the faulty ±1 sidebands sit some 18 dB below the
//   mesh line; so this test analyses 0.4 s (6.3 bins: the nearest bin 4.3 bins away, where
//   Hann's sidelobes are below -50 dB), and the growth must exceed 20 dB;
// - the folder's results are not overwritten without --force (one error line);
// - the two runs go at once in child processes (forked_run.h): a run that fails in its child is
//   reported on one line with its reason, and the other run is stopped.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "models/planetary_scenes.h"
#include "models/train_description.h"
#include "tests/common/cli_support.h"
#include "tests/tools/signal_run_files.h"
#include "tools/cli/fault_study_analysis.h"
#include "tools/cli/fault_study_command.h"

namespace orrery::cli {
namespace {

namespace fs = std::filesystem;
using test_support::IsOneErrorLine;
using test_support::JsonNumber;

Scene Seed003Lumped(bool faulty) {
  gears::GearTrainDescription d = gears::MakeSeed003StageDescription(-10);
  d.options.mesh_stiffness_source = gears::MeshStiffnessSource::kTvms;
  d.options.mesh_damping_ratio = 0.05;
  d.options.sensors = {{.name = "rp1", .kind = SensorKind::kGearMesh, .mesh = "S.ring-planet#1"},
                       {.name = "carrier", .kind = SensorKind::kAngularAccelerometer, .body = "S.carrier", .axes = {2}}};
  if (faulty)
    d.options.tooth_faults = {{.gear = "S.planet", .branch = 0,
                               .spec = {.kind = gears::ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0,
                                        .height_fraction = 1.0, .face_fraction = 0.5}}};
  gears::GearTrainAssembly a = gears::AssembleGearTrain(d);
  auto g = std::make_shared<GearTrainScene>();
  g->description = d;
  g->train = a.train;
  g->range = a.range;
  g->input_speeds_rad_s = {80.6, -10};
  g->options = a.options;
  g->model = std::make_shared<const gears::TrainModel>(std::move(a.model));
  Scene s;
  s.name = "seed003_lumped";
  s.kind = SceneKind::kGearTrain;
  s.model = g->model->model;
  s.gear_train = g;
  s.simulation.end_time = kFaultStudyT0 + 0.4;  // 0.4 s analysed (header)
  s.simulation.output_interval = 1e-4;
  return s;
}

class FaultStudyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() / ("orrery_fault_study_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  int Study(const Scene& faulty, const Scene& healthy, bool force = false) {
    FaultStudyArgs args{.scene_path = "seed003_lumped (C++)", .output_dir = dir_, .force = force, .plots = false,
                        .quiet = true};
    std::ostringstream out, err;
    const int code = RunFaultStudy(faulty, healthy, args, out, err);
    out_ = out.str();
    err_ = err.str();
    return code;
  }
  std::string dir_, out_, err_;
};

TEST_F(FaultStudyTest, BrokenPlanetToothRaisesTheSidebandsTheHealthyRunLacks) {
  const Scene faulty = Seed003Lumped(true), healthy = Seed003Lumped(false);
  ASSERT_EQ(Study(faulty, healthy), 0) << err_;
  for (const char* name : {"healthy.h5", "faulty.h5", "summary.json", "summary.md"})
    EXPECT_TRUE(fs::exists(fs::path(dir_) / name)) << name;
  std::ifstream in(fs::path(dir_) / "summary.json");
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const double resolution = JsonNumber(json, "resolution_hz");
  EXPECT_NEAR(JsonNumber(json, "mesh_frequency_hz"), 220.3, 0.05);
  EXPECT_NEAR(JsonNumber(json, "mesh_frequency_found_hz"), 220.3, resolution);
  EXPECT_GT(JsonNumber(json, "sideband_energy_ratio"), 100);
  EXPECT_NE(out_.find("| f_m + f_p^H |"), std::string::npos) << out_;

  // The sidebands around the first mesh harmonic, read again from the files
  const FaultStudyAnalysis a = AnalyseFaultStudy((fs::path(dir_) / "healthy.h5").string(),
                                                 (fs::path(dir_) / "faulty.h5").string(),
                                                 {.signal = "/sensors/rp1/force", .t0_s = kFaultStudyT0,
                                                  .fault_gear = "S.planet", .fault_on_planet = true});
  EXPECT_NEAR(a.modulation.frequency_hz, 15.74, 0.01);
  int checked = 0;
  for (const SidebandLevel& s : a.sidebands)
    if (s.harmonic == 1 && std::abs(s.order) <= 2) {
      EXPECT_GT(s.faulty_db - s.healthy_db, 20) << s.label << " at " << s.frequency_hz << " Hz";
      ++checked;
    }
  EXPECT_EQ(checked, 4);

  // A second study into the same folder is refused without --force, allowed with it
  EXPECT_EQ(Study(faulty, healthy), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {dir_, "fault study", "--force"}));
}

TEST_F(FaultStudyTest, RefusesAHealthySceneAndAFolderThatIsAFile) {
  const Scene healthy = Seed003Lumped(false);
  EXPECT_EQ(Study(healthy, healthy), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {"declares no tooth faults"}));
  std::ofstream(dir_) << "x";
  EXPECT_EQ(Study(Seed003Lumped(true), healthy), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {dir_, "not a folder"}));
  fs::remove(dir_);
}

TEST_F(FaultStudyTest, ARunThatFailsInItsProcessIsReportedWithItsReason) {
  // faulty.h5 a folder: the faulty run's child cannot create its result file
  fs::create_directories(fs::path(dir_) / "faulty.h5");
  EXPECT_EQ(Study(Seed003Lumped(true), Seed003Lumped(false), /*force=*/true), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {"faulty run failed", "faulty.h5", "the healthy run was stopped"})) << err_;
  EXPECT_FALSE(fs::exists(fs::path(dir_) / "summary.json"));
}

}  // namespace
}  // namespace orrery::cli

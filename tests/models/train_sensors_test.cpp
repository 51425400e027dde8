// Sensors of a gear train (TrainModelOptions::sensors, models/train_sensors.cpp), and what the
// mesh signals they record must show on seed 003's stage (22/14/50, 3 planets).
//
// Planet phasing (Parker 2000, "A physical explanation for the effectiveness of planet phasing to
// suppress planetary gear vibration", J. Sound Vib. 236(4) 561-573): with N equally spaced planets
// the mesh of planet n lags planet 1's by Z_s psi_n / 2 pi mesh cycles (sun) and Z_r psi_n / 2 pi
// (ring). The k-th mesh harmonic of the net mesh force on a central member (its torque) is the sum
// of N phasors exp(-2 pi i k Z (n-1) / N), which vanishes unless k Z / N is an integer. For
// Z_s = 22, Z_r = 50, N = 3 the sun's and ring's net torques keep harmonics k = 3, 6, ... and lose
// k = 1, 2, 4, 5; each single mesh carries all of them. The model's phasing comes from the involute
// (train_dynamics.h, "Mesh phasing"), not from Parker's formula: the test is an oracle for it.
// Tolerance: a planet mesh out of phase by d cycles leaves a residual of about 2 pi k d / N of a
// single mesh's harmonic; 1 % bounds d below 0.005 cycles (a wrong phasing by one tooth, 1 / Z,
// leaves tens of percent), and the cyclic symmetry of the model holds to the integrator's tolerance.
#include <cmath>
#include <complex>
#include <filesystem>
#include <numbers>

#include <gtest/gtest.h>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/sensor_signals.h"
#include "mbd/simulation.h"
#include "models/planetary_scenes.h"
#include "models/train_description.h"

namespace orrery::gears {
namespace {

GearTrainDescription LumpedStage() {
  GearTrainDescription d = MakeSeed003StageDescription(-10);
  d.options.mesh_stiffness_source = MeshStiffnessSource::kTvms;
  d.options.mesh_damping_ratio = 0.05;
  return d;
}

TEST(TrainSensors, ResolveAgainstTheTrainAndReadTheKinematics) {
  GearTrainDescription d = LumpedStage();
  const double r = 0.12;
  d.options.sensors = {
      {.name = "ring_xy", .kind = SensorKind::kAccelerometer, .body = "S.ring", .position_m = Vec3(r, 0, 0),
       .measured_in = "world", .axes = {0, 1}},
      {.name = "carrier_speed", .kind = SensorKind::kTachometer, .joint = "S.carrier"},
      {.name = "sp1", .kind = SensorKind::kGearMesh, .mesh = "S.sun-planet#1"},
      {.name = "rp2_te", .kind = SensorKind::kGearMesh, .mesh = "S.ring-planet#2",
       .quantity = MeshQuantity::kTransmissionError}};
  const GearTrainAssembly a = AssembleGearTrain(d);
  const Model& m = *a.model.model;
  ASSERT_EQ(m.sensors.size(), 4u);
  EXPECT_EQ(m.frames[m.sensors[0].spec.frame].body, a.model.member_bodies[a.train->member_by_name.at("S.ring")]);
  EXPECT_EQ(m.joints[m.sensors[1].spec.joint].spec.name, "S.carrier");
  EXPECT_EQ(m.gear_meshes[m.sensors[2].spec.gear_mesh].spec.name, "S.sun-planet#1");
  EXPECT_EQ(m.sensors[3].spec.mesh_quantity, MeshQuantity::kTransmissionError);

  // At the initial state (members at their kinematic speeds, no accelerations): the ring point
  // reads the centripetal acceleration -w_r^2 r along x, the tachometer the carrier's speed
  const State x0 = State::Initial(m);
  Data data(m);
  CalcSensorSignals(m, 0, x0.q, x0.v, Eigen::VectorXd::Zero(m.nv), data);
  const double w_r = 80.6;
  EXPECT_NEAR(data.sensor_values(0), -w_r * w_r * r, 1e-9 * w_r * w_r * r);
  EXPECT_NEAR(data.sensor_values(1), 0, 1e-9 * w_r * w_r * r);
  const int carrier = a.train->member_by_name.at("S.carrier");
  EXPECT_NEAR(data.sensor_values(2), a.model.kinematics.speeds_rad_s(carrier), 1e-9);
}

TEST(TrainSensors, ErrorsNameTheSensorAndWhatIsWrong) {
  auto error = [](TrainSensor s) {
    GearTrainDescription d = LumpedStage();
    d.options.mesh_models["S.sun-planet#1"] = MeshModel::kKinematic;
    d.options.sensors = {s};
    try {
      AssembleGearTrain(d);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error({.name = "a", .body = "S.moon"}).find("sensor 'a': body 'S.moon' is no body of the train"),
            std::string::npos);
  EXPECT_NE(error({.name = "b", .kind = SensorKind::kGearMesh, .mesh = "S.sun-planet#1"}).find("is kinematic"),
            std::string::npos);
  EXPECT_NE(error({.name = "c", .kind = SensorKind::kGearMesh, .mesh = "S.sun-planet#7"}).find("no lumped or contact"),
            std::string::npos);
  EXPECT_NE(error({.name = "d", .body = "S.ring", .node = 3}).find("is rigid"), std::string::npos);
}

// Hann-weighted DFT amplitude of x at f (single-sided, a sine of amplitude A reads A).
double Amplitude(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double f) {
  std::complex<double> sum = 0;
  double weight = 0;
  const double t0 = t(0), span = t(t.size() - 1) - t(0);
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * (t(i) - t0) / span);
    sum += w * x(i) * std::polar(1.0, -2 * std::numbers::pi * f * t(i));
    weight += w;
  }
  return 2 * std::abs(sum) / weight;
}

TEST(TrainSensors, PlanetPhasingCancelsTheNetMeshTorqueHarmonicsParker2000) {
  GearTrainDescription d = LumpedStage();
  for (const char* mesh : {"S.sun-planet", "S.ring-planet"})
    for (int n = 1; n <= 3; ++n) {
      const std::string branch = std::string(mesh) + "#" + std::to_string(n);
      d.options.sensors.push_back({.name = branch, .kind = SensorKind::kGearMesh, .mesh = branch});
    }
  const GearTrainAssembly a = AssembleGearTrain(d);
  const State x0 = SolveTrainStaticState(a.model, State::Initial(*a.model.model));
  const std::string path = (std::filesystem::temp_directory_path() / "orrery_train_sensors_parker.h5").string();
  SimulationOptions o;
  o.end_time = 0.12;
  o.output_interval = 1e-4;
  {
    ResultFile out = ResultFile::Create(path);
    Simulate(*a.model.model, o, &out, {}, &x0);
  }
  const Hdf5Reader r(path);
  const Eigen::MatrixXd time = r.ReadMatrix("/time");
  // The last 20 mesh cycles (the start transient decays within a few)
  const double f_m = 220.3;  // seed 003 case 1 (docs/validation/scenarios.md)
  const Eigen::Index n = static_cast<Eigen::Index>(std::round(20 / f_m / o.output_interval));
  const Eigen::VectorXd t = time.col(0).tail(n);
  for (const char* mesh : {"S.sun-planet", "S.ring-planet"}) {
    Eigen::VectorXd net = Eigen::VectorXd::Zero(n), single;
    for (int p = 1; p <= 3; ++p) {
      const Eigen::VectorXd f = r.ReadMatrix("/sensors/" + std::string(mesh) + "#" + std::to_string(p) + "/force").col(0).tail(n);
      if (p == 1) single = f;
      net += f;
    }
    for (int k = 1; k <= 6; ++k) {
      const double one = Amplitude(t, single, k * f_m), sum = Amplitude(t, net, k * f_m);
      ASSERT_GT(one, 1.0) << mesh << " harmonic " << k << ": a single mesh carries it (N)";
      if (k % 3 == 0)
        EXPECT_NEAR(sum / one, 3.0, 0.03) << mesh << " harmonic " << k << " adds up in phase";
      else
        EXPECT_LT(sum / one, 0.01) << mesh << " harmonic " << k << " cancels";
    }
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace orrery::gears

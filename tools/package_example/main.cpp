// A small program built against the installed Orrery package: a compound pendulum released at a
// small angle theta0, built in C++ and again from a YAML scene, integrated with IDA over half the
// small-amplitude period T = 2 pi sqrt(I_o / (m g c)) with results written to an HDF5 file.
// After T/2 the angle is -theta0 (to 1e-9 relative: the amplitude lengthens the period by a
// factor 1 + theta0^2 / 16); the program prints theta(T/2) / theta0 and fails if it is not -1 to
// 1e-5 (the integrator's tolerance) or if the two models disagree.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include "import/scene.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace {

constexpr double kMass = 1.0, kArm = 0.5, kGravity = 9.81, kTheta0 = 0.01;
constexpr double kInertiaCm = 0.083358;  // rod of 1 m about its centre, kg m^2

std::shared_ptr<const orrery::Model> BuildInCpp() {
  using namespace orrery;
  ModelBuilder b;
  const BodyIndex rod =
      b.AddBody("rod", kMass, Vec3(0, -kArm, 0), Vec3(kInertiaCm, 5e-5, kInertiaCm).asDiagonal());
  const JointIndex hinge = b.AddJoint({.name = "hinge",
                                       .type = JointType::kRevolute,
                                       .parent = kWorldBody,
                                       .child = rod,
                                       .axis = Vec3::UnitZ()});
  b.SetJointPosition(hinge, Eigen::VectorXd::Constant(1, kTheta0));
  b.SetGravity(Vec3(0, -kGravity, 0));
  return std::move(b).Finalize();
}

const char* kScene = R"(
name: pendulum
gravity: [0, -9.81, 0]
bodies:
  - {name: rod, mass: 1.0, com: [0, -0.5, 0], inertia: [0.083358, 0.00005, 0.083358]}
joints:
  - {name: hinge, type: revolute, parent: world, child: rod, axis: [0, 0, 1],
     initial_position: 0.01}
solver: {integrator: ida, end_time: 1.0}
output: {interval: 1e-3}
)";

double FinalAngle(const orrery::Model& model, double end_time, const std::string& h5) {
  orrery::SimulationOptions opt;
  opt.end_time = end_time;
  opt.output_interval = end_time / 100;
  opt.integrator.rtol = 1e-9;
  opt.integrator.atol = 1e-11;
  orrery::ResultFile out = orrery::ResultFile::Create(h5);
  return orrery::Simulate(model, opt, &out).final_state.q(0);
}

}  // namespace

int main() {
  const double inertia_o = kInertiaCm + kMass * kArm * kArm;
  const double period = 2 * std::numbers::pi * std::sqrt(inertia_o / (kMass * kGravity * kArm));
  const auto dir = std::filesystem::temp_directory_path();
  const double cpp =
      FinalAngle(*BuildInCpp(), period / 2, (dir / "orrery_example_cpp.h5").string());
  const orrery::Scene scene = orrery::LoadSceneFromString(kScene, "pendulum.yaml");
  const double yaml =
      FinalAngle(*scene.model, period / 2, (dir / "orrery_example_yaml.h5").string());
  const double ratio = cpp / kTheta0;
  std::printf("pendulum: theta(T/2) / theta0 = %.9f (expected -1), YAML scene %.9f\n", ratio,
              yaml / kTheta0);
  const bool ok = std::abs(ratio + 1) < 1e-5 && std::abs(cpp - yaml) < 1e-12;
  if (!ok) std::printf("pendulum: FAILED\n");
  return ok ? 0 : 1;
}

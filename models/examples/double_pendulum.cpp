// A double pendulum written as a C++ scene: two links on revolute joints, released from rest.
// Writes double_pendulum.h5 and prints the energy error of the run.
//
//   build/bin/example_double_pendulum [end_time_s]
#include <cstdio>
#include <cstdlib>

#include "mbd/model.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

using namespace orrery;

int main(int argc, char** argv) {
  const double end_time = argc > 1 ? std::atof(argv[1]) : 5.0;
  const double L = 0.5, m = 1.0;
  const Mat3 I = Vec3(1e-4, m * L * L / 12, m * L * L / 12).asDiagonal();  // slender rod along x

  ModelBuilder b;
  b.SetGravity(Vec3(0, -9.81, 0));
  const BodyIndex upper = b.AddBody("upper", m, Vec3(L / 2, 0, 0), I);
  const BodyIndex lower = b.AddBody("lower", m, Vec3(L / 2, 0, 0), I);
  const JointIndex shoulder = b.AddJoint({.name = "shoulder", .type = JointType::kRevolute,
                                          .parent = kWorldBody, .child = upper, .axis = Vec3::UnitZ()});
  const JointIndex elbow = b.AddJoint({.name = "elbow", .type = JointType::kRevolute, .parent = upper,
                                       .child = lower, .X_PF = Transform::Translation(Vec3(L, 0, 0)),
                                       .axis = Vec3::UnitZ()});
  b.SetJointPosition(shoulder, Eigen::VectorXd::Constant(1, 0.5));
  b.SetJointPosition(elbow, Eigen::VectorXd::Constant(1, 1.0));
  const std::shared_ptr<const Model> model = std::move(b).Finalize();

  SimulationOptions options;
  options.end_time = end_time;
  options.output_interval = 1e-3;
  options.integrator.rtol = 1e-8;
  options.integrator.atol = 1e-10;
  options.scene_name = "double pendulum (C++ example)";
  ResultFile out = ResultFile::Create("double_pendulum.h5");
  const SimulationReport report = Simulate(*model, options, &out);
  out.Close();

  // Energy at the start and the end, from the file.
  const Hdf5Reader in("double_pendulum.h5");
  const Eigen::MatrixXd energy = in.ReadMatrix("/energy");
  const double e0 = energy.row(0).sum(), e1 = energy.row(energy.rows() - 1).sum();
  std::printf("double pendulum: %.1f s simulated in %.3f s wall, %ld steps; energy %.9f -> %.9f J\n",
              end_time, report.wall_s, report.stats.steps, e0, e1);
  return 0;
}

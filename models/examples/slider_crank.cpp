// A slider-crank written as a C++ scene: the crank turns at constant speed, the connecting rod
// sits on a universal joint at the crank pin and is tied to the slider by a spherical loop
// closure (a revolute cut in this planar loop would give redundant constraint rows). Prints the
// driving torque range and writes slider_crank.h5.
//
//   build/bin/example_slider_crank [crank_speed_rad_s]
#include <cstdio>
#include <cstdlib>

#include "mbd/model.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

using namespace orrery;

int main(int argc, char** argv) {
  const double speed = argc > 1 ? std::atof(argv[1]) : 20.0;
  const double r = 0.1, l = 0.35;

  ModelBuilder b;
  b.SetGravity(Vec3(0, -9.81, 0));
  const BodyIndex crank = b.AddBody("crank", 2.0, Vec3(r / 2, 0, 0), Vec3(1e-3, 2e-3, 2e-3).asDiagonal());
  const BodyIndex rod = b.AddBody("rod", 1.5, Vec3(l / 2, 0, 0), Vec3(1e-4, 1.5e-2, 1.5e-2).asDiagonal());
  const BodyIndex slider = b.AddBody("slider", 3.0, Vec3::Zero(), Vec3(2e-3, 2e-3, 2e-3).asDiagonal());
  b.AddJoint({.name = "crank_bearing", .type = JointType::kRevolute, .parent = kWorldBody, .child = crank,
              .axis = Vec3::UnitZ()});
  b.AddJoint({.name = "crank_pin", .type = JointType::kUniversal, .parent = crank, .child = rod,
              .X_PF = Transform::Translation(Vec3(r, 0, 0)), .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitY()});
  const JointIndex guide = b.AddJoint({.name = "guide", .type = JointType::kPrismatic, .parent = kWorldBody,
                                       .child = slider, .axis = Vec3::UnitX()});
  b.SetJointPosition(guide, Eigen::VectorXd::Constant(1, r + l));
  // Close the loop at the wrist pin: rod end meets the slider.
  const FrameIndex rod_end = b.AddFrame("rod_end", rod, Transform::Translation(Vec3(l, 0, 0)));
  b.AddLoopClosure({.name = "wrist_pin", .type = JointType::kSpherical, .frame_a = b.body_frame(slider),
                    .frame_b = rod_end});
  b.AddDriver({.name = "motor", .joint = b.draft().joint("crank_bearing"), .coordinate = 0,
               .mode = DriverSpec::Mode::kSpeed, .function = TimeFunction::Constant(speed)});
  const std::shared_ptr<const Model> model = std::move(b).Finalize();

  SimulationOptions options;
  options.end_time = 1.0;
  options.output_interval = 1e-3;
  options.scene_name = "slider-crank (C++ example)";
  ResultFile out = ResultFile::Create("slider_crank.h5");
  const SimulationReport report = Simulate(*model, options, &out);
  out.Close();

  const Hdf5Reader in("slider_crank.h5");
  const Eigen::MatrixXd torque = in.ReadMatrix("/drivers/motor/effort");
  const Eigen::MatrixXd x = in.ReadMatrix("/joints/guide/q");
  std::printf("slider-crank at %.1f rad/s: stroke %.4f m, motor torque %.2f .. %.2f N m, "
              "constraint drift %.2e m; %ld steps, %.3f s wall\n",
              speed, x.maxCoeff() - x.minCoeff(), torque.minCoeff(), torque.maxCoeff(),
              report.stats.max_abs_phi, report.stats.steps, report.wall_s);
  return 0;
}

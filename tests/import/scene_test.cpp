// Scene loader: every element kind maps onto the builder, unit conversions, overrides, scenes that
// run, and one test per class of error (file, line and key path in every message).
#include "import/scene.h"

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"

namespace orrery {
namespace {

constexpr double kPi = std::numbers::pi;

// A scene with every element kind (SI units). Line numbers matter only for kPendulum below.
constexpr const char* kEverything = R"(name: everything
gravity: [0, 0, -9.81]
bodies:
  - name: crank
    mass: 2.0
    com: [0.05, 0, 0]
    inertia: [0.001, 0.004, 0.004, 0.0001, 0, 0]
    frames:
      - {name: crank_pin, position: [0.1, 0, 0]}
      - {name: crank_mark, position: [0, 0, 0], rotation: {rpy_deg: [90, 0, 90]}}
  - name: rod
    mass: 1.0
    inertia: [0.0001, 0.0075, 0.0075]
    frames:
      - {name: rod_end, position: [0.3, 0, 0]}
  - {name: slider, mass: 0.5, inertia: [0.001, 0.001, 0.001]}
  - {name: spool, mass: 1.5, inertia: [0.002, 0.002, 0.003]}
  - {name: cap, mass: 0.1, inertia: [0.0001, 0.0001, 0.0001]}
  - name: top
    mass: 1.0
    inertia: [0.01, 0.01, 0.02]
    frames:
      - {name: top_tip, position: [0, 0, 0.2], rotation: {quaternion: [2, 0, 0, 0]}}
  - {name: puck, mass: 0.3, inertia: [0.001, 0.001, 0.0015]}
  - {name: sheet, mass: 0.2, inertia: [0.001, 0.002, 0.003]}
world_frames:
  - {name: anchor, position: [1, 0, 0], rotation: {axis: [0, 0, 1], angle_deg: 90}}
joints:
  - {name: hinge, type: revolute, parent: world, child: crank, axis: [0, 0, 2], initial_velocity: 6.283185307179586}
  - {name: pin, type: universal, parent: crank, child: rod, parent_frame: crank_pin, axis: [0, 0, 1], axis2: [0, 1, 0]}
  - {name: slide, type: prismatic, parent: world, child: slider, axis: [1, 0, 0], initial_position: 0.4}
  - name: cyl
    type: cylindrical
    parent: world
    child: spool
    parent_frame: {position: [0, 1, 0], rotation: [[1, 0, 0], [0, 0, -1], [0, 1, 0]]}
    initial_position_deg: [90, 0.25]
  - {name: weld, type: fixed, parent: spool, child: cap, child_frame: {position: [0, 0, -0.05]}}
  - name: ball
    type: spherical
    parent: world
    child: top
    parent_frame: {position: [0, 2, 0]}
    initial_position: [1, 0, 0, 1]
    initial_velocity_deg: [0, 0, 360]
  - {name: float, type: free, parent: world, child: puck, initial_position: [0, 0, 1, 1, 0, 0, 0], initial_velocity: [0.1, 0, 0, 0, 0, 1]}
  - {name: plane, type: planar, parent: world, child: sheet, axis: [0, 0, 1], axis2: [1, 0, 0], initial_position: [0.1, 0.2, 0.3]}
loop_closures:
  - {name: cut, type: spherical, frame_a: rod_end, frame_b: slider}
drivers:
  - {name: motor, joint: hinge, mode: speed, function: {type: constant, value_rpm: 60}}
  - {name: lift, joint: cyl, coordinate: 1, mode: position, function: {type: ramp, t0: 0, t1: 1, v0: 0.25, v1: 0.5}}
  - name: spin
    joint: ball
    coordinate: 2
    mode: speed
    function: {type: trapezoid, w0_rpm: 0, w1_rpm: 600, w2_rpm: 0, t4: 1, alpha1: 0.1, alpha2: 0.5, alpha3: 0.8}
force_elements:
  - {type: applied_load, name: push, frame: puck, force: [1, 0, 0], torque: [0, 0, 0.5], scale: {type: sine, amplitude: 2, frequency_hz: 5, phase_deg: 90}, in_frame_axes: true}
  - {type: joint_load, name: brake, joint: plane, coordinate: 2, function: {type: table, times: [0, 1, 2], values: [0, -1, 0]}}
  - {type: translational_spring, name: tether, frame_a: anchor, frame_b: puck, stiffness: 100, damping: 2, free_length: 0.5, preload: 3}
  - {type: rotational_spring, name: twist, frame_a: world, frame_b: sheet, stiffness: 10, damping: 0.1, angle0_deg: 45}
  - {type: torsional_spring_to_ground, name: k_hinge, joint: hinge, stiffness: 50, damping: 0.5, q0: 0.1}
  - {type: coordinate_spring, name: k_slide, joint: slide, stiffness: 1000, q0: 0.4}
  - type: bushing
    name: bearing
    frame_a: world
    frame_b: top_tip
    stiffness: [1e6, 1e6, 1e6, 1e3, 1e3, 0]
    damping: [[10, 0, 0, 0, 0, 0], [0, 10, 0, 0, 0, 0], [0, 0, 10, 0, 0, 0],
              [0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 0]]
solver: {integrator: generalized_alpha, end_time: 2, step: 1e-4, rho_inf: 0.8, rtol: 1e-7}
output: {interval: 0.01, file: everything_out.h5, flush_interval: 5}
)";

TEST(SceneTest, EveryElementKindLoads) {
  const Scene scene = LoadSceneFromString(kEverything, "everything.yaml");
  const Model& m = *scene.model;
  // Sizes: q 1+2+1+2+0+4+7+3, v 1+2+1+2+0+3+6+3; rows: spherical cut 3, position driver 1,
  // speed drivers 2.
  EXPECT_EQ(m.nbodies, 9);
  EXPECT_EQ(m.nq, 20);
  EXPECT_EQ(m.nv, 18);
  EXPECT_EQ(m.n_holonomic, 4);
  EXPECT_EQ(m.n_constraints, 6);
  EXPECT_EQ(m.joints.size(), 8u);
  EXPECT_EQ(m.loop_closures.size(), 1u);
  EXPECT_EQ(m.drivers.size(), 3u);
  EXPECT_EQ(m.applied_loads.size(), 1u);
  EXPECT_EQ(m.joint_loads.size(), 1u);
  EXPECT_EQ(m.translational_springs.size(), 1u);
  EXPECT_EQ(m.rotational_springs.size(), 1u);
  EXPECT_EQ(m.coordinate_springs.size(), 2u);
  EXPECT_EQ(m.bushings.size(), 1u);
  EXPECT_EQ(m.gravity, Vec3(0, 0, -9.81));

  // Bodies: inertia with a product term, centre of mass.
  const Body& crank = m.bodies[m.body("crank")];
  EXPECT_DOUBLE_EQ(crank.mass, 2.0);
  EXPECT_EQ(crank.com_B, Vec3(0.05, 0, 0));
  EXPECT_DOUBLE_EQ(crank.inertia_cm_B(0, 1), 0.0001);
  EXPECT_DOUBLE_EQ(crank.inertia_cm_B(1, 0), 0.0001);
  EXPECT_DOUBLE_EQ(crank.inertia_cm_B(2, 2), 0.004);

  // Frames: rpy, axis-angle, normalized quaternion.
  const Frame& mark = m.frames[m.frame("crank_mark")];
  EXPECT_EQ(mark.body, m.body("crank"));
  // R = Rz(90) Ry(0) Rx(90): x -> y, y -> z (the other order would send y to -x).
  EXPECT_NEAR((mark.X_BF.R * Vec3::UnitX() - Vec3::UnitY()).norm(), 0, 1e-15);
  EXPECT_NEAR((mark.X_BF.R * Vec3::UnitY() - Vec3::UnitZ()).norm(), 0, 1e-15);
  const Frame& anchor = m.frames[m.frame("anchor")];
  EXPECT_EQ(anchor.body, kWorldBody);
  EXPECT_EQ(anchor.X_BF.p, Vec3(1, 0, 0));
  EXPECT_NEAR((anchor.X_BF.R * Vec3::UnitX() - Vec3::UnitY()).norm(), 0, 1e-15);
  EXPECT_NEAR((m.frames[m.frame("top_tip")].X_BF.R - Mat3::Identity()).norm(), 0, 1e-15);

  // Joints: normalized axis, frame by name, 3x3 rotation, initial values with units.
  const Joint& hinge = m.joints[m.joint("hinge")];
  EXPECT_EQ(hinge.axis, Vec3::UnitZ());
  EXPECT_DOUBLE_EQ(m.v_initial(hinge.v_start), 2 * kPi);
  const Joint& pin = m.joints[m.joint("pin")];
  EXPECT_EQ(pin.spec.type, JointType::kUniversal);
  EXPECT_EQ(pin.spec.X_PF.p, Vec3(0.1, 0, 0));
  EXPECT_EQ(pin.axis2, Vec3::UnitY());
  EXPECT_DOUBLE_EQ(m.q_initial(m.joints[m.joint("slide")].q_start), 0.4);
  const Joint& cyl = m.joints[m.joint("cyl")];
  EXPECT_NEAR((cyl.spec.X_PF.R * Vec3::UnitZ() - (-Vec3::UnitY())).norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(m.q_initial(cyl.q_start), kPi / 2);  // _deg converts the angle only
  EXPECT_DOUBLE_EQ(m.q_initial(cyl.q_start + 1), 0.25);
  EXPECT_EQ(m.joints[m.joint("weld")].spec.X_CM.p, Vec3(0, 0, -0.05));
  const Joint& ball = m.joints[m.joint("ball")];
  EXPECT_NEAR(m.q_initial(ball.q_start), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(m.q_initial(ball.q_start + 3), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(m.v_initial(ball.v_start + 2), 2 * kPi, 1e-12);
  const Joint& free = m.joints[m.joint("float")];
  EXPECT_DOUBLE_EQ(m.q_initial(free.q_start + 2), 1.0);
  EXPECT_DOUBLE_EQ(m.v_initial(free.v_start + 5), 1.0);
  const Joint& plane = m.joints[m.joint("plane")];
  EXPECT_DOUBLE_EQ(m.q_initial(plane.q_start + 2), 0.3);

  // Loop closure and drivers (rpm converted; trapezoid plateau 600 rpm).
  EXPECT_EQ(m.loop_closures[0].type, JointType::kSpherical);
  EXPECT_EQ(m.loop_closures[0].frame_a, m.frame("rod_end"));
  EXPECT_EQ(m.loop_closures[0].frame_b, m.frame("slider"));
  const DriverSpec& motor = m.drivers[m.driver("motor")].spec;
  EXPECT_EQ(motor.mode, DriverSpec::Mode::kSpeed);
  EXPECT_NEAR(motor.function.Value(0.3), 2 * kPi, 1e-12);
  const DriverSpec& lift = m.drivers[m.driver("lift")].spec;
  EXPECT_EQ(lift.mode, DriverSpec::Mode::kPosition);
  EXPECT_EQ(lift.coordinate, 1);
  EXPECT_DOUBLE_EQ(lift.function.Value(0.5), 0.375);
  const DriverSpec& spin = m.drivers[m.driver("spin")].spec;
  EXPECT_EQ(spin.function.kind(), TimeFunction::Kind::kTrapezoid);
  EXPECT_NEAR(spin.function.Value(0.2), 20 * kPi, 1e-12);  // plateau t1 = 0.1 .. t2 = 0.3
  EXPECT_NEAR(spin.function.Value(0.05), 10 * kPi, 1e-12);

  // Force elements.
  const AppliedLoadSpec& push = m.applied_loads[0];
  EXPECT_EQ(push.frame, m.frame("puck"));
  EXPECT_EQ(push.torque, Vec3(0, 0, 0.5));
  EXPECT_TRUE(push.in_frame_axes);
  EXPECT_NEAR(push.scale.Value(0), 2.0, 1e-12);  // sin(90 deg)
  EXPECT_EQ(m.joint_loads[0].coordinate, 2);
  EXPECT_DOUBLE_EQ(m.joint_loads[0].function.Value(0.5), -0.5);
  const TranslationalSpringSpec& tether = m.translational_springs[0];
  EXPECT_EQ(tether.frame_a, m.frame("anchor"));
  EXPECT_DOUBLE_EQ(tether.stiffness, 100);
  EXPECT_DOUBLE_EQ(tether.damping, 2);
  EXPECT_DOUBLE_EQ(tether.free_length, 0.5);
  EXPECT_DOUBLE_EQ(tether.preload, 3);
  EXPECT_DOUBLE_EQ(m.rotational_springs[0].angle0, kPi / 4);
  EXPECT_DOUBLE_EQ(m.coordinate_springs[0].stiffness, 50);
  EXPECT_DOUBLE_EQ(m.coordinate_springs[0].q0, 0.1);
  EXPECT_EQ(m.coordinate_springs[1].joint, m.joint("slide"));
  EXPECT_DOUBLE_EQ(m.coordinate_springs[1].damping, 0);
  const BushingSpec& bearing = m.bushings[0];
  EXPECT_DOUBLE_EQ(bearing.stiffness(0, 0), 1e6);
  EXPECT_DOUBLE_EQ(bearing.stiffness(4, 4), 1e3);
  EXPECT_DOUBLE_EQ(bearing.stiffness(0, 1), 0);
  EXPECT_DOUBLE_EQ(bearing.damping(3, 3), 1);

  // Solver and output.
  EXPECT_EQ(scene.name, "everything");
  EXPECT_EQ(scene.simulation.scene_name, "everything");
  EXPECT_EQ(scene.simulation.integrator.kind, IntegratorKind::kGeneralizedAlpha);
  EXPECT_DOUBLE_EQ(scene.simulation.end_time, 2);
  EXPECT_DOUBLE_EQ(scene.simulation.integrator.step, 1e-4);
  EXPECT_DOUBLE_EQ(scene.simulation.integrator.rho_inf, 0.8);
  EXPECT_DOUBLE_EQ(scene.simulation.integrator.rtol, 1e-7);
  EXPECT_TRUE(std::isnan(scene.simulation.integrator.alpha_m));
  EXPECT_DOUBLE_EQ(scene.simulation.output_interval, 0.01);
  EXPECT_DOUBLE_EQ(scene.simulation.flush_interval_s, 5);
  EXPECT_EQ(scene.output_path, "everything_out.h5");
  EXPECT_EQ(scene.source_path, "");
  EXPECT_EQ(scene.simulation.scene_text, kEverything);  // no overrides: the text as written
}

// units: {length: mm} scales every quantity whose unit contains a length (Adams MMKS).
TEST(SceneTest, MillimetreUnitsConvertToSi) {
  const Scene scene = LoadSceneFromString(R"(units: {length: mm}
gravity: [0, -9810, 0]
bodies:
  - {name: arm, mass: 2, com: [50, 0, 0], inertia: [1000, 2000, 2500, 100, 0, 0],
     frames: [{name: arm_tip, position: [100, 0, 0]}]}
  - {name: carriage, mass: 1, inertia: [1000, 1000, 1000]}
joints:
  - {name: shoulder, type: revolute, parent: world, child: arm, parent_frame: {position: [0, 0, 10]}, initial_velocity_deg: 90}
  - {name: rail, type: prismatic, parent: world, child: carriage, axis: [1, 0, 0], initial_position: 400, initial_velocity: 20}
drivers:
  - {name: feed, joint: rail, mode: speed, function: {type: ramp, t0: 0, t1: 1, v0: 0, v1: 10}}
force_elements:
  - {type: applied_load, name: load, frame: arm_tip, force: [0, -5, 0], torque: [0, 0, 1000]}
  - {type: joint_load, name: motor, joint: shoulder, function: 2000}
  - {type: joint_load, name: push, joint: rail, function: 3}
  - {type: translational_spring, name: spring, frame_a: world, frame_b: arm_tip, stiffness: 2, damping: 0.5, free_length: 100}
  - {type: rotational_spring, name: coil, frame_a: world, frame_b: arm, stiffness: 1000, damping: 10}
  - {type: coordinate_spring, name: stop, joint: rail, stiffness: 1, damping: 0.1, q0: 400}
  - {type: coordinate_spring, name: wind, joint: shoulder, stiffness: 3000, q0_deg: 30}
  - {type: bushing, name: mount, frame_a: world, frame_b: carriage,
     stiffness: [[1, 0, 0, 0, 7, 0], [0, 1, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0],
                 [0, 0, 0, 1000, 0, 0], [0, 0, 0, 0, 1000, 0], [5, 0, 0, 0, 0, 1000]]}
solver: {end_time: 1}
output: {interval: 0.01}
)",
                                          "units.yaml");
  const Model& m = *scene.model;
  EXPECT_NEAR(m.gravity.y(), -9.81, 1e-12);
  const Body& arm = m.bodies[m.body("arm")];
  EXPECT_NEAR(arm.com_B.x(), 0.05, 1e-15);
  EXPECT_NEAR(arm.inertia_cm_B(0, 0), 1e-3, 1e-15);   // kg mm^2 -> kg m^2
  EXPECT_NEAR(arm.inertia_cm_B(0, 1), 1e-4, 1e-15);
  EXPECT_NEAR(m.frames[m.frame("arm_tip")].X_BF.p.x(), 0.1, 1e-15);
  EXPECT_NEAR(m.joints[m.joint("shoulder")].spec.X_PF.p.z(), 0.01, 1e-15);
  const Joint& rail = m.joints[m.joint("rail")];
  EXPECT_NEAR(m.q_initial(rail.q_start), 0.4, 1e-15);
  EXPECT_NEAR(m.v_initial(rail.v_start), 0.02, 1e-15);
  EXPECT_NEAR(m.v_initial(m.joints[m.joint("shoulder")].v_start), kPi / 2, 1e-15);  // angles stay
  EXPECT_NEAR(m.drivers[0].spec.function.Value(1.0), 0.01, 1e-15);  // mm/s -> m/s
  EXPECT_EQ(m.applied_loads[0].force, Vec3(0, -5, 0));                // N stays N
  EXPECT_NEAR(m.applied_loads[0].torque.z(), 1.0, 1e-15);              // N mm -> N m
  EXPECT_NEAR(m.joint_loads[0].function.Value(0), 2.0, 1e-15);         // torque: N mm -> N m
  EXPECT_NEAR(m.joint_loads[1].function.Value(0), 3.0, 1e-15);         // force: N
  const TranslationalSpringSpec& spring = m.translational_springs[0];
  EXPECT_NEAR(spring.stiffness, 2000, 1e-9);                           // N/mm -> N/m
  EXPECT_NEAR(spring.damping, 500, 1e-9);
  EXPECT_NEAR(spring.free_length, 0.1, 1e-15);
  EXPECT_NEAR(m.rotational_springs[0].stiffness, 1.0, 1e-15);          // N mm/rad -> N m/rad
  EXPECT_NEAR(m.rotational_springs[0].damping, 0.01, 1e-15);
  EXPECT_NEAR(m.coordinate_springs[0].stiffness, 1000, 1e-9);          // on a slide: N/mm
  EXPECT_NEAR(m.coordinate_springs[0].damping, 100, 1e-9);
  EXPECT_NEAR(m.coordinate_springs[0].q0, 0.4, 1e-15);
  EXPECT_NEAR(m.coordinate_springs[1].stiffness, 3.0, 1e-15);          // on a hinge: N mm/rad
  EXPECT_NEAR(m.coordinate_springs[1].q0, kPi / 6, 1e-15);
  const Mat6& K = m.bushings[0].stiffness;
  EXPECT_NEAR(K(0, 0), 1000, 1e-9);  // N/mm -> N/m
  EXPECT_NEAR(K(3, 3), 1.0, 1e-15);  // N mm/rad -> N m/rad
  EXPECT_NEAR(K(0, 4), 7.0, 1e-15);  // N/rad stays
  EXPECT_NEAR(K(5, 0), 5.0, 1e-15);  // N mm/mm = N stays
}

// The pendulum used by the run and error tests. Line numbers are referred to by the error tests:
//  4 "- name: bob", 5 mass, 6 com, 7 inertia, 9 "- name: hinge", 12 child, 13 axis,
// 16 end_time, 17 rtol, 20 interval.
constexpr const char* kPendulum = R"(name: pendulum
gravity: [0, -9.81, 0]
bodies:
  - name: bob
    mass: 1.0
    com: [0, -0.5, 0]
    inertia: [0.0833, 0.0001, 0.0833]
joints:
  - name: hinge
    type: revolute
    parent: world
    child: bob
    axis: [0, 0, 1]
    initial_position: 1.0
solver:
  end_time: 0.1
  rtol: 1e-9
  atol: 1e-11
output:
  interval: 0.01
)";

// kPendulum with one line replaced (the line numbers of the others stay).
std::string With(const std::string& line, const std::string& replacement) {
  std::string text = kPendulum;
  const size_t at = text.find(line + "\n");
  EXPECT_NE(at, std::string::npos) << line;
  return text.replace(at, line.size(), replacement);
}

// The message of the SceneError that loading `text` throws ("" if none).
std::string ErrorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    LoadSceneFromString(text, "bad.yaml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// The message starts with "bad.yaml:LINE: PATH: " and contains `reason`.
void ExpectError(const std::string& message, int line, const std::string& path,
                 const std::string& reason) {
  const std::string prefix = "bad.yaml:" + std::to_string(line) + ": " + path + ": ";
  EXPECT_EQ(message.substr(0, prefix.size()), prefix) << message;
  EXPECT_NE(message.find(reason), std::string::npos) << message;
}

// Integrates I_o theta'' = -m g c sin(theta) by classical Runge-Kutta (the oracle).
double PendulumAngle(double theta0, double t_end, double k) {
  const int n = 20000;
  const double h = t_end / n;
  double th = theta0, w = 0;
  for (int i = 0; i < n; ++i) {
    const double k1t = w, k1w = -k * std::sin(th);
    const double k2t = w + 0.5 * h * k1w, k2w = -k * std::sin(th + 0.5 * h * k1t);
    const double k3t = w + 0.5 * h * k2w, k3w = -k * std::sin(th + 0.5 * h * k2t);
    const double k4t = w + h * k3w, k4w = -k * std::sin(th + h * k3t);
    th += h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t);
    w += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
  }
  return th;
}

TEST(SceneTest, PendulumRunsWithoutResultFile) {
  const Scene scene = LoadSceneFromString(kPendulum, "pendulum.yaml");
  EXPECT_EQ(scene.output_path, "pendulum.h5");
  const SimulationReport report = Simulate(*scene.model, scene.simulation, nullptr);
  EXPECT_DOUBLE_EQ(report.final_state.t, 0.1);
  EXPECT_EQ(report.output_rows, 11);
  // m g c / I_o with I_o = I_zz + m c^2.
  const double k = 1.0 * 9.81 * 0.5 / (0.0833 + 0.25);
  EXPECT_NEAR(report.final_state.q(0), PendulumAngle(1.0, 0.1, k), 1e-7);
  EXPECT_LT(report.final_state.q(0), 1.0 - 0.05);  // it did swing
}

TEST(SceneTest, OverridesEditTheTreeBeforeValidation) {
  const Scene scene = LoadSceneFromString(
      kPendulum, "pendulum.yaml",
      {"bodies.bob.mass=2", "joints[hinge].initial_position=0.5", "gravity=[0, 0, -1]",
       "solver.integrator=generalized_alpha", "output.file=run.h5", "bodies.bob.com.1=-0.25"});
  const Model& m = *scene.model;
  EXPECT_DOUBLE_EQ(m.bodies[m.body("bob")].mass, 2.0);
  EXPECT_DOUBLE_EQ(m.bodies[m.body("bob")].com_B.y(), -0.25);
  EXPECT_DOUBLE_EQ(m.q_initial(0), 0.5);
  EXPECT_EQ(m.gravity, Vec3(0, 0, -1));
  EXPECT_EQ(scene.simulation.integrator.kind, IntegratorKind::kGeneralizedAlpha);
  EXPECT_EQ(scene.output_path, "run.h5");
  // The scene text lists the overrides and is the edited scene: it loads to the same model.
  const std::string& text = scene.simulation.scene_text;
  EXPECT_NE(text.find("--set bodies.bob.mass=2"), std::string::npos) << text;
  const Scene again = LoadSceneFromString(text, "again.yaml");
  EXPECT_DOUBLE_EQ(again.model->bodies[1].mass, 2.0);
  EXPECT_DOUBLE_EQ(again.model->q_initial(0), 0.5);
  EXPECT_EQ(again.output_path, "run.h5");
}

// The example scenes in models/scenes load and run 0.05 s.
TEST(SceneTest, ExamplePendulumLoadsAndRuns) {
  const std::string path = ORRERY_SOURCE_DIR "/models/scenes/pendulum.yaml";
  const Scene full = LoadScene(path);
  EXPECT_EQ(full.name, "compound pendulum");
  EXPECT_EQ(full.source_path, path);
  EXPECT_EQ(full.output_path, "pendulum.h5");
  EXPECT_DOUBLE_EQ(full.simulation.end_time, 10);
  EXPECT_NEAR(full.model->q_initial(0), 150 * kPi / 180, 1e-15);
  const Scene scene = LoadScene(path, {"solver.end_time=0.05"});
  const SimulationReport report = Simulate(*scene.model, scene.simulation, nullptr);
  EXPECT_DOUBLE_EQ(report.final_state.t, 0.05);
  const Body& rod = scene.model->bodies[1];
  const double k = rod.mass * 9.81 * 0.5 / (rod.inertia_cm_B(2, 2) + rod.mass * 0.25);
  EXPECT_NEAR(report.final_state.q(0), PendulumAngle(150 * kPi / 180, 0.05, k), 1e-7);
}

TEST(SceneTest, ExampleSliderCrankLoadsAndRuns) {
  const Scene scene =
      LoadScene(ORRERY_SOURCE_DIR "/models/scenes/slider_crank.yaml", {"solver.end_time=0.05"});
  const Model& m = *scene.model;
  EXPECT_EQ(m.nq, 4);
  EXPECT_EQ(m.nv, 4);
  EXPECT_EQ(m.n_constraints, 4);  // spherical closure 3 + speed driver 1
  const SimulationReport report = Simulate(m, scene.simulation, nullptr);
  EXPECT_DOUBLE_EQ(report.final_state.t, 0.05);
  EXPECT_LT(report.stats.max_abs_phi, 1e-6);
  // Crank at 120 rpm; slider at r cos(theta) + sqrt(L^2 - r^2 sin^2(theta)).
  const double theta = 4 * kPi * 0.05, r = 0.1, L = 0.3;
  const Eigen::VectorXd& q = report.final_state.q;
  EXPECT_NEAR(q(m.joints[m.joint("crank_hinge")].q_start), theta, 1e-6);
  EXPECT_NEAR(q(m.joints[m.joint("slider_guide")].q_start),
              r * std::cos(theta) + std::sqrt(L * L - r * r * std::sin(theta) * std::sin(theta)),
              1e-6);
}

// Sensors ------------------------------------------------------------------------------------

// The pendulum with a sensors section (its first item on line 22).
std::string WithSensors(const std::string& sensors) {
  return std::string(kPendulum) + "sensors:\n" + sensors;
}

TEST(SceneSensorTest, EveryFrameAndJointKindLoads) {
  const Scene scene = LoadSceneFromString(
      WithSensors("  - {name: a, type: accelerometer, body: bob, position: [0, -1, 0], measured_in: world, "
                  "axes: [y, x], include_gravity: true}\n"
                  "  - {name: v, type: velocity, frame: bob}\n"
                  "  - {name: d, type: displacement, body: bob, position: [0, -1, 0], "
                  "rotation: {axis: [0, 0, 1], angle_deg: 90}}\n"
                  "  - {name: g, type: gyroscope, frame: bob, axes: [z]}\n"
                  "  - {name: al, type: angular_accelerometer, frame: bob, measured_in: bob}\n"
                  "  - {name: e, type: encoder, joint: hinge}\n"
                  "  - {name: t, type: tachometer, joint: hinge, coordinate: 0}\n"),
      "sensors.yaml");
  const Model& m = *scene.model;
  ASSERT_EQ(m.sensors.size(), 7u);
  const Sensor& a = m.sensors[m.sensor("a")];
  EXPECT_EQ(a.spec.kind, SensorKind::kAccelerometer);
  EXPECT_EQ(a.spec.measured_in, kWorldFrame);
  EXPECT_EQ(a.spec.axes, (std::vector<int>{1, 0}));
  EXPECT_TRUE(a.spec.include_gravity);
  EXPECT_EQ(a.spec.frame, m.frame("bob"));
  EXPECT_EQ(a.spec.X_FS.p, Vec3(0, -1, 0));
  EXPECT_EQ(m.sensors[m.sensor("v")].spec.measured_in, kSensorAxes);
  const Sensor& d = m.sensors[m.sensor("d")];
  EXPECT_EQ(d.spec.measured_in, kWorldFrame);  // a displacement's default
  EXPECT_NEAR((d.spec.X_FS.R * Vec3::UnitX() - Vec3::UnitY()).norm(), 0, 1e-15);
  EXPECT_EQ(m.sensors[m.sensor("g")].channels, 1);
  EXPECT_EQ(m.sensors[m.sensor("al")].spec.measured_in, m.frame("bob"));
  EXPECT_EQ(m.sensors[m.sensor("e")].quantity, "angle");
  EXPECT_EQ(m.sensors[m.sensor("t")].unit, "rad/s");
  EXPECT_TRUE(scene.simulation.sensors.anti_alias);
}

TEST(SceneSensorTest, SamplingOptionsAndLengthUnits) {
  const Scene scene = LoadSceneFromString(
      "units: {length: mm}\n" +
          WithSensors("  - {name: a, type: accelerometer, body: bob, position: [0, -1000, 0]}\n"),
      "sensors.yaml",
      {"output.sensors={oversampling: 16, passband_fraction: 0.7, stopband_attenuation_db: 90}"});
  const Model& m = *scene.model;
  EXPECT_EQ(m.sensors[0].spec.X_FS.p, Vec3(0, -1, 0));
  EXPECT_EQ(scene.simulation.sensors.oversampling, 16);
  EXPECT_EQ(scene.simulation.sensors.passband_fraction, 0.7);
  EXPECT_EQ(scene.simulation.sensors.stopband_attenuation_db, 90);
  const Scene point = LoadSceneFromString(kPendulum, "p.yaml", {"output.sensors={anti_alias: false}"});
  EXPECT_FALSE(point.simulation.sensors.anti_alias);
}

TEST(SceneSensorTest, ErrorsAtTheirKey) {
  auto error = [](const std::string& sensor) { return ErrorOf(WithSensors("  - " + sensor + "\n")); };
  ExpectError(error("{name: a, type: accelerometer, body: bobb}"), 22, "sensors[a].body",
              "no body named 'bobb'; did you mean 'bob'?");
  ExpectError(error("{name: a, type: accelerometer, frame: tip}"), 22, "sensors[a].frame",
              "no frame named 'tip'");
  ExpectError(error("{name: a, type: acelerometer, frame: bob}"), 22, "sensors[a].type",
              "did you mean 'accelerometer'?");
  ExpectError(error("{name: a, type: accelerometer, frame: bob, axes: [x, w]}"), 22,
              "sensors[a].axes[1]", "unknown axis 'w'");
  ExpectError(error("{name: a, type: accelerometer, frame: bob, axes: [x, x]}"), 22,
              "sensors[a].axes[1]", "axis x given twice");
  ExpectError(error("{name: a, type: accelerometer, frame: bob, axes: []}"), 22, "sensors[a].axes",
              "1 to 3 axes");
  ExpectError(error("{name: a, type: accelerometer, frame: bob, measured_in: housing}"), 22,
              "sensors[a].measured_in", "no frame named 'housing'");
  ExpectError(error("{name: a, type: accelerometer, frame: bob, joint: hinge}"), 22,
              "sensors[a].joint", "reads no joint");
  ExpectError(error("{name: a, type: gyroscope, frame: bob, include_gravity: true}"), 22,
              "sensors[a].include_gravity", "only accelerometers");
  ExpectError(error("{name: a, type: accelerometer, frame: bob, body: bob}"), 22, "sensors[a].body",
              "either 'frame' or 'body'");
  ExpectError(error("{name: a, type: accelerometer}"), 22, "sensors[a].frame", "missing 'frame'");
  ExpectError(error("{name: a, type: accelerometer, body: bob, node: 3}"), 22, "sensors[a].node",
              "rigid");
  ExpectError(error("{name: a, type: displacement, frame: bob, measured_in: sensor}"), 22,
              "sensors[a].measured_in", "relative to another frame");
  ExpectError(error("{name: a, type: encoder, joint: hing}"), 22, "sensors[a].joint",
              "did you mean 'hinge'?");
  ExpectError(error("{name: a, type: encoder, joint: hinge, coordinate: 1}"), 22,
              "sensors[a].coordinate", "no coordinate 1");
  ExpectError(error("{name: a, type: gear_mesh, mesh: m}"), 22, "sensors[a].mesh",
              "there are no lumped gear meshes");
  ExpectError(error("{name: a, type: element_output, element: contact, output: force}"), 22,
              "sensors[a].element", "no element named 'contact'");
  ExpectError(ErrorOf(WithSensors("  - {name: a, type: encoder, joint: hinge}\n"
                                  "  - {name: a, type: tachometer, joint: hinge}\n")),
              23, "sensors[a].name", "name already used");
  const std::string sampling = ErrorOf(kPendulum, {"output.sensors={passband_fraction: 1.2}"});
  EXPECT_NE(sampling.find("--set output.sensors: output.sensors.passband_fraction: must be in (0, 1)"),
            std::string::npos) << sampling;
  const std::string point = ErrorOf(kPendulum, {"output.sensors={anti_alias: false, oversampling: 4}"});
  EXPECT_NE(point.find("oversampling: has no effect with anti_alias: false"), std::string::npos) << point;
}

TEST(SceneSensorTest, SliderCrankSensorsMatchTheClosedForm) {
  // The example scene's sensors: the crank pin at 120 rpm sees -omega^2 r along the crank and
  // nothing across; the slider's acceleration is the second derivative of
  // s(theta) = r cos(theta) + sqrt(L^2 - r^2 sin^2(theta)) at theta = omega t (central
  // differences of that formula, step 1e-4 rad: error ~1e-9 m/s^2, far below the filter's
  // ripple times the amplitude, 25 m/s^2 at most).
  const Scene scene = LoadScene(ORRERY_SOURCE_DIR "/models/scenes/slider_crank.yaml",
                                {"solver.end_time=0.3", "solver.rtol=1e-10", "solver.atol=1e-12"});
  const std::string path = ::testing::TempDir() + "orrery_slider_crank_sensors.h5";
  {
    ResultFile out = ResultFile::Create(path);
    Simulate(*scene.model, scene.simulation, &out);
  }
  Hdf5Reader in(path);
  const Eigen::MatrixXd t = in.ReadMatrix("/time");
  const Eigen::MatrixXd slider = in.ReadMatrix("/sensors/slider_acc/acceleration");
  const Eigen::MatrixXd pin = in.ReadMatrix("/sensors/pin_acc/acceleration");
  const double delay = std::stod(in.ReadAttributeText("/sensors", "group_delay_s"));
  const double ripple =
      std::pow(10.0, std::stod(in.ReadAttributeText("/sensors", "passband_ripple_db")) / 20) - 1;
  const double w = 4 * kPi, r = 0.1, L = 0.3, h = 1e-4;
  auto s = [&](double th) {
    return r * std::cos(th) + std::sqrt(L * L - r * r * std::sin(th) * std::sin(th));
  };
  ASSERT_EQ(slider.rows(), t.rows());
  int checked = 0;
  for (int i = 0; i < t.rows(); ++i) {
    if (t(i, 0) < delay + 1e-3 || t(i, 0) > 0.3 - delay - 1e-3) continue;
    const double th = w * t(i, 0);
    const double a = w * w * (s(th + h) - 2 * s(th) + s(th - h)) / (h * h);
    // Harmonics of 2 Hz, far inside the passband: within the ripple (plus integration, 1e-6).
    EXPECT_NEAR(slider(i, 0), a, 25 * (ripple + 1e-6)) << t(i, 0);
    EXPECT_NEAR(pin(i, 0), -w * w * r, 16 * (ripple + 1e-6));
    EXPECT_NEAR(pin(i, 1), 0, 16 * (ripple + 1e-6));
    ++checked;
  }
  EXPECT_GT(checked, 200);
  std::filesystem::remove(path);
}

// Errors -------------------------------------------------------------------------------------

TEST(SceneErrorTest, UnknownKeySuggestsTheClosest) {
  ExpectError(ErrorOf(With("    mass: 1.0", "    mas: 1.0")), 5, "bodies[bob].mas",
              "unknown key 'mas'; did you mean 'mass'?");
  // Far from every key: the allowed keys are listed.
  ExpectError(ErrorOf(With("    mass: 1.0", "    colour: red")), 5, "bodies[bob].colour",
              "allowed: name, mass, com, inertia, frames");
  // A key valid for other joint types says why it is wrong here.
  ExpectError(ErrorOf(With("    type: revolute", "    type: spherical")), 13, "joints[hinge].axis",
              "a spherical joint has no axis");
}

TEST(SceneErrorTest, MissingKeyNamesIt) {
  ExpectError(ErrorOf(With("    mass: 1.0", "")), 4, "bodies[bob].mass",
              "missing required key 'mass'");
  ExpectError(ErrorOf(With("  end_time: 0.1", "")), 15, "solver.end_time",
              "missing required key 'end_time'");
}

TEST(SceneErrorTest, WrongTypeNamesTheExpectedType) {
  ExpectError(ErrorOf(With("    mass: 1.0", "    mass: heavy")), 5, "bodies[bob].mass",
              "expected a number, got 'heavy'");
  ExpectError(ErrorOf(With("    mass: 1.0", "    mass: \"1.0\"")), 5, "bodies[bob].mass",
              "expected a number, got the quoted string");
  ExpectError(ErrorOf(With("    axis: [0, 0, 1]", "    axis: [0, zero, 1]")), 13,
              "joints[hinge].axis[1]", "expected a number");
  ExpectError(ErrorOf(With("    com: [0, -0.5, 0]", "    com: {x: 0}")), 6, "bodies[bob].com",
              "expected a list of 3 numbers, got a map");
  ExpectError(ErrorOf(With("    type: revolute", "    type: revolut")), 10, "joints[hinge].type",
              "unknown type 'revolut'; did you mean 'revolute'?");
}

TEST(SceneErrorTest, WrongListLength) {
  ExpectError(ErrorOf(With("    com: [0, -0.5, 0]", "    com: [0, -0.5]")), 6, "bodies[bob].com",
              "expected a list of 3 numbers, got a list of 2");
  ExpectError(ErrorOf(With("    initial_position: 1.0", "    initial_position: [1, 2]")), 14,
              "joints[hinge].initial_position", "expected a list of 1 number, got a list of 2");
  ExpectError(ErrorOf(With("    inertia: [0.0833, 0.0001, 0.0833]", "    inertia: [1, 1, 1, 0]")),
              7, "bodies[bob].inertia", "3 numbers [Ixx, Iyy, Izz] or 6 numbers");
}

TEST(SceneErrorTest, NonPositiveMass) {
  ExpectError(ErrorOf(With("    mass: 1.0", "    mass: 0")), 5, "bodies[bob].mass",
              "mass must be positive");
  ExpectError(ErrorOf(With("    mass: 1.0", "    mass: -1")), 5, "bodies[bob].mass",
              "mass must be positive");
}

TEST(SceneErrorTest, InertiaViolatingTheTriangleInequality) {
  ExpectError(ErrorOf(With("    inertia: [0.0833, 0.0001, 0.0833]",
                           "    inertia: [0.001, 0.001, 0.01]")),
              7, "bodies[bob].inertia", "triangle inequality");
}

TEST(SceneErrorTest, InertiaNotPositiveDefinite) {
  ExpectError(ErrorOf(With("    inertia: [0.0833, 0.0001, 0.0833]",
                           "    inertia: [0.0833, -0.0001, 0.0833]")),
              7, "bodies[bob].inertia", "not positive definite");
}

TEST(SceneErrorTest, NegativeStiffness) {
  const std::string text = std::string(kPendulum) +
                           "force_elements:\n"
                           "  - {type: coordinate_spring, name: k, joint: hinge, stiffness: -1}\n";
  ExpectError(ErrorOf(text), 22, "force_elements[k].stiffness", "stiffness must be >= 0");
}

TEST(SceneErrorTest, ZeroLengthAxis) {
  ExpectError(ErrorOf(With("    axis: [0, 0, 1]", "    axis: [0, 0, 0]")), 13,
              "joints[hinge].axis", "zero length");
}

TEST(SceneErrorTest, EndTimeMustBePositive) {
  ExpectError(ErrorOf(With("  end_time: 0.1", "  end_time: 0")), 16, "solver.end_time",
              "must be > 0");
  ExpectError(ErrorOf(With("  end_time: 0.1", "  end_time: -2")), 16, "solver.end_time",
              "must be > 0, got -2");
  ExpectError(ErrorOf(With("  interval: 0.01", "  interval: 0")), 20, "output.interval",
              "must be > 0");
  ExpectError(ErrorOf(With("  rtol: 1e-9", "  rtol: 0")), 17, "solver.rtol", "must be > 0");
}

TEST(SceneErrorTest, UnknownReference) {
  ExpectError(ErrorOf(With("    child: bob", "    child: bobb")), 12, "joints[hinge].child",
              "no body named 'bobb'; did you mean 'bob'?");
  ExpectError(ErrorOf(With("    parent: world", "    parent: ground")), 11, "joints[hinge].parent",
              "no body named 'ground' (bodies: bob, world)");
  const std::string text = std::string(kPendulum) +
                           "drivers:\n"
                           "  - {name: d, joint: hinj, mode: speed, function: 1}\n";
  ExpectError(ErrorOf(text), 22, "drivers[d].joint", "no joint named 'hinj'; did you mean 'hinge'?");
}

TEST(SceneErrorTest, DuplicateName) {
  const std::string text =
      With("solver:", "  - {name: hinge, type: fixed, parent: world, child: bob}\nsolver:");
  ExpectError(ErrorOf(text), 15, "joints[hinge].name",
              "duplicate joint name 'hinge' (first defined at line 9)");
  // A frame may not take a body's name (the body frame has it).
  ExpectError(ErrorOf(With("    inertia: [0.0833, 0.0001, 0.0833]",
                           "    inertia: [0.0833, 0.0001, 0.0833]\n    frames: [{name: bob}]")),
              8, "bodies[bob].frames[bob].name", "'bob' is already a body");
}

TEST(SceneErrorTest, BadOverridePath) {
  // A missing intermediate element: the file, the override, where it stopped (line 3).
  const std::string message = ErrorOf(kPendulum, {"bodies.bobb.mass=2"});
  EXPECT_EQ(message, "bad.yaml: --set bodies.bobb.mass: no item named 'bobb' in 'bodies' (line 3); "
                     "did you mean 'bob'?");
  EXPECT_NE(ErrorOf(kPendulum, {"solver.tolerances.rtol=1"}).find(
                "bad.yaml: --set solver.tolerances.rtol: no key 'tolerances' in 'solver' (line 15)"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kPendulum, {"solver.end_time"}).find("expected KEY.PATH=VALUE"),
            std::string::npos);
  // A new key is added, then validated like any other.
  EXPECT_EQ(ErrorOf(kPendulum, {"solver.end_tme=2"}),
            "bad.yaml: --set solver.end_tme: unknown key 'end_tme'; did you mean 'end_time'?");
  // A value set by an override is reported against the override.
  EXPECT_EQ(ErrorOf(kPendulum, {"solver.end_time=-1"}),
            "bad.yaml: --set solver.end_time: must be > 0, got -1");
  const std::string mass = ErrorOf(kPendulum, {"bodies.bob.mass=-2"});
  EXPECT_EQ(mass.substr(0, 33), "bad.yaml: --set bodies.bob.mass: ") << mass;
  EXPECT_NE(mass.find("mass must be positive"), std::string::npos) << mass;
  EXPECT_EQ(ErrorOf(kPendulum, {"bodies.bob.com=[1, 2]"}),
            "bad.yaml: --set bodies.bob.com: expected a list of 3 numbers, got a list of 2");
}

TEST(SceneErrorTest, RotationsAndSyntax) {
  ExpectError(ErrorOf(With("    axis: [0, 0, 1]",
                           "    axis: [0, 0, 1]\n    parent_frame: {rotation: [[1, 0, 0], [0, 1, 0], "
                           "[0, 0, 2]]}")),
              14, "joints[hinge].parent_frame.rotation", "not a rotation");
  ExpectError(ErrorOf(With("    axis: [0, 0, 1]",
                           "    axis: [0, 0, 1]\n    parent_frame: {rotation: {axis: [0, 0, 1]}}")),
              14, "joints[hinge].parent_frame.rotation.angle", "missing required key 'angle'");
  const std::string syntax = ErrorOf(With("    com: [0, -0.5, 0]", "    com: [0, -0.5, 0"));
  EXPECT_EQ(syntax.rfind("bad.yaml:", 0), 0u) << syntax;
  EXPECT_NE(syntax.find("YAML syntax error"), std::string::npos) << syntax;
  // A file that does not exist.
  EXPECT_THROW(LoadScene("/nonexistent/scene.yaml"), SceneError);
}

}  // namespace
}  // namespace orrery

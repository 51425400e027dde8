// Sensor readings (mbd/sensor_signals.cpp) against oracles that share no code with them:
// - the kinematics of frame sensors (rigid bodies on revolute, universal and free joints; node
//   frames of a flexible body, elastic motion included) against central differences in time of
//   the frame poses that CalcPositionKinematics gives along q(tau) = q (+) (tau v + tau^2/2 vdot),
//   a curve with velocity v and acceleration vdot at tau = 0; the tolerance is the differences'
//   own error, estimated by Richardson's comparison of steps h and h/2;
// - joint, mesh and element sensors against the quantities the force stages compute for the
//   result file at the same state.
// Also: the builder's validation of sensors.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "mbd/data.h"
#include "mbd/force_elements.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/sensor_signals.h"
#include "mbd/state.h"

namespace orrery {
namespace {

JointSpec Joint(const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                const Transform& X_PF = Transform(), const Vec3& axis = Vec3::UnitZ(),
                const Vec3& axis2 = Vec3::UnitX()) {
  JointSpec j;
  j.name = name, j.type = type, j.parent = parent, j.child = child, j.X_PF = X_PF;
  j.axis = axis, j.axis2 = axis2;
  return j;
}

// A flexible body of point masses: a rigid core and two nodes moved by two modes; node 1 also
// turns (rotation shapes), so a frame off it swings with it.
std::shared_ptr<FlexibleBodyModes> TwoModeBody() {
  auto m = std::make_shared<FlexibleBodyModes>();
  const int n = 2;
  m->nf = n;
  m->I2 = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
  m->I4.assign(n, Mat3::Zero());
  m->I5.assign(n * n, Mat3::Zero());
  for (const Vec3& x : {Vec3(0.2, 0, 0), Vec3(-0.1, 0.2, 0.05), Vec3(0, -0.1, 0.25)}) {
    m->mass += 1.0;
    m->I1 += x;
    m->I3 += x * x.transpose();
  }
  for (int j = 0; j < 2; ++j) {
    FlexibleBodyModes::Node node;
    node.id = 10 + j;
    node.position = Vec3(0.3, 0.1 * j, -0.05);
    node.translation_shapes = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    node.translation_shapes.col(j) = Vec3(0.3, 1, 0.2 * j).normalized();
    node.translation_shapes.col(1 - j) = Vec3(0.1, 0, 0.4);
    node.rotation_shapes = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    if (j == 1) {
      node.rotation_shapes.col(0) = Vec3(0.5, -0.2, 1.0);
      node.rotation_shapes.col(1) = Vec3(-0.3, 0.8, 0.1);
    }
    const double mass = 0.4;
    m->mass += mass;
    m->I1 += mass * node.position;
    m->I3 += mass * node.position * node.position.transpose();
    m->I2 += mass * node.translation_shapes;
    for (int k = 0; k < n; ++k) {
      m->I4[k] += mass * node.position * node.translation_shapes.col(k).transpose();
      for (int l = 0; l < n; ++l)
        m->I5[k * n + l] += mass * node.translation_shapes.col(k) * node.translation_shapes.col(l).transpose();
    }
    m->nodes.push_back(node);
  }
  m->stiffness = Eigen::Vector2d(900, 1600).asDiagonal();
  return m;
}

// Bodies on revolute, universal and free joints, a flexible body on a revolute joint carried by
// the universal one, gravity; frames with offsets and rotations on each.
struct Chain {
  std::shared_ptr<const Model> model;
  FrameIndex rigid_mark, floater_mark, node_frame, offset_node_frame, crank, arm;
  // Sensor places: (frame, pose in the frame); sensors "acc<k>", ... sit at place k.
  std::vector<std::pair<FrameIndex, Transform>> places;
};

Chain BuildChain() {
  ModelBuilder b;
  const Mat3 I = Vec3(2e-3, 3e-3, 4e-3).asDiagonal();
  const BodyIndex crank = b.AddBody("crank", 1.0, Vec3(0.05, 0, 0), I);
  const BodyIndex arm = b.AddBody("arm", 0.5, Vec3(0.1, 0, 0), I);
  const BodyIndex floater = b.AddBody("floater", 2.0, Vec3(0.01, 0.02, 0), I);
  b.AddJoint(Joint("crank", JointType::kRevolute, kWorldBody, crank,
                   Transform(AxisAngle(Vec3::UnitX(), 0.2), Vec3(0.1, 0, 0.3))));
  b.AddJoint(Joint("arm", JointType::kUniversal, crank, arm, Transform::Translation(Vec3(0.2, 0, 0)),
                   Vec3::UnitZ(), Vec3::UnitY()));
  b.AddJoint(Joint("floater", JointType::kFree, kWorldBody, floater, Transform::Translation(Vec3(0, 1, 0))));
  const BodyIndex flex = b.AddFlexibleBody("flex", TwoModeBody());
  b.AddJoint(Joint("flex", JointType::kRevolute, arm, flex, Transform::Translation(Vec3(0.3, 0, 0)),
                   Vec3(0, 1, 0.2).normalized()));
  b.SetGravity(Vec3(0, -9.81, 0));
  Chain c;
  c.rigid_mark = b.AddFrame("arm_mark", arm, Transform(AxisAngle(Vec3(1, 1, 0).normalized(), 0.7), Vec3(0.25, 0.03, -0.02)));
  c.floater_mark = b.AddFrame("floater_mark", floater, Transform(AxisAngle(Vec3::UnitY(), -0.4), Vec3(0.1, 0, 0.05)));
  c.node_frame = b.AddNodeFrame("node", flex, 0, Transform::Translation(Vec3(0.3, 0, -0.05)));
  c.offset_node_frame = b.AddNodeFrame("node_offset", flex, 1,
                                       Transform(AxisAngle(Vec3::UnitZ(), 0.5), Vec3(0.35, 0.2, 0.0)));
  c.crank = b.body_frame(crank);
  c.arm = b.body_frame(arm);
  // Every frame sensor kind at every kind of place, measured in various axes: at frames, and at
  // poses on a body's frame and on a turning node's frame.
  const Transform X_FS(AxisAngle(Vec3(0.2, -1, 0.4).normalized(), 1.1), Vec3(-0.04, 0.06, 0.03));
  c.places = {{c.rigid_mark, Transform()}, {c.floater_mark, Transform()}, {c.node_frame, Transform()},
              {c.offset_node_frame, Transform()}, {c.arm, X_FS}, {c.offset_node_frame, X_FS}};
  int k = 0;
  for (const auto& [f, X] : c.places) {
    const std::string s = std::to_string(k++);
    b.AddSensor({.name = "acc" + s, .kind = SensorKind::kAccelerometer, .frame = f, .X_FS = X});
    b.AddSensor({.name = "accg" + s, .kind = SensorKind::kAccelerometer, .frame = f, .X_FS = X,
                 .measured_in = kWorldFrame, .axes = {2, 0}, .include_gravity = true});
    b.AddSensor({.name = "vel" + s, .kind = SensorKind::kVelocity, .frame = f, .X_FS = X,
                 .measured_in = c.crank});
    b.AddSensor({.name = "disp" + s, .kind = SensorKind::kDisplacement, .frame = f, .X_FS = X,
                 .measured_in = kWorldFrame});
    b.AddSensor({.name = "gyro" + s, .kind = SensorKind::kGyroscope, .frame = f, .X_FS = X});
    b.AddSensor({.name = "alpha" + s, .kind = SensorKind::kAngularAccelerometer, .frame = f, .X_FS = X,
                 .measured_in = kWorldFrame, .axes = {1}});
  }
  b.AddSensor({.name = "deflection", .kind = SensorKind::kDisplacement, .frame = c.node_frame,
               .measured_in = b.body_frame(flex)});
  b.AddSensor({.name = "encoder", .kind = SensorKind::kEncoder, .joint = b.draft().joint("arm"),
               .coordinate = 1});
  b.AddSensor({.name = "tacho", .kind = SensorKind::kTachometer, .joint = b.draft().joint("floater"),
               .coordinate = 4});
  c.model = std::move(b).Finalize();
  return c;
}

// A state with every velocity and acceleration nonzero; the modal coordinates, rates and
// accelerations scaled by `modal_scale`.
struct TestState {
  Eigen::VectorXd q, v, vdot;
};
TestState MakeState(const Model& m, double modal_scale) {
  TestState s{m.q_initial, Eigen::VectorXd::LinSpaced(m.nv, -1.3, 1.7), Eigen::VectorXd::LinSpaced(m.nv, 2.1, -0.9)};
  Eigen::VectorXd dq = Eigen::VectorXd::LinSpaced(m.nv, 0.4, -0.3);
  const FlexibleBody& fb = m.flexible_bodies[0];
  for (Eigen::VectorXd* x : {&s.v, &s.vdot, &dq}) x->segment(fb.v_start, fb.nf) *= modal_scale;
  IntegratePositions(m, dq, s.q);
  return s;
}

// Pose of S (pose X_FS in frame f) at q(tau) = q (+) (tau v + tau^2 / 2 vdot).
Transform PoseAt(const Model& m, const TestState& s, double tau, FrameIndex f, Data& data,
                 const Transform& X_FS = Transform()) {
  Eigen::VectorXd q = s.q;
  IntegratePositions(m, tau * s.v + 0.5 * tau * tau * s.vdot, q);
  CalcPositionKinematics(m, q, data);
  return data.X_WFrame[f] * X_FS;
}

Vec3 Vee(const Mat3& S) { return 0.5 * Vec3(S(2, 1) - S(1, 2), S(0, 2) - S(2, 0), S(1, 0) - S(0, 1)); }

// Central differences with step h: velocity, acceleration, angular velocity and acceleration.
struct Differences {
  Vec3 v, a, w, alpha;
};
Differences Differentiate(const Model& m, const TestState& s, FrameIndex f, const Transform& X_FS,
                          double h, Data& data) {
  Transform X[5];
  for (int i = 0; i < 5; ++i) X[i] = PoseAt(m, s, (i - 2) * h, f, data, X_FS);
  auto omega = [&](int i) -> Vec3 { return Vee((X[i + 1].R - X[i - 1].R) * X[i].R.transpose()) / (2 * h); };
  Differences d;
  d.v = (X[3].p - X[1].p) / (2 * h);
  d.a = (X[3].p - 2 * X[2].p + X[1].p) / (h * h);
  d.w = omega(2);
  d.alpha = (omega(3) - omega(1)) / (2 * h);
  return d;
}

// Expects the sensor's channels to be `x_W` in axes E (and components as listed).
void ExpectReading(const Model& m, const Data& data, const std::string& name, const Vec3& x_W,
                   const Mat3& R_WE, double tol) {
  const Sensor& s = m.sensors[m.sensor(name)];
  const Vec3 x_E = R_WE.transpose() * x_W;
  for (int c = 0; c < s.channels; ++c)
    EXPECT_NEAR(data.sensor_values(s.channel_start + c), x_E(s.spec.axes[c]), tol) << name << " column " << c;
}

// Checks every frame sensor at place k of BuildChain against differences of its poses; `extra`
// widens the tolerance of velocities (first) and accelerations (second).
void CheckFrame(const Chain& c, const TestState& s, int k, const Data& data, Data& scratch,
                double extra_v, double extra_a) {
  const Model& m = *c.model;
  const auto& [f, X_FS] = c.places[k];
  SCOPED_TRACE("place " + std::to_string(k) + ": frame " + m.frames[f].name);
  const std::string n = std::to_string(k);
  const double h = 1e-3;
  const Differences d1 = Differentiate(m, s, f, X_FS, h, scratch);
  const Differences d2 = Differentiate(m, s, f, X_FS, h / 2, scratch);
  // Tolerance: the step-h/2 differences' error, about a third of their change from step h
  // (O(h^2)), plus their rounding (eps |x| / h^2 for second differences, 1e-9 here).
  auto tol = [&](const Vec3& a, const Vec3& b, double extra) { return (a - b).norm() + 1e-7 + extra; };
  const Mat3 R_WS = PoseAt(m, s, 0, f, scratch, X_FS).R;
  const Mat3 R_WC = PoseAt(m, s, 0, c.crank, scratch).R;
  ExpectReading(m, data, "acc" + n, d2.a, R_WS, tol(d1.a, d2.a, extra_a));
  ExpectReading(m, data, "accg" + n, d2.a - m.gravity, Mat3::Identity(), tol(d1.a, d2.a, extra_a));
  ExpectReading(m, data, "vel" + n, d2.v, R_WC, tol(d1.v, d2.v, extra_v));
  ExpectReading(m, data, "gyro" + n, d2.w, R_WS, tol(d1.w, d2.w, extra_v));
  ExpectReading(m, data, "alpha" + n, d2.alpha, Mat3::Identity(), tol(d1.alpha, d2.alpha, extra_a));
  // Displacement: world position minus the one at the initial configuration.
  CalcPositionKinematics(m, m.q_initial, scratch);
  const Vec3 p0 = scratch.X_WFrame[f] * X_FS.p;
  ExpectReading(m, data, "disp" + n, PoseAt(m, s, 0, f, scratch, X_FS).p - p0, Mat3::Identity(), 1e-14);
}

TEST(SensorSignals, FrameKinematicsMatchDifferencesOfPoses) {
  const Chain c = BuildChain();
  const Model& m = *c.model;
  Data data(m), scratch(m);
  // Rigid frames and a node that only translates: exact at any amplitude.
  const TestState s = MakeState(m, 1.0);
  CalcSensorSignals(m, 0.0, s.q, s.v, s.vdot, data);
  for (const int k : {0, 1, 2, 4}) CheckFrame(c, s, k, data, scratch, 0, 0);
  // A frame off a node that turns: the engine takes the node's rotation theta = Psi q_f as small
  // (angular velocity Psi q_f-dot; the exact one is dexp(theta) theta-dot = theta-dot +
  // theta x theta-dot / 2 + ...), as elastic rotations are. At modal amplitudes of 1e-3 its error,
  // |theta| |theta-dot| in angular velocity and |theta| |theta-ddot| + |theta-dot|^2 in angular
  // acceleration (times 1 + the offset's length for the point), is kept in the tolerance.
  const TestState small = MakeState(m, 1e-3);
  CalcSensorSignals(m, 0.0, small.q, small.v, small.vdot, data);
  const FlexibleBody& fb = m.flexible_bodies[0];
  const auto& psi = fb.modes->nodes[1].rotation_shapes;
  const double th = (psi * small.q.segment(fb.q_start, fb.nf)).norm();
  const double th_d = (psi * small.v.segment(fb.v_start, fb.nf)).norm();
  const double th_dd = (psi * small.vdot.segment(fb.v_start, fb.nf)).norm();
  for (const int k : {3, 5}) {
    const Vec3 p_B = m.frames[c.offset_node_frame].X_BF * c.places[k].second.p;
    const double lever = 1 + (p_B - fb.modes->nodes[1].position).norm();
    const double w_body = 3;  // bound on the body's angular velocity here (rad/s)
    CheckFrame(c, small, k, data, scratch, th * th_d * lever,
               (th * th_dd + th_d * th_d + 2 * w_body * th * th_d) * lever);
  }
  // A node's deflection in its body's frame: the node's translation shapes times q_f.
  CalcSensorSignals(m, 0.0, s.q, s.v, s.vdot, data);
  const Vec3 u = fb.modes->nodes[0].translation_shapes * s.q.segment(fb.q_start, fb.nf);
  ExpectReading(m, data, "deflection", u, Mat3::Identity(), 1e-14);
  // Joint sensors read the coordinates.
  EXPECT_EQ(data.sensor_values(m.sensors[m.sensor("encoder")].channel_start),
            s.q(m.joints[m.joint("arm")].q_start + 1));
  EXPECT_EQ(data.sensor_values(m.sensors[m.sensor("tacho")].channel_start),
            s.v(m.joints[m.joint("floater")].v_start + 4));
}

// A spring from a frame's origin to a fixed point, with outputs of one and three columns.
class TetherElement final : public ExternalForceElement {
 public:
  struct Workspace final : ExternalForceWorkspace {
    double values[4] = {0, 0, 0, 0};
  };
  TetherElement(FrameIndex frame, double k) : frame_(frame), k_(k) {}
  const std::string& name() const override { return name_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model&) const override {
    return std::make_unique<Workspace>();
  }
  void Apply(const Model& model, double, Data& data, ExternalForceWorkspace& ws) const override {
    const Vec3 p = data.X_WFrame[frame_].p;
    const Vec3 f = -k_ * p;
    AddFrameForce(model, data, frame_, ForceAtPoint(p, f));
    auto& w = static_cast<Workspace&>(ws);
    w.values[0] = p.norm();
    for (int i = 0; i < 3; ++i) w.values[1 + i] = f(i);
  }
  bool HasTangents() const override { return false; }
  void AddTangents(const Model&, const Data&, ExternalForceWorkspace&, Eigen::Ref<Eigen::MatrixXd>,
                   Eigen::Ref<Eigen::MatrixXd>) const override {}
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  void GetOutputs(const ExternalForceWorkspace& ws, double* values) const override {
    for (int i = 0; i < 4; ++i) values[i] = static_cast<const Workspace&>(ws).values[i];
  }

 private:
  std::string name_ = "tether";
  std::vector<OutputDescription> outputs_{{"stretch", "m", 1}, {"force", "N", 3}};
  FrameIndex frame_;
  double k_;
};

// Two gears on revolute joints with a lumped mesh, one of them tethered by an external element.
std::shared_ptr<const Model> GearPair() {
  ModelBuilder b;
  const double alpha = 20 * std::numbers::pi / 180, rb1 = 0.02 * std::cos(alpha), rb2 = 0.04 * std::cos(alpha);
  const BodyIndex g1 = b.AddBody("pinion", 0.3, Vec3::Zero(), Vec3(1e-4, 1e-4, 2e-4).asDiagonal());
  const BodyIndex g2 = b.AddBody("wheel", 1.2, Vec3::Zero(), Vec3(8e-4, 8e-4, 1.6e-3).asDiagonal());
  b.AddJoint(Joint("pinion", JointType::kRevolute, kWorldBody, g1));
  b.AddJoint(Joint("wheel", JointType::kRevolute, kWorldBody, g2, Transform::Translation(Vec3(0.06, 0, 0))));
  GearMeshSpec mesh;
  mesh.name = "mesh";
  mesh.gear_a = b.body_frame(g1), mesh.gear_b = b.body_frame(g2);
  mesh.teeth_a = 20, mesh.teeth_b = 40;
  mesh.base_radius_a = rb1, mesh.base_radius_b = rb2, mesh.working_pressure_angle = alpha;
  mesh.stiffness = 2e8, mesh.damping = 100;
  b.AddGearMesh(mesh);
  const FrameIndex rim = b.AddFrame("rim", g2, Transform::Translation(Vec3(0.04, 0, 0)));
  b.AddExternalForce(std::make_shared<TetherElement>(rim, 50.0));
  b.AddSensor({.name = "f", .kind = SensorKind::kGearMesh, .gear_mesh = 0});
  b.AddSensor({.name = "d", .kind = SensorKind::kGearMesh, .gear_mesh = 0,
               .mesh_quantity = MeshQuantity::kDeflection});
  b.AddSensor({.name = "te", .kind = SensorKind::kGearMesh, .gear_mesh = 0,
               .mesh_quantity = MeshQuantity::kTransmissionError});
  b.AddSensor({.name = "tether_force", .kind = SensorKind::kElementOutput, .element = 0, .output = "force"});
  b.AddSensor({.name = "tether_stretch", .kind = SensorKind::kElementOutput, .element = 0, .output = "stretch"});
  return std::move(b).Finalize();
}

TEST(SensorSignals, MeshAndElementSensorsReadWhatTheForceStagesCompute) {
  const std::shared_ptr<const Model> model = GearPair();
  const Model& m = *model;
  Data data(m), reference(m);
  const Eigen::VectorXd q = Eigen::Vector2d(1e-4, -2e-5), v = Eigen::Vector2d(3.0, -1.4);
  CalcSensorSignals(m, 0.1, q, v, Eigen::VectorXd::Zero(2), data);
  CalcPositionKinematics(m, q, reference);
  CalcVelocityKinematics(m, v, reference);
  CalcForceElements(m, 0.1, v, reference);
  auto value = [&](const std::string& name, int c = 0) {
    return data.sensor_values(m.sensors[m.sensor(name)].channel_start + c);
  };
  EXPECT_GT(reference.mesh_force[0], 0);
  EXPECT_EQ(value("f"), reference.mesh_force[0]);
  EXPECT_EQ(value("d"), reference.mesh_deflection[0]);
  // The transmission coordinate r_ba theta_a + r_bb theta_b (external pair, sigma = +1).
  EXPECT_NEAR(value("te"), m.gear_meshes[0].spec.base_radius_a * q(0) + m.gear_meshes[0].spec.base_radius_b * q(1), 1e-15);
  double out[4];
  m.external_forces[0]->GetOutputs(*reference.external[0], out);
  EXPECT_EQ(value("tether_stretch"), out[0]);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(value("tether_force", c), out[1 + c]);
  const Sensor& s = m.sensors[m.sensor("tether_force")];
  EXPECT_EQ(s.unit, "N");
  EXPECT_EQ(s.channels, 3);
  EXPECT_EQ(s.quantity, "force");
}

TEST(SensorSignals, BuilderRefusesBadSensorsNamingThem) {
  ModelBuilder b;
  const BodyIndex body = b.AddBody("body", 1.0, Vec3::Zero(), Mat3::Identity() * 0.01);
  const JointIndex ball = b.AddJoint(Joint("ball", JointType::kSpherical, kWorldBody, body));
  const FrameIndex f = b.body_frame(body);
  auto fails = [&](const SensorSpec& s, const std::string& part) {
    try {
      b.AddSensor(s);
      ADD_FAILURE() << "accepted " << s.name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("'" + s.name + "'"), std::string::npos) << e.what();
    }
  };
  fails({.name = "a", .frame = 99}, "frame index 99");
  fails({.name = "b", .frame = f, .axes = {}}, "1 to 3");
  fails({.name = "c", .frame = f, .axes = {0, 3}}, "got 3");
  fails({.name = "d", .frame = f, .axes = {1, 1}}, "y twice");
  fails({.name = "e", .kind = SensorKind::kDisplacement, .frame = f}, "relative to another frame");
  fails({.name = "f", .kind = SensorKind::kEncoder, .joint = ball, .coordinate = 1}, "quaternion");
  fails({.name = "g", .kind = SensorKind::kTachometer, .joint = ball, .coordinate = 3}, "no coordinate 3");
  fails({.name = "h", .kind = SensorKind::kGearMesh, .gear_mesh = 0}, "gear mesh index 0");
  fails({.name = "i", .kind = SensorKind::kElementOutput, .element = 0}, "external element index 0");
  fails({.name = "j", .kind = SensorKind::kGyroscope, .frame = f, .include_gravity = true}, "accelerometers");
  fails({.name = "l", .frame = f, .X_FS = Transform(2 * Mat3::Identity(), Vec3::Zero())}, "X_FS");
  b.AddSensor({.name = "ok", .frame = f});
  fails({.name = "ok", .frame = f}, "already used");
  b.AddExternalForce(std::make_shared<TetherElement>(f, 1.0));
  fails({.name = "k", .kind = SensorKind::kElementOutput, .element = 0, .output = "torque"},
        "outputs: stretch, force");
}

}  // namespace
}  // namespace orrery

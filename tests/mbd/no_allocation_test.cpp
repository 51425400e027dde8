// The step pipeline allocates nothing once Data (and the integrator's workspace) is sized
// (STYLE.md, "no allocation in a step"), counted by tests/common/counting_allocator.h.
//
// Model: a slider-crank closed by a spherical loop (speed driver on the crank), a pendulum with
// a position driver, and a floating body on a free joint (quaternions), with one force element of
// every kind; and a spatial stage of free bodies (tests/common/spatial_stage.h) for the paths
// that model does not take.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <new>
#include <string>

#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/result_recorder.h"
#include "mbd/run_health.h"
#include "mbd/sensor_sampler.h"
#include "mbd/sensor_signals.h"
#include "mbd/state.h"

#include "tests/common/counting_allocator.h"
#include "tests/common/spatial_stage.h"

namespace orrery {
namespace {

using test_support::AllocationsIn;

TEST(NoAllocation, CounterSeesEigenAndOperatorNew) {
  // The counter must be able to fail: a dynamic Eigen temporary and a std::string are counted.
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(30, 30), b = a;
  EXPECT_GT(AllocationsIn([&] { b = (a * a + a).eval(); }, 0), 0);
  EXPECT_GT(AllocationsIn([&] { std::string s(100, 'x'); (void)s; }, 0), 0);
}

JointSpec Joint(const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                const Transform& X_PF = Transform(), const Vec3& axis = Vec3::UnitZ(),
                const Vec3& axis2 = Vec3::UnitX()) {
  JointSpec j;
  j.name = name, j.type = type, j.parent = parent, j.child = child, j.X_PF = X_PF;
  j.axis = axis, j.axis2 = axis2;
  return j;
}

// A small flexible body: point masses, three of them moved by three modes, with damping,
// geometric stiffness, stress modes and a surface (every output path of the engine).
std::shared_ptr<FlexibleBodyModes> PointMassModes() {
  auto m = std::make_shared<FlexibleBodyModes>();
  const int n = 3;
  m->nf = n;
  m->I2 = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
  m->I4.assign(n, Mat3::Zero());
  m->I5.assign(n * n, Mat3::Zero());
  const Vec3 core[4] = {{0.2, 0, 0}, {-0.1, 0.25, 0.05}, {0, -0.15, 0.3}, {0.05, 0.1, -0.2}};
  for (const Vec3& x : core) {
    m->mass += 1.0;
    m->I1 += x;
    m->I3 += x * x.transpose();
  }
  for (int j = 0; j < 3; ++j) {
    FlexibleBodyModes::Node node;
    node.id = j + 1;
    node.position = Vec3(0.3 * j, 0.2, -0.1 * j);
    node.translation_shapes = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    node.translation_shapes.col(j) = Vec3(1, 0.5 * j, 0.2).normalized();
    node.rotation_shapes = 0.1 * node.translation_shapes;
    const double mass = 0.5;
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
  m->stiffness = Eigen::Vector3d(400, 900, 1600).asDiagonal();
  m->geometric_stiffness.assign(6, Eigen::MatrixXd::Identity(n, n) * 0.1);
  m->surface_triangles = {{0, 1, 2}};
  m->stress_nodes = {0, 1, 2};
  m->stress_modes = Eigen::MatrixXd::Ones(18, n) * 1e6;
  return m;
}

std::shared_ptr<const Model> BuildModel() {
  const double r = 0.1, l = 0.35, theta = 0.3;
  ModelBuilder b;
  const Mat3 I = Vec3(2e-3, 3e-3, 4e-3).asDiagonal();
  const BodyIndex crank = b.AddBody("crank", 1.0, Vec3(r / 2, 0, 0), I);
  const BodyIndex rod = b.AddBody("rod", 0.5, Vec3(l / 2, 0, 0), I);
  const BodyIndex slider = b.AddBody("slider", 2.0, Vec3::Zero(), I);
  const BodyIndex pendulum = b.AddBody("pendulum", 1.0, Vec3(0, -0.3, 0), I);
  const BodyIndex floater = b.AddBody("floater", 3.0, Vec3(0.01, 0.02, 0), I);
  const JointIndex jc = b.AddJoint(Joint("crank", JointType::kRevolute, kWorldBody, crank));
  const JointIndex jr = b.AddJoint(Joint("rod", JointType::kUniversal, crank, rod,
                                         Transform::Translation(Vec3(r, 0, 0)), Vec3::UnitZ(), Vec3::UnitY()));
  const JointIndex js = b.AddJoint(Joint("slider", JointType::kPrismatic, kWorldBody, slider, Transform(), Vec3::UnitX()));
  const JointIndex jp = b.AddJoint(Joint("pendulum", JointType::kRevolute, kWorldBody, pendulum,
                                         Transform::Translation(Vec3(0, 1, 0))));
  b.AddJoint(Joint("floater", JointType::kFree, kWorldBody, floater, Transform::Translation(Vec3(0, 0, 1))));
  const FrameIndex rod_end = b.AddFrame("rod_end", rod, Transform::Translation(Vec3(l, 0, 0)));
  b.AddLoopClosure({"wrist", JointType::kSpherical, rod_end, b.body_frame(slider)});
  b.AddDriver({"motor", jc, 0, DriverSpec::Mode::kSpeed, TimeFunction::Trapezoid(5, 10, 5, 1.0, 0.1, 0.1, 0.6)});
  b.AddDriver({"swing", jp, 0, DriverSpec::Mode::kPosition, TimeFunction::Sine(0.2, 1.0, 0.0, 0.0)});
  b.SetGravity(Vec3(0, -9.81, 0));
  const FrameIndex anchor = b.AddFrame("anchor", kWorldBody, Transform::Translation(Vec3(0, 0, 1)));
  const FrameIndex mark = b.AddFrame("mark", floater, Transform(AxisAngle(Vec3::UnitX(), 0.3), Vec3(0.05, 0, 0)));
  b.AddAppliedLoad({"push", rod_end, Vec3(1, 2, 0), Vec3(0, 0, 0.1), TimeFunction::Ramp(0, 1, 0, 1), true});
  b.AddJointLoad({"brake", js, 0, TimeFunction::Table({0, 0.5, 1}, {0, -1, 0})});
  b.AddTranslationalSpring({"spring", kWorldFrame, b.body_frame(slider), 100, 1, 0.4, 2});
  b.AddRotationalSpring({"torsion", kWorldFrame, b.body_frame(pendulum), 5, 0.1, 0});
  b.AddCoordinateSpring({"coord", js, 0, 50, 0.5, 0.4});
  Mat6 K = Mat6::Identity() * 1e4;
  K.topRightCorner<3, 3>() = Mat3::Identity() * 100;
  K.bottomLeftCorner<3, 3>() = Mat3::Identity() * 100;
  K.bottomRightCorner<3, 3>() = Mat3::Identity() * 1e3;
  b.AddBushing({"mount", anchor, mark, K, K * 1e-3});
  const BodyIndex flex = b.AddFlexibleBody("flex", PointMassModes(),
                                           {.damping_ratios = {0.02}, .geometric_stiffening = true,
                                            .record_surface = true});
  b.AddJoint(Joint("flex", JointType::kRevolute, kWorldBody, flex, Transform::Translation(Vec3(2, 0, 0))));
  const FrameIndex node = b.AddNodeFrame("flex_node", flex, 1, Transform::Translation(Vec3(0.3, 0.2, -0.1)));
  b.AddTranslationalSpring({"flex_spring", anchor, node, 100, 1, 0.4, 0});
  // A lumped gear mesh with stiffness and transmission-error tables (mbd/gear_mesh.h).
  const BodyIndex ga = b.AddBody("gear_a", 1.0, Vec3::Zero(), I), gb = b.AddBody("gear_b", 2.0, Vec3::Zero(), I);
  const double rba = 0.03, rbb = 0.05, alpha = 0.35, centre = (rba + rbb) / std::cos(alpha);
  b.AddJoint(Joint("gear_a", JointType::kRevolute, kWorldBody, ga, Transform::Translation(Vec3(5, 0, 0))));
  b.AddJoint(Joint("gear_b", JointType::kRevolute, kWorldBody, gb, Transform::Translation(Vec3(5 + centre, 0, 0))));
  GearMeshSpec mesh{.name = "mesh", .gear_a = b.body_frame(ga), .gear_b = b.body_frame(gb), .teeth_a = 30,
                    .teeth_b = 50, .base_radius_a = rba, .base_radius_b = rbb, .working_pressure_angle = alpha};
  mesh.stiffness_table = {4e8, 3e8, 4.5e8, 3.5e8};
  mesh.table_cycles = 2;
  mesh.ste_table_m = {0, 1e-6, 2e-6};
  mesh.ste_amplitudes = {0.5e-6};
  b.AddGearMesh(mesh);
  // Sensors of every frame kind on rigid and node frames, and on joints.
  b.AddSensor({.name = "acc", .kind = SensorKind::kAccelerometer, .frame = mark});
  b.AddSensor({.name = "node_acc", .kind = SensorKind::kAccelerometer, .frame = node,
               .measured_in = kWorldFrame, .axes = {1, 2}, .include_gravity = true});
  b.AddSensor({.name = "node_vel", .kind = SensorKind::kVelocity, .frame = node});
  b.AddSensor({.name = "node_disp", .kind = SensorKind::kDisplacement, .frame = node,
               .measured_in = b.body_frame(flex)});
  b.AddSensor({.name = "gyro", .kind = SensorKind::kGyroscope, .frame = rod_end});
  b.AddSensor({.name = "alpha", .kind = SensorKind::kAngularAccelerometer, .frame = node});
  b.AddSensor({.name = "encoder", .kind = SensorKind::kEncoder, .joint = jc});
  b.AddSensor({.name = "tacho", .kind = SensorKind::kTachometer, .joint = js});
  const double s = std::sin(theta), x = r * std::cos(theta) + std::sqrt(l * l - r * r * s * s);
  b.SetJointPosition(jc, Eigen::VectorXd::Constant(1, theta));
  b.SetJointPosition(jr, Eigen::Vector2d(std::atan2(-r * s, x - r * std::cos(theta)) - theta, 0));
  b.SetJointPosition(js, Eigen::VectorXd::Constant(1, x));
  b.SetJointVelocity(jc, Eigen::VectorXd::Constant(1, 5.0));
  return std::move(b).Finalize();
}

// A state with nonzero velocities and accelerations everywhere.
State TestState(const Model& m) {
  State s = State::Initial(m);
  s.t = 0.05;
  for (int k = 0; k < m.nv; ++k) s.v(k) = 0.1 * (k + 1);
  return s;
}

TEST(NoAllocation, EvaluateDynamicsAndMassMatrix) {
  const std::shared_ptr<const Model> model = BuildModel();
  const Model& m = *model;
  Data data(m);
  const State s = TestState(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::LinSpaced(m.nv, -1, 1);
  EXPECT_EQ(AllocationsIn([&] { EvaluateDynamics(m, s.t, s.q, s.v, vdot, data); }), 0);
  EXPECT_EQ(AllocationsIn([&] { CalcMassMatrix(m, data); }), 0);
  EXPECT_EQ(AllocationsIn([&] { (void)CalcKineticEnergy(m, data); }), 0);
}

TEST(NoAllocation, DaeResidualAndJacobian) {
  const std::shared_ptr<const Model> model = BuildModel();
  DaeSystem dae(*model);
  Eigen::VectorXd y(dae.size()), yp(dae.size()), r(dae.size());
  Eigen::MatrixXd J(dae.size(), dae.size());
  State s = TestState(*model);
  dae.ConsistentInitial(s, y, yp);
  EXPECT_EQ(AllocationsIn([&] { dae.Residual(s.t, y, yp, r); }), 0);
  EXPECT_EQ(AllocationsIn([&] { dae.Jacobian(s.t, 1e3, y, yp, J); }), 0);
}

TEST(NoAllocation, GeneralizedAlphaStep) {
  const std::shared_ptr<const Model> model = BuildModel();
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = 1e-3;
  for (const bool estimate : {true, false}) {  // newton_estimate false: the Broyden updates
    o.newton_estimate = estimate;
    std::unique_ptr<Integrator> integ = MakeIntegrator(*model, o);
    integ->Initialize(State::Initial(*model));
    integ->AdvanceTo(1e-3);
    int k = 1;
    EXPECT_EQ(AllocationsIn([&] { integ->AdvanceTo(++k * 1e-3); }), 0)
        << "newton_estimate " << estimate;
    EXPECT_EQ(AllocationsIn([&] { integ->AdvanceTo(++k * 1e-3); }), 0)
        << "newton_estimate " << estimate;
  }
}

// The analytic modal columns of a leaf flexible body (SetFlexibleModalTangents; the model above
// differences them: a spring pulls one of its node frames).
TEST(NoAllocation, AnalyticModalTangents) {
  ModelBuilder b;
  b.SetGravity(Vec3(0, -9.81, 0));
  const BodyIndex flex = b.AddFlexibleBody(
      "flex", PointMassModes(), {.damping_ratios = {0.02}, .geometric_stiffening = true});
  const JointIndex pin = b.AddJoint(
      Joint("flex", JointType::kRevolute, kWorldBody, flex, Transform::Translation(Vec3(2, 0, 0))));
  b.SetJointVelocity(pin, Eigen::VectorXd::Constant(1, 3.0));
  b.SetModalCoordinates(flex, Eigen::Vector3d(0.01, -0.02, 0.03), Eigen::Vector3d(0.1, 0.2, -0.3));
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  DaeSystem dae(*model);
  ASSERT_EQ(dae.differenced_columns(), 1);
  Eigen::VectorXd y(dae.size()), yp(dae.size());
  Eigen::MatrixXd J(dae.size(), dae.size());
  dae.ConsistentInitial(State::Initial(*model), y, yp);
  EXPECT_EQ(AllocationsIn([&] { dae.Jacobian(0.0, 1e3, y, yp, J); }), 0);
}

// The paths the model above does not take (it has a flexible body and a loop closure): the
// velocity projection by articulated solves and the grouped differences of the tangents, on a
// spatial stage of free bodies with a speed driver (tests/common/spatial_stage.h). The first
// step builds the iteration matrix; the Jacobian is measured on its own.
TEST(NoAllocation, FreeBodyStageProjectionAndGroupedTangents) {
  const std::shared_ptr<const Model> model = test_support::SpatialStage(false);
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = 1e-4;
  std::unique_ptr<Integrator> integ = MakeIntegrator(*model, o);
  integ->Initialize(State::Initial(*model));
  integ->AdvanceTo(1e-4);
  int k = 1;
  EXPECT_EQ(AllocationsIn([&] { integ->AdvanceTo(++k * 1e-4); }), 0);
  // The per-step health reading the gear angles from the projection's kinematics
  // (Integrator::PositionKinematicsAtState), as Simulate calls it.
  RunHealth health(*model, o, {}, 1e-3);
  int checked = 0;
  integ->SetStepCallback([&](double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                             const Eigen::Ref<const Eigen::VectorXd>& v) {
    const Data* at_q = integ->PositionKinematicsAtState();
    checked += at_q != nullptr;
    health.OnStep(t, q, v, at_q);
  });
  EXPECT_EQ(AllocationsIn([&] { integ->AdvanceTo(++k * 1e-4); }), 0);
  EXPECT_GT(checked, 0);
  DaeSystem dae(*model);
  ASSERT_GT(dae.difference_groups(), 0);
  Eigen::VectorXd y(dae.size()), yp(dae.size());
  Eigen::MatrixXd J(dae.size(), dae.size());
  dae.ConsistentInitial(State::Initial(*model), y, yp);
  EXPECT_EQ(AllocationsIn([&] { dae.Jacobian(0.0, 1e3, y, yp, J); }), 0);
}

TEST(NoAllocation, ResultRecorderBetweenBlocks) {
  const std::shared_ptr<const Model> model = BuildModel();
  const std::string path = ::testing::TempDir() + "orrery_no_alloc_" + std::to_string(::getpid()) + ".h5";
  {
    ResultFile out = ResultFile::Create(path);
    ResultRecorder rec(*model, out);
    const State s = TestState(*model);
    const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(model->nv);
    const Eigen::VectorXd lambda = Eigen::VectorXd::Ones(model->n_constraints);
    // The first row sizes every series' block; later rows (well within a block) must not allocate.
    EXPECT_EQ(AllocationsIn([&] { rec.Record(s, vdot, lambda); }, 2), 0);
  }
  std::filesystem::remove(path);
}

TEST(NoAllocation, SensorSignals) {
  const std::shared_ptr<const Model> model = BuildModel();
  Data data(*model);
  const State s = TestState(*model);
  const Eigen::VectorXd vdot = Eigen::VectorXd::LinSpaced(model->nv, -1, 1);
  EXPECT_EQ(AllocationsIn([&] { CalcSensorSignals(*model, s.t, s.q, s.v, vdot, data); }), 0);
}

// The sensor path inside the step: dense output at the internal rate, the signals, the filter,
// the rows written (within the series' blocks), for both integrators.
TEST(NoAllocation, SensorSamplingInsideSteps) {
  const std::shared_ptr<const Model> model = BuildModel();
  for (const IntegratorKind kind : {IntegratorKind::kGeneralizedAlpha, IntegratorKind::kIda}) {
    const std::string path = ::testing::TempDir() + "orrery_no_alloc_sensors_" + std::to_string(::getpid()) + ".h5";
    {
      IntegratorOptions o;
      o.kind = kind;
      o.step = 1e-4;
      ResultFile out = ResultFile::Create(path);
      SensorSampler sampler(*model, {}, o, 1e-3, 1.0, out);
      std::unique_ptr<Integrator> integ = MakeIntegrator(*model, o);
      integ->set_step_observer(&sampler);
      integ->Initialize(State::Initial(*model));
      sampler.Start(integ->state(), integ->vdot());
      int k = 0;
      // Past the filter's delay, so rows are computed and written too.
      for (; k < 50; ++k) {
        integ->AdvanceTo((k + 1) * 1e-3);
        sampler.Release((k + 1) * 1e-3);
      }
      const long samples = sampler.samples();
      EXPECT_EQ(AllocationsIn([&] {
                  for (int i = 0; i < 5; ++i, ++k) {
                    integ->AdvanceTo((k + 1) * 1e-3);
                    sampler.Release((k + 1) * 1e-3);
                  }
                }),
                0)
          << integ->name();
      EXPECT_GE(sampler.samples() - samples, 5 * sampler.oversampling());
    }
    std::filesystem::remove(path);
  }
}

}  // namespace
}  // namespace orrery

// Integrator::DataAtState (the output rows' shortcut: the recorder and the health read the
// integrator's last evaluation instead of evaluating again) against an evaluation of its own.
//
// Oracle: EvaluateDynamics on a fresh Data at the integrator's (t, q, v, v-dot), the path a row
// takes without the shortcut. Every field a row reads must be the same to the last bit wherever
// DataAtState is not null; it must be null on a model with constraints (the velocity projection
// moves v after the last evaluation) and on IDA.
//
// Integrator::PositionKinematicsAtState (the per-step health's shortcut: the gear angles from the
// integrator's poses) likewise against CalcPositionKinematics and CalcConstraints on a fresh Data
// at (t, q), both in the step callback (where the health reads it) and after AdvanceTo.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "mbd/constraints.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/gear_mesh.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "tests/common/spatial_stage.h"

namespace orrery {
namespace {

// A double pendulum about z under in-plane gravity, a spring from its tip to the world and a
// torque on the first joint; with a speed driver on the second joint when `driven`.
std::shared_ptr<const Model> Pendulum(bool driven) {
  ModelBuilder b;
  const Mat3 I = Vec3(1e-3, 1e-3, 2e-3).asDiagonal();
  const BodyIndex upper = b.AddBody("upper", 1.0, Vec3(0.25, 0, 0), I);
  const BodyIndex lower = b.AddBody("lower", 0.5, Vec3(0.2, 0.01, 0), I);
  const JointIndex shoulder =
      b.AddJoint({.name = "shoulder", .type = JointType::kRevolute, .child = upper});
  const JointIndex elbow = b.AddJoint({.name = "elbow",
                                       .type = JointType::kRevolute,
                                       .parent = upper,
                                       .child = lower,
                                       .X_PF = Transform(Mat3::Identity(), Vec3(0.5, 0, 0))});
  b.SetGravity(Vec3(0, -9.81, 0));
  const FrameIndex tip = b.AddFrame("tip", lower, Transform(Mat3::Identity(), Vec3(0.4, 0, 0)));
  const FrameIndex anchor =
      b.AddFrame("anchor", kWorldBody, Transform(Mat3::Identity(), Vec3(0.6, -0.5, 0)));
  b.AddTranslationalSpring({.name = "spring",
                            .frame_a = anchor,
                            .frame_b = tip,
                            .stiffness = 400,
                            .damping = 2,
                            .free_length = 0.3});
  b.AddJointLoad({.name = "torque", .joint = shoulder, .function = TimeFunction::Sine(3, 2, 0, 1)});
  if (driven)
    b.AddDriver({.name = "drive",
                 .joint = elbow,
                 .mode = DriverSpec::Mode::kSpeed,
                 .function = TimeFunction::Constant(1.5)});
  b.SetJointPosition(shoulder, Eigen::VectorXd::Constant(1, 0.4));
  return std::move(b).Finalize();
}

IntegratorOptions Alpha() {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = 1e-3;
  return o;
}

// Every field of `a` a result row or the health reads, against `b`, bit for bit.
void ExpectSameRow(const Model& m, const Data& a, const Data& b, double t) {
  for (BodyIndex k = 1; k < m.nbodies; ++k) {
    for (int r = 0; r < 3; ++r) {
      EXPECT_EQ(a.X_WB[k].p(r), b.X_WB[k].p(r)) << t;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(a.X_WB[k].R(r, c), b.X_WB[k].R(r, c)) << t;
    }
    for (int r = 0; r < 6; ++r) {
      EXPECT_EQ(a.V_WB[k](r), b.V_WB[k](r)) << t;
      EXPECT_EQ(a.A_WB[k](r), b.A_WB[k](r)) << t;
      EXPECT_EQ(a.f_joint[k](r), b.f_joint[k](r)) << t;
    }
  }
  for (int k = 0; k < m.nv; ++k) EXPECT_EQ(a.tau_id(k), b.tau_id(k)) << t;
  EXPECT_EQ(a.potential_energy, b.potential_energy) << t;
  EXPECT_EQ(a.power_applied, b.power_applied) << t;
  EXPECT_EQ(a.power_dissipated, b.power_dissipated) << t;
}

TEST(DataAtState, IsTheEvaluationAtTheState) {
  const std::shared_ptr<const Model> model = Pendulum(false);
  const Model& m = *model;
  std::unique_ptr<Integrator> integ = MakeIntegrator(m, Alpha());
  integ->Initialize(State::Initial(m));
  EXPECT_EQ(integ->DataAtState(), nullptr);  // nothing evaluated at the start yet
  Data own(m);
  int at_state = 0, not_at_state = 0;
  for (int i = 1; i <= 400; ++i) {
    integ->AdvanceTo(i * 1e-3);
    const Data* d = integ->DataAtState();
    if (!d) {
      ++not_at_state;
      continue;
    }
    ++at_state;
    const State& s = integ->state();
    EvaluateDynamics(m, s.t, s.q, s.v, integ->vdot(), own);
    ExpectSameRow(m, *d, own, s.t);
  }
  // Both kinds of step occur, so the comparison above ran.
  EXPECT_GT(at_state, 10);
  EXPECT_GT(not_at_state, 0);
}

// IDA on `model`, initialized at its initial state.
std::unique_ptr<Integrator> StartedIda(const Model& model) {
  IntegratorOptions ida;
  ida.kind = IntegratorKind::kIda;
  std::unique_ptr<Integrator> bdf = MakeIntegrator(model, ida);
  bdf->Initialize(State::Initial(model));
  return bdf;
}

TEST(DataAtState, NullWithConstraintsAndOnIda) {
  const std::shared_ptr<const Model> driven = Pendulum(true);
  std::unique_ptr<Integrator> alpha = MakeIntegrator(*driven, Alpha());
  alpha->Initialize(State::Initial(*driven));
  const std::shared_ptr<const Model> free = Pendulum(false);
  std::unique_ptr<Integrator> bdf = StartedIda(*free);
  for (int i = 1; i <= 100; ++i) {
    alpha->AdvanceTo(i * 1e-3);
    bdf->AdvanceTo(i * 1e-3);
    EXPECT_EQ(alpha->DataAtState(), nullptr);
    EXPECT_EQ(bdf->DataAtState(), nullptr);
  }
}

// The position kinematics and constraints of `a` against `b`, bit for bit, and the gear angles
// read from them (what the health's check reads).
void ExpectSameKinematics(const Model& m, const Data& a, const Data& b, double t) {
  for (int k = 0; k < m.nq; ++k) EXPECT_EQ(a.q_normalized(k), b.q_normalized(k)) << t;
  for (BodyIndex k = 1; k < m.nbodies; ++k)
    for (int r = 0; r < 3; ++r) {
      EXPECT_EQ(a.X_WB[k].p(r), b.X_WB[k].p(r)) << t;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(a.X_WB[k].R(r, c), b.X_WB[k].R(r, c)) << t;
    }
  for (size_t f = 0; f < m.frames.size(); ++f)
    for (int r = 0; r < 3; ++r) {
      EXPECT_EQ(a.X_WFrame[f].p(r), b.X_WFrame[f].p(r)) << t;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(a.X_WFrame[f].R(r, c), b.X_WFrame[f].R(r, c)) << t;
    }
  EXPECT_TRUE(a.S == b.S) << t;
  EXPECT_TRUE(a.phi == b.phi) << t;
  EXPECT_TRUE(a.G == b.G) << t;
  EXPECT_TRUE(a.g_t == b.g_t) << t;
  for (size_t i = 0; i < m.gear_angles.size(); ++i)
    EXPECT_EQ(GearAngleAt(m, a, static_cast<int>(i)), GearAngleAt(m, b, static_cast<int>(i))) << t;
}

// Generalized-alpha with a speed driver (the projection's kinematics) on the driven pendulum and
// on the spatial stage (free joints: quaternions normalized after the step; meshes' gear angles).
TEST(PositionKinematicsAtState, IsTheKinematicsAtTheState) {
  for (const bool stage : {false, true}) {
    const std::shared_ptr<const Model> model =
        stage ? test_support::SpatialStage(false) : Pendulum(true);
    const Model& m = *model;
    IntegratorOptions o = Alpha();
    o.step = stage ? 1e-4 : 1e-3;
    std::unique_ptr<Integrator> integ = MakeIntegrator(m, o);
    integ->Initialize(State::Initial(m));
    Data own(m);
    int in_callback = 0;
    integ->SetStepCallback([&](double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                               const Eigen::Ref<const Eigen::VectorXd>&) {
      const Data* d = integ->PositionKinematicsAtState();
      ASSERT_NE(d, nullptr) << t;
      CalcPositionKinematics(m, q, own);
      CalcConstraints(m, t, own);
      ExpectSameKinematics(m, *d, own, t);
      ++in_callback;
    });
    for (int i = 1; i <= 100; ++i) {
      // Outputs off the step grid as well: the steps between them are shortened.
      integ->AdvanceTo(i * 2.5 * o.step);
      const Data* d = integ->PositionKinematicsAtState();
      ASSERT_NE(d, nullptr);
      const State& s = integ->state();
      CalcPositionKinematics(m, s.q, own);
      CalcConstraints(m, s.t, own);
      ExpectSameKinematics(m, *d, own, s.t);
    }
    EXPECT_GE(in_callback, 250);
  }
}

// Without constraints it is DataAtState (an evaluation at the state, or nothing); IDA: nothing.
TEST(PositionKinematicsAtState, DataAtStateWithoutConstraintsAndNullOnIda) {
  const std::shared_ptr<const Model> free = Pendulum(false);
  std::unique_ptr<Integrator> alpha = MakeIntegrator(*free, Alpha());
  alpha->Initialize(State::Initial(*free));
  std::unique_ptr<Integrator> bdf = StartedIda(*free);
  for (int i = 1; i <= 100; ++i) {
    alpha->AdvanceTo(i * 1e-3);
    bdf->AdvanceTo(i * 1e-3);
    EXPECT_EQ(alpha->PositionKinematicsAtState(), alpha->DataAtState());
    EXPECT_EQ(bdf->PositionKinematicsAtState(), nullptr);
  }
}

}  // namespace
}  // namespace orrery

// Derivative and consistency checks of the step pipeline on a model with every joint type
// (fixed, revolute, prismatic, cylindrical, universal, spherical, planar, free) in a tree with
// rotated and offset joint frames, three loop closures (revolute, prismatic, universal cuts), a
// position driver, a speed driver, every force element (damped translational spring,
// rotational spring, coordinate springs, a bushing with full 6x6 stiffness and damping, an
// applied load, a joint load) and gravity, at several random states:
//   (a) mass matrix by the composite-rigid-body algorithm = columns rebuilt from inverse dynamics,
//   (b) body spatial velocities = central differences of the body poses along q (+) t v,
//   (c) constraint Jacobian G (holonomic rows) = central differences of Phi along q (+) h e_k,
//   (d) DaeSystem::Jacobian = central-difference Jacobian of DaeSystem::Residual,
//   (e) kinetic energy 1/2 v^T M v = CalcKineticEnergy,
//   (f) body spatial accelerations (A_WB minus the base acceleration -g) = central differences of
//       V_WB along (q (+) (t v + t^2/2 vdot), v + t vdot)  (checks the velocity-product terms c_J).
// Finite-difference tolerances are a posteriori: for a central difference D(h) the truncation
// error is C h^2, and D(2h) - D(h) = 3 C h^2 estimates it (Richardson); the tolerance is twice
// that estimate plus the rounding error of the difference quotient, 2 * 100 eps |f| / (2h) (each
// function value carries ~100 eps |f| of rounding from the pipeline's sums).
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "mbd/constraints.h"
#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/force_elements.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "tests/common/random_spatial.h"

namespace orrery {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kEngineFdStep = 1.5e-8;  // dae.cpp's forward-difference step (kFdStep)

// A central difference of a vector function of a scalar, with its error bound (see top).
struct CentralDifference {
  Eigen::VectorXd d;      // (f(h) - f(-h)) / 2h
  Eigen::VectorXd bound;  // per component: truncation estimate * 2 + rounding
};

CentralDifference Differentiate(const std::function<Eigen::VectorXd(double)>& f, double h) {
  const Eigen::VectorXd f0 = f(0), fp = f(h), fm = f(-h), fp2 = f(2 * h), fm2 = f(-2 * h);
  CentralDifference r;
  r.d = (fp - fm) / (2 * h);
  const Eigen::VectorXd d2 = (fp2 - fm2) / (4 * h);
  const Eigen::VectorXd scale =
      f0.cwiseAbs().cwiseMax(fp2.cwiseAbs()).cwiseMax(fm2.cwiseAbs()).array() + 1.0;
  r.bound = 2 * (d2 - r.d).cwiseAbs() / 3 + 2 * 100 * kEps * scale / (2 * h);
  return r;
}

using test_support::RandomFrame;
using test_support::RandomInertia;
using test_support::RandomRotation;

struct Fixture {
  std::shared_ptr<const Model> model;
  BodyIndex bushing_a = 0, bushing_b = 0;
  FrameIndex bushing_frame_a = 0, bushing_frame_b = 0, rot_frame_a = 0, rot_frame_b = 0;
};

Fixture BuildEveryJointModel() {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> u(-1, 1);
  ModelBuilder b;
  auto body = [&](const std::string& name) {
    return b.AddBody(name, 0.5 + std::abs(u(rng)), Vec3(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)),
                     RandomInertia(rng));
  };
  auto joint = [&](const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                   const Vec3& axis, const Vec3& axis2) {
    return b.AddJoint({.name = name, .type = type, .parent = parent, .child = child,
                       .X_PF = RandomFrame(rng, 0.3), .X_CM = RandomFrame(rng, 0.2),
                       .axis = axis, .axis2 = axis2});
  };
  const BodyIndex b1 = body("b1"), b2 = body("b2"), b3 = body("b3"), b4 = body("b4"),
                  b5 = body("b5"), b6 = body("b6"), b7 = body("b7"), b8 = body("b8"),
                  b9 = body("b9");
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  const JointIndex j_rev = joint("rev", JointType::kRevolute, kWorldBody, b1, Vec3(1, 2, 3), x);
  joint("pri", JointType::kPrismatic, b1, b2, Vec3(0, 1, 1), x);
  const JointIndex j_cyl = joint("cyl", JointType::kCylindrical, b2, b3, Vec3(1, 0, 1), x);
  const JointIndex j_uni = joint("uni", JointType::kUniversal, b3, b4, z, Vec3(1, 1, 0));
  joint("sph", JointType::kSpherical, kWorldBody, b5, z, x);
  const JointIndex j_pla = joint("pla", JointType::kPlanar, b5, b6, y, Vec3(1, 0, 1));
  joint("free", JointType::kFree, kWorldBody, b7, z, x);
  joint("fix", JointType::kFixed, b4, b8, z, x);
  joint("rev2", JointType::kRevolute, b7, b9, Vec3(-1, 1, 0.5), x);

  auto frame = [&](const std::string& name, BodyIndex on) {
    return b.AddFrame(name, on, RandomFrame(rng, 0.3));
  };
  // Loop closures (the tree is not assembled: the checks hold off the constraint manifold too).
  b.AddLoopClosure({.name = "loop_rev", .type = JointType::kRevolute,
                    .frame_a = frame("lr_a", b8), .frame_b = frame("lr_b", b6)});
  b.AddLoopClosure({.name = "loop_pri", .type = JointType::kPrismatic,
                    .frame_a = frame("lp_a", b9), .frame_b = frame("lp_b", b3)});
  b.AddLoopClosure({.name = "loop_uni", .type = JointType::kUniversal,
                    .frame_a = frame("lu_a", b2), .frame_b = frame("lu_b", b7)});
  // Drivers: slide of the cylindrical joint (position), angle of the planar joint (speed).
  b.AddDriver({.name = "drive_pos", .joint = j_cyl, .coordinate = 1,
               .mode = DriverSpec::Mode::kPosition,
               .function = TimeFunction::Sine(0.2, 0.7, 0.3, 0.05)});
  b.AddDriver({.name = "drive_speed", .joint = j_pla, .coordinate = 2,
               .mode = DriverSpec::Mode::kSpeed,
               .function = TimeFunction::Sine(0.5, 1.1, -0.2, 0.1)});
  // Force elements.
  Fixture fx;
  b.AddTranslationalSpring({.name = "tspring", .frame_a = frame("ts_a", b1),
                            .frame_b = frame("ts_b", b7), .stiffness = 50, .damping = 3,
                            .free_length = 0.4, .preload = 2});
  fx.rot_frame_a = frame("rs_a", b3);
  fx.rot_frame_b = frame("rs_b", b9);
  b.AddRotationalSpring({.name = "rspring", .frame_a = fx.rot_frame_a, .frame_b = fx.rot_frame_b,
                         .stiffness = 20, .damping = 1.5, .angle0 = 0.2});
  b.AddCoordinateSpring({.name = "cspring_rev", .joint = j_rev, .coordinate = 0, .stiffness = 10,
                         .damping = 0.7, .q0 = 0.1});
  b.AddCoordinateSpring({.name = "cspring_uni", .joint = j_uni, .coordinate = 1, .stiffness = 6,
                         .damping = 0.4, .q0 = -0.2});
  Mat6 A, B;
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 6; ++k) A(i, k) = u(rng), B(i, k) = u(rng);
  BushingSpec bushing{.name = "bushing", .frame_a = frame("bu_a", b2), .frame_b = frame("bu_b", b5),
                      .stiffness = 30 * (A * A.transpose() + Mat6::Identity()),
                      .damping = 2 * (B * B.transpose() + 0.5 * Mat6::Identity())};
  // A skew part adds a circulatory (non-conservative) stiffness; allowed (symmetric part PSD).
  bushing.stiffness(0, 4) += 5;
  bushing.stiffness(4, 0) -= 5;
  fx.bushing_frame_a = bushing.frame_a;
  fx.bushing_frame_b = bushing.frame_b;
  b.AddBushing(bushing);
  b.AddAppliedLoad({.name = "load", .frame = frame("load_f", b4), .force = Vec3(1, 2, -1),
                    .torque = Vec3(0.3, -0.2, 0.5),
                    .scale = TimeFunction::Sine(1.0, 0.5, 0.1, 0.5), .in_frame_axes = true});
  b.AddJointLoad({.name = "jload", .joint = j_pla, .coordinate = 0,
                  .function = TimeFunction::Sine(3.0, 0.8, 0.0, 1.0)});
  // Gears: a carrier turning about z, two gears on planar joints on it with a lumped mesh
  // (linear, STE, damping), a third with an ideal mesh to the first, a bearing on the second.
  const BodyIndex carrier = body("carrier"), g1 = body("g1"), g2 = body("g2"), g3 = body("g3");
  const double alpha = 0.35, d12 = (0.03 + 0.05) / std::cos(alpha), d13 = (0.03 + 0.04) / std::cos(alpha);
  b.AddJoint({.name = "carrier_rev", .type = JointType::kRevolute, .parent = kWorldBody, .child = carrier,
              .X_PF = Transform::Translation(Vec3(0.2, -0.1, 0.3)), .axis = z});
  b.AddJoint({.name = "g1_pla", .type = JointType::kPlanar, .parent = carrier, .child = g1, .axis = z, .axis2 = x});
  b.AddJoint({.name = "g2_pla", .type = JointType::kPlanar, .parent = carrier, .child = g2,
              .X_PF = Transform::Translation(Vec3(d12, 0, 0)), .axis = z, .axis2 = x});
  b.AddJoint({.name = "g3_pla", .type = JointType::kPlanar, .parent = carrier, .child = g3,
              .X_PF = Transform::Translation(Vec3(0, d13, 0)), .axis = z, .axis2 = x});
  GearMeshSpec mesh{.name = "mesh", .gear_a = b.body_frame(g1), .gear_b = b.body_frame(g2),
                    .reference = b.body_frame(carrier), .teeth_a = 30, .teeth_b = 50,
                    .base_radius_a = 0.03, .base_radius_b = 0.05, .working_pressure_angle = alpha,
                    .base_helix_angle = 0.2, .contact = GearMeshSpec::Contact::kLinearDrive,
                    .stiffness = 4e3, .damping = 3.0};
  mesh.ste_amplitudes = {5e-6, 2e-6};  // micrometres, as real transmission errors
  mesh.ste_phases = {0.3, -1.0};
  b.AddGearMesh(mesh);
  b.AddGearConstraint({.name = "ideal", .gear_a = b.body_frame(g1), .gear_b = b.body_frame(g3),
                       .reference = b.body_frame(carrier), .teeth_a = 30, .teeth_b = 40,
                       .base_radius_a = 0.03, .base_radius_b = 0.04, .working_pressure_angle = alpha});
  b.AddBearing({.name = "bearing", .frame_a = b.AddFrame("g2_pin", carrier, Transform::Translation(Vec3(d12, 0, 0))),
                .frame_b = b.body_frame(g2), .radial_stiffness = 300, .axial_stiffness = 100,
                .tilt_stiffness = 20, .radial_damping = 2, .axial_damping = 1, .tilt_damping = 0.5});
  b.SetGravity(Vec3(0.5, -9.81, 0.3));
  fx.model = std::move(b).Finalize();
  return fx;
}

// A random state: joint angles and slides in [-0.6, 0.6], quaternions turned by up to 0.8 rad
// (unit length), velocities in [-1, 1].
State RandomState(const Model& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  State s = State::Initial(model);
  s.t = 0.5 * (1 + u(rng));
  for (int k = 0; k < model.nq; ++k) s.q(k) = 0.6 * u(rng);
  for (const Joint& jt : model.joints) {
    const int quat = jt.spec.type == JointType::kSpherical ? 0
                     : jt.spec.type == JointType::kFree    ? 3
                                                           : -1;
    if (quat < 0) continue;
    const Quat r(RandomRotation(rng, 0.8));
    s.q.segment<4>(jt.q_start + quat) << r.w(), r.x(), r.y(), r.z();
  }
  // Gear centres move by micrometres to millimetres, not by a centre distance: keep the planar
  // gear joints' slides small (a 0.6 m slide would make the mesh carry kilonewtons whose
  // cancelling moments on the carrier swamp the finite differences in rounding).
  for (const Joint& jt : model.joints)
    if (jt.spec.type == JointType::kPlanar && jt.spec.name.rfind("g", 0) == 0)
      s.q.segment<2>(jt.q_start) *= 1e-3;
  for (int k = 0; k < model.nv; ++k) s.v(k) = u(rng);
  return s;
}

class JacobianTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fx_ = BuildEveryJointModel();
    const Model& m = *fx_.model;
    ASSERT_EQ(m.nv, 29);  // 19 + carrier 1 + three planar gears 9
    ASSERT_EQ(m.nq, 31);
    ASSERT_EQ(m.n_holonomic, 16);  // 5 + 5 + 4 loop rows + 1 gear constraint + 1 position driver
    ASSERT_EQ(m.n_constraints, 17);
    std::mt19937 rng(7);
    for (int i = 0; i < 4; ++i) states_.push_back(RandomState(m, rng));
  }

  // Keeps the test away from the branch cuts of the rotational spring's angle (+-pi) and the
  // bushing's rotation vector (pi), where the elements are not differentiable.
  void CheckAwayFromBranchCuts(const Data& d) {
    const Transform& a = d.X_WFrame[fx_.rot_frame_a];
    const Mat3 R_AB = a.R.transpose() * d.X_WFrame[fx_.rot_frame_b].R;
    ASSERT_LT(std::abs(std::atan2(R_AB(1, 0), R_AB(0, 0))), 3.0);
    const Mat3 R_ab = d.X_WFrame[fx_.bushing_frame_a].R.transpose() *
                      d.X_WFrame[fx_.bushing_frame_b].R;
    ASSERT_LT(Eigen::AngleAxisd(R_ab).angle(), 3.0);
  }

  Fixture fx_;
  std::vector<State> states_;
};

// (a) and (e): the mass matrix two ways, and the kinetic energy two ways. Both differences are
// rounding only: inverse dynamics is linear in vdot, so tau(e_k) - tau(0) = M e_k exactly in
// exact arithmetic. The pipeline's sums over bodies and joints (tens of terms of magnitude up to
// the largest of |tau(0)|, |M| times the lever arms) leave ~100 eps of that scale.
TEST_F(JacobianTest, MassMatrixEqualsInverseDynamicsColumnsAndKineticEnergy) {
  const Model& m = *fx_.model;
  Data d(m);
  for (const State& s : states_) {
    CalcPositionKinematics(m, s.q, d);
    CalcVelocityKinematics(m, s.v, d);
    CalcForceElements(m, s.t, s.v, d);
    CalcMassMatrix(m, d);
    const Eigen::MatrixXd M = d.M;
    EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-15 * M.cwiseAbs().maxCoeff());
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.nv);
    CalcInverseDynamics(m, zero, d);
    const Eigen::VectorXd tau0 = d.tau_id;
    Eigen::MatrixXd M_id(m.nv, m.nv);
    for (int k = 0; k < m.nv; ++k) {
      CalcInverseDynamics(m, Eigen::VectorXd::Unit(m.nv, k), d);
      M_id.col(k) = d.tau_id - tau0;
    }
    const double scale = std::max(M.cwiseAbs().maxCoeff(), tau0.cwiseAbs().maxCoeff());
    const double err = (M - M_id).cwiseAbs().maxCoeff();
    EXPECT_LE(err, 100 * kEps * scale);
    // Positive definite (all bodies have mass and every joint moves some inertia).
    EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(M).info(), Eigen::Success);
    // (e)
    const double T_matrix = 0.5 * s.v.dot(M * s.v);
    const double T_bodies = CalcKineticEnergy(m, d);
    EXPECT_NEAR(T_matrix, T_bodies, 100 * kEps * M.cwiseAbs().maxCoeff() * s.v.squaredNorm());
    std::printf("[jacobian] (a) |M - M_id| = %.2e (scale %.2e), (e) T %.6f vs %.6f\n", err, scale,
                T_matrix, T_bodies);
  }
}

// (b) V_WB = d/dt X_WB along q(t) = q (+) t v, and (f) the accelerations.
TEST_F(JacobianTest, BodyVelocitiesAndAccelerationsEqualFiniteDifferences) {
  const Model& m = *fx_.model;
  Data d(m);
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-1, 1);
  const double h = 1e-4;
  for (const State& s : states_) {
    // Poses along the curve as one vector (R columns, p), per body.
    auto poses = [&](double t) {
      Eigen::VectorXd q = s.q;
      IntegratePositions(m, t * s.v, q);
      CalcPositionKinematics(m, q, d);
      Eigen::VectorXd out(12 * m.nbodies);
      for (BodyIndex b = 0; b < m.nbodies; ++b)
        out.segment<12>(12 * b) << d.X_WB[b].R.reshaped(), d.X_WB[b].p;
      return out;
    };
    const CentralDifference D = Differentiate(poses, h);
    CalcPositionKinematics(m, s.q, d);
    CalcVelocityKinematics(m, s.v, d);
    double worst = 0;  // largest error / bound
    for (BodyIndex b = 1; b < m.nbodies; ++b) {
      const Transform X = d.X_WB[b];
      const Mat3 Rdot = D.d.segment<9>(12 * b).reshaped(3, 3);
      const Vec3 pdot = D.d.segment<3>(12 * b + 9);
      // Analytic derivative of the pose from V_WB = (w, v_o): R' = [w]x R, p' = v_o + w x p.
      const Vec3 w = d.V_WB[b].head<3>();
      const Mat3 Rdot_analytic = Skew(w) * X.R;
      const Vec3 pdot_analytic = d.V_WB[b].tail<3>() + w.cross(X.p);
      for (int i = 0; i < 9; ++i) {
        const double e = std::abs(Rdot_analytic.reshaped()(i) - Rdot.reshaped()(i));
        worst = std::max(worst, e / D.bound(12 * b + i));
        EXPECT_LE(e, D.bound(12 * b + i)) << "body " << b << " R entry " << i;
      }
      for (int i = 0; i < 3; ++i) {
        const double e = std::abs(pdot_analytic(i) - pdot(i));
        worst = std::max(worst, e / D.bound(12 * b + 9 + i));
        EXPECT_LE(e, D.bound(12 * b + 9 + i)) << "body " << b << " p entry " << i;
      }
    }
    // (f) Accelerations along (q (+) (t v + t^2/2 a), v + t a) for a random a.
    Eigen::VectorXd a(m.nv);
    for (int k = 0; k < m.nv; ++k) a(k) = u(rng);
    auto velocities = [&](double t) {
      Eigen::VectorXd q = s.q;
      IntegratePositions(m, t * s.v + 0.5 * t * t * a, q);
      CalcPositionKinematics(m, q, d);
      CalcVelocityKinematics(m, s.v + t * a, d);
      Eigen::VectorXd out(6 * m.nbodies);
      for (BodyIndex b = 0; b < m.nbodies; ++b) out.segment<6>(6 * b) = d.V_WB[b];
      return out;
    };
    const CentralDifference DV = Differentiate(velocities, h);
    CalcPositionKinematics(m, s.q, d);
    CalcVelocityKinematics(m, s.v, d);
    CalcForceElements(m, s.t, s.v, d);
    CalcInverseDynamics(m, a, d);
    double worst_acc = 0;
    for (BodyIndex b = 1; b < m.nbodies; ++b) {
      Vec6 A = d.A_WB[b];
      A.tail<3>() += m.gravity;  // remove the base acceleration -g
      for (int i = 0; i < 6; ++i) {
        const double e = std::abs(A(i) - DV.d(6 * b + i));
        worst_acc = std::max(worst_acc, e / DV.bound(6 * b + i));
        EXPECT_LE(e, DV.bound(6 * b + i)) << "body " << b << " acceleration entry " << i;
      }
    }
    std::printf("[jacobian] (b) max error/bound %.3f, (f) %.3f\n", worst, worst_acc);
  }
}

// (c) Holonomic rows of G = d Phi / d(dv_k) along q (+) h e_k.
TEST_F(JacobianTest, ConstraintJacobianEqualsFiniteDifferences) {
  const Model& m = *fx_.model;
  Data d(m);
  const int nh = m.n_holonomic;
  for (const State& s : states_) {
    CalcPositionKinematics(m, s.q, d);
    CalcConstraints(m, s.t, d);
    const Eigen::MatrixXd G = d.G;
    ASSERT_GT(d.phi.norm(), 1e-3);  // off the manifold: Phi's partials, not its zeros, matter
    double worst = 0;
    for (int k = 0; k < m.nv; ++k) {
      auto phi = [&](double t) {
        Eigen::VectorXd q = s.q;
        IntegratePositions(m, t * Eigen::VectorXd::Unit(m.nv, k), q);
        CalcPositionKinematics(m, q, d);
        CalcConstraints(m, s.t, d);
        return Eigen::VectorXd(d.phi);
      };
      const CentralDifference D = Differentiate(phi, 1e-4);
      for (int r = 0; r < nh; ++r) {
        const double e = std::abs(G(r, k) - D.d(r));
        worst = std::max(worst, e / D.bound(r));
        EXPECT_LE(e, D.bound(r)) << ConstraintRowName(m, r) << ", velocity " << k;
      }
    }
    // Velocity-constraint offsets: g_t = dPhi/dt for holonomic rows (position driver row).
    auto phi_t = [&](double dt) {
      CalcPositionKinematics(m, s.q, d);
      CalcConstraints(m, s.t + dt, d);
      return Eigen::VectorXd(d.phi);
    };
    const CentralDifference Dt = Differentiate(phi_t, 1e-4);
    CalcPositionKinematics(m, s.q, d);
    CalcConstraints(m, s.t, d);
    for (int r = 0; r < nh; ++r) EXPECT_LE(std::abs(d.g_t(r) - Dt.d(r)), Dt.bound(r));
    std::printf("[jacobian] (c) max error/bound %.3f\n", worst);
  }
}

// Every loop-closure type on its own (two bodies on free joints): G = d Phi along e_k.
TEST(JacobianLoopClosures, EveryCutTypeMatchesFiniteDifferences) {
  for (JointType type : {JointType::kRevolute, JointType::kSpherical, JointType::kUniversal,
                         JointType::kPrismatic, JointType::kCylindrical, JointType::kPlanar,
                         JointType::kFixed}) {
    std::mt19937 rng(3);
    ModelBuilder b;
    const BodyIndex a = b.AddBody("a", 1, Vec3(0.1, 0, 0), RandomInertia(rng));
    const BodyIndex c = b.AddBody("c", 1, Vec3(0, 0.1, 0), RandomInertia(rng));
    b.AddJoint({.name = "fa", .type = JointType::kFree, .parent = kWorldBody, .child = a,
                .X_PF = RandomFrame(rng, 0.5), .X_CM = RandomFrame(rng, 0.5)});
    b.AddJoint({.name = "fc", .type = JointType::kFree, .parent = a, .child = c,
                .X_PF = RandomFrame(rng, 0.5), .X_CM = RandomFrame(rng, 0.5)});
    b.AddLoopClosure({.name = "cut", .type = type,
                      .frame_a = b.AddFrame("fa_cut", a, RandomFrame(rng, 0.4)),
                      .frame_b = b.AddFrame("fc_cut", c, RandomFrame(rng, 0.4))});
    const std::shared_ptr<const Model> model = std::move(b).Finalize();
    const Model& m = *model;
    Data d(m);
    const State s = RandomState(m, rng);
    CalcPositionKinematics(m, s.q, d);
    CalcConstraints(m, s.t, d);
    const Eigen::MatrixXd G = d.G;
    for (int k = 0; k < m.nv; ++k) {
      auto phi = [&](double t) {
        Eigen::VectorXd q = s.q;
        IntegratePositions(m, t * Eigen::VectorXd::Unit(m.nv, k), q);
        CalcPositionKinematics(m, q, d);
        CalcConstraints(m, s.t, d);
        return Eigen::VectorXd(d.phi);
      };
      const CentralDifference D = Differentiate(phi, 1e-4);
      for (int r = 0; r < m.n_holonomic; ++r)
        EXPECT_LE(std::abs(G(r, k) - D.d(r)), D.bound(r))
            << JointTypeName(type) << " cut row " << r << ", velocity " << k;
    }
  }
}

// (d) The assembled DAE Jacobian J = dr/dy + cj dr/dyp against central differences of the
// residual in every component of y and yp, at mu = 0 (the analytic Jacobian drops the
// q-dependence of N(q) G_h^T mu, which vanishes on the solution).
//
// Quaternion columns: the residual's dynamics and constraint rows see q only through the
// kinematics, which normalize each quaternion, so perturbing one raw component changes them like
// its tangential part; the analytic q-columns are the velocity-space tangents times
// dv/dq = 2 E(q), which maps the radial direction q to zero and the tangential ones to the
// rotation vector. The two agree at unit q, which is where we test (the kinematic rows use the
// raw q, linearly, on both sides).
//
// Tolerance per row i: the analytic Jacobian takes the q- and v-dependence of the forces and of G
// by forward differences with step h_a = 1.5e-8 (times max(1, |v_k|) for velocities), so its
// error is at most h_a/2 |d2 r_i| + 2 rho_i / h_a, with |d2 r_i| the largest second derivative of
// r_i along the perturbed directions (estimated by second differences, times 4 for the
// dv/dq map on quaternion columns and max(1, |v|) for the velocity step) and rho_i ~ 100 eps times
// the magnitude of the terms summed in r_i; plus our own central-difference bound.
TEST_F(JacobianTest, DaeJacobianEqualsFiniteDifferencesOfResidual) {
  const Model& m = *fx_.model;
  DaeSystem dae(m);
  // The differenced Jacobian through every element: the lumped mesh's analytic tangents leave out
  // the turning of its line of action with the carrier (gear_mesh_test.cpp checks them).
  dae.set_element_tangents(false);
  const int n = dae.size();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const State& s : states_) {
    {
      Data d(m);
      CalcPositionKinematics(m, s.q, d);
      CheckAwayFromBranchCuts(d);
    }
    Eigen::VectorXd y(n), yp(n);
    for (int i = 0; i < n; ++i) y(i) = u(rng), yp(i) = u(rng);
    y.head(m.nq) = s.q;
    y.segment(dae.v_offset(), m.nv) = s.v;
    y.tail(dae.nh()).setZero();  // mu = 0
    for (int i = 0; i < dae.nc(); ++i) y(dae.lambda_offset() + i) = 5 * u(rng);
    const double cj = 37.0;
    Eigen::MatrixXd J(n, n);
    dae.Jacobian(s.t, cj, y, yp, J);

    Eigen::MatrixXd J_fd(n, n), bound(n, n);
    Eigen::VectorXd d2max = Eigen::VectorXd::Zero(n), rmax = Eigen::VectorXd::Zero(n);
    Eigen::VectorXd r(n);
    const double h = 1e-4;
    for (int j = 0; j < n; ++j) {
      for (int which = 0; which < 2; ++which) {  // 0: y column, 1: yp column
        if (which == 1 && j >= dae.lambda_offset()) continue;  // r does not see lambda', mu'
        auto residual = [&](double t) {
          Eigen::VectorXd yy = y, yyp = yp;
          (which == 0 ? yy : yyp)(j) += t;
          dae.Residual(s.t, yy, yyp, r);
          return Eigen::VectorXd(r);
        };
        const CentralDifference D = Differentiate(residual, h);
        const Eigen::VectorXd r0 = residual(0), rp = residual(h), rm = residual(-h);
        const Eigen::VectorXd d2 = ((rp - 2 * r0 + rm) / (h * h)).cwiseAbs();
        d2max = d2max.cwiseMax(d2);
        rmax = rmax.cwiseMax(r0.cwiseAbs());
        if (which == 0) {
          J_fd.col(j) = D.d;
          bound.col(j) = D.bound;
        } else {
          J_fd.col(j) += cj * D.d;
          bound.col(j) += cj * D.bound;
        }
      }
    }
    // Second derivatives along velocity-space directions (the engine's perturbations), and the
    // magnitude of the terms in each row: tau_id at vdot = 0, M vdot, G^T lambda.
    for (int k = 0; k < m.nv; ++k) {
      auto along = [&](double t) {
        Eigen::VectorXd yy = y;
        Eigen::VectorXd q = s.q;
        IntegratePositions(m, t * Eigen::VectorXd::Unit(m.nv, k), q);
        yy.head(m.nq) = q;
        dae.Residual(s.t, yy, yp, r);
        return Eigen::VectorXd(r);
      };
      const Eigen::VectorXd rp = along(h), r0 = along(0), rm = along(-h);
      d2max = d2max.cwiseMax(((rp - 2 * r0 + rm) / (h * h)).cwiseAbs());
    }
    {
      Data& d = dae.data();
      EvaluateDynamics(m, s.t, s.q, s.v, Eigen::VectorXd::Zero(m.nv), d);
      CalcMassMatrix(m, d);
      const Eigen::VectorXd terms =
          d.tau_id.cwiseAbs() + (d.M * yp.segment(dae.v_offset(), m.nv)).cwiseAbs() +
          (d.G.transpose() * y.segment(dae.lambda_offset(), m.n_constraints)).cwiseAbs();
      rmax.segment(dae.v_offset(), m.nv) = rmax.segment(dae.v_offset(), m.nv).cwiseMax(terms);
    }
    const double vscale = std::max(1.0, s.v.lpNorm<Eigen::Infinity>());
    const Eigen::VectorXd engine_error =
        (kEngineFdStep * vscale / 2) * 4 * d2max +
        2 * 100 * kEps * (rmax.array() + 1).matrix() / kEngineFdStep;
    double worst = 0;
    int worst_i = 0, worst_j = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double tol = bound(i, j) + engine_error(i);
        const double e = std::abs(J(i, j) - J_fd(i, j));
        if (e / tol > worst) worst = e / tol, worst_i = i, worst_j = j;
        EXPECT_LE(e, tol) << "J(" << i << ", " << j << ") = " << J(i, j) << ", FD " << J_fd(i, j);
      }
    std::printf("[jacobian] (d) max error/bound %.3f at (%d, %d), |J| max %.2e\n", worst, worst_i,
                worst_j, J.cwiseAbs().maxCoeff());
  }
}

}  // namespace
}  // namespace orrery

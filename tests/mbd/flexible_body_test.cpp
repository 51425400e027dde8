// Floating-frame flexible bodies (mbd/flexible_body.h) against an independent model.
//
// Oracle: a flexible body made of point masses whose "modes" move some of them along straight
// lines fixed in the body is, exactly, a rigid core carrying point masses on prismatic joints
// with springs. The joint-tree engine (composite-rigid-body mass matrix, Newton-Euler bias
// terms) integrates that second model with no flexible-body code at all; every floating-frame
// term (deformed inertia, rigid-modal coupling, centrifugal and Coriolis terms, modal forces of
// loads on node frames, modal columns of constraint rows) must reproduce it. The modes are mixed
// by an invertible matrix T (q_joint = T q_modal) so that every invariant has off-diagonal
// entries. The rigid model's point masses carry a rotational inertia of 1e-12 kg m^2 (a body
// needs one); its effect is far below the tolerances.
//
// Tolerance: both runs use IDA at rtol 1e-10, atol 1e-12; each holds its local errors to that
// level, so positions of order 1 m agree to ~steps * rtol (a few 1e-7 at most over the runs
// here); the bound printed is 2 steps rtol sqrt(n) like the rigid-body tests.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/flexible_dynamics.h"
#include "mbd/force_elements.h"
#include "mbd/hdf5_reader.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "mbd/state.h"
#include "mbd/xdmf_writer.h"
#include "tests/common/particle_cloud.h"

namespace orrery {
namespace {

constexpr double kRtol = 1e-10, kAtol = 1e-12;

IntegratorOptions IdaOptions() {
  IntegratorOptions opt;
  opt.kind = IntegratorKind::kIda;
  opt.rtol = kRtol;
  opt.atol = kAtol;
  return opt;
}

Eigen::VectorXd QuatCoords(const Quat& q) {
  Eigen::VectorXd c(4);
  c << q.w(), q.x(), q.y(), q.z();
  return c;
}

// The point-mass body: a rigid core of four masses and three movers on body-fixed lines.
struct PointMassBody {
  std::vector<double> core_mass{0.8, 1.1, 0.6, 0.9};
  std::vector<Vec3> core_pos{{0.2, 0.0, 0.0}, {-0.1, 0.25, 0.05}, {0.0, -0.15, 0.3},
                             {0.05, 0.1, -0.2}};
  std::vector<double> mover_mass{0.3, 0.45, 0.25};
  std::vector<Vec3> mover_pos{{0.5, 0.1, 0.0}, {-0.2, -0.4, 0.1}, {0.1, 0.3, 0.45}};
  std::vector<Vec3> mover_dir{Vec3(1, 0.2, 0).normalized(), Vec3(0.1, 1, 0.3).normalized(),
                              Vec3(-0.3, 0.2, 1).normalized()};
  Vec3 spring{400.0, 250.0, 600.0};  // N/m on each mover's slide
  Eigen::Matrix3d T;                 // q_joint = T q_modal

  PointMassBody() { T << 1.0, 0.3, -0.2, 0.1, 0.9, 0.25, -0.15, 0.2, 1.1; }

  // The invariants of flexible_body.h, summed over the point masses.
  std::shared_ptr<FlexibleBodyModes> Modes() const {
    auto m = std::make_shared<FlexibleBodyModes>();
    const int n = 3;
    m->nf = n;
    m->I2 = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    m->I4.assign(n, Mat3::Zero());
    m->I5.assign(n * n, Mat3::Zero());
    auto add_point = [&](double mass, const Vec3& x, const Eigen::Matrix<double, 3, Eigen::Dynamic>& phi) {
      m->mass += mass;
      m->I1 += mass * x;
      m->I3 += mass * x * x.transpose();
      m->I2 += mass * phi;
      for (int k = 0; k < n; ++k) {
        m->I4[k] += mass * x * phi.col(k).transpose();
        for (int l = 0; l < n; ++l) m->I5[k * n + l] += mass * phi.col(k) * phi.col(l).transpose();
      }
    };
    for (size_t i = 0; i < core_mass.size(); ++i)
      add_point(core_mass[i], core_pos[i], Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n));
    for (int j = 0; j < 3; ++j) {
      FlexibleBodyModes::Node node;
      node.id = 100 + j;
      node.position = mover_pos[j];
      node.translation_shapes = mover_dir[j] * T.row(j);  // 3 x n
      add_point(mover_mass[j], mover_pos[j], node.translation_shapes);
      m->nodes.push_back(node);
    }
    m->stiffness = T.transpose() * spring.asDiagonal() * T;
    return m;
  }

  // Central inertia of the core (point masses) about its centre of mass.
  void Core(double* mass, Vec3* com, Mat3* I_cm) const {
    *mass = 0;
    *com = Vec3::Zero();
    for (size_t i = 0; i < core_mass.size(); ++i) {
      *mass += core_mass[i];
      *com += core_mass[i] * core_pos[i];
    }
    *com /= *mass;
    *I_cm = Mat3::Zero();
    for (size_t i = 0; i < core_mass.size(); ++i) {
      const Vec3 r = core_pos[i] - *com;
      *I_cm += core_mass[i] * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
    }
  }
};

struct Scenario {
  bool gravity = true;
  bool spring_on_node = true;     // a translational spring from the world to mover 0's node
  bool loop_on_node = false;      // mover 1's node held on a world point by a spherical loop
};

Vec3 kFreeP0(0.1, -0.2, 0.3);
const Quat kFreeQ0(AxisAngle(Vec3(1, -1, 0.5).normalized(), 0.7));

struct Built {
  std::shared_ptr<const Model> model;
  std::vector<FrameIndex> mover_frames;  // world positions compared
};

// The flexible-body model.
Built BuildFlexible(const PointMassBody& pm, const Scenario& sc, const Eigen::Vector3d& q_modal,
                    const Eigen::Vector3d& v_modal, const Eigen::VectorXd& v_free) {
  ModelBuilder b;
  const BodyIndex body = b.AddFlexibleBody("body", pm.Modes());
  const JointIndex free = b.AddJoint({.name = "free", .type = JointType::kFree,
                                      .parent = kWorldBody, .child = body});
  Eigen::VectorXd q0(7);
  q0 << kFreeP0, QuatCoords(kFreeQ0);
  b.SetJointPosition(free, q0);
  b.SetJointVelocity(free, v_free);
  b.SetModalCoordinates(body, q_modal, v_modal);
  Built out;
  for (int j = 0; j < 3; ++j)
    out.mover_frames.push_back(b.AddNodeFrame("mover" + std::to_string(j), body, b.FindNode(body, 100 + j),
                                              Transform::Translation(pm.mover_pos[j])));
  const FrameIndex anchor = b.AddFrame("anchor", kWorldBody, Transform::Translation(Vec3(1.0, 0.5, 0.2)));
  if (sc.spring_on_node)
    b.AddTranslationalSpring({.name = "tether", .frame_a = anchor, .frame_b = out.mover_frames[0],
                              .stiffness = 50.0, .damping = 0.0, .free_length = 0.6});
  if (sc.gravity) b.SetGravity(Vec3(0, 0, -9.81));
  if (sc.loop_on_node) {
    // The pivot where mover 1 starts (computed from the initial configuration).
    const Transform X_WB0(kFreeQ0.toRotationMatrix(), kFreeP0);
    const Vec3 p1 = X_WB0 * (pm.mover_pos[1] + pm.mover_dir[1] * (pm.T.row(1) * q_modal));
    const FrameIndex pivot = b.AddFrame("pivot", kWorldBody, Transform::Translation(p1));
    b.AddLoopClosure({.name = "hold", .type = JointType::kSpherical, .frame_a = pivot,
                      .frame_b = out.mover_frames[1]});
  }
  out.model = std::move(b).Finalize();
  return out;
}

// The equivalent rigid model: core on a free joint, movers on prismatic joints with springs.
Built BuildRigid(const PointMassBody& pm, const Scenario& sc, const Eigen::Vector3d& q_modal,
                 const Eigen::Vector3d& v_modal, const Eigen::VectorXd& v_free) {
  ModelBuilder b;
  double m0;
  Vec3 c0;
  Mat3 I0;
  pm.Core(&m0, &c0, &I0);
  const BodyIndex core = b.AddBody("core", m0, c0, I0);
  const JointIndex free = b.AddJoint({.name = "free", .type = JointType::kFree,
                                      .parent = kWorldBody, .child = core});
  Eigen::VectorXd q0(7);
  q0 << kFreeP0, QuatCoords(kFreeQ0);
  b.SetJointPosition(free, q0);
  const Eigen::Vector3d q_joint = pm.T * q_modal, v_joint = pm.T * v_modal;
  Built out;
  for (int j = 0; j < 3; ++j) {
    const BodyIndex mover = b.AddBody("mover" + std::to_string(j), pm.mover_mass[j], Vec3::Zero(),
                                      1e-12 * Mat3::Identity());
    const JointIndex slide = b.AddJoint({.name = "slide" + std::to_string(j), .type = JointType::kPrismatic,
                                         .parent = core, .child = mover,
                                         .X_PF = Transform::Translation(pm.mover_pos[j]),
                                         .axis = pm.mover_dir[j]});
    b.SetJointPosition(slide, Eigen::VectorXd::Constant(1, q_joint(j)));
    b.SetJointVelocity(slide, Eigen::VectorXd::Constant(1, v_joint(j)));
    b.AddCoordinateSpring({.name = "k" + std::to_string(j), .joint = slide, .stiffness = pm.spring(j)});
    out.mover_frames.push_back(b.body_frame(mover));
  }
  // The free joint's velocity is that of the core frame, the same variables as the flexible
  // body's frame.
  b.SetJointVelocity(free, v_free);
  const FrameIndex anchor = b.AddFrame("anchor", kWorldBody, Transform::Translation(Vec3(1.0, 0.5, 0.2)));
  if (sc.spring_on_node)
    b.AddTranslationalSpring({.name = "tether", .frame_a = anchor, .frame_b = out.mover_frames[0],
                              .stiffness = 50.0, .damping = 0.0, .free_length = 0.6});
  if (sc.gravity) b.SetGravity(Vec3(0, 0, -9.81));
  if (sc.loop_on_node) {
    const Transform X_WB0(kFreeQ0.toRotationMatrix(), kFreeP0);
    const Vec3 p1 = X_WB0 * (pm.mover_pos[1] + pm.mover_dir[1] * q_joint(1));
    const FrameIndex pivot = b.AddFrame("pivot", kWorldBody, Transform::Translation(p1));
    b.AddLoopClosure({.name = "hold", .type = JointType::kSpherical, .frame_a = pivot,
                      .frame_b = out.mover_frames[1]});
  }
  out.model = std::move(b).Finalize();
  return out;
}

// Runs both models and returns the largest distance between matching movers.
double CompareRuns(const Scenario& sc, double t_end, long* steps, double* bound) {
  const PointMassBody pm;
  const Eigen::Vector3d q_modal(0.02, -0.03, 0.015);
  Eigen::Vector3d v_modal(0.1, 0.2, -0.15);
  Eigen::VectorXd v_free(6);
  v_free << 0.2, -0.1, 0.3, 1.5, -2.0, 3.0;
  // Hung by a node: start at rest (the initial velocity projection onto the constraints is a
  // minimum-norm step whose metric depends on the coordinates, so the two models would start
  // from different velocities).
  if (sc.loop_on_node) {
    v_free.setZero();
    v_modal.setZero();
  }
  const Built flex = BuildFlexible(pm, sc, q_modal, v_modal, v_free);
  const Built rigid = BuildRigid(pm, sc, q_modal, v_modal, v_free);
  auto fi = MakeIntegrator(*flex.model, IdaOptions());
  auto ri = MakeIntegrator(*rigid.model, IdaOptions());
  fi->Initialize(State::Initial(*flex.model));
  ri->Initialize(State::Initial(*rigid.model));
  Data fd(*flex.model), rd(*rigid.model);
  double err = 0;
  const double dt = 0.01;
  for (int i = 0; i * dt <= t_end + 1e-12; ++i) {
    if (i > 0) {
      fi->AdvanceTo(i * dt);
      ri->AdvanceTo(i * dt);
    }
    CalcPositionKinematics(*flex.model, fi->state().q, fd);
    CalcPositionKinematics(*rigid.model, ri->state().q, rd);
    for (int j = 0; j < 3; ++j)
      err = std::max(err, (fd.X_WFrame[flex.mover_frames[j]].p - rd.X_WFrame[rigid.mover_frames[j]].p).norm());
  }
  *steps = std::max(fi->stats().steps, ri->stats().steps);
  *bound = 2 * (*steps) * kRtol * std::sqrt(flex.model->nq + flex.model->nv);
  return err;
}

TEST(FlexibleBody, PointMassModesMatchPrismaticMovers) {
  long steps;
  double bound;
  const double err = CompareRuns({.gravity = true, .spring_on_node = true}, 2.0, &steps, &bound);
  std::printf("[flex] free tumbling point-mass body, spring on a node: max position difference "
              "%.2e m over %ld steps (bound %.2e)\n", err, steps, bound);
  EXPECT_LE(err, bound);
}

TEST(FlexibleBody, ConstraintOnNodeMatchesPrismaticMovers) {
  long steps;
  double bound;
  const double err = CompareRuns({.gravity = true, .spring_on_node = false, .loop_on_node = true},
                                 1.0, &steps, &bound);
  std::printf("[flex] point-mass body hung by a node on a spherical loop closure: max position "
              "difference %.2e m over %ld steps (bound %.2e)\n", err, steps, bound);
  EXPECT_LE(err, bound);
}

// The mass matrix of the flexible model equals the rigid model's in the modal coordinates:
// M_flex = P^T M_rigid P with P = diag(I6, T) (q_joint = T q_modal). Independent of integration.
TEST(FlexibleBody, MassMatrixAndBiasMatchTheJointModel) {
  const PointMassBody pm;
  const Eigen::Vector3d q_modal(0.05, -0.02, 0.03), v_modal(0.3, -0.1, 0.2);
  Eigen::VectorXd v_free(6);
  v_free << 0.2, -0.1, 0.3, 1.5, -2.0, 3.0;
  const Scenario sc{.gravity = true, .spring_on_node = true};
  const Built flex = BuildFlexible(pm, sc, q_modal, v_modal, v_free);
  const Built rigid = BuildRigid(pm, sc, q_modal, v_modal, v_free);
  Data fd(*flex.model), rd(*rigid.model);
  const State fs = State::Initial(*flex.model), rs = State::Initial(*rigid.model);
  CalcPositionKinematics(*flex.model, fs.q, fd);
  CalcPositionKinematics(*rigid.model, rs.q, rd);
  CalcMassMatrix(*flex.model, fd);
  CalcMassMatrix(*rigid.model, rd);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(9, 9);
  P.topLeftCorner(6, 6).setIdentity();
  P.bottomRightCorner(3, 3) = pm.T;
  const Eigen::MatrixXd M_expected = P.transpose() * rd.M * P;
  const double dM = (fd.M - M_expected).norm() / M_expected.norm();
  // Bias: inverse dynamics at vdot = 0 (Coriolis, centrifugal, gravity, spring), mapped by P^T.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(9);
  EvaluateDynamics(*flex.model, 0.0, fs.q, fs.v, zero, fd);
  EvaluateDynamics(*rigid.model, 0.0, rs.q, rs.v, zero, rd);
  const Eigen::VectorXd h_expected = P.transpose() * rd.tau_id;
  const double dh = (fd.tau_id - h_expected).norm() / h_expected.norm();
  // Kinetic energy and momentum.
  const double T_f = CalcKineticEnergy(*flex.model, fd), T_r = CalcKineticEnergy(*rigid.model, rd);
  const Vec6 h_f = CalcSpatialMomentum(*flex.model, fd), h_r = CalcSpatialMomentum(*rigid.model, rd);
  std::printf("[flex] mass matrix rel. diff %.2e, bias rel. diff %.2e, T %.2e, momentum %.2e "
              "(rigid movers' inertia 1e-12 kg m^2)\n",
              dM, dh, std::abs(T_f - T_r) / T_r, (h_f - h_r).norm() / h_r.norm());
  EXPECT_LT(dM, 1e-10);
  EXPECT_LT(dh, 1e-10);
  EXPECT_LT(std::abs(T_f - T_r), 1e-10 * T_r);
  EXPECT_LT((h_f - h_r).norm(), 1e-10 * h_r.norm());
}

// A free flexible body without gravity or damping keeps its energy (kinetic + elastic) and its
// spatial momentum.
TEST(FlexibleBody, FreeBodyConservesEnergyAndMomentum) {
  const PointMassBody pm;
  Eigen::VectorXd v_free(6);
  v_free << 0.2, -0.1, 0.3, 1.5, -2.0, 3.0;
  const Built flex = BuildFlexible(pm, {.gravity = false, .spring_on_node = false},
                                   Eigen::Vector3d(0.02, -0.03, 0.015),
                                   Eigen::Vector3d(0.1, 0.2, -0.15), v_free);
  const Model& model = *flex.model;
  auto integ = MakeIntegrator(model, IdaOptions());
  integ->Initialize(State::Initial(model));
  Data data(model);
  auto measure = [&](double* E, Vec6* h) {
    CalcPositionKinematics(model, integ->state().q, data);
    CalcVelocityKinematics(model, integ->state().v, data);
    CalcForceElements(model, integ->state().t, integ->state().v, data);
    *E = CalcKineticEnergy(model, data) + data.potential_energy;
    *h = CalcSpatialMomentum(model, data);
  };
  double E0, E;
  Vec6 h0, h;
  measure(&E0, &h0);
  double dE = 0, dh = 0;
  for (int i = 1; i <= 300; ++i) {
    integ->AdvanceTo(0.01 * i);
    measure(&E, &h);
    dE = std::max(dE, std::abs(E - E0) / E0);
    dh = std::max(dh, (h - h0).norm() / h0.norm());
  }
  const long steps = integ->stats().steps;
  const double bound = 2 * steps * kRtol * std::sqrt(model.nq + model.nv);
  std::printf("[flex] free flexible body, 3 s: rel. drift E %.2e, momentum %.2e over %ld steps "
              "(bound %.2e)\n", dE, dh, steps, bound);
  EXPECT_LE(dE, bound);
  EXPECT_LE(dh, bound);
}

// Frozen modes: the flexible body moves exactly like the rigid body with its mass properties.
TEST(FlexibleBody, FrozenModesMoveLikeTheRigidBody) {
  const PointMassBody pm;
  auto modes = pm.Modes();
  auto build = [&](bool flexible) {
    ModelBuilder b;
    BodyIndex body;
    if (flexible) {
      body = b.AddFlexibleBody("body", modes, {.frozen = true});
    } else {
      const Vec3 com = modes->I1 / modes->mass;
      Mat3 J = -modes->I3;
      J.diagonal().array() += modes->I3.trace();
      const Mat3 Jc = J - modes->mass * (com.squaredNorm() * Mat3::Identity() - com * com.transpose());
      body = b.AddBody("body", modes->mass, com, Jc);
    }
    const JointIndex ball = b.AddJoint({.name = "ball", .type = JointType::kSpherical,
                                        .parent = kWorldBody, .child = body,
                                        .X_CM = Transform::Translation(Vec3(0.3, -0.2, 0.4))});
    b.SetJointPosition(ball, QuatCoords(kFreeQ0));
    b.SetJointVelocity(ball, Eigen::Vector3d(1.0, -2.0, 0.5));
    b.SetGravity(Vec3(0, 0, -9.81));
    return std::move(b).Finalize();
  };
  const auto flex = build(true), rigid = build(false);
  ASSERT_EQ(flex->nv, 3);
  auto fi = MakeIntegrator(*flex, IdaOptions()), ri = MakeIntegrator(*rigid, IdaOptions());
  fi->Initialize(State::Initial(*flex));
  ri->Initialize(State::Initial(*rigid));
  double err = 0;
  for (int i = 1; i <= 200; ++i) {
    fi->AdvanceTo(0.01 * i);
    ri->AdvanceTo(0.01 * i);
    err = std::max(err, (fi->state().q - ri->state().q).lpNorm<Eigen::Infinity>());
  }
  const long steps = std::max(fi->stats().steps, ri->stats().steps);
  const double bound = 2 * steps * kRtol * std::sqrt(flex->nq + flex->nv);
  std::printf("[flex] frozen flexible body vs rigid body on a spherical joint, 2 s: max |dq| "
              "%.2e over %ld steps (bound %.2e)\n", err, steps, bound);
  EXPECT_LE(err, bound);
}

// A cloud of point masses, each moved by all nf modes along its own random directions (no body
// of the joint model above: every I5_kl is a full 3 x 3 matrix and the sums run over seven modes,
// so a wrong stride or index in the stacked products of flexible_dynamics.cpp shows). The oracle
// is the particles themselves: with y_p = x_p + Phi_p q the deformed position of point p in B,
//   S = sum m_p y_p,   J = sum m_p (|y_p|^2 1 - y_p y_p^T),   D_l = sum m_p y_p Phi_pl^T,
//   L_l = sum m_p y_p x Phi_pl,
// and Newton's law per particle gives the modal rows of inverse dynamics (no stiffness, gravity
// or load): r_l = sum m_p Phi_pl . (a + alpha x y_p + w x (w x y_p) + 2 w x Phi_p qd + Phi_p qdd),
// with a, alpha, w the acceleration of B's origin, B's angular acceleration and velocity, in B.
using test_support::ParticleCloud;

TEST(FlexibleBody, ModalSumsMatchAParticleCloud) {
  const ParticleCloud cloud;
  const int n = ParticleCloud::kModes;
  ModelBuilder b;
  const BodyIndex body = b.AddFlexibleBody("cloud", cloud.Modes());
  const JointIndex free =
      b.AddJoint({.name = "free", .type = JointType::kFree, .parent = kWorldBody, .child = body});
  Eigen::VectorXd q0(7), v0(6), qf(n), vf(n);
  q0 << kFreeP0, QuatCoords(kFreeQ0);
  v0 << 0.7, -1.1, 0.4, 1.5, -2.0, 3.0;
  for (int k = 0; k < n; ++k) {
    qf(k) = 0.01 * (k + 1) * (k % 2 ? -1 : 1);
    vf(k) = 0.3 - 0.07 * k;
  }
  b.SetJointPosition(free, q0);
  b.SetJointVelocity(free, v0);
  b.SetModalCoordinates(body, qf, vf);
  const auto model = std::move(b).Finalize();
  const State s = State::Initial(*model);
  Eigen::VectorXd vdot(model->nv);
  for (int i = 0; i < model->nv; ++i) vdot(i) = 0.5 * std::sin(1.0 + i);
  Data data(*model);
  EvaluateDynamics(*model, 0.0, s.q, s.v, vdot, data);

  const int fi = model->bodies[body].flexible;
  const FlexibleBody& fb = model->flexible_bodies[fi];
  const Data::FlexibleBodyTerms& T = data.flex[fi];
  // B's motion in B axes from the spatial (world-origin) velocity and acceleration.
  const Transform& X = data.X_WB[body];
  const Vec3 w_W = data.V_WB[body].head<3>();
  const Vec3 v_o = data.V_WB[body].tail<3>() + w_W.cross(X.p);
  const Vec3 a_o =
      data.A_WB[body].tail<3>() + data.A_WB[body].head<3>().cross(X.p) + w_W.cross(v_o);
  const Vec3 w = X.R.transpose() * w_W, alpha = X.R.transpose() * data.A_WB[body].head<3>();
  const Vec3 a = X.R.transpose() * a_o;
  const Eigen::VectorXd qd = vf, qdd = vdot.segment(fb.v_start, n);

  Vec3 S = Vec3::Zero();
  Mat3 J = Mat3::Zero();
  Eigen::Matrix<double, 3, Eigen::Dynamic> D =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, 3 * n);
  Eigen::Matrix<double, 3, Eigen::Dynamic> L = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
  for (int p = 0; p < ParticleCloud::kPoints; ++p) {
    const double m = cloud.mass[p];
    const Vec3 y = cloud.x[p] + cloud.phi[p] * qf;
    S += m * y;
    J += m * (y.squaredNorm() * Mat3::Identity() - y * y.transpose());
    const Vec3 acc = a + alpha.cross(y) + w.cross(w.cross(y)) + 2 * w.cross(cloud.phi[p] * qd) +
                     cloud.phi[p] * qdd;
    for (int l = 0; l < n; ++l) {
      D.block<3, 3>(0, 3 * l) += m * y * cloud.phi[p].col(l).transpose();
      L.col(l) += m * y.cross(cloud.phi[p].col(l));
      r(l) += m * cloud.phi[p].col(l).dot(acc);
    }
  }
  // Rounding only: sums of ~100 terms of order 1 (bound 1e-13 of each quantity's size).
  const double dS = (T.S - S).norm() / S.norm(), dJ = (T.J - J).norm() / J.norm();
  const double dD = (T.D - D).norm() / D.norm(), dL = (T.L - L).norm() / L.norm();
  const double dr = (data.tau_id.segment(fb.v_start, n) - r).norm() / r.norm();
  std::printf(
      "[flex] particle cloud, 7 modes: rel. diff S %.1e, J %.1e, D %.1e, L %.1e, "
      "modal rows %.1e\n",
      dS, dJ, dD, dL, dr);
  EXPECT_LT(dS, 1e-13);
  EXPECT_LT(dJ, 1e-13);
  EXPECT_LT(dD, 1e-13);
  EXPECT_LT(dL, 1e-13);
  EXPECT_LT(dr, 1e-13);

  // The stage's caches: a Data that went through other coordinates and rates (and back to
  // these, with the body elsewhere) writes what a fresh Data writes, to the bit.
  Data fresh(*model);
  EvaluateDynamics(*model, 0.0, s.q, s.v, vdot, fresh);
  Eigen::VectorXd q1 = s.q, v1 = s.v;
  q1.segment(fb.q_start, n) *= 1.5;
  v1.segment(fb.v_start, n) *= -0.5;
  EvaluateDynamics(*model, 0.0, q1, v1, vdot, data);
  EXPECT_NE(data.tau_id, fresh.tau_id);
  q1 = s.q;
  q1(0) += 0.1;  // another place, the same modal coordinates
  EvaluateDynamics(*model, 0.0, q1, s.v, vdot, data);
  EvaluateDynamics(*model, 0.0, s.q, s.v, vdot, data);
  EXPECT_EQ(data.tau_id, fresh.tau_id);
  EXPECT_EQ(data.flex[fi].D, fresh.flex[fi].D);
  EXPECT_EQ(data.flex[fi].J, fresh.flex[fi].J);
  EXPECT_EQ(data.flex[fi].G, fresh.flex[fi].G);
}

// The floating frame's column-combination kernel against the plain sequential sum, to the bit:
// every row summed in the order b_i + A_i0 x_0 + A_i1 x_1 + ... whatever the block a row falls
// in (blocks of 16, 8, 4 and single rows) and whatever vector width this machine's clone uses;
// both builds are called (the baseline runs everywhere, the AVX one where the CPU has it).

TEST(FlexibleBody, ColumnCombinationIsTheSequentialSumToTheBit) {
  std::srand(11);
  auto uniform = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
  for (int rows : {1, 3, 4, 7, 8, 15, 16, 17, 24, 29, 72, 216})
    for (int cols : {0, 1, 5, 24}) {
      const long lda = rows + 3;
      std::vector<double> A(static_cast<size_t>(lda) * std::max(cols, 1)), x(std::max(cols, 1)),
          b(rows), y(rows), expected(rows);
      for (double& v : A) v = uniform() * std::pow(10.0, 3 * uniform());
      for (double& v : x) v = uniform();
      for (double& v : b) v = uniform();
      for (const bool with_b : {false, true}) {
        for (int i = 0; i < rows; ++i) {
          volatile double sum = with_b ? b[i] : 0.0;  // no reassociation, no contraction
          for (int k = 0; k < cols; ++k) {
            volatile double product = A[k * lda + i] * x[k];
            sum = sum + product;
          }
          expected[i] = sum;
        }
        const double* bp = with_b ? b.data() : nullptr;
        AddColumnCombination(rows, cols, A.data(), lda, x.data(), bp, y.data());
        EXPECT_EQ(y, expected) << rows << " x " << cols << (with_b ? " with b" : "");
        AddColumnCombinationBaseline(rows, cols, A.data(), lda, x.data(), bp, y.data());
        EXPECT_EQ(y, expected) << "baseline, " << rows << " x " << cols;
#if ORRERY_COLUMN_COMBINATION_AVX
        if (__builtin_cpu_supports("avx")) {
          AddColumnCombinationAvx(rows, cols, A.data(), lda, x.data(), bp, y.data());
          EXPECT_EQ(y, expected) << "AVX, " << rows << " x " << cols;
        }
#endif
      }
    }
}

TEST(FlexibleBody, BadInputIsNamed) {
  const PointMassBody pm;
  auto modes = pm.Modes();
  modes->stiffness(0, 1) += 1.0;  // no longer symmetric
  ModelBuilder b;
  try {
    b.AddFlexibleBody("planet", modes);
    FAIL() << "accepted a non-symmetric stiffness";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("flexible body 'planet'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("stiffness"), std::string::npos) << e.what();
  }
  ModelBuilder b2;
  try {
    b2.AddFlexibleBody("planet", pm.Modes(), {.geometric_stiffening = true});
    FAIL() << "accepted geometric stiffening without data";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("geometric stiffness"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace orrery

namespace orrery {
namespace {

// The recorder's flexible-body outputs: modal coordinates, the von Mises hot spot (recomputed
// here from the stress modes) and the deformed surface (equal to the node frames), plus the
// XDMF file that animates it.
TEST(FlexibleBody, RecorderWritesModesStressAndSurface) {
  const PointMassBody pm;
  auto modes = pm.Modes();
  modes->surface_triangles = {{0, 1, 2}};
  modes->stress_nodes = {0, 1, 2};
  modes->stress_modes = Eigen::MatrixXd::Zero(18, 3);
  modes->node_sets["MOVERS"] = {2, 0};
  for (int r = 0; r < 18; ++r)
    for (int c = 0; c < 3; ++c) modes->stress_modes(r, c) = 1e6 * std::sin(1.0 + 3 * r + c);
  ModelBuilder b;
  FlexibleBodyOptions options;
  options.record_surface = true;
  options.record_node_sets = {"MOVERS"};
  const BodyIndex body = b.AddFlexibleBody("body", modes, options);
  b.AddJoint({.name = "free", .type = JointType::kFree, .parent = kWorldBody, .child = body});
  b.SetModalCoordinates(body, Eigen::Vector3d(0.02, -0.03, 0.015), Eigen::Vector3d(0.1, 0.2, -0.15));
  std::vector<FrameIndex> frames;
  for (int j = 0; j < 3; ++j)
    frames.push_back(b.AddNodeFrame("n" + std::to_string(j), body, j, Transform::Translation(pm.mover_pos[j])));
  const auto model = std::move(b).Finalize();
  const std::string path = ::testing::TempDir() + "flex_recorder.h5";
  SimulationOptions opt;
  opt.end_time = 0.05;
  opt.output_interval = 0.01;
  opt.integrator = IdaOptions();
  {
    ResultFile out = ResultFile::Create(path);
    Simulate(*model, opt, &out);
  }
  WriteSurfaceXdmf(path);
  Hdf5Reader r(path);
  const Eigen::MatrixXd q = r.ReadMatrix("/flexible_bodies/body/modal_q");
  const Eigen::MatrixXd vm = r.ReadMatrix("/flexible_bodies/body/von_mises_max");
  const Eigen::MatrixXd surf = r.ReadMatrix("/flexible_bodies/body/surface/positions");
  const Eigen::MatrixXd time = r.ReadMatrix("/time");
  ASSERT_EQ(q.rows(), 6);
  ASSERT_EQ(surf.cols(), 9);
  // Last row: recompute from the modal coordinates and the final pose.
  const int last = static_cast<int>(q.rows()) - 1;
  Eigen::VectorXd state_q = model->q_initial;
  const Eigen::MatrixXd qfree = r.ReadMatrix("/joints/free/q");
  state_q.head(7) = qfree.row(last).transpose();
  state_q.tail(3) = q.row(last).transpose();
  Data d(*model);
  CalcPositionKinematics(*model, state_q, d);
  const Eigen::VectorXd sigma = modes->stress_modes * q.row(last).transpose();
  double best = 0;
  for (int k = 0; k < 3; ++k) {
    const double* x = sigma.data() + 6 * k;
    const double s = std::sqrt(0.5 * ((x[0] - x[1]) * (x[0] - x[1]) + (x[1] - x[2]) * (x[1] - x[2]) +
                                      (x[2] - x[0]) * (x[2] - x[0])) +
                               3 * (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]));
    best = std::max(best, s);
  }
  EXPECT_NEAR(vm(last, 0), best, 1e-9 * best);
  for (int j = 0; j < 3; ++j)
    EXPECT_LT((surf.row(last).segment<3>(3 * j).transpose() - d.X_WFrame[frames[j]].p).norm(), 1e-12);
  EXPECT_TRUE(std::filesystem::exists(XdmfPathFor(path)));
  const Eigen::MatrixXd movers = r.ReadMatrix("/flexible_bodies/body/node_sets/MOVERS/displacement");
  ASSERT_EQ(movers.cols(), 6);
  EXPECT_LT((movers.row(last).segment<3>(0).transpose() - modes->nodes[2].translation_shapes * q.row(last).transpose()).norm(), 1e-15);
  EXPECT_LT((movers.row(last).segment<3>(3).transpose() - modes->nodes[0].translation_shapes * q.row(last).transpose()).norm(), 1e-15);
  EXPECT_NEAR(time(last, 0), 0.05, 1e-12);
}

}  // namespace
}  // namespace orrery

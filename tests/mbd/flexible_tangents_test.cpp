// DaeSystem::Tangents' modal columns of a leaf flexible body from the floating-frame equations
// (mbd/flexible_dynamics.h SetFlexibleModalTangents) against central differences of the whole
// pipeline's residual (DaeSystem::Residual: every stage from the coordinates, no tangent code).
//
// Oracle: every term of the dynamic rows is at most quadratic in q_f and linear in q_f-dot
// (flexible_body.h: S, D_l, L_l linear, U quadratic, the modal Coriolis sums linear in the
// rates), and the body is a leaf, so q_f and q_f-dot move nothing else (the body's frame moves
// with its ancestors' coordinates only). A central difference of a quadratic is exact: the
// difference quotient differs from the derivative by rounding alone, about eps |r| / h for a
// residual of size |r| and a step h (here |r| ~ 1e2 N, h = 1e-4: ~1e-10), against columns of
// size ~1 to 1e3. The bound per entry below is 100 eps |r|_inf / h.
//
// The model: a particle cloud (7 modes mixing 11 point masses along their own random directions,
// as flexible_body_test.cpp's ModalSumsMatchAParticleCloud) on a revolute joint about a tilted
// axis, hanging from a rigid arm on a free joint: B turns and accelerates in 3-D, with gravity,
// modal stiffness and damping, geometric stiffening (random symmetric G_c) and a bearing between
// the world and the arm.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/flexible_dynamics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "tests/common/particle_cloud.h"

namespace orrery {
namespace {

constexpr int kModes = test_support::ParticleCloud::kModes;

// The particle cloud of seed 11, with a node at its first particle (for a node frame), modal
// stiffness and random symmetric geometric stiffness.
std::shared_ptr<FlexibleBodyModes> CloudModes(bool with_node) {
  const test_support::ParticleCloud cloud(11);
  std::shared_ptr<FlexibleBodyModes> m = cloud.Modes();
  auto uniform = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
  const int n = kModes;
  if (with_node) {
    FlexibleBodyModes::Node node;
    node.id = 1;
    node.position = cloud.x[0];
    node.translation_shapes = cloud.phi[0];
    m->nodes.push_back(node);
  }
  m->stiffness = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k) m->stiffness(k, k) = 1e3 * (k + 1);
  for (int c = 0; c < 6; ++c) {
    Eigen::MatrixXd G(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) G(i, j) = uniform();
    m->geometric_stiffness.push_back(G + G.transpose());
  }
  return m;
}

struct CloudModel {
  std::shared_ptr<const Model> model;
  BodyIndex cloud = -1;
};

// child_joint: a body hangs from the cloud; node_spring: a spring pulls a frame on its node.
CloudModel BuildCloud(bool child_joint = false, bool node_spring = false) {
  ModelBuilder b;
  b.SetGravity(Vec3(0.0, -9.81, 0.0));
  const BodyIndex arm = b.AddBody("arm", 3.0, Vec3(0.05, 0.0, 0.02),
                                  Vec3(0.04, 0.05, 0.06).asDiagonal().toDenseMatrix());
  const JointIndex free =
      b.AddJoint({.name = "free", .type = JointType::kFree, .parent = kWorldBody, .child = arm});
  FlexibleBodyOptions options;
  options.damping_ratios = {0.02};
  options.geometric_stiffening = true;
  const BodyIndex cloud = b.AddFlexibleBody("cloud", CloudModes(node_spring), options);
  const JointIndex pin = b.AddJoint({.name = "pin",
                                     .type = JointType::kRevolute,
                                     .parent = arm,
                                     .child = cloud,
                                     .X_PF = Transform::Translation(Vec3(0.2, -0.1, 0.05)),
                                     .axis = Vec3(0.3, -0.5, 1.0).normalized()});
  Eigen::VectorXd q0(7), v0(6), qf(kModes), vf(kModes);
  q0 << 0.1, -0.2, 0.3, Quat(AxisAngle(Vec3(1, -1, 0.5).normalized(), 0.7)).w(),
      Quat(AxisAngle(Vec3(1, -1, 0.5).normalized(), 0.7)).vec();
  v0 << 0.7, -1.1, 0.4, 1.5, -2.0, 3.0;
  for (int k = 0; k < kModes; ++k) {
    qf(k) = 0.01 * (k + 1) * (k % 2 ? -1 : 1);
    vf(k) = 0.3 - 0.07 * k;
  }
  b.SetJointPosition(free, q0);
  b.SetJointVelocity(free, v0);
  b.SetJointPosition(pin, Eigen::VectorXd::Constant(1, 0.4));
  b.SetJointVelocity(pin, Eigen::VectorXd::Constant(1, 5.0));
  b.SetModalCoordinates(cloud, qf, vf);
  const FrameIndex anchor =
      b.AddFrame("anchor", kWorldBody, Transform::Translation(Vec3(0.1, -0.2, 0.3)));
  b.AddBearing({.name = "mount",
                .frame_a = anchor,
                .frame_b = b.body_frame(arm),
                .radial_stiffness = 1e4,
                .axial_stiffness = 2e4,
                .tilt_stiffness = 3e2,
                .radial_damping = 5.0,
                .axial_damping = 7.0,
                .tilt_damping = 0.3});
  if (child_joint) {
    const BodyIndex tip = b.AddBody("tip", 0.5, Vec3::Zero(), 1e-3 * Mat3::Identity());
    b.AddJoint({.name = "tip", .type = JointType::kRevolute, .parent = cloud, .child = tip});
  }
  if (node_spring) {
    const FrameIndex node = b.AddNodeFrame("node", cloud, 0, Transform::Identity());
    b.AddTranslationalSpring({.name = "tether",
                              .frame_a = anchor,
                              .frame_b = node,
                              .stiffness = 50.0,
                              .free_length = 0.2});
  }
  CloudModel out;
  out.cloud = cloud;
  out.model = std::move(b).Finalize();
  return out;
}

TEST(FlexibleTangents, ModalColumnsMatchCentralDifferencesOfTheResidual) {
  const CloudModel built = BuildCloud();
  const Model& model = *built.model;
  const int fi = model.bodies[built.cloud].flexible;
  ASSERT_TRUE(ModalColumnsAreLocal(model, fi));
  const FlexibleBody& fb = model.flexible_bodies[fi];
  const int nv = model.nv, nq = model.nq, nc = model.n_constraints, n = fb.nf;

  DaeSystem dae(model);
  EXPECT_EQ(dae.differenced_columns(), nv - n);
  const State s = State::Initial(model);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(dae.size()), yp = Eigen::VectorXd::Zero(dae.size());
  y.segment(0, nq) = s.q;
  y.segment(nq, nv) = s.v;
  for (int i = 0; i < nv; ++i) yp(nq + i) = 0.5 * std::sin(1.0 + i);  // v-dot
  const auto q = y.segment(0, nq), v = y.segment(nq, nv), vdot = yp.segment(nq, nv);
  const auto lambda = y.segment(nq + nv, nc);
  Eigen::MatrixXd Kq(nv + nc, nv), Cv(nv, nv);
  dae.Tangents(0.0, q, v, vdot, lambda, Kq, Cv);

  // The oracle: central differences of r_v in q_f (plain coordinates) and in q_f-dot.
  const double h = 1e-4, eps = std::numeric_limits<double>::epsilon();
  Eigen::VectorXd r(dae.size()), r_plus(dae.size()), r_minus(dae.size());
  dae.Residual(0.0, y, yp, r);
  const double bound = 100 * eps * r.segment(nq, nv).lpNorm<Eigen::Infinity>() / h;
  double worst[2] = {0, 0}, size[2] = {0, 0};  // position, rate columns
  for (int k = 0; k < n; ++k)
    for (const int rate : {0, 1}) {
      const int coordinate = rate ? nq + fb.v_start + k : fb.q_start + k;
      Eigen::VectorXd yk = y;
      yk(coordinate) += h;
      dae.Residual(0.0, yk, yp, r_plus);
      yk(coordinate) -= 2 * h;
      dae.Residual(0.0, yk, yp, r_minus);
      const Eigen::VectorXd central = (r_plus - r_minus).segment(nq, nv) / (2 * h);
      const Eigen::VectorXd analytic = rate ? Eigen::VectorXd(Cv.col(fb.v_start + k))
                                            : Eigen::VectorXd(Kq.col(fb.v_start + k).head(nv));
      worst[rate] = std::max(worst[rate], (analytic - central).lpNorm<Eigen::Infinity>());
      size[rate] = std::max(size[rate], central.lpNorm<Eigen::Infinity>());
    }
  // The velocity constraints' rows do not see q_f.
  EXPECT_EQ(Kq.block(nv, fb.v_start, nc, n).norm(), 0.0);
  std::printf(
      "[flex tangents] 7 modes, leaf on a tilted pin: max |analytic - central| position "
      "columns %.2e (entries up to %.2e), rate columns %.2e (up to %.2e); bound %.2e\n",
      worst[0], size[0], worst[1], size[1], bound);
  EXPECT_LT(worst[0], bound);
  EXPECT_LT(worst[1], bound);

  // The other columns are the differences as before, to the bit; the modal ones within the
  // forward differences' error: their rounding eps |r| / h with h = 1.5e-8 and |r| ~ 4.5e2 is
  // ~7e-6 per entry, against columns of norm 1 and more (checked at 1e-5 of the column's norm).
  DaeSystem differenced(model);
  differenced.set_analytic_modal_columns(false);
  EXPECT_EQ(differenced.differenced_columns(), nv);
  Eigen::MatrixXd Kq_fd(nv + nc, nv), Cv_fd(nv, nv);
  differenced.Tangents(0.0, q, v, vdot, lambda, Kq_fd, Cv_fd);
  for (int k = 0; k < nv; ++k) {
    if (k >= fb.v_start && k < fb.v_start + n) {
      EXPECT_LT((Kq.col(k) - Kq_fd.col(k)).norm(), 1e-5 * Kq.col(k).norm()) << "column " << k;
      EXPECT_LT((Cv.col(k) - Cv_fd.col(k)).norm(), 1e-5 * Cv.col(k).norm()) << "column " << k;
    } else {
      EXPECT_EQ(Kq.col(k), Kq_fd.col(k)) << "column " << k;
      EXPECT_EQ(Cv.col(k), Cv_fd.col(k)) << "column " << k;
    }
  }
}

TEST(FlexibleTangents, ModalColumnsAreDifferencedWhereTheyReachOtherElements) {
  // A body hanging from the flexible one moves with its deformation only through the joint's
  // frame; a spring on a node frame reads q_f: both keep the differences.
  const CloudModel with_child = BuildCloud(/*child_joint=*/true);
  EXPECT_FALSE(ModalColumnsAreLocal(*with_child.model, 0));
  EXPECT_EQ(DaeSystem(*with_child.model).differenced_columns(), with_child.model->nv);
  const CloudModel with_spring = BuildCloud(false, /*node_spring=*/true);
  EXPECT_FALSE(ModalColumnsAreLocal(*with_spring.model, 0));
  EXPECT_EQ(DaeSystem(*with_spring.model).differenced_columns(), with_spring.model->nv);
}

}  // namespace
}  // namespace orrery

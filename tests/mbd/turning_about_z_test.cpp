// The shortcut CalcInverseDynamics takes for bodies that turn about z (Body::turns_about_z)
// against the general path on the same trees.
//
// Inverse dynamics: the general recursion written out here (I A + V x* (I V) - f_ext per body,
// subtree sums, S^T f); the shortcut leaves out only products with exact zeros, so every joint
// force and generalized force must be the same to the last bit, and the zeros it relies on must
// be exact in V_WB and A_WB.
//
// Finalize's flag: bodies below a tilted joint or on a free joint must not carry it (their V
// and A have no such zeros). The world inertias keep R I Rᵀ for every body: taking inertia_cm_B
// for the bodies whose inertia is axisymmetric about z (equal to R I Rᵀ to a few ε) was tried
// and not kept, because the seed 003 fault study's healthy sideband energy ratio moved with that
// rounding (docs/performance.md, stop 24).
#include <cmath>

#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"

namespace orrery {
namespace {

// A planetary-like tree turning about z (sun, carrier turned by a fixed rotation about z and by
// a flip of z, a planet on the carrier, a fixed disc on the planet) beside bodies that must keep
// the general path.
struct Tree {
  std::shared_ptr<const Model> model;
  BodyIndex sun, carrier, planet, disc, lopsided;  // turn about z (lopsided: not axisymmetric)
  BodyIndex tilted, under_tilt, floating;          // do not
};

Tree MakeTree(const Vec3& gravity = Vec3::Zero()) {
  ModelBuilder mb;
  mb.SetGravity(gravity);
  Tree t;
  const Mat3 axisymmetric = Vec3(2e-3, 2e-3, 3.5e-3).asDiagonal();
  Mat3 flip_z;  // a half turn about x, written exactly: z -> -z
  flip_z << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const Mat3 turn_z = AxisAngle(Vec3::UnitZ(), 0.7);  // exact zeros off the z block
  t.sun = mb.AddBody("sun", 1.2, Vec3(0, 0, 0.01), axisymmetric);
  t.carrier = mb.AddBody("carrier", 3.0, Vec3(1e-4, -2e-4, 0.02), 4 * axisymmetric);
  t.planet = mb.AddBody("planet", 0.4, Vec3(0, 0, -0.003), 0.3 * axisymmetric);
  t.disc = mb.AddBody("disc", 0.1, Vec3(0.002, 0, 0), 0.1 * axisymmetric);
  t.lopsided = mb.AddBody("lopsided", 0.5, Vec3::Zero(), Vec3(1e-3, 2e-3, 3e-3).asDiagonal());
  t.tilted = mb.AddBody("tilted", 0.5, Vec3::Zero(), axisymmetric);
  t.under_tilt = mb.AddBody("under_tilt", 0.5, Vec3::Zero(), axisymmetric);
  t.floating = mb.AddBody("floating", 0.5, Vec3::Zero(), axisymmetric);
  mb.AddJoint({.name = "sun", .type = JointType::kRevolute, .child = t.sun, .axis = Vec3::UnitZ()});
  mb.AddJoint({.name = "carrier",
               .type = JointType::kRevolute,
               .child = t.carrier,
               .X_PF = Transform(turn_z, Vec3(0, 0, 0.05)),
               .X_CM = Transform(flip_z, Vec3(0, 0, 0.01)),
               .axis = -Vec3::UnitZ()});
  mb.AddJoint({.name = "planet",
               .type = JointType::kRevolute,
               .parent = t.carrier,
               .child = t.planet,
               .X_PF = Transform(flip_z * turn_z, Vec3(0.039, 0.002, 0)),
               .axis = Vec3::UnitZ()});
  mb.AddJoint({.name = "disc",
               .type = JointType::kFixed,
               .parent = t.planet,
               .child = t.disc,
               .X_PF = Transform(turn_z, Vec3(0, 0.01, 0.003))});
  mb.AddJoint({.name = "lopsided",
               .type = JointType::kRevolute,
               .parent = t.sun,
               .child = t.lopsided,
               .axis = Vec3::UnitZ()});
  mb.AddJoint({.name = "tilted",
               .type = JointType::kRevolute,
               .parent = t.carrier,
               .child = t.tilted,
               .axis = Vec3(0.1, 0, 1).normalized()});
  mb.AddJoint({.name = "under_tilt",
               .type = JointType::kRevolute,
               .parent = t.tilted,
               .child = t.under_tilt,
               .axis = Vec3::UnitZ()});
  mb.AddJoint({.name = "floating", .type = JointType::kFree, .child = t.floating});
  t.model = std::move(mb).Finalize();
  return t;
}

TEST(TurningAboutZ, FlagsOnlyBodiesThatTurnAboutZ) {
  const Tree t = MakeTree();
  const Model& m = *t.model;
  for (BodyIndex b : {t.sun, t.carrier, t.planet, t.disc, t.lopsided})
    EXPECT_TRUE(m.bodies[b].turns_about_z) << m.bodies[b].name;
  for (BodyIndex b : {t.tilted, t.under_tilt, t.floating})
    EXPECT_FALSE(m.bodies[b].turns_about_z) << m.bodies[b].name;
}

TEST(TurningAboutZ, InverseDynamicsAsTheGeneralPath) {
  // Gravity in and out of the plane: A_WB's linear z is not zero.
  const Tree t = MakeTree(Vec3(0.3, -9.81, -2.0));
  const Model& m = *t.model;
  Data d(m);
  for (int sample = 0; sample < 8; ++sample) {
    Eigen::VectorXd q = m.q_initial, v(m.nv), vdot(m.nv);
    for (int k = 0; k < m.nq; ++k) q(k) += 3.1 * std::sin(1.7 * k + 0.9 * sample) + 2 * sample;
    for (int k = 0; k < m.nv; ++k) {
      v(k) = 40 * std::cos(2.3 * k + 0.4 * sample);
      vdot(k) = 3e3 * std::sin(0.7 * k - 1.1 * sample);
    }
    NormalizeQuaternions(m, q);
    CalcPositionKinematics(m, q, d);
    CalcVelocityKinematics(m, v, d);
    for (BodyIndex b = 0; b < m.nbodies; ++b)
      for (int r = 0; r < 6; ++r)
        d.f_ext[b](r) = b == 0 ? 0.0 : 50 * std::sin(1.9 * b + 0.6 * r + sample);
    d.tau_applied.setZero();
    CalcInverseDynamics(m, vdot, d);
    // The general recursion by hand, with the accelerations just computed.
    std::vector<Vec6> f(m.nbodies, Vec6::Zero());
    for (BodyIndex b = 1; b < m.nbodies; ++b) {
      const SpatialInertia& I = d.I_W[b];
      const Vec6& V = d.V_WB[b];
      f[b] = I * d.A_WB[b] + CrossForce(V, I * V) - d.f_ext[b];
      if (!m.bodies[b].turns_about_z) continue;
      // The zeros the shortcut relies on.
      for (int r : {0, 1, 5}) EXPECT_EQ(V(r), 0.0) << m.bodies[b].name << " V " << r;
      for (int r : {0, 1}) EXPECT_EQ(d.A_WB[b](r), 0.0) << m.bodies[b].name << " A " << r;
    }
    Eigen::VectorXd tau(m.nv);
    for (auto it = m.tree_order.rbegin(); it != m.tree_order.rend(); ++it) {
      const Joint& jt = m.joints[*it];
      const BodyIndex b = jt.spec.child;
      for (int k = 0; k < jt.nv; ++k) tau(jt.v_start + k) = d.S.col(jt.v_start + k).dot(f[b]);
      if (jt.spec.parent != kWorldBody) f[jt.spec.parent] += f[b];
    }
    for (BodyIndex b = 1; b < m.nbodies; ++b)
      for (int r = 0; r < 6; ++r)
        EXPECT_EQ(d.f_joint[b](r), f[b](r)) << m.bodies[b].name << " " << sample << " " << r;
    for (int k = 0; k < m.nv; ++k) EXPECT_EQ(d.tau_id(k), tau(k)) << k << " " << sample;
  }
}

}  // namespace
}  // namespace orrery

// The joint-type table (mbd/joint_types.cpp) against independent definitions.
//
// Oracles:
// - the motion subspace is the derivative of the joint transform: moving q along the velocity
//   v (q-dot = N(q) v; quaternions turned by the exponential map) for a time h, the central
//   difference of X_FM(q) gives the spatial velocity of M relative to F about F's origin,
//   w = vee(R-dot R^T), v_O = p-dot + p x w, which must equal S_F(q) v;
// - the velocity-product term is the time derivative of S_F along the same motion,
//   dS_F/dt v = (S_F(q(h)) - S_F(q(-h))) v / 2h;
// - a loop closure of a type removes exactly the motions the joint allows: 6 - nv rows;
// - CalcFramePoses' own paths for revolute joints about +-z (RevoluteAboutZ) and for free joints
//   (FreeJoint) give the table entry's poses and motion subspace to the last bit.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/joint_types.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"

namespace orrery {
namespace {

Joint MakeJoint(JointType type) {
  Joint j;
  j.spec.type = type;
  j.nq = JointNq(type);
  j.nv = JointNv(type);
  j.axis = Vec3(0.3, -0.5, 0.8).normalized();
  const Vec3 other = Vec3(1.0, 0.2, -0.1);
  j.axis2 = (other - other.dot(j.axis) * j.axis).normalized();
  j.axis3 = j.axis.cross(j.axis2);
  return j;
}

// q at time h when moving with constant v from q0 (quaternion blocks: q <- exp(h w) q).
Eigen::VectorXd Advance(const JointTypeInfo& info, const Eigen::VectorXd& q0,
                        const Eigen::VectorXd& v, double h) {
  Eigen::VectorXd q = q0;
  const int n_plain = info.quaternion < 0 ? info.nv : info.quaternion;
  q.head(n_plain) += h * v.head(n_plain);
  if (info.quaternion >= 0) {
    const int k = info.quaternion;
    const Quat current(q(k), q(k + 1), q(k + 2), q(k + 3));
    const Quat next = QuatExp(h * Vec3(v.segment<3>(k))) * current;
    q(k) = next.w();
    q.segment<3>(k + 1) = next.vec();
  }
  return q;
}

// A configuration away from every special value (quaternions unit, not the identity).
Eigen::VectorXd SomePosition(const JointTypeInfo& info) {
  Eigen::VectorXd q(info.nq);
  for (int k = 0; k < info.nq; ++k) q(k) = 0.3 + 0.17 * k;
  if (info.quaternion >= 0) q.segment<4>(info.quaternion).normalize();
  return q;
}

Eigen::VectorXd SomeVelocity(const JointTypeInfo& info) {
  Eigen::VectorXd v(info.nv);
  for (int k = 0; k < info.nv; ++k) v(k) = 0.7 - 0.4 * k;
  return v;
}

Vec6 SubspaceTimes(const JointTypeInfo& info, const Joint& j, const Eigen::VectorXd& q,
                   const Eigen::VectorXd& v) {
  Transform X;
  Vec6 S_F[6];
  info.position(j, q.data(), X, S_F);
  Vec6 m = Vec6::Zero();
  for (int k = 0; k < info.nv; ++k) m += S_F[k] * v(k);
  return m;
}

class JointTypeTest : public ::testing::TestWithParam<JointType> {};

TEST_P(JointTypeTest, MotionSubspaceIsTheDerivativeOfTheJointTransform) {
  const JointTypeInfo& info = JointInfo(GetParam());
  const Joint j = MakeJoint(GetParam());
  const Eigen::VectorXd q = SomePosition(info), v = SomeVelocity(info);
  const double h = 1e-5;
  Transform X0, Xp, Xm;
  Vec6 S_F[6];
  info.position(j, q.data(), X0, S_F);
  const Eigen::VectorXd qp = Advance(info, q, v, h), qm = Advance(info, q, v, -h);
  info.position(j, qp.data(), Xp, S_F);
  info.position(j, qm.data(), Xm, S_F);
  const Mat3 Rdot = (Xp.R - Xm.R) / (2 * h);
  const Vec3 pdot = (Xp.p - Xm.p) / (2 * h);
  const Mat3 W = Rdot * X0.R.transpose();
  const Vec3 w(W(2, 1), W(0, 2), W(1, 0));
  Vec6 expected;
  expected << w, pdot + X0.p.cross(w);
  // Central differences: error ~ h^2 |third derivative| ~ 1e-10 for these O(1) motions.
  EXPECT_LT((SubspaceTimes(info, j, q, v) - expected).norm(), 1e-8) << info.name;
  // W is skew for a rotation: a check on the difference itself.
  EXPECT_LT((W + W.transpose()).norm(), 1e-8) << info.name;
}

TEST_P(JointTypeTest, VelocityProductIsTheDerivativeOfTheSubspaceAlongTheMotion) {
  const JointTypeInfo& info = JointInfo(GetParam());
  const Joint j = MakeJoint(GetParam());
  const Eigen::VectorXd q = SomePosition(info), v = SomeVelocity(info);
  const double h = 1e-5;
  const Vec6 expected = (SubspaceTimes(info, j, Advance(info, q, v, h), v) -
                         SubspaceTimes(info, j, Advance(info, q, v, -h), v)) /
                        (2 * h);
  const Vec6 got =
      info.velocity_product ? info.velocity_product(j, q.data(), v.data()) : Vec6::Zero().eval();
  EXPECT_LT((got - expected).norm(), 1e-8) << info.name;
}

TEST_P(JointTypeTest, LoopClosureRemovesTheMotionsTheJointAllows) {
  const JointTypeInfo& info = JointInfo(GetParam());
  EXPECT_EQ(info.loop_rows, 6 - info.nv) << info.name;
}

TEST_P(JointTypeTest, NameRoundTripsAndUnitsNameEveryCoordinate) {
  const JointTypeInfo& info = JointInfo(GetParam());
  JointType parsed = JointType::kFixed;
  ASSERT_TRUE(JointTypeFromName(info.name, &parsed));
  EXPECT_EQ(parsed, GetParam());
  EXPECT_EQ(info.type, GetParam());
  EXPECT_EQ(info.nq - info.nv, info.quaternion >= 0 ? 1 : 0) << info.name;
  for (int k = 0; k < info.nq; ++k) EXPECT_NE(info.q_names[k], nullptr) << info.name << " q" << k;
  for (int k = 0; k < info.nv; ++k) EXPECT_NE(info.v_names[k], nullptr) << info.name << " v" << k;
}

INSTANTIATE_TEST_SUITE_P(AllTypes, JointTypeTest,
                         ::testing::Values(JointType::kFixed, JointType::kRevolute,
                                           JointType::kPrismatic, JointType::kCylindrical,
                                           JointType::kUniversal, JointType::kSpherical,
                                           JointType::kPlanar, JointType::kFree),
                         [](const auto& info) { return std::string(JointTypeName(info.param)); });

TEST(JointTypes, UnitsAsTheResultFilesWriteThem) {
  EXPECT_EQ(JointCoordinateUnits(JointType::kRevolute, false), "rad");
  EXPECT_EQ(JointCoordinateUnits(JointType::kSpherical, false), "1");
  EXPECT_EQ(JointCoordinateUnits(JointType::kSpherical, true), "rad/s");
  EXPECT_EQ(JointCoordinateUnits(JointType::kPlanar, false), "m, m, rad");
  EXPECT_EQ(JointCoordinateUnits(JointType::kFree, true), "m/s, m/s, m/s, rad/s, rad/s, rad/s");
  JointType t;
  EXPECT_FALSE(JointTypeFromName("hinge", &t));
}

// A chain world -(free, tilted)- A -(revolute +z, turned and offset X_PF, X_CM)- B -(revolute -z)- C:
// the poses CalcFramePoses writes for B and C against the general path composed by hand
// (X_WF = X_WP X_PF, the table's X_FM, X_MC; S = Ad(X_WF) S_F), bit for bit.
TEST(JointTypes, RevoluteAboutZPosesAsTheTableEntry) {
  ModelBuilder mb;
  const Mat3 I = Vec3(1e-3, 2e-3, 3e-3).asDiagonal();
  const BodyIndex a = mb.AddBody("a", 1.0, Vec3::Zero(), I);
  const BodyIndex b = mb.AddBody("b", 1.0, Vec3::Zero(), I);
  const BodyIndex c = mb.AddBody("c", 1.0, Vec3::Zero(), I);
  mb.AddJoint({.name = "free", .type = JointType::kFree, .child = a});
  const Transform X_PF(AxisAngle(Vec3(0.2, 0.9, -0.4).normalized(), 0.8), Vec3(0.1, -0.2, 0.3));
  const Transform X_CM(AxisAngle(Vec3(-0.5, 0.1, 0.7).normalized(), -1.3), Vec3(0.05, 0.02, -0.01));
  const JointIndex jb = mb.AddJoint({.name = "jb", .type = JointType::kRevolute, .parent = a, .child = b,
                                     .X_PF = X_PF, .X_CM = X_CM, .axis = Vec3::UnitZ()});
  const JointIndex jc = mb.AddJoint({.name = "jc", .type = JointType::kRevolute, .parent = b, .child = c,
                                     .X_PF = X_CM, .axis = Vec3(0, 0, -2)});
  const std::shared_ptr<const Model> model = std::move(mb).Finalize();
  const Model& m = *model;
  EXPECT_EQ(m.joints[jb].revolute_z, 1);
  EXPECT_EQ(m.joints[jc].revolute_z, -1);
  Data d(m);
  for (int sample = 0; sample < 6; ++sample) {
    Eigen::VectorXd q = m.q_initial;
    for (int k = 0; k < m.nq; ++k) q(k) += 2.9 * std::sin(1.3 * k + 0.7 * sample) + sample;
    NormalizeQuaternions(m, q);
    CalcFramePoses(m, q, d);
    for (JointIndex j : {jb, jc}) {
      const Joint& jt = m.joints[j];
      const Transform X_WF = d.X_WB[jt.spec.parent] * jt.spec.X_PF;
      Transform X_FM;
      Vec6 S_F[6];
      JointInfo(JointType::kRevolute).position(jt, q.data() + jt.q_start, X_FM, S_F);
      const Transform X_WB = (X_WF * X_FM) * jt.X_MC;
      const Vec6 S = MotionToWorld(X_WF, S_F[0]);
      for (int r = 0; r < 3; ++r) {
        EXPECT_EQ(d.X_WB[jt.spec.child].p(r), X_WB.p(r)) << j << " " << sample;
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(d.X_WB[jt.spec.child].R(r, k), X_WB.R(r, k)) << j << " " << sample;
          EXPECT_EQ(d.X_FM[j].R(r, k), X_FM.R(r, k)) << j << " " << sample;
        }
      }
      for (int r = 0; r < 6; ++r) EXPECT_EQ(d.S(r, jt.v_start), S(r)) << j << " " << sample;
    }
  }
}

// Free joints (CalcFramePoses' FreeJoint, CalcVelocityKinematics' free path): on the world with a
// turned X_PF and under a free body with turned X_PF and X_CM (a planet on a carrier), at positions
// of metres and turned quaternions: X_FM, the child's pose and the six motion-subspace columns
// equal to the table entry's, composed by hand, bit for bit; so is the velocity-product term S-dot
// v.
TEST(JointTypes, FreePosesAsTheTableEntry) {
  ModelBuilder mb;
  const Mat3 I = Vec3(1e-3, 2e-3, 3e-3).asDiagonal();
  const BodyIndex a = mb.AddBody("a", 1.0, Vec3::Zero(), I);
  const BodyIndex b = mb.AddBody("b", 1.0, Vec3::Zero(), I);
  const Transform X_PF(AxisAngle(Vec3(0.2, 0.9, -0.4).normalized(), 0.8), Vec3(0.1, -0.2, 0.3));
  const Transform X_CM(AxisAngle(Vec3(-0.5, 0.1, 0.7).normalized(), -1.3), Vec3(0.05, 0.02, -0.01));
  const JointIndex ja =
      mb.AddJoint({.name = "ja", .type = JointType::kFree, .child = a, .X_PF = X_CM});
  const JointIndex jb = mb.AddJoint({.name = "jb",
                                     .type = JointType::kFree,
                                     .parent = a,
                                     .child = b,
                                     .X_PF = X_PF,
                                     .X_CM = X_CM});
  const std::shared_ptr<const Model> model = std::move(mb).Finalize();
  const Model& m = *model;
  Data d(m);
  for (int sample = 0; sample < 6; ++sample) {
    Eigen::VectorXd q = m.q_initial;
    for (int k = 0; k < m.nq; ++k) q(k) += 2.9 * std::sin(1.3 * k + 0.7 * sample) + sample;
    NormalizeQuaternions(m, q);
    CalcFramePoses(m, q, d);
    for (JointIndex j : {ja, jb}) {
      const Joint& jt = m.joints[j];
      const Transform X_WF =
          jt.spec.parent == kWorldBody ? jt.spec.X_PF : d.X_WB[jt.spec.parent] * jt.spec.X_PF;
      Transform X_FM;
      Vec6 S_F[6];
      // (the quaternions as the kinematics read them, normalized once more)
      JointInfo(JointType::kFree).position(jt, d.q_normalized.data() + jt.q_start, X_FM, S_F);
      const Transform X_WB = jt.X_MC_is_identity ? X_WF * X_FM : (X_WF * X_FM) * jt.X_MC;
      for (int r = 0; r < 3; ++r) {
        EXPECT_EQ(d.X_WB[jt.spec.child].p(r), X_WB.p(r)) << j << " " << sample;
        EXPECT_EQ(d.X_FM[j].p(r), X_FM.p(r)) << j << " " << sample;
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(d.X_WB[jt.spec.child].R(r, k), X_WB.R(r, k)) << j << " " << sample;
          EXPECT_EQ(d.X_FM[j].R(r, k), X_FM.R(r, k)) << j << " " << sample;
        }
      }
      for (int k = 0; k < 6; ++k) {
        const Vec6 S = MotionToWorld(X_WF, S_F[k]);
        for (int r = 0; r < 6; ++r)
          EXPECT_EQ(d.S(r, jt.v_start + k), S(r)) << j << " column " << k << " " << sample;
      }
    }
    // The velocity-product term S-dot v (CalcVelocityKinematics' free-joint path) as the table's
    Eigen::VectorXd v(m.nv);
    for (int k = 0; k < m.nv; ++k) v(k) = 3.1 * std::cos(0.9 * k + sample) - 0.4 * k;
    CalcVelocityKinematics(m, v, d);
    for (JointIndex j : {ja, jb}) {
      const Joint& jt = m.joints[j];
      const Vec6 V_joint = JointMotion(d, jt.v_start, jt.nv, v);
      const Vec6 product =
          JointInfo(JointType::kFree)
              .velocity_product(jt, d.q_normalized.data() + jt.q_start, v.data() + jt.v_start);
      const Vec6 c =
          CrossMotion(d.V_WB[jt.spec.parent], V_joint) + MotionToWorld(d.X_WF[j], product);
      for (int r = 0; r < 6; ++r)
        EXPECT_EQ(d.c_J[j](r), c(r)) << j << " row " << r << " " << sample;
    }
  }
}

}  // namespace
}  // namespace orrery

// DaeSystem::Tangents with grouped differences (mbd/dae.h set_grouped_differences) against the
// one-column-per-evaluation differences: a spatial planetary stage as seed 002 builds it (sun,
// ring and carrier on free joints on the world, each on a bearing to the world, two planets on
// free joints on the carrier with pin bearings, lumped meshes with analytic tangents, a speed
// driver on the carrier). The meshes are the only elements between the three subtrees and are
// not differenced, so a column's differenced rows lie in its own subtree: Kq and Cv must be the
// one-column differences' to the last bit (a wrong class, a missed coupling or a row taken from
// the wrong evaluation shows as a difference of the size of the entries).
#include <cmath>
#include <memory>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

constexpr double kAlpha = 20 * 3.14159265358979323846 / 180;

std::shared_ptr<const Model> SpatialStage(bool spring_between_sun_and_ring) {
  ModelBuilder mb;
  const Mat3 I = Vec3(1e-3, 1e-3, 2e-3).asDiagonal();
  auto rz = [](double a) { return AxisAngle(Vec3::UnitZ(), a); };
  const double rba = 0.03, rbb = 0.05, rbr = rba + 2 * rbb;  // base radii: sun, planet, ring
  const int za = 30, zb = 50;
  const double d_sp = (rba + rbb) / std::cos(kAlpha);
  const BodyIndex sun = mb.AddBody("sun", 1.0, Vec3::Zero(), I);
  const BodyIndex ring = mb.AddBody("ring", 3.0, Vec3::Zero(), 3 * I);
  const BodyIndex carrier = mb.AddBody("carrier", 2.0, Vec3::Zero(), 2 * I);
  mb.AddJoint({.name = "j_sun", .type = JointType::kFree, .child = sun});
  mb.AddJoint({.name = "j_ring", .type = JointType::kFree, .child = ring, .X_PF = Transform(rz(0.4), Vec3::Zero())});
  const JointIndex j_carrier = mb.AddJoint({.name = "j_carrier", .type = JointType::kFree, .child = carrier,
                                            .X_PF = Transform(rz(0.3), Vec3(0, 0, 0.02))});
  for (const BodyIndex b : {sun, ring, carrier})
    mb.AddBearing({.name = "bearing_" + std::to_string(b), .frame_a = kWorldFrame, .frame_b = mb.body_frame(b),
                   .radial_stiffness = 2e8, .axial_stiffness = 1e8, .tilt_stiffness = 1e5,
                   .radial_damping = 50, .axial_damping = 20, .tilt_damping = 1});
  const FrameIndex reference = mb.body_frame(carrier);
  for (int i = 0; i < 2; ++i) {
    const std::string name = "planet" + std::to_string(i);
    const BodyIndex planet = mb.AddBody(name, 0.5, Vec3::Zero(), I);
    const double psi = 0.5 + 2.5 * i;
    const Transform X_CP(rz(psi), d_sp * Vec3(std::cos(psi), std::sin(psi), 0));
    mb.AddJoint({.name = "j_" + name, .type = JointType::kFree, .parent = carrier, .child = planet, .X_PF = X_CP});
    mb.AddBearing({.name = "pin_" + name, .frame_a = mb.AddFrame(name + "_pin", carrier, X_CP),
                   .frame_b = mb.body_frame(planet), .radial_stiffness = 1e8, .axial_stiffness = 5e7,
                   .tilt_stiffness = 1e5, .radial_damping = 30, .axial_damping = 10, .tilt_damping = 1});
    for (int k = 0; k < 2; ++k) {
      GearMeshSpec s;
      s.name = (k ? "ring-" : "sun-") + name;
      s.contact = GearMeshSpec::Contact::kLinearDrive;
      s.gear_a = k ? mb.body_frame(planet) : mb.body_frame(sun);
      s.gear_b = k ? mb.body_frame(ring) : mb.body_frame(planet);
      s.reference = reference;
      s.teeth_a = k ? zb : za;
      s.teeth_b = k ? za + 2 * zb : zb;
      s.base_radius_a = k ? rbb : rba;
      s.base_radius_b = k ? rbr : rbb;
      s.internal_b = k == 1;
      s.working_pressure_angle = kAlpha;
      s.stiffness = 4e8;
      s.damping = 200;
      mb.AddGearMesh(s);
    }
  }
  if (spring_between_sun_and_ring)
    mb.AddTranslationalSpring({.name = "tie", .frame_a = mb.body_frame(sun), .frame_b = mb.body_frame(ring),
                               .stiffness = 1e4, .damping = 1, .free_length = 0});
  DriverSpec d;
  d.name = "drive", d.joint = j_carrier, d.coordinate = 5, d.mode = DriverSpec::Mode::kSpeed;
  d.function = TimeFunction::Sine(0.5, 3.0, 0.0, 2.0);
  mb.AddDriver(d);
  return std::move(mb).Finalize();
}

// A state off equilibrium: every coordinate moved (micrometres and milliradians on the bearings'
// and meshes' scale, turns of the free rotations), velocities of all sizes.
State Moved(const Model& m) {
  State s = State::Initial(m);
  s.t = 0.37;
  for (int k = 0; k < m.nv; ++k) {
    Eigen::VectorXd dv = Eigen::VectorXd::Zero(m.nv);
    dv(k) = (k % 6 < 3 ? 1e-5 : 1e-3) * std::sin(1.3 * k + 0.4) + (k % 6 == 5 ? 2.0 + 0.1 * k : 0.0);
    IntegratePositions(m, dv, s.q);
    s.v(k) = (k % 6 < 3 ? 1e-3 : 0.2) * std::cos(0.7 * k) + (k % 6 == 5 ? 5.0 : 0.0);
  }
  return s;
}

void ExpectGroupedAsOneColumnEach(const Model& m, int groups) {
  DaeSystem grouped(m), single(m);
  single.set_grouped_differences(false);
  EXPECT_EQ(grouped.difference_groups(), groups);
  const State s = Moved(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::LinSpaced(m.nv, -3.0, 4.0);
  const Eigen::VectorXd lambda = Eigen::VectorXd::Constant(m.n_constraints, 12.5);
  Eigen::MatrixXd Kq_g(m.nv + m.n_constraints, m.nv), Cv_g(m.nv, m.nv);
  Eigen::MatrixXd Kq_s(m.nv + m.n_constraints, m.nv), Cv_s(m.nv, m.nv);
  grouped.Tangents(s.t, s.q, s.v, vdot, lambda, Kq_g, Cv_g);
  single.Tangents(s.t, s.q, s.v, vdot, lambda, Kq_s, Cv_s);
  ASSERT_GT(Kq_s.cwiseAbs().maxCoeff(), 1e5);  // the bearings' and meshes' stiffness is in it
  for (int c = 0; c < m.nv; ++c) {
    for (int r = 0; r < m.nv + m.n_constraints; ++r) EXPECT_EQ(Kq_g(r, c), Kq_s(r, c)) << "Kq " << r << ", " << c;
    for (int r = 0; r < m.nv; ++r) EXPECT_EQ(Cv_g(r, c), Cv_s(r, c)) << "Cv " << r << ", " << c;
  }
  // Data is left at the base point alike
  EXPECT_EQ(grouped.data().tau_id, single.data().tau_id);
}

TEST(GroupedDifferences, TangentsAsOneColumnPerEvaluation) {
  const std::shared_ptr<const Model> model = SpatialStage(false);
  // Sun 6, ring 6, carrier with two planets 18 coordinates: 18 evaluations for 30 columns
  ExpectGroupedAsOneColumnEach(*model, 18);
}

TEST(GroupedDifferences, ASpringBetweenSubtreesJoinsThem) {
  const std::shared_ptr<const Model> model = SpatialStage(true);
  // Sun and ring in one class (12 coordinates), the carrier's 18: still 18 groups, and the
  // sun's and ring's columns no longer share an evaluation
  ExpectGroupedAsOneColumnEach(*model, 18);
}

}  // namespace
}  // namespace orrery

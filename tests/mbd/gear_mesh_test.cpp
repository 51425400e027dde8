// Lumped gear mesh and ideal gear constraint on a parallel-axis pair (two gears on revolute
// joints), against closed forms: torsional natural frequency, static deflection under torque,
// mesh damping decay, backlash free play, and the ideal ratio with its tooth force; the mesh's
// analytic tangents (AddGearMeshTangents) against forward differences of the whole pipeline; the
// transmission error's harmonics against their own cosines; meshes of one gear sharing its angle;
// gear angles read from the joint coordinates against the general path.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "mbd/dae.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"
#include "mbd/integrator.h"
#include "mbd/linearization.h"
#include "mbd/model.h"

namespace orrery {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAlpha = 20 * kPi / 180;

struct Pair {
  double rba = 0.03, rbb = 0.05;  // base radii (m): 30 and 50 teeth
  int za = 30, zb = 50;
  double Ja = 2e-4, Jb = 1e-3;    // kg m^2
  double k = 4e8;                 // N/m
  bool internal = false;
};

struct Built {
  std::shared_ptr<const Model> model;
  JointIndex a = -1, b = -1;
};

// Gear a at the origin, gear b at the centre distance along x; both on revolute joints about z.
Built Build(const Pair& p, const GearMeshSpec& extra, bool constraint = false, double load_on_a = 0) {
  ModelBuilder mb;
  const Mat3 Ia = Vec3(p.Ja / 2, p.Ja / 2, p.Ja).asDiagonal(), Ib = Vec3(p.Jb / 2, p.Jb / 2, p.Jb).asDiagonal();
  const BodyIndex ga = mb.AddBody("a", 1.0, Vec3::Zero(), Ia);
  const BodyIndex gb = mb.AddBody("b", 2.0, Vec3::Zero(), Ib);
  const double d = (p.internal ? p.rbb - p.rba : p.rba + p.rbb) / std::cos(kAlpha);
  Built out;
  out.a = mb.AddJoint({.name = "ja", .type = JointType::kRevolute, .parent = kWorldBody, .child = ga, .axis = Vec3::UnitZ()});
  out.b = mb.AddJoint({.name = "jb", .type = JointType::kRevolute, .parent = kWorldBody, .child = gb,
                       .X_PF = Transform::Translation(Vec3(p.internal ? -d : d, 0, 0)), .axis = Vec3::UnitZ()});
  if (constraint) {
    mb.AddGearConstraint({.name = "ideal", .gear_a = mb.body_frame(ga), .gear_b = mb.body_frame(gb),
                          .teeth_a = p.za, .teeth_b = p.zb, .base_radius_a = p.rba, .base_radius_b = p.rbb,
                          .working_pressure_angle = kAlpha, .internal_b = p.internal});
  } else {
    GearMeshSpec s = extra;
    s.name = "mesh";
    s.gear_a = mb.body_frame(ga);
    s.gear_b = mb.body_frame(gb);
    s.teeth_a = p.za;
    s.teeth_b = p.zb;
    s.base_radius_a = p.rba;
    s.base_radius_b = p.rbb;
    s.working_pressure_angle = kAlpha;
    s.internal_b = p.internal;
    if (s.stiffness_table.empty() && s.stiffness == 0) s.stiffness = p.k;
    mb.AddGearMesh(s);
  }
  if (load_on_a != 0)
    mb.AddJointLoad({.name = "torque", .joint = out.a, .coordinate = 0, .function = TimeFunction::Constant(load_on_a)});
  out.model = std::move(mb).Finalize();
  return out;
}

// Torsional mode of a free pair: w^2 = k (r_a^2 / J_a + r_b^2 / J_b) (one rigid-body mode at 0).
TEST(GearMesh, TorsionalNaturalFrequencyMatchesClosedForm) {
  for (bool internal : {false, true}) {
    Pair p;
    p.internal = internal;
    if (internal) p.rbb = 0.09, p.zb = 90;
    GearMeshSpec s;
    s.contact = GearMeshSpec::Contact::kLinearDrive;
    const Built b = Build(p, s);
    const ModalResult modes = CalcModes(Linearize(*b.model, State::Initial(*b.model)));
    ASSERT_EQ(modes.frequencies_hz.size(), 2u);
    const double f = std::sqrt(p.k * (p.rba * p.rba / p.Ja + p.rbb * p.rbb / p.Jb)) / (2 * kPi);
    EXPECT_NEAR(modes.frequencies_hz[0], 0.0, 1e-3 * f);
    // Central differences of a linear spring: exact up to rounding of the force (1e-9 relative).
    EXPECT_NEAR(modes.frequencies_hz[1], f, 1e-7 * f) << (internal ? "internal" : "external");
  }
}

// Gear b held (ideal pair against a fixed gear): a torque T on a deflects the mesh by
// T / (r_ba k) and the tooth force is T / r_ba.
TEST(GearMesh, StaticDeflectionUnderTorque) {
  Pair p;
  GearMeshSpec s;
  s.contact = GearMeshSpec::Contact::kTwoSided;
  const double T = 50;
  const Built b = Build(p, s, false, T);
  Data d(*b.model);
  State st = State::Initial(*b.model);
  const double delta = T / (p.rba * p.k);
  st.q(b.model->joints[b.a].q_start) = delta / p.rba;  // a turned forward by delta / r_ba
  EvaluateDynamics(*b.model, 0, st.q, st.v, Eigen::VectorXd::Zero(2), d);
  EXPECT_EQ(d.mesh_contact[0], 1);
  EXPECT_NEAR(d.mesh_deflection[0], delta, 1e-12 * delta);
  EXPECT_NEAR(d.mesh_force[0], T / p.rba, 1e-9 * T / p.rba);
  // Equilibrium of a: the generalized force on its coordinate vanishes.
  EXPECT_NEAR(d.tau_id(b.model->joints[b.a].v_start), 0.0, 1e-9 * T);
  // Reaction torque on b: F r_bb (external pair: b is pushed to turn -z).
  EXPECT_NEAR(d.tau_id(b.model->joints[b.b].v_start), T * p.rbb / p.rba, 1e-9 * T);
}

// Static transmission error from a table (GearMeshSpec::ste_table_m): the mesh force is
// k (delta - e(psi)), e interpolated linearly between the samples at the mesh phase
// psi = z_a theta_a / 2 pi (hand interpolation), plus the harmonics.
TEST(GearMesh, TransmissionErrorTableShiftsTheForce) {
  Pair p;
  GearMeshSpec s;
  s.contact = GearMeshSpec::Contact::kLinearDrive;
  s.ste_table_m = {0.0, 2e-6, 4e-6, 2e-6};  // over one mesh cycle
  s.ste_amplitudes = {0.5e-6};
  const Built b = Build(p, s);
  Data d(*b.model);
  State st = State::Initial(*b.model);
  for (const double psi : {0.375, 0.9, 1.25}) {
    const double theta = psi * 2 * kPi / p.za;
    st.q(b.model->joints[b.a].q_start) = theta;
    EvaluateDynamics(*b.model, 0, st.q, st.v, Eigen::VectorXd::Zero(2), d);
    // Table at x = 4 frac(psi): samples i, i + 1 (wrapping).
    const double x = 4 * (psi - std::floor(psi));
    const int i = static_cast<int>(x);
    const double e = (1 - (x - i)) * s.ste_table_m[i] + (x - i) * s.ste_table_m[(i + 1) % 4] +
                     0.5e-6 * std::cos(2 * kPi * psi);
    // The deflection is wrapped to one base pitch (mbd/gear_mesh.h).
    const double delta = 2 * kPi * p.rba / p.za * (psi - std::round(psi));
    EXPECT_NEAR(d.mesh_phase[0], psi, 1e-12);
    EXPECT_NEAR(d.mesh_force[0], p.k * (delta - e), 1e-9 * p.k * std::abs(delta)) << "psi " << psi;
  }
  // A table value that is not finite is refused when the mesh is added.
  s.ste_table_m = {0.0, std::nan("")};
  EXPECT_THROW(Build(p, s), std::invalid_argument);
}

// Backlash: inside the gap no force; the coast flank engages past it.
TEST(GearMesh, BacklashFreePlayAndCoastFlank) {
  Pair p;
  GearMeshSpec s;
  s.backlash = 100e-6;
  const Built b = Build(p, s);
  Data d(*b.model);
  State st = State::Initial(*b.model);
  const int ia = b.model->joints[b.a].q_start;
  for (double e : {-50e-6, -1e-6, -99e-6}) {
    st.q(ia) = e / p.rba;
    EvaluateDynamics(*b.model, 0, st.q, st.v, Eigen::VectorXd::Zero(2), d);
    EXPECT_EQ(d.mesh_contact[0], 0) << e;
    EXPECT_EQ(d.mesh_force[0], 0.0);
  }
  st.q(ia) = -120e-6 / p.rba;  // 20 um past the gap: coast flank compressed by 20 um cos(beta)
  EvaluateDynamics(*b.model, 0, st.q, st.v, Eigen::VectorXd::Zero(2), d);
  EXPECT_EQ(d.mesh_contact[0], -1);
  EXPECT_NEAR(d.mesh_deflection[0], 20e-6, 1e-12);
  EXPECT_NEAR(d.mesh_force[0], p.k * 20e-6, 1e-6 * p.k * 20e-6);
  // A whole base pitch later the same tooth state repeats (mesh periodicity).
  st.q(ia) = (-120e-6 + 2 * kPi * p.rba / p.za) / p.rba;
  EvaluateDynamics(*b.model, 0, st.q, st.v, Eigen::VectorXd::Zero(2), d);
  EXPECT_EQ(d.mesh_contact[0], -1);
  EXPECT_NEAR(d.mesh_deflection[0], 20e-6, 1e-11);
}

// Mesh damping ratio: free decay of the torsional mode, logarithmic decrement 2 pi zeta/sqrt(1-zeta^2).
TEST(GearMesh, DampingRatioGivesTheDecayOfTheTorsionalMode) {
  Pair p;
  GearMeshSpec s;
  s.contact = GearMeshSpec::Contact::kLinearDrive;
  s.damping_ratio = 0.05;
  const Built b = Build(p, s);
  const LinearModel lin = Linearize(*b.model, State::Initial(*b.model));
  // Damped eigenvalues of the state matrix: -zeta w +- i w sqrt(1 - zeta^2).
  const int n = lin.M_r.rows();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -lin.M_r.inverse() * lin.K_r;
  A.bottomRightCorner(n, n) = -lin.M_r.inverse() * lin.D_r;
  const Eigen::VectorXcd ev = A.eigenvalues();
  double zeta = 0;
  for (int i = 0; i < ev.size(); ++i)
    if (std::abs(ev(i)) > 1) zeta = -ev(i).real() / std::abs(ev(i));
  EXPECT_NEAR(zeta, 0.05, 1e-6);
}

// Ideal mesh: speed ratio -r_ba / r_bb, and the multiplier is the tooth force T / r_ba.
TEST(GearConstraint, RatioAndToothForce) {
  Pair p;
  const double T = 20;
  const Built b = Build(p, GearMeshSpec{}, true, T);
  IntegratorOptions o;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  auto integ = MakeIntegrator(*b.model, o);
  integ->Initialize(State::Initial(*b.model));
  integ->AdvanceTo(0.1);
  const State& s = integ->state();
  const double wa = s.v(b.model->joints[b.a].v_start), wb = s.v(b.model->joints[b.b].v_start);
  EXPECT_NEAR(wb / wa, -p.rba / p.rbb, 1e-8);
  // Angular acceleration of a under T with b reflected: T / (J_a + J_b (r_a/r_b)^2).
  const double alpha = T / (p.Ja + p.Jb * (p.rba / p.rbb) * (p.rba / p.rbb));
  EXPECT_NEAR(wa, alpha * 0.1, 1e-6 * alpha * 0.1);
  // Tooth force: b accelerates at alpha r_a/r_b, so F r_bb = J_b alpha r_a / r_b.
  const double F = p.Jb * alpha * (p.rba / p.rbb) / p.rbb;
  EXPECT_NEAR(integ->lambda()(b.model->gear_constraint_row[0]), F, 1e-6 * F);
}

// The analytic tangents of a lumped mesh (a TVMS table, two STE harmonics, damping; linear on
// the drive flank, and two-sided with backlash) against DaeSystem::Tangents' forward
// differences through the mesh (set_element_tangents(false)). With the gears on revolute joints
// about fixed centres the line of action and lever points do not turn, so no term is left out:
// they agree to the forward difference's error, h |f''| / 2 with h = 1.5e-8 rad and |f''| ~ k r^2
// |psi''| (the table's slope term), a relative 1e-6 of k r^2 at most; states mid-segment of the
// table (a kink within h would break the difference, not the tangent).
TEST(GearMesh, AnalyticTangentsMatchDifferencesThroughThePipeline) {
  for (const auto contact : {GearMeshSpec::Contact::kLinearDrive, GearMeshSpec::Contact::kTwoSided}) {
    Pair p;
    GearMeshSpec s;
    s.contact = contact;
    s.backlash = contact == GearMeshSpec::Contact::kTwoSided ? 50e-6 : 0.0;
    s.stiffness_table = {4e8, 4.4e8, 5.2e8, 6e8, 6.1e8, 5.5e8, 4.6e8, 4.1e8};
    s.ste_amplitudes = {3e-6, 1e-6};
    s.ste_phases = {0.4, -0.8};
    s.damping = 600;
    const Built b = Build(p, s);
    const Model& m = *b.model;
    State x = State::Initial(m);
    // Gear a 0.3 rad ahead, gear b loading the drive flank by ~20 um; phase 30 * 0.3 / 2 pi =
    // 1.43 cycles: 0.43 of the table, mid-segment (segments of 1/8).
    x.q(m.joints[b.a].q_start) = 0.3;
    x.q(m.joints[b.b].q_start) = -(0.3 * p.rba - 20e-6) / p.rbb;
    x.v(m.joints[b.a].v_start) = 2.0;
    x.v(m.joints[b.b].v_start) = -1.1;
    const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv), lambda = Eigen::VectorXd::Zero(0);
    Eigen::MatrixXd K_an(m.nv, m.nv), C_an(m.nv, m.nv), K_fd(m.nv, m.nv), C_fd(m.nv, m.nv);
    DaeSystem dae(m);
    dae.Tangents(0, x.q, x.v, vdot, lambda, K_an, C_an);
    ASSERT_GT(dae.data().mesh_force[0], 1e3);
    ASSERT_EQ(dae.data().mesh_contact[0], 1);
    dae.set_element_tangents(false);
    dae.Tangents(0, x.q, x.v, vdot, lambda, K_fd, C_fd);
    const double scale = 6e8 * p.rbb * p.rbb;
    EXPECT_LE((K_an - K_fd).cwiseAbs().maxCoeff(), 1e-6 * scale) << "K\n" << K_an << "\nfd\n" << K_fd;
    // C's differences are at the rounding of the quotient: 64 eps |tau| / h, tau ~ f r_b, with
    // the velocity step h = 1.5e-8 max(1, |v|) (dae.cpp).
    const double tau = dae.data().mesh_force[0] * p.rbb;
    const double rounding = 64 * std::numeric_limits<double>::epsilon() * tau / (1.5e-8 * 2.0);
    EXPECT_LE((C_an - C_fd).cwiseAbs().maxCoeff(), 1e-6 * s.damping * p.rbb * p.rbb + rounding)
        << "C\n" << C_an << "\nfd\n" << C_fd;
    // The stiffness is not that of the mean: the table's slope term is in both.
    EXPECT_GT(K_fd.cwiseAbs().maxCoeff(), 0.5 * 4e8 * p.rba * p.rba);
  }
}

// The transmission error's harmonics (taken by the angle-addition recurrence from one cosine
// and sine of the phase, mbd/gear_mesh.cpp) against each harmonic's own std::cos and std::sin,
// with and without phases, at phases of a long run: within a few ulp of the amplitudes' sum
// (the recurrence adds about one per harmonic).
TEST(GearMesh, TransmissionErrorHarmonicsMatchTheirCosines) {
  GearMeshSpec s;
  s.ste_amplitudes = {3e-6, 1e-6, -0.7e-6, 0.4e-6, 0.25e-6};
  for (const std::vector<double>& phases :
       {std::vector<double>{}, std::vector<double>{0.4, -0.8, 0.0, 2.5}}) {
    s.ste_phases = phases;
    double sum = 0;
    for (double a : s.ste_amplitudes) sum += std::abs(a);
    for (const double psi : {0.0, 0.125, 0.37, 0.999, 12.9, -3.2, 1234.5678, 98765.4321}) {
      const double x = 2 * kPi * (psi - std::floor(psi));
      double e = 0, slope = 0;
      for (size_t k = 0; k < s.ste_amplitudes.size(); ++k) {
        const double w = 2 * kPi * double(k + 1), phi = k < phases.size() ? phases[k] : 0.0;
        e += s.ste_amplitudes[k] * std::cos(double(k + 1) * x + phi);
        slope -= s.ste_amplitudes[k] * w * std::sin(double(k + 1) * x + phi);
      }
      const double eps = std::numeric_limits<double>::epsilon();
      EXPECT_NEAR(MeshTransmissionError(s, psi), e, 16 * eps * sum) << "psi " << psi;
      EXPECT_NEAR(MeshTransmissionErrorSlope(s, psi), slope, 16 * eps * sum * 2 * kPi * 5) << "psi " << psi;
    }
  }
}

// A sun meshing with two planets: the sun's angle is one entry of Model::gear_angles for both
// meshes (three angles, not four), and the pipeline's meshes (CalcGearAngles, then each mesh at
// the shared angles) give what each mesh gives alone (EvaluateGearMesh, its own angles), to the
// last bit.
TEST(GearMesh, MeshesOfOneGearShareItsAngle) {
  const Pair p;
  ModelBuilder mb;
  const Mat3 Ia = Vec3(p.Ja / 2, p.Ja / 2, p.Ja).asDiagonal(), Ib = Vec3(p.Jb / 2, p.Jb / 2, p.Jb).asDiagonal();
  const BodyIndex sun = mb.AddBody("sun", 1.0, Vec3::Zero(), Ia);
  const double d = (p.rba + p.rbb) / std::cos(kAlpha);
  mb.AddJoint({.name = "j_sun", .type = JointType::kRevolute, .parent = kWorldBody, .child = sun, .axis = Vec3::UnitZ()});
  for (int i = 0; i < 2; ++i) {
    const std::string name = "planet" + std::to_string(i);
    const BodyIndex planet = mb.AddBody(name, 2.0, Vec3::Zero(), Ib);
    const Vec3 at = i == 0 ? Vec3(d, 0, 0) : Vec3(-d, 0, 0);
    mb.AddJoint({.name = "j_" + name, .type = JointType::kRevolute, .parent = kWorldBody, .child = planet,
                 .X_PF = Transform::Translation(at), .axis = Vec3::UnitZ()});
    GearMeshSpec s;
    s.name = "sun-" + name;
    s.contact = GearMeshSpec::Contact::kLinearDrive;
    s.gear_a = mb.body_frame(sun);
    s.gear_b = mb.body_frame(planet);
    s.teeth_a = p.za;
    s.teeth_b = p.zb;
    s.base_radius_a = p.rba;
    s.base_radius_b = p.rbb;
    s.working_pressure_angle = kAlpha;
    s.stiffness_table = {4e8, 5e8, 6e8, 5e8};
    s.ste_amplitudes = {2e-6, 0.5e-6};
    mb.AddGearMesh(s);
  }
  const std::shared_ptr<const Model> model = std::move(mb).Finalize();
  const Model& m = *model;
  ASSERT_EQ(m.gear_meshes.size(), 2u);
  EXPECT_EQ(m.gear_angles.size(), 3u);
  EXPECT_EQ(m.gear_meshes[0].angle_a, m.gear_meshes[1].angle_a);
  EXPECT_NE(m.gear_meshes[0].angle_b, m.gear_meshes[1].angle_b);
  State x = State::Initial(m);
  x.q << 0.7, -0.7 * p.rba / p.rbb + 3e-5, 0.7 * p.rba / p.rbb - 2e-5;
  x.v << 3.0, -1.7, 1.9;
  Data d_run(m), d_alone(m);
  EvaluateDynamics(m, 0, x.q, x.v, Eigen::VectorXd::Zero(m.nv), d_run);
  CalcPositionKinematics(m, x.q, d_alone);
  CalcVelocityKinematics(m, x.v, d_alone);
  EXPECT_DOUBLE_EQ(d_run.gear_angle[m.gear_meshes[0].angle_a], 0.7);
  for (size_t i = 0; i < m.gear_meshes.size(); ++i) {
    const MeshEvaluation alone = EvaluateGearMesh(m, m.gear_meshes[i], d_alone);
    EXPECT_GT(std::abs(alone.force), 1e3) << i;  // linear drive flank: either sign
    EXPECT_EQ(d_run.mesh_force[i], alone.force) << i;
    EXPECT_EQ(d_run.mesh_phase[i], alone.psi) << i;
    EXPECT_EQ(d_run.mesh_deflection[i], alone.delta) << i;
  }
}

// A planetary tree on a free, tilted housing: sun (revolute about +z), ring (planar, normal to
// +z), carrier (revolute about -z, offset turned about z) and a planet on the carrier (revolute,
// pin offset and frames turned about z). Every gear angle about the carrier is then a sum of
// joint coordinates (GearAngle::by_coordinates); a second planet on a spherical joint keeps the
// general path. Both against the general path (GearSpinAngle, atan2 of the relative rotation) at
// configurations with large angles, to the rounding of the coordinates' sums and the wrap.
struct PlanetaryTree {
  std::shared_ptr<const Model> model;
  JointIndex housing = -1;
};

PlanetaryTree MakePlanetaryTree(bool spherical_second_planet) {
  const Pair p;
  ModelBuilder mb;
  const Mat3 I = Vec3(1e-3, 1e-3, 2e-3).asDiagonal();
  auto rz = [](double a) { return AxisAngle(Vec3::UnitZ(), a); };
  PlanetaryTree t;
  const BodyIndex housing = mb.AddBody("housing", 10.0, Vec3::Zero(), I);
  t.housing = mb.AddJoint({.name = "j_housing", .type = JointType::kFree, .child = housing});
  const BodyIndex sun = mb.AddBody("sun", 1.0, Vec3::Zero(), I);
  const BodyIndex ring = mb.AddBody("ring", 3.0, Vec3::Zero(), I);
  const BodyIndex carrier = mb.AddBody("carrier", 2.0, Vec3::Zero(), I);
  mb.AddJoint({.name = "j_sun", .type = JointType::kRevolute, .parent = housing, .child = sun,
               .X_PF = Transform::Translation(Vec3(0, 0, 0.1)), .axis = Vec3::UnitZ()});
  mb.AddJoint({.name = "j_ring", .type = JointType::kPlanar, .parent = housing, .child = ring,
               .X_PF = Transform(rz(0.4), Vec3::Zero()), .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
  mb.AddJoint({.name = "j_carrier", .type = JointType::kRevolute, .parent = housing, .child = carrier,
               .X_PF = Transform(rz(0.3), Vec3(0, 0, 0.2)), .axis = -Vec3::UnitZ()});
  const FrameIndex reference = mb.AddFrame("carrier_c", carrier, Transform(rz(-1.1), Vec3(0, 0, 0.01)));
  const FrameIndex sun_gear = mb.AddFrame("sun_gear", sun, Transform(rz(0.2), Vec3::Zero()));
  const FrameIndex ring_gear = mb.body_frame(ring);
  const double d_sp = (p.rba + p.rbb) / std::cos(kAlpha);
  const double rbr = p.rba + 2 * p.rbb;  // ring base radius: centre distance rbr - rbb = rba + rbb
  for (int i = 0; i < 2; ++i) {
    const std::string name = "planet" + std::to_string(i);
    const BodyIndex planet = mb.AddBody(name, 0.5, Vec3::Zero(), I);
    // The pin at angle psi in the carrier frame C (which is turned by -1.1 on the carrier body).
    const double psi = 0.5 + 2.5 * i;
    const Transform X_CP(rz(psi), d_sp * Vec3(std::cos(psi), std::sin(psi), 0));
    const Transform X_PF = Transform(rz(-1.1), Vec3(0, 0, 0.01)) * X_CP;
    const bool spherical = spherical_second_planet && i == 1;
    mb.AddJoint({.name = "j_" + name, .type = spherical ? JointType::kSpherical : JointType::kRevolute,
                 .parent = carrier, .child = planet, .X_PF = X_PF, .X_CM = Transform(rz(0.7), Vec3::Zero()),
                 .axis = Vec3::UnitZ()});
    const FrameIndex planet_gear = mb.AddFrame(name + "_gear", planet, Transform(rz(-0.4), Vec3::Zero()));
    for (int k = 0; k < 2; ++k) {
      GearMeshSpec s;
      s.name = (k ? "ring-" : "sun-") + name;
      s.contact = GearMeshSpec::Contact::kLinearDrive;
      s.gear_a = k ? planet_gear : sun_gear;
      s.gear_b = k ? ring_gear : planet_gear;
      s.reference = reference;
      s.teeth_a = k ? p.zb : p.za;
      s.teeth_b = k ? p.za + 2 * p.zb : p.zb;
      s.base_radius_a = k ? p.rbb : p.rba;
      s.base_radius_b = k ? rbr : p.rbb;
      s.internal_b = k == 1;
      s.working_pressure_angle = kAlpha;
      s.stiffness = 4e8;
      mb.AddGearMesh(s);
    }
  }
  t.model = std::move(mb).Finalize();
  return t;
}

// Positions with the housing tilted and every joint angle large (several turns).
Eigen::VectorXd TurnedPositions(const Model& m, JointIndex housing, int sample) {
  Eigen::VectorXd q = m.q_initial;
  for (int k = 0; k < m.nq; ++k) q(k) += 7.3 * std::sin(1.7 * k + 0.9 * sample) + 0.3 * sample;
  const int h = m.joints[housing].q_start;
  const Quat tilt(Eigen::AngleAxisd(0.6 + 0.1 * sample, Vec3(1, 2, 0.5).normalized()));
  q(h + 3) = tilt.w();
  q.segment<3>(h + 4) = tilt.vec();
  NormalizeQuaternions(m, q);  // the spherical planet's block too
  return q;
}

void ExpectAnglesAgree(const Model& m, JointIndex housing) {
  const double eps = std::numeric_limits<double>::epsilon();
  Data d(m);
  for (int sample = 0; sample < 8; ++sample) {
    const Eigen::VectorXd q = TurnedPositions(m, housing, sample);
    CalcPositionKinematics(m, q, d);
    for (size_t i = 0; i < m.gear_angles.size(); ++i) {
      const GearAngle& a = m.gear_angles[i];
      const double general = GearSpinAngle(d, a.gear, a.reference, a.R_CG0);
      const double angle = GearAngleAt(m, d, int(i));
      if (!a.by_coordinates) {
        EXPECT_EQ(angle, general) << i;
        continue;
      }
      // Rounding: the sum's terms (each |q| + |q0| at an ulp), the wrap's multiple of 2 pi, and
      // the general path's rotation products (a few ulp of 1 rad).
      double scale = 2 * kPi;
      for (const GearAngleTerm& t : a.terms) scale += std::abs(q(t.q)) + std::abs(t.q0);
      EXPECT_LE(std::abs(angle), kPi) << i;
      const double diff = std::remainder(angle - general, 2 * kPi);
      EXPECT_LE(std::abs(diff), 8 * eps * scale) << "angle " << i << " sample " << sample;
    }
  }
}

TEST(GearAngle, CoordinatesAgreeWithTheGeneralPath) {
  const PlanetaryTree t = MakePlanetaryTree(false);
  const Model& m = *t.model;
  // sun, planet0, ring, planet1 about the carrier frame
  ASSERT_EQ(m.gear_angles.size(), 4u);
  EXPECT_TRUE(m.gear_angles_by_coordinates);
  for (const GearAngle& a : m.gear_angles) EXPECT_TRUE(a.by_coordinates);
  // The sun: its own joint and the carrier's (about -z): two terms, both +1.
  const GearAngle& sun = m.gear_angles[m.gear_meshes[0].angle_a];
  ASSERT_EQ(sun.terms.size(), 2u);
  EXPECT_EQ(sun.terms[0].sign, 1.0);
  EXPECT_EQ(sun.terms[1].sign, 1.0);  // -1 for the reference's side times -1 for the axis
  // A planet: its own joint only.
  EXPECT_EQ(m.gear_angles[m.gear_meshes[0].angle_b].terms.size(), 1u);
  ExpectAnglesAgree(m, t.housing);
}

TEST(GearAngle, GeneralPathWhereTheTreeDoesNotTurnAboutZ) {
  const PlanetaryTree t = MakePlanetaryTree(true);
  const Model& m = *t.model;
  ASSERT_EQ(m.gear_angles.size(), 4u);
  EXPECT_FALSE(m.gear_angles_by_coordinates);
  // The spherical planet's angle keeps the general path; the others still read coordinates.
  const GearMesh& spherical = m.gear_meshes[2];
  EXPECT_FALSE(m.gear_angles[spherical.angle_b].by_coordinates);
  EXPECT_TRUE(m.gear_angles[spherical.angle_a].by_coordinates);
  EXPECT_TRUE(m.gear_angles[m.gear_meshes[0].angle_b].by_coordinates);
  ExpectAnglesAgree(m, t.housing);
}

}  // namespace
}  // namespace orrery

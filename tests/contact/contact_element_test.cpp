// Block on a plane through the engine (both integrators), against closed forms:
//   static penetration  delta = (m g / (k_A A))^(1/e)   (penalty per unit area, contact area A),
//   sliding             v_x(t) = v0 - mu g t - mu (v_y(t) - v_y(0))   (x and y momentum with
//                       F_T = mu F_N while slipping; v_y stays small),
//   impact              restitution e_r of the Hunt-Crossley law, exact: with
//                       m delta'' = -k delta^n (1 + b delta') the first integral
//                       m v dv / (1 + b v) = -k delta^n d delta, taken over the contact from
//                       delta = 0 at speed v0 to delta = 0 at speed -e_r v0, gives
//                       b v0 (1 + e_r) = ln((1 + b v0) / (1 - b e_r v0)),
//                       independent of k, n and m. Lankarani & Nikravesh (1990) set
//                       b = 3 (1 - e^2) / (4 v0) for a nominal e; the exact relation says what
//                       restitution that b really gives.
#include "contact/contact_element.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mbd/data.h"
#include "mbd/integrator.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "models/gear_contact.h"
#include "models/gear_geometry.h"

namespace orrery::contact {
namespace {

constexpr double kL = 0.1;      // block footprint side (m)
constexpr double kH = 0.01;     // block and plane mesh spacing (m)
constexpr double kMass = 1.0;   // kg
constexpr double kG = 9.81;

// Grid of n_x by n_z cells of size h in the plane y = 0 starting at (x0, z0), normal +y (up) or
// -y (down).
TriangleMesh Grid(double x0, double z0, int n_x, int n_z, double h, bool up) {
  TriangleMesh m;
  for (int i = 0; i <= n_x; ++i)
    for (int k = 0; k <= n_z; ++k) m.vertices.push_back(Vec3(x0 + i * h, 0, z0 + k * h));
  auto id = [&](int i, int k) { return i * (n_z + 1) + k; };
  for (int i = 0; i < n_x; ++i)
    for (int k = 0; k < n_z; ++k) {
      const int a = id(i, k), b = id(i + 1, k), c = id(i + 1, k + 1), d = id(i, k + 1);
      // x cross z = -y: (a, b, d) faces down.
      if (up) {
        m.triangles.push_back({a, d, b});
        m.triangles.push_back({b, d, c});
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      }
    }
  return m;
}

// The block's bottom face (body frame: origin at the face centre, y up) and a plane whose nodes
// sit half a spacing off the block's nodes, so that 10 x 10 plane nodes lie under the footprint
// and their area weights sum to exactly L^2.
struct Surfaces {
  std::shared_ptr<const ContactSurface> block, plane;
};
Surfaces MakeSurfaces(double plane_length_x) {
  const double margin = 1e-3;
  Surfaces s;
  const int n = static_cast<int>(std::lround(kL / kH));
  s.block = std::make_shared<const ContactSurface>(
      std::vector{Grid(-kL / 2, -kL / 2, n, n, kH, false)}, margin);
  const int nx = static_cast<int>(std::lround(plane_length_x / kH));
  s.plane = std::make_shared<const ContactSurface>(
      std::vector{Grid(-0.095, -0.095, nx, 19, kH, true)}, margin);
  return s;
}

enum class Mount { kFree, kVertical, kSlider };

struct Scene {
  std::shared_ptr<const Model> model;
  BodyIndex block = -1;
};

// A 1 kg block, 0.1 x 0.01 x 0.1 m, body origin at the centre of its bottom face, on a free
// joint, a vertical prismatic joint, or a slider (x prismatic, then y prismatic on a carriage of
// 1 microgram that only moves in x) above the plane y = 0.
Scene MakeScene(Mount mount, const ContactLaw& law, double y0, double vx0, double vy0,
                double gravity, double plane_length_x = 0.19) {
  ModelBuilder b;
  b.SetGravity(Vec3(0, -gravity, 0));
  const double h = 0.01;
  const Mat3 I = Vec3(kMass * (h * h + kL * kL) / 12, kMass * 2 * kL * kL / 12,
                      kMass * (h * h + kL * kL) / 12).asDiagonal();
  Scene s;
  s.block = b.AddBody("block", kMass, Vec3(0, h / 2, 0), I);
  if (mount == Mount::kFree) {
    JointIndex j = b.AddJoint({.name = "free", .type = JointType::kFree, .parent = kWorldBody,
                               .child = s.block});
    Eigen::VectorXd q(7);
    q << 0, y0, 0, 1, 0, 0, 0;
    b.SetJointPosition(j, q);
    Eigen::VectorXd v = Eigen::VectorXd::Zero(6);
    v << vx0, vy0, 0, 0, 0, 0;
    b.SetJointVelocity(j, v);
  } else if (mount == Mount::kVertical) {
    JointIndex j = b.AddJoint({.name = "y", .type = JointType::kPrismatic, .parent = kWorldBody,
                               .child = s.block, .axis = Vec3::UnitY()});
    b.SetJointPosition(j, Eigen::VectorXd::Constant(1, y0));
    b.SetJointVelocity(j, Eigen::VectorXd::Constant(1, vy0));
  } else {
    BodyIndex carriage = b.AddBody("carriage", 1e-9, Vec3::Zero(), Mat3::Identity() * 1e-12);
    JointIndex jx = b.AddJoint({.name = "x", .type = JointType::kPrismatic, .parent = kWorldBody,
                                .child = carriage, .axis = Vec3::UnitX()});
    JointIndex jy = b.AddJoint({.name = "y", .type = JointType::kPrismatic, .parent = carriage,
                                .child = s.block, .axis = Vec3::UnitY()});
    b.SetJointVelocity(jx, Eigen::VectorXd::Constant(1, vx0));
    b.SetJointPosition(jy, Eigen::VectorXd::Constant(1, y0));
    b.SetJointVelocity(jy, Eigen::VectorXd::Constant(1, vy0));
  }
  const Surfaces surfaces = MakeSurfaces(plane_length_x);
  b.AddExternalForce(std::make_shared<ContactElement>(
      ContactElementSpec{.name = "block_on_plane", .body_a = s.block, .body_b = kWorldBody,
                         .surface_a = surfaces.block, .surface_b = surfaces.plane, .law = law}));
  s.model = std::move(b).Finalize();
  return s;
}

IntegratorOptions Ida() {
  IntegratorOptions o;
  o.kind = IntegratorKind::kIda;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  return o;
}

IntegratorOptions GenAlpha(double step) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kGeneralizedAlpha;
  o.step = step;
  o.rho_inf = 1.0;  // no numerical dissipation: the restitution is the law's alone
  return o;
}

// Height of the block's bottom face (world y of the body origin).
double BlockHeight(const Scene& s, const State& state) {
  Data data(*s.model);
  CalcPositionKinematics(*s.model, state.q, data);
  return data.X_WB[s.block].p.y();
}

TEST(ContactElementTest, PenetrationWarnsBeyondTheMarginAndStopsBeyondItsLimit) {
  // Default limit: the search distance plus the slack (contact_outputs.h)
  const auto a = std::make_shared<const ContactSurface>(std::vector{Grid(-0.01, -0.01, 2, 2, 0.01, false)}, 1e-3, 4e-3);
  const auto b = std::make_shared<const ContactSurface>(std::vector{Grid(-0.01, -0.01, 2, 2, 0.01, true)}, 3e-3, 2e-3);
  ContactElementSpec spec{.name = "c", .body_a = 1, .body_b = kWorldBody, .surface_a = a, .surface_b = b,
                          .law = {.stiffness_per_area = 1e9}};
  const std::vector<ElementHealthCheck> checks = ContactElement(spec).HealthChecks();
  ASSERT_EQ(checks.size(), 2u);
  EXPECT_FALSE(checks[0].stops);
  EXPECT_DOUBLE_EQ(checks[0].limit, 2e-3);
  EXPECT_EQ(checks[1].name, "penetration_limit");
  EXPECT_TRUE(checks[1].stops);
  EXPECT_DOUBLE_EQ(checks[1].limit, 2e-3 + 3e-3);
  // A given limit, with its reason; a negative one is refused naming the element
  spec.penetration_limit = {.depth_m = 7e-3, .reason = "half the part"};
  EXPECT_DOUBLE_EQ(ContactElement(spec).HealthChecks()[1].limit, 7e-3);
  EXPECT_EQ(ContactElement(spec).HealthChecks()[1].cause, "half the part");
  spec.penetration_limit.depth_m = -1;
  try {
    ContactElement refused(spec);
    ADD_FAILURE() << "a negative penetration limit was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ContactElement 'c': penetration limit"), std::string::npos)
        << e.what();
  }
}

TEST(ContactElementTest, StaticPenetrationIsWeightOverPenaltyStiffness) {
  for (double exponent : {1.0, 1.5}) {
    ContactLaw law{.stiffness_per_area = exponent == 1.0 ? 1e7 : 1e9, .exponent = exponent,
                   .hunt_crossley_s_per_m = 20};
    const double expected = std::pow(kMass * kG / (law.stiffness_per_area * kL * kL), 1 / exponent);
    Scene s = MakeScene(Mount::kFree, law, 0.0, 0, 0, kG);
    auto integ = MakeIntegrator(*s.model, Ida());
    integ->Initialize(State::Initial(*s.model));
    integ->AdvanceTo(1.0);
    const double depth = -BlockHeight(s, integ->state());
    // Settled (Hunt-Crossley damping, e^-30 of the initial drop left) to the solver tolerance.
    EXPECT_NEAR(depth, expected, 1e-6 * expected) << "exponent " << exponent;
    EXPECT_LT(integ->state().v.norm(), 1e-6);
  }
}

TEST(ContactElementTest, SlidingBlockDeceleratesAtMuG) {
  const double mu = 0.3, v0 = 1.0;
  ContactLaw law{.stiffness_per_area = 1e7, .hunt_crossley_s_per_m = 20,
                 .friction_coefficient = mu, .slip_velocity_m_s = 1e-3};
  const double y_static = -kMass * kG / (law.stiffness_per_area * kL * kL);
  for (IntegratorOptions opt : {Ida(), GenAlpha(1e-4)}) {
    Scene s = MakeScene(Mount::kSlider, law, y_static, v0, 0, kG, 0.5);
    auto integ = MakeIntegrator(*s.model, opt);
    integ->Initialize(State::Initial(*s.model));
    double max_vy = 0;
    for (int k = 1; k <= 300; ++k) {
      const double t = 1e-3 * k;
      integ->AdvanceTo(t);
      const double vx = integ->state().v(0), vy = integ->state().v(1);
      max_vy = std::max(max_vy, std::abs(vy));
      // Momentum balance while slipping (vx > v_s): exact up to the integration error.
      EXPECT_NEAR(vx, v0 - mu * kG * t - mu * vy, 1e-6) << integ->name() << " t = " << t;
    }
    // The footprint crossing plane nodes shakes the block a little; the deceleration itself is
    // mu g within mu max|v_y|.
    EXPECT_NEAR(integ->state().v(0), v0 - mu * kG * 0.3, mu * max_vy + 1e-6) << integ->name();
    EXPECT_LT(max_vy, 1e-2);
  }
}

// Exact Hunt-Crossley restitution for x = b v0 (bisection on the relation in the header).
double HuntCrossleyRestitution(double x) {
  double lo = 0, hi = 1;
  for (int i = 0; i < 200; ++i) {
    const double e = 0.5 * (lo + hi);
    const double r = x * (1 + e) - std::log((1 + x) / (1 - e * x));
    // r(0) = x - ln(1 + x) > 0 and dr/de = x - x / (1 - e x) < 0: r > 0 below the root.
    (r > 0 ? lo : hi) = e;
  }
  return 0.5 * (lo + hi);
}

TEST(ContactElementTest, ImpactRestitutionMatchesHuntCrossley) {
  const double v0 = 0.1, e_nominal = 0.8;
  const double b = HuntCrossleyFactorLankaraniNikravesh(e_nominal, v0);
  const double e_exact = HuntCrossleyRestitution(b * v0);
  // Lankarani-Nikravesh is an approximation for e near 1: at e = 0.8 it is off by a few percent.
  EXPECT_GT(std::abs(e_exact - e_nominal), 0.01);
  struct Case {
    double exponent;
    IntegratorOptions opt;
    double tol;
  };
  // Tolerances: IDA at rtol 1e-9; generalized-alpha at 1e-5 s has (omega h)^2 ~ 1e-5.
  for (const Case& c : {Case{1.0, Ida(), 1e-6}, Case{1.5, Ida(), 1e-6},
                        Case{1.0, GenAlpha(1e-5), 1e-4}}) {
    ContactLaw law{.stiffness_per_area = c.exponent == 1.0 ? 1e7 : 1e9, .exponent = c.exponent,
                   .hunt_crossley_s_per_m = b};
    Scene s = MakeScene(Mount::kVertical, law, 1e-4, 0, -v0, 0.0);
    auto integ = MakeIntegrator(*s.model, c.opt);
    integ->Initialize(State::Initial(*s.model));
    integ->AdvanceTo(0.05);
    ASSERT_GT(BlockHeight(s, integ->state()), 0) << "still in contact";
    const double e = integ->state().v(0) / v0;
    EXPECT_NEAR(e, e_exact, c.tol) << integ->name() << " exponent " << c.exponent;
  }
}

// A spur pair's rows of nodes share one row's gaps (tracked_gaps.h), and CalcForces evaluates
// the contact law once per profile point for all its rows (ContactElement::ForEachContactPoint):
// their areas summed, the force applied at their area-weighted mean position. Against the
// contact force as the sum over every listed node of its own law call at its own position
// (seed 000 eq. 20 as the element evaluated it before), with damping and friction so that the
// relative velocity matters: an 18/34 pair turning about parallel axes (z), 4 face intervals
// (5 rows), pressed 1 to 5 um ahead through a mesh period. Forces and moments within 1e-12 of
// their scale (the sums' association), the counts exact. Then with gear 1 also turning about x
// (the rows' velocities differ): every row on its own, the per-node sum to the bit.
TEST(ContactElementTest, SharedRowsForcesEqualTheSumOverTheirNodes) {
  const double pi = 3.14159265358979323846;
  gears::GearSpec s1{.teeth = 18,
                     .normal_module_m = 1.5e-3,
                     .normal_pressure_angle_rad = 20 * pi / 180,
                     .face_width_m = 0.02};
  gears::GearSpec s2 = s1;
  s2.teeth = 34;
  const gears::GearPair pair{gears::Gear(s1), gears::Gear(s2)};
  gears::GearContactOptions o;
  o.involute_intervals = 16;
  o.face_intervals = 4;
  o.hunt_crossley_s_per_m = 0.3;
  o.friction_coefficient = 0.08;
  o.slip_velocity_m_s = 0.05;
  const ContactElement element(gears::MakeGearContactSpec("mesh", pair, 1, 2, o));
  const ContactSurface& sa = *element.spec().surface_a;
  const ContactSurface& sb = *element.spec().surface_b;
  const ContactLaw& law = element.spec().law;
  ContactWorkspace ws(sa, sb);
  const double rb1 = pair.gear1().base_radius_m(), c = pair.center_distance_m();
  struct Sum {
    Vec6 f_A = Vec6::Zero(), f_B = Vec6::Zero();
    double energy = 0, power = 0, normal = 0, friction = 0;
    int points = 0;
  };
  // The oracle: every penetrating node of both lists on its own.
  auto per_node = [&](const Vec6& V_A, const Vec6& V_B) {
    Sum sum;
    auto pass = [&](const std::vector<NodeGap>& gaps, const ContactSurface& nodes,
                    const ContactSurface& faces, const Vec6& V_N, const Vec6& V_F, Vec6& f_N,
                    Vec6& f_F) {
      for (const NodeGap& g : gaps) {
        if (!(g.gap < 0) || !g.on_surface) continue;
        const Vec3 v_rel = PointVelocity(V_N, g.p_W) - PointVelocity(V_F, g.p_W);
        const double scale =
            nodes.vertex_stiffness_scale()[g.node] * faces.face_stiffness_scale()[g.face];
        const double area = 0.5 * g.weight * nodes.vertex_areas()[g.node] * scale;
        const NodeForce f = EvaluateContactLaw(law, -g.gap, -v_rel.dot(g.n_W), g.n_W, v_rel, area);
        const Vec6 wrench = ForceAtPoint(g.p_W, f.f_W);
        f_N += wrench;
        f_F -= wrench;
        sum.energy += f.energy;
        sum.power += f.power_dissipated;
        sum.normal += f.normal;
        sum.friction += f.friction;
        ++sum.points;
      }
    };
    pass(ws.gaps_a, sa, sb, V_A, V_B, sum.f_A, sum.f_B);
    pass(ws.gaps_b, sb, sa, V_B, V_A, sum.f_B, sum.f_A);
    return sum;
  };
  int grouped = 0;
  for (int k = 0; k < 24; ++k) {
    const double theta1 = 2 * pi / 18 * k / 24;
    const double ahead = (3e-6 + 2e-6 * std::sin(0.9 * k)) / rb1;
    const Transform X_W1(AxisAngle(Vec3::UnitZ(), theta1 + ahead), Vec3::Zero());
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), pi + pi / 34 - theta1 * 18.0 / 34.0),
                         Vec3(c, 0, 0));
    element.UpdateGaps(X_W1, X_W2, ws);
    // Spatial velocities at the world origin: gear 1 about its axis through the origin, gear 2
    // about its axis through (c, 0, 0), slipping a little against the pair's ratio.
    const double w1 = 20, w2 = -20 * 18.0 / 34.0 + 0.05 * std::cos(0.7 * k);
    Vec6 V_A, V_B;
    V_A << 0, 0, w1, 0, 0, 0;
    V_B << 0, 0, w2, Vec3(0, 0, w2).cross(-Vec3(c, 0, 0));
    const bool shares = !ws.row_groups_a.empty() || !ws.row_groups_b.empty();
    grouped += shares;
    for (const bool tilted : {false, true}) {
      Vec6 V_At = V_A;
      if (tilted) V_At(0) = 0.7;  // gear 1 also turning about x: the rows move differently
      const Sum want = per_node(V_At, V_B);
      Vec6 f_A, f_B;
      double energy = 0, power = 0;
      element.CalcForces(V_At, V_B, ws, &f_A, &f_B, &energy, &power);
      const std::string at = "pose " + std::to_string(k) + (tilted ? ", tilted" : "");
      EXPECT_EQ(ws.contact_points, want.points) << at;
      if (tilted) {  // every node on its own: the same operations in the same order
        EXPECT_TRUE(f_A == want.f_A && f_B == want.f_B) << at;
        EXPECT_EQ(energy, want.energy) << at;
        EXPECT_EQ(power, want.power) << at;
        EXPECT_EQ(ws.normal_force, want.normal) << at;
        EXPECT_EQ(ws.friction_force, want.friction) << at;
        continue;
      }
      // Scales: the normal force (N), and for the moments about the world origin its arm, at
      // most the centre distance plus gear 2's tip radius (N m).
      const double F = want.normal, M = F * (c + pair.gear2().tip_radius_m());
      ASSERT_GT(F, 0) << at;
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(f_A(i), want.f_A(i), 1e-12 * M) << at << " moment " << i;
        EXPECT_NEAR(f_B(i), want.f_B(i), 1e-12 * M) << at << " moment " << i;
        EXPECT_NEAR(f_A(3 + i), want.f_A(3 + i), 1e-12 * F) << at << " force " << i;
        EXPECT_NEAR(f_B(3 + i), want.f_B(3 + i), 1e-12 * F) << at << " force " << i;
      }
      EXPECT_NEAR(energy, want.energy, 1e-12 * std::abs(want.energy)) << at;
      EXPECT_NEAR(power, want.power, 1e-12 * std::abs(want.power)) << at;
      EXPECT_NEAR(ws.normal_force, want.normal, 1e-12 * F) << at;
      EXPECT_NEAR(ws.friction_force, want.friction, 1e-12 * F) << at;
    }
  }
  EXPECT_EQ(grouped, 24);  // every pose shares its rows
}

}  // namespace
}  // namespace orrery::contact

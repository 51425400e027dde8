// Gear geometry: involute and fillet profiles, pair quantities, meshes, STL.
//
// Oracles (none of them written by this project):
// - the involute's defining properties: r = r_b / cos(alpha) and polar angle = +-inv(alpha) + const,
//   normals tangent to the base circle (Litvin & Fuentes 2004, sec. 10.2);
// - central finite differences of the profile for the normals (also on the generated trochoid);
// - Wildhaber's span measurement (ISO 21771) against the caliper distance measured on the profile
//   points (support lines of the sampled flanks);
// - published worked examples: SDP/SI "Elements of Metric Gear Technology" Table 10-1 (chordal
//   thickness, m = 10, z = 12, x = +0.3), Table 5-4 (internal pair z = 44/50, x2 = 0.11 in KHK
//   sign) and the KHK profile-shifted pair (m = 3, z = 12/24, x = 0.6/0.36, a = 56.5) as tabulated
//   at bolsover.com/utilitiesforalibre/profile-shifted-external-spur-gears.html;
// - eps_alpha from the law of gearing applied to the generated profile points (contact points
//   where the profile normal passes through the pitch point, limited by the mating tip circle);
// - the zero-backlash center distance checked by measuring tooth and space widths on the profiles;
// - the classical undercut limit z_min = 2 (h* - x) / sin^2(alpha);
// - mesh topology (every edge shared by two opposite half-edges) and the divergence-theorem
//   volume against the shoelace area of the outline times the face width;
// - the STL byte layout of the de-facto standard (84 + 50 n bytes).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "models/gear_geometry.h"
#include "models/stl.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
double PolarAngle(const Vec2& p) { return std::atan2(p.y(), p.x()); }

// Internal gears get a 0.8 m_n addendum so that their tips stay clear of the fillets of
// hob-cut pinions (see Seed001Ring).
GearSpec Spec(int z, double m, double alpha_deg, double x = 0, bool internal = false) {
  GearSpec s;
  s.addendum_coef = internal ? 0.8 : 1.0;
  s.teeth = z;
  s.normal_module_m = m;
  s.normal_pressure_angle_rad = alpha_deg * kDeg;
  s.profile_shift = x;
  s.face_width_m = 10 * m;
  s.internal = internal;
  return s;
}

// Seed 001 gears (docs/validation/scenarios.md): module 1.5 mm, 21.3 deg, 30 mm face width.
GearSpec Seed001(int z, bool internal = false) {
  GearSpec s = Spec(z, 1.5e-3, 21.3, 0, internal);
  s.face_width_m = 0.030;
  return s;
}

// Seed 001 ring: the paper gives no tip diameters. With the standard addendum (h_aP* = 1) the
// ring tip would reach 0.09 m_n into the rack-generated fillet of the 18-tooth planet (GearPair
// rejects that), so the ring addendum is 0.9 m_n.
GearSpec Seed001Ring() {
  GearSpec s = Seed001(70, true);
  s.addendum_coef = 0.9;
  return s;
}

GearSpec Helical(int z, HelixHand hand, bool internal = false) {
  GearSpec s = Spec(z, 2e-3, 20, 0.1, internal);
  s.helix_angle_rad = 15 * kDeg;
  s.hand = hand;
  return s;
}

// Finds the profile parameter in [s0, s1] where |p| = radius (radius monotone on the interval).
double ParamAtRadius(const Gear& g, double s0, double s1, double radius) {
  const double f0 = g.ProfileAt(s0).p.norm() - radius;
  for (int it = 0; it < 200; ++it) {
    const double sm = 0.5 * (s0 + s1);
    const double fm = g.ProfileAt(sm).p.norm() - radius;
    if ((fm < 0) == (f0 < 0)) s0 = sm;
    else s1 = sm;
  }
  return 0.5 * (s0 + s1);
}

// Arc tooth thickness at radius R measured on the generated flanks (tooth 0): the polar angles of
// the two flank points at that radius.
double MeasuredThickness(const Gear& g, double radius) {
  const Vec2 plus = g.ProfileAt(ParamAtRadius(g, 4.0, 5.0, radius)).p;
  const Vec2 minus = g.ProfileAt(ParamAtRadius(g, 2.0, 3.0, radius)).p;
  return radius * (PolarAngle(plus) - PolarAngle(minus));
}

// ---- Involute and fillet profile properties ------------------------------------------------

void CheckInvolute(const Gear& g) {
  SCOPED_TRACE(testing::Message() << "z = " << g.teeth() << (g.internal() ? " internal" : " external")
                                  << ", beta = " << g.spec().helix_angle_rad / kDeg);
  const double rb = g.base_radius_m(), scale = g.tip_radius_m();
  for (double seg : {2.0, 4.0}) {
    const double sign = (seg == 4.0) == !g.internal() ? -1.0 : 1.0;  // d(polar)/d(inv)
    double constant = 0;
    for (int j = 0; j <= 200; ++j) {
      const double s = seg + std::min(j / 200.0, 1 - 1e-15);  // s = seg + 1 is the tip arc
      const ProfilePoint q = g.ProfileAt(s);
      const double r = q.p.norm();
      const double alpha = std::acos(rb / r);
      // r = r_b / cos(alpha) holds by the definition of alpha; the polar-angle law is the test.
      const double c = PolarAngle(q.p) - sign * Involute(alpha);
      if (j == 0) constant = c;
      EXPECT_NEAR(c, constant, 1e-12) << "s = " << s;
      EXPECT_NEAR(r, rb / std::cos(alpha), 1e-15 * scale);
      // Unit normal, tangent to the base circle (distance of the normal line from the centre).
      EXPECT_NEAR(q.n.norm(), 1.0, 1e-14);
      EXPECT_NEAR(std::abs(Cross(q.p, q.n)), rb, 1e-12 * scale);
      // Normal perpendicular to the central-difference tangent (error O(h^2)).
      if (j > 0 && j < 200) {
        const double h = 1e-5;
        const Vec2 t = (g.ProfileAt(s + h).p - g.ProfileAt(s - h).p).normalized();
        EXPECT_NEAR(t.dot(q.n), 0.0, 1e-8) << "s = " << s;
      }
    }
  }
  // The half thickness on the profile agrees with psi(R) of the formula.
  const double rm = 0.5 * (g.form_radius_m() + g.tip_radius_m());
  EXPECT_NEAR(MeasuredThickness(g, rm), g.ToothThickness(rm), 1e-12 * scale);
}

TEST(GearProfile, InvolutePointsNormalsAndThickness) {
  CheckInvolute(Gear(Seed001(18)));
  CheckInvolute(Gear(Seed001(34)));
  CheckInvolute(Gear(Seed001(70, true)));
  CheckInvolute(Gear(Spec(12, 3e-3, 20, 0.6)));
  CheckInvolute(Gear(Helical(19, HelixHand::kRight)));
  CheckInvolute(Gear(Helical(61, HelixHand::kRight, true)));
}

// Normals on every segment (fillet trochoid included) against central differences, and C1
// continuity at the segment joints.
void CheckOutlineNormals(const Gear& g) {
  SCOPED_TRACE(testing::Message() << "z = " << g.teeth());
  const double scale = g.tip_radius_m();
  for (int seg = 0; seg < kNumProfileSegments; ++seg) {
    const double len = (g.ProfileAt(seg).p - g.ProfileAt(seg + 1.0).p).norm();
    if (len < 1e-12 * scale) continue;
    for (int j = 1; j < 50; ++j) {
      const double s = seg + j / 50.0, h = 1e-5;
      const ProfilePoint q = g.ProfileAt(s);
      const Vec2 t = (g.ProfileAt(s + h).p - g.ProfileAt(s - h).p).normalized();
      EXPECT_NEAR(q.n.norm(), 1.0, 1e-14);
      EXPECT_NEAR(t.dot(q.n), 0.0, 1e-7) << "segment " << seg << " s = " << s;
      // Outward: the normal turns to the right of the counter-clockwise tangent for external
      // gears (material on the left) and to the left for internal gears.
      EXPECT_GT(Cross(t, q.n) * (g.internal() ? 1 : -1), 0.99);
    }
    // Joints: position continuous; normal continuous except at the two tip corners.
    const ProfilePoint end = g.ProfileAt(seg + 1.0 - 1e-12), next = g.ProfileAt(seg + 1.0);
    EXPECT_NEAR((end.p - next.p).norm(), 0.0, 1e-9 * scale) << "joint after segment " << seg;
    if (seg != 2 && seg != 3 && seg != 6) {
      EXPECT_NEAR((end.n - next.n).norm(), 0.0, 1e-6) << "joint after segment " << seg;
    }
  }
  // Root circle and form circle where they belong.
  EXPECT_NEAR(g.ProfileAt(5.0).p.norm(), g.form_radius_m(), 1e-12 * scale);
  EXPECT_NEAR(g.ProfileAt(6.0).p.norm(), g.root_radius_m(), 1e-12 * scale);
  EXPECT_NEAR(g.ProfileAt(3.0).p.norm(), g.tip_radius_m(), 1e-12 * scale);
}

TEST(GearProfile, FilletAndArcsNormalsAndContinuity) {
  CheckOutlineNormals(Gear(Seed001(18)));
  CheckOutlineNormals(Gear(Seed001(70, true)));
  CheckOutlineNormals(Gear(Spec(12, 3e-3, 20, 0.6)));
  CheckOutlineNormals(Gear(Helical(19, HelixHand::kLeft)));
  GearSpec sharp = Seed001(40);
  sharp.root_fillet_coef = 0;  // the rack corner generates a pure trochoid
  CheckOutlineNormals(Gear(sharp));
}

// The trochoid is the path of the rack-tip fillet centre offset by rho (Litvin & Fuentes
// sec. 6.1): every fillet point lies at distance rho from the extended-epicycloid path of the
// centre, x_c = r (sin phi - phi cos phi) ... checked here in its equivalent form: the fillet
// point minus rho times its outward normal is the fillet centre, whose distance from the gear
// centre is |(u_c - r phi, r + v_c)| for the rolling angle phi of that point.
TEST(GearProfile, SpurFilletCentreFollowsTheRollingRack) {
  GearSpec s = Seed001(18);
  const Gear g(s);
  const double m = s.normal_module_m, rho = s.root_fillet_coef * m, r = g.reference_radius_m();
  const double u_c = kPi * m / 4 - (s.dedendum_coef * m - rho) * std::tan(s.normal_pressure_angle_rad) -
                     rho / std::cos(s.normal_pressure_angle_rad);
  const double v_c = -s.dedendum_coef * m + rho;
  // (The last point, on the root circle, has u_c - r phi = 0 where the square root below loses
  // half the digits; it is covered by the root-radius check of CheckOutlineNormals.)
  for (int j = 0; j < 20; ++j) {
    const ProfilePoint q = g.ProfileAt(5.0 + j / 20.0);
    const Vec2 centre = q.p + rho * q.n;  // the gear normal points into the rack, to its centre
    // The centre in the rack frame is fixed; rotated by phi in the gear frame it sits at radius
    // sqrt((u_c - r phi)^2 + (r + v_c)^2). Solve for phi from the polar angle and compare radii.
    const double rad = centre.norm();
    const double a = rad * rad - (r + v_c) * (r + v_c);
    ASSERT_GE(a, -1e-18);
    const double d = std::sqrt(std::max(0.0, a));  // |u_c - r phi|
    // Polar angle of the centre (space at +pi/z frame): pi/z - atan2(u_c - r phi, r + v_c) - phi.
    bool found = false;
    for (double sign : {1.0, -1.0}) {
      const double phi = (u_c - sign * d) / r;
      const double predicted = kPi / 18 - std::atan2(u_c - r * phi, r + v_c) - phi;
      if (std::abs(std::remainder(predicted - PolarAngle(centre), 2 * kPi)) < 1e-12) found = true;
    }
    EXPECT_TRUE(found) << "fillet point " << j;
  }
}

// Fillet samples within ProfileResolution::fillet_max_sag_m: the largest distance of the exact
// fillet (ProfileAt, 400 points per sampled interval) from the polyline of the samples, for seed
// 003's 14-tooth planet (m_n 4 mm, 22.5 deg: its rack-angle intervals are uneven, 1.3 mm at the
// form circle) and its 50-tooth ring (circular fillet). Concave: the polyline lies in the space.
double FilletChordError(const Gear& g, const ProfileResolution& res) {
  std::vector<ProfilePoint> pts;
  for (const ProfilePoint& q : g.SampleToothOutline(res))
    if (q.segment == ProfileSegment::kFilletPlus) pts.push_back(q);
  pts.push_back(g.ProfileAt(6.0));
  double worst = 0;
  for (std::size_t j = 0; j + 1 < pts.size(); ++j) {
    const Vec2 a = pts[j].p, d = pts[j + 1].p - a;
    for (int k = 1; k < 400; ++k) {
      const Vec2 q = g.ProfileAt(pts[j].s + (pts[j + 1].s - pts[j].s) * k / 400.0).p;
      worst = std::max(worst, std::abs(d.x() * (q - a).y() - d.y() * (q - a).x()) / d.norm());
    }
  }
  return worst;
}

TEST(GearProfile, FilletSamplesWithinTheirSag) {
  GearSpec planet = Spec(14, 4e-3, 22.5, 0);
  GearSpec ring = Spec(50, 4e-3, 22.5, 0);
  ring.internal = true;
  ring.addendum_coef = 0.85;
  ring.root_fillet_coef = 0.25;
  for (const GearSpec& s : {planet, ring}) {
    const Gear g(s);
    ProfileResolution res{.root = 2, .fillet = 6, .involute = 40, .tip = 4};
    const double even = FilletChordError(g, res);
    res.fillet_max_sag_m = 1e-6;
    const double refined = FilletChordError(g, res);
    std::printf("z %d%s: fillet chords %.2f um off at 6 even intervals, %.3f um within 1 um\n", s.teeth,
                s.internal ? " (ring)" : "", even * 1e6, refined * 1e6);
    // The bound is checked at each interval's middle; the curvature varies little within one.
    EXPECT_LT(refined, 1.1e-6);
    if (!s.internal) {
      EXPECT_GT(even, 40e-6);  // the planet's: 52 um (docs/faults.md)
    }
  }
}

// ---- Published examples ------------------------------------------------------------------

// SDP/SI Elements of Metric Gear Technology, Table 10-1: m = 10, alpha = 20 deg, z = 12,
// x = +0.3, h_a = 13.000 -> s = 17.8918, theta = 8.54270 deg, s_j = 17.8256, h_j = 13.6657 (mm).
TEST(GearPublished, SdpChordalThicknessTable10_1) {
  const Gear g(Spec(12, 10e-3, 20, 0.3));
  const double r = g.reference_radius_m();
  EXPECT_NEAR(g.tip_radius_m() - r, 13.000e-3, 0.5e-6);
  const Vec2 plus = g.ProfileAt(ParamAtRadius(g, 4.0, 5.0, r)).p;
  const Vec2 minus = g.ProfileAt(ParamAtRadius(g, 2.0, 3.0, r)).p;
  const double theta = 0.5 * (PolarAngle(plus) - PolarAngle(minus));
  EXPECT_NEAR(2 * r * theta, 17.8918e-3, 0.5e-7);                   // s, printed to 1e-4 mm
  EXPECT_NEAR(theta / kDeg, 8.54270, 0.5e-5);                        // theta, to 1e-5 deg
  EXPECT_NEAR((plus - minus).norm(), 17.8256e-3, 0.5e-7);            // chordal thickness s_j
  EXPECT_NEAR(g.tip_radius_m() - r * std::cos(theta), 13.6657e-3, 0.5e-7);  // chordal addendum
}

// KHK profile-shifted spur pair (KHK Gear Technical Reference, profile shifted spur gears;
// tabulated at bolsover.com): m = 3, 20 deg, z = 12/24, x = 0.6/0.36, a = 56.500,
// inv(alpha_w) = 0.034317, alpha_w = 26.0888 deg, d_b = 33.8289/67.6579, d_w = 37.667/75.333,
// d_a = 44.840/79.400, d_f = 32.100/66.660, contact ratio 1.202 (mm).
TEST(GearPublished, KhkProfileShiftedPair) {
  GearSpec s1 = Spec(12, 3e-3, 20, 0.6), s2 = Spec(24, 3e-3, 20, 0.36);
  s1.tip_radius_m = 44.840e-3 / 2;
  s2.tip_radius_m = 79.400e-3 / 2;
  const GearPair pair(Gear(s1), Gear(s2), 56.500e-3);
  EXPECT_NEAR(Involute(pair.working_pressure_angle_rad()), 0.034317, 0.5e-6);
  EXPECT_NEAR(pair.working_pressure_angle_rad() / kDeg, 26.0888, 0.5e-4);
  EXPECT_NEAR(2 * pair.gear1().base_radius_m(), 33.8289e-3, 0.5e-7);
  EXPECT_NEAR(2 * pair.gear2().base_radius_m(), 67.6579e-3, 0.5e-7);
  EXPECT_NEAR(2 * pair.working_pitch_radius1_m(), 37.667e-3, 0.5e-6);
  EXPECT_NEAR(2 * pair.working_pitch_radius2_m(), 75.333e-3, 0.5e-6);
  EXPECT_NEAR(2 * pair.gear1().root_radius_m(), 32.100e-3, 0.5e-6);
  EXPECT_NEAR(2 * pair.gear2().root_radius_m(), 66.660e-3, 0.5e-6);
  EXPECT_NEAR(pair.transverse_contact_ratio(), 1.202, 0.5e-3);
  // The printed shift sum 0.960 is derived from a = 56.500: the zero-backlash distance from
  // the shifts reproduces it to the printed precision.
  EXPECT_NEAR(pair.zero_backlash_center_distance_m(), 56.500e-3, 0.5e-6);
}

// SDP/SI Table 5-4 (internal gear with a small tooth difference; m = 1 implied by a):
// z1 = 44, x1 = 0, z2 = 50, x2 = 0.11 (KHK sign; ISO x2 = -0.11): alpha_w = 24.5356 deg,
// a = 3.099, eps = 2.014. The table states these pairs have no involute or trochoid interference.
// SDP/SI checks involute, trochoid and trimming interference only; with a hob of tip radius
// 0.38 m_n the ring tip would also reach into the pinion's fillet, so the pinion here is cut by a
// sharp-cornered rack (rho_fP* = 0), which leaves the tabulated quantities unchanged.
TEST(GearPublished, SdpInternalPairTable5_4) {
  GearSpec pinion = Spec(44, 1e-3, 20, 0);
  pinion.root_fillet_coef = 0;
  GearSpec ring = Spec(50, 1e-3, 20, -0.11, true);
  ring.addendum_coef = 1.0;  // standard internal gear
  const GearPair pair{Gear(pinion), Gear(ring)};
  EXPECT_NEAR(pair.working_pressure_angle_rad() / kDeg, 24.5356, 0.5e-4);
  EXPECT_NEAR(pair.center_distance_m(), 3.099e-3, 0.5e-6);
  EXPECT_NEAR(pair.transverse_contact_ratio(), 2.014, 0.5e-3);
}

// ---- Span measurement ---------------------------------------------------------------------

// Caliper on the generated flanks: teeth 0..k-1 turned so that the span is symmetric about +x;
// W = max y over the plus flank of the last tooth - min y over the minus flank of the first.
double MeasuredSpan(const Gear& g, int k, int samples, double* bound) {
  const double turn = -(k - 1) * kPi / g.teeth();
  double y_max = -1e9, y_min = 1e9, ds_max = 0;
  int arg_max = -1, arg_min = -1;
  Vec2 prev;
  for (int j = 0; j <= samples; ++j) {
    const double t = static_cast<double>(j) / samples;
    const Vec2 top = Eigen::Rotation2Dd(turn + 2 * kPi * (k - 1) / g.teeth()) * g.ProfileAt(4.0 + t).p;
    const Vec2 bottom = Eigen::Rotation2Dd(turn) * g.ProfileAt(2.0 + t).p;
    if (top.y() > y_max) y_max = top.y(), arg_max = j;
    if (bottom.y() < y_min) y_min = bottom.y(), arg_min = j;
    if (j > 0) ds_max = std::max(ds_max, (top - prev).norm());
    prev = top;
  }
  EXPECT_GT(arg_max, 0);
  EXPECT_LT(arg_max, samples);  // a tangent point inside the involute, not a corner
  EXPECT_GT(arg_min, 0);
  EXPECT_LT(arg_min, samples);
  // Sampling a curve of curvature radius rho >= r_b xi_min misses its support line by at most
  // ds^2 / (8 rho) per side; rho at the caliper contact is at least the form-circle value.
  const double rho_min = std::sqrt(std::pow(g.form_radius_m(), 2) - std::pow(g.base_radius_m(), 2));
  *bound = 2 * ds_max * ds_max / (8 * rho_min);
  return y_max - y_min;
}

TEST(GearSpan, WildhaberAgainstProfileCaliper) {
  struct Case { GearSpec spec; int k; };
  std::vector<Case> cases = {{Spec(24, 3e-3, 20, 0.4), 4}, {Seed001(18), 3}, {Seed001(34), 5},
                             {Spec(60, 2e-3, 20, -0.2), 7}};
  GearSpec thinned = Seed001(34);
  thinned.thickness_allowance_m = -40e-6;
  cases.push_back({thinned, 5});
  for (const Case& c : cases) {
    const Gear g(c.spec);
    double bound = 0;
    const double w = MeasuredSpan(g, c.k, 4000, &bound);
    EXPECT_NEAR(w, g.SpanMeasurement(c.k), bound + 1e-12) << "z = " << c.spec.teeth;
    EXPECT_LT(bound, 1e-9);
  }
  // Published: m = 2, z = 20, 20 deg, x = 0, k = 3 -> W = 15.321 mm (machinecalcs.com worked
  // example, span measurement calculator).
  EXPECT_NEAR(Gear(Spec(20, 2e-3, 20)).SpanMeasurement(3), 15.321e-3, 0.5e-6);
}

TEST(GearSpan, TipThicknessFormulaAgainstProfile) {
  for (const GearSpec& s : {Spec(12, 3e-3, 20, 0.6), Seed001(18), Seed001(70, true)}) {
    const Gear g(s);
    const double ra = g.tip_radius_m();
    // psi_a from the involute ends of the profile (generated by the rack for external gears).
    const double psi_a = 0.5 * (PolarAngle(g.ProfileAt(4.0).p) - PolarAngle(g.ProfileAt(3.0).p));
    const double alpha_a = std::acos(g.base_radius_m() / ra);
    const double psi_formula = (kPi / 2 + 2 * s.profile_shift * std::tan(s.normal_pressure_angle_rad)) / s.teeth +
                               (s.internal ? -1 : 1) * (Involute(g.transverse_pressure_angle_rad()) - Involute(alpha_a));
    EXPECT_NEAR(2 * ra * psi_a, 2 * ra * psi_formula, 1e-12 * ra);
    EXPECT_NEAR(g.NormalTipThickness(), 2 * ra * psi_formula, 1e-15);
  }
}

// ---- Pair: contact ratio, center distance, backlash -----------------------------------------

// Path of contact by the law of gearing on the generated profile of gear 1 (plus flank): for
// each flank point the rotation that puts its normal through the pitch point gives the contact
// point; contact exists while that point is inside gear 2's tip circle. Returns eps_alpha.
double NumericContactRatio(const GearPair& pair) {
  const Gear& g1 = pair.gear1();
  const double rw1 = pair.working_pitch_radius1_m(), a = pair.center_distance_m();
  const Vec2 pitch(rw1, 0), o2(pair.internal() ? rw1 - pair.working_pitch_radius2_m() : a, 0);
  const double ra2 = pair.gear2().tip_radius_m();
  auto contact = [&](double t) {
    const ProfilePoint q = g1.ProfileAt(4.0 + t);
    const double c = Cross(q.p, q.n), angle_n = PolarAngle(q.n);
    // cross(R p - I, R n) = cross(p, n) - r_w1 sin(phi + angle_n) = 0.
    const double phi = std::asin(c / rw1) - angle_n;
    return Vec2(Eigen::Rotation2Dd(phi) * q.p);
  };
  auto inside2 = [&](double t) {
    const double d = (contact(t) - o2).norm();
    return pair.internal() ? d >= ra2 : d <= ra2;
  };
  // Gear 1's tip (t = 0) is in contact; bisection for the entry at gear 2's tip circle.
  EXPECT_TRUE(inside2(0.0));
  EXPECT_FALSE(inside2(1.0));
  double lo = 0, hi = 1;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (inside2(mid) ? lo : hi) = mid;
  }
  const Vec2 a_end = contact(0.0), a_start = contact(lo);
  // Both ends lie on one straight line through the pitch point (the line of action).
  EXPECT_NEAR(Cross(a_end - pitch, a_start - pitch), 0.0, 1e-12 * rw1 * rw1);
  return (a_end - a_start).norm() / g1.transverse_base_pitch_m();
}

TEST(GearPair, ContactRatioByTheLawOfGearing) {
  std::vector<GearPair> pairs;
  pairs.emplace_back(Gear(Seed001(18)), Gear(Seed001(34)));
  pairs.emplace_back(Gear(Seed001(18)), Gear(Seed001Ring()));
  GearSpec s1 = Spec(12, 3e-3, 20, 0.6), s2 = Spec(24, 3e-3, 20, 0.36);
  s1.tip_radius_m = 44.840e-3 / 2;
  s2.tip_radius_m = 79.400e-3 / 2;
  pairs.emplace_back(Gear(s1), Gear(s2), 56.500e-3);
  pairs.emplace_back(Gear(Helical(19, HelixHand::kRight)), Gear(Helical(41, HelixHand::kLeft)));
  pairs.emplace_back(Gear(Helical(19, HelixHand::kRight)), Gear(Helical(61, HelixHand::kRight, true)));
  for (const GearPair& p : pairs) {
    SCOPED_TRACE(testing::Message() << p.gear1().teeth() << "/" << p.gear2().teeth());
    EXPECT_NEAR(NumericContactRatio(p), p.transverse_contact_ratio(), 1e-9);
  }
  // Seed 001 values (reported, no reference): sun-planet and ring-planet eps_alpha.
  EXPECT_GT(pairs[0].transverse_contact_ratio(), 1.4);
  EXPECT_GT(pairs[1].transverse_contact_ratio(), pairs[0].transverse_contact_ratio());
  std::printf("seed 001: eps_alpha sun-planet %.4f, ring-planet %.4f\n", pairs[0].transverse_contact_ratio(),
              pairs[1].transverse_contact_ratio());
}

// At the zero-backlash distance from inv(alpha_w) the tooth of one gear fills the space of the
// other on the working pitch circles, measured on the profiles.
TEST(GearPair, ZeroBacklashDistanceMatchesProfiles) {
  struct Case { GearSpec s1, s2; };
  std::vector<Case> cases = {{Spec(12, 3e-3, 20, 0.6), Spec(24, 3e-3, 20, 0.36)},
                             {Seed001(18), Seed001(34)},
                             {Spec(17, 2e-3, 20, 0.3), Spec(40, 2e-3, 20, -0.1)},
                             {Spec(18, 2e-3, 20, 0.2), Spec(61, 2e-3, 20, 0.15, true)},
                             {Spec(44, 1e-3, 20, 0), Spec(50, 1e-3, 20, -0.11, true)}};
  for (const Case& c : cases) {
    const GearPair p(Gear(c.s1), Gear(c.s2));
    SCOPED_TRACE(testing::Message() << c.s1.teeth << "/" << c.s2.teeth);
    const double rw1 = p.working_pitch_radius1_m(), rw2 = p.working_pitch_radius2_m();
    const double tooth1 = MeasuredThickness(p.gear1(), rw1);
    const double space2 = 2 * kPi * rw2 / c.s2.teeth - MeasuredThickness(p.gear2(), rw2);
    EXPECT_NEAR(tooth1, space2, 1e-12);
    EXPECT_NEAR(p.circumferential_backlash_m(), 0.0, 1e-12);
  }
}

// Backlash from thickness allowances and from a larger center distance (ISO 21771 / ISO TR
// 10064-2): j_wt = -(A_s1 + A_s2)/cos(beta) * ... at the reference circle; for spur gears and
// a = a0 the circumferential backlash equals -(A_s1 + A_s2) r_w / r, and a center distance
// increase da adds 2 da tan(alpha_w) (both from the involute geometry).
TEST(GearPair, BacklashFromAllowancesAndCenterDistance) {
  GearSpec s1 = Seed001(18), s2 = Seed001(34);
  s1.thickness_allowance_m = -30e-6;
  s2.thickness_allowance_m = -50e-6;
  const GearPair tight{Gear(s1), Gear(s2)};
  const double rw1 = tight.working_pitch_radius1_m(), r1 = tight.gear1().reference_radius_m();
  EXPECT_NEAR(tight.circumferential_backlash_m(), 80e-6 * rw1 / r1, 1e-12);
  EXPECT_NEAR(tight.normal_backlash_m(), tight.circumferential_backlash_m() * std::cos(tight.working_pressure_angle_rad()), 1e-15);
  // Small center distance increase: dj = 2 da tan(alpha_w) to first order; the remainder is of
  // order da^2 / r_w1 (curvature of the involutes over the shift), bounded here by 2 da^2 / r_w1.
  const double da = 1e-6;
  const GearPair loose(Gear(Seed001(18)), Gear(Seed001(34)), tight.zero_backlash_center_distance_m() + da);
  EXPECT_NEAR(loose.circumferential_backlash_m(), 2 * da * std::tan(loose.working_pressure_angle_rad()),
              2 * da * da / loose.working_pitch_radius1_m());
  EXPECT_NEAR(loose.angular_backlash1_rad(), loose.circumferential_backlash_m() / loose.working_pitch_radius1_m(), 1e-15);
}

// ---- Inconsistent input ----------------------------------------------------------------------

template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(GearErrors, UndercutLimit) {
  // z_min = 2 (h* - x) / sin^2(alpha) with h* = h_fP* - rho_fP* (1 - sin alpha) = 1.0 for the
  // ISO 53 rack A (1.25, 0.38): 17.097 for x = 0, 11.968 for x = 0.3.
  for (double x : {0.0, 0.3, -0.2}) {
    const double h = 1.25 - 0.38 * (1 - std::sin(20 * kDeg));
    const double zmin = 2 * (h - x) / std::pow(std::sin(20 * kDeg), 2);
    const int z_ok = static_cast<int>(std::ceil(zmin)), z_bad = z_ok - 1;
    EXPECT_NEAR(Gear(Spec(z_ok, 2e-3, 20, x)).MinTeethWithoutUndercut(), zmin, 1e-12);
    EXPECT_NO_THROW(Gear(Spec(z_ok, 2e-3, 20, x)));
    EXPECT_NE(ErrorOf([&] { Gear(Spec(z_bad, 2e-3, 20, x)); }).find("undercut"), std::string::npos);
  }
  // Another rack: rho_fP* = 0.25 -> h* = 1.0855, z_min(x = 0) = 18.56.
  GearSpec s = Spec(19, 2e-3, 20);
  s.root_fillet_coef = 0.25;
  EXPECT_NO_THROW(Gear{s});
  s.teeth = 18;
  EXPECT_NE(ErrorOf([&] { Gear{s}; }).find("z_min = 18.5"), std::string::npos);
}

TEST(GearErrors, InvalidInputsNameTheValue) {
  EXPECT_NE(ErrorOf([] { Gear(Spec(0, 2e-3, 20)); }).find("z = 0"), std::string::npos);
  EXPECT_NE(ErrorOf([] { Gear(Spec(20, -1e-3, 20)); }).find("m_n = -0.001"), std::string::npos);
  GearSpec s = Spec(20, 2e-3, 20);
  s.face_width_m = 0;
  EXPECT_NE(ErrorOf([&] { Gear{s}; }).find("face width"), std::string::npos);
  // Pointed tip: z = 10, x = 0.8 with the default tip r + (1 + x) m.
  EXPECT_NE(ErrorOf([] { Gear(Spec(10, 2e-3, 20, 0.8)); }).find("pointed tip"), std::string::npos);
  // The minimum tip thickness is a parameter.
  GearSpec tip = Spec(12, 3e-3, 20, 0.6);
  EXPECT_NO_THROW(Gear{tip});  // s_an = 0.39 m_n
  tip.min_tip_thickness_coef = 0.4;
  EXPECT_NE(ErrorOf([&] { Gear{tip}; }).find("pointed tip"), std::string::npos);
  // Rack fillet too large.
  GearSpec big = Spec(30, 2e-3, 20);
  big.root_fillet_coef = 0.6;
  EXPECT_NE(ErrorOf([&] { Gear{big}; }).find("rho_fP*"), std::string::npos);
}

TEST(GearErrors, PairInconsistencies) {
  // Contact ratio below 1: tips cut down.
  GearSpec a = Seed001(18), b = Seed001(34);
  a.tip_radius_m = Gear(a).reference_radius_m() + 0.45e-3;
  b.tip_radius_m = Gear(b).reference_radius_m() + 0.45e-3;
  EXPECT_NE(ErrorOf([&] { GearPair(Gear(a), Gear(b)); }).find("eps_alpha"), std::string::npos);
  // Center distance below the tight-mesh distance.
  EXPECT_NE(ErrorOf([] { GearPair(Gear(Seed001(18)), Gear(Seed001(34)), 0.0389); }).find("tight-mesh"),
            std::string::npos);
  // Internal pair with a small tooth difference (SDP/SI sec. 5.2 (b): trochoid interference
  // "tends to happen when the difference between the numbers of teeth is small"). A standard
  // ring (h_aP* = 1) would also reach into this pinion's fillet, so the ring has 0.8 m_n.
  GearSpec small = Spec(30, 2e-3, 20);
  small.root_fillet_coef = 0;
  EXPECT_NE(ErrorOf([&] { GearPair(Gear(small), Gear(Spec(34, 2e-3, 20, 0, true))); }).find("trochoid"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { GearPair(Gear(small), Gear(Spec(36, 2e-3, 20, 0, true))); }).find("trochoid"),
            std::string::npos);
  EXPECT_NO_THROW(GearPair(Gear(small), Gear(Spec(40, 2e-3, 20, 0, true))));
  // The standard ring tip in the pinion fillet is reported with the limiting tip radius.
  GearSpec ring = Spec(44, 2e-3, 20, 0, true);
  ring.addendum_coef = 1.0;
  EXPECT_NE(ErrorOf([&] { GearPair(Gear(small), Gear(ring)); }).find("must be >= 0.0420646"), std::string::npos);
  // Mismatched modules and helical hands.
  EXPECT_NE(ErrorOf([] { GearPair(Gear(Spec(20, 2e-3, 20)), Gear(Spec(30, 3e-3, 20))); }).find("modules"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { GearPair(Gear(Helical(19, HelixHand::kRight)), Gear(Helical(41, HelixHand::kRight))); })
                .find("opposite hands"),
            std::string::npos);
  // A fillet in the active profile: a long-addendum wheel on a short-dedendum pinion.
  GearSpec p = Spec(20, 2e-3, 20), w = Spec(60, 2e-3, 20);
  p.dedendum_coef = 1.05;
  p.root_fillet_coef = 0.38;
  w.tip_radius_m = Gear(w).reference_radius_m() + 1.0e-3 * 2;
  EXPECT_NE(ErrorOf([&] { GearPair(Gear(p), Gear(w)); }).find("fillet"), std::string::npos);
}

// ---- Meshes --------------------------------------------------------------------------------

double ShoelaceArea(const std::vector<Vec2>& poly) {
  double a = 0;
  for (size_t i = 0; i < poly.size(); ++i) a += Cross(poly[i], poly[(i + 1) % poly.size()]);
  return 0.5 * a;
}

void CheckClosedGearMesh(const Gear& g, double rim, int n_face) {
  SCOPED_TRACE(testing::Message() << "z = " << g.teeth() << (g.internal() ? " internal" : ""));
  const ProfileResolution res{.root = 3, .fillet = 8, .involute = 12, .tip = 4};
  const TriangleMesh mesh = MakeGearMesh(g, res, n_face, rim);
  EXPECT_EQ(CountOpenOrInconsistentEdges(mesh), 0);
  // Euler characteristic of a solid with one hole (genus 1): V - E + F = 0.
  const long f = static_cast<long>(mesh.triangles.size()), e = 3 * f / 2;
  EXPECT_EQ(static_cast<long>(mesh.vertices.size()) - e + f, 0);
  // Area between the outline polygon and the rim polygon, times the face width.
  std::vector<Vec2> outline;
  for (const ProfilePoint& q : g.SampleGearOutline(res)) outline.push_back(q.p);
  const int m = std::max(3 * g.teeth(), static_cast<int>(outline.size()) / 3);
  std::vector<Vec2> circle;
  for (int j = 0; j < m; ++j) circle.push_back(rim * Vec2(std::cos(2 * kPi * j / m - kPi / g.teeth()),
                                                          std::sin(2 * kPi * j / m - kPi / g.teeth())));
  const double area = std::abs(ShoelaceArea(outline) - ShoelaceArea(circle));
  const double b = g.spec().face_width_m;
  const double volume = EnclosedVolume(mesh);
  // Helical twist: the side quads are not planar. Their two triangles come in pairs (a, b, c),
  // (a, c, d); the two diagonal splits of a quad differ by the volume of the tetrahedron abcd, and
  // the twisted (helicoidal) surface lies between them up to the sagitta r dphi^2 / 8 of the
  // rotated edges. Tolerance: the sum of both per quad.
  double tol = 1e-12 * area * b;
  const double dphi = std::abs(g.twist_per_length()) * b / n_face;
  if (dphi > 0) {
    for (size_t i = 0; i + 1 < mesh.triangles.size(); i += 2) {
      const auto& t1 = mesh.triangles[i];
      const auto& t2 = mesh.triangles[i + 1];
      const Vec3 &p0 = mesh.vertices[t1[0]], &p1 = mesh.vertices[t1[1]], &p2 = mesh.vertices[t1[2]];
      if (p0.z() == p1.z() && p1.z() == p2.z()) break;  // the end faces follow the side strips
      const int d = t2[0] == t1[0] && t2[1] == t1[2] ? t2[2] : t2[1];
      const Vec3& p3 = mesh.vertices[d];
      const double tet = std::abs((p1 - p0).dot((p2 - p0).cross(p3 - p0))) / 6;
      const double quad_area = 0.5 * ((p2 - p0).cross(p3 - p1)).norm();
      tol += tet + quad_area * p0.head<2>().norm() * dphi * dphi / 8;
    }
  }
  std::printf("z = %d: mesh volume error %.3e of %.3e, tolerance %.3e\n", g.teeth(), volume - area * b,
              area * b, tol);
  EXPECT_NEAR(volume, area * b, tol);
  EXPECT_LT(tol, 0.02 * area * b);
}

TEST(GearMesh, ClosedWatertightAndVolume) {
  CheckClosedGearMesh(Gear(Seed001(18)), 4e-3, 4);
  CheckClosedGearMesh(Gear(Seed001(70, true)), 0.060, 3);
  CheckClosedGearMesh(Gear(Helical(19, HelixHand::kRight)), 6e-3, 12);
  CheckClosedGearMesh(Gear(Helical(61, HelixHand::kLeft, true)), 0.070, 12);
}

TEST(GearMesh, FlankMeshFollowsTheHelix) {
  const Gear g(Helical(19, HelixHand::kRight));
  const int n_profile = 8, n_face = 6;
  const TriangleMesh flank = MakeFlankMesh(g, 2, true, n_profile, n_face);
  EXPECT_EQ(flank.vertices.size(), static_cast<size_t>((n_profile + 1) * (n_face + 1)));
  EXPECT_EQ(flank.triangles.size(), static_cast<size_t>(2 * n_profile * n_face));
  // Every vertex is the transverse profile point rotated by the tooth angle and the twist
  // z tan(beta) / r, i.e. on the involute helicoid; right hand: polar angle grows with z.
  const double b = g.spec().face_width_m;
  for (int k = 0; k <= n_face; ++k) {
    for (int j = 0; j <= n_profile; ++j) {
      const Vec3& v = flank.vertices[k * (n_profile + 1) + j];
      const double z = b * k / n_face;
      EXPECT_NEAR(v.z(), z, 1e-15);
      const Vec2 p0 = g.ProfileAt(4.0 + static_cast<double>(j) / n_profile).p;
      const double expected = PolarAngle(p0) + 2 * kPi * 2 / 19 + z * std::tan(15 * kDeg) / g.reference_radius_m();
      EXPECT_NEAR(std::remainder(PolarAngle(v.head<2>()) - expected, 2 * kPi), 0.0, 1e-12);
      EXPECT_NEAR(v.head<2>().norm(), p0.norm(), 1e-15);
    }
  }
  // Outward orientation: triangle normals agree with the profile normals.
  const Vec3& a = flank.vertices[flank.triangles[0][0]];
  const Vec3& bb = flank.vertices[flank.triangles[0][1]];
  const Vec3& c = flank.vertices[flank.triangles[0][2]];
  const Vec3 n = (bb - a).cross(c - a);
  const Vec2 n_prof = Eigen::Rotation2Dd(2 * kPi * 2 / 19) * g.ProfileAt(4.0 + 0.5 / n_profile).n;
  EXPECT_GT(n.head<2>().normalized().dot(n_prof), 0.9);
  // Open tooth strip of one tooth: 2 (points - 1) n_face triangles.
  const TriangleMesh tooth = MakeToothSurfaceMesh(g, 0, {}, 3);
  EXPECT_EQ(tooth.triangles.size(), 2 * (tooth.vertices.size() / 4 - 1) * 3);
}

// ---- STL -----------------------------------------------------------------------------------

TEST(Stl, BinaryAndAsciiRoundTrip) {
  const Gear g(Seed001(18));
  const TriangleMesh mesh = MakeGearMesh(g, {.root = 2, .fillet = 4, .involute = 6, .tip = 2}, 2, 4e-3);
  const auto dir = std::filesystem::temp_directory_path();
  const std::string bin = (dir / "orrery_gear_test.stl").string();
  const std::string asc = (dir / "orrery_gear_test_ascii.stl").string();
  WriteStlBinary(mesh, bin, {.scale = 1000.0});
  WriteStlAscii(mesh, asc, {.scale = 1.0, .solid_name = "planet"});

  // Binary: size 84 + 50 n, count, facets as float32 of the scaled vertices, unit normals.
  std::ifstream in(bin, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t n = mesh.triangles.size();
  ASSERT_EQ(bytes.size(), 84 + 50 * n);
  EXPECT_NE(bytes.compare(0, 5, "solid"), 0);  // a binary header must not look like ASCII
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(count, n);
  for (size_t i = 0; i < n; i += 97) {
    float f[12];
    std::memcpy(f, bytes.data() + 84 + 50 * i, 48);
    const Vec3 normal(f[0], f[1], f[2]);
    EXPECT_NEAR(normal.norm(), 1.0, 1e-6);
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(f[3 + 3 * v + c], static_cast<float>(mesh.vertices[mesh.triangles[i][v]][c] * 1000.0));
    const Vec3 e1 = mesh.vertices[mesh.triangles[i][1]] - mesh.vertices[mesh.triangles[i][0]];
    const Vec3 e2 = mesh.vertices[mesh.triangles[i][2]] - mesh.vertices[mesh.triangles[i][0]];
    EXPECT_GT(normal.dot(e1.cross(e2).normalized()), 1 - 1e-6);
  }
  // ASCII: one facet per triangle, named solid, vertices parse back to 9 significant digits.
  std::ifstream ain(asc);
  std::string line, first;
  std::getline(ain, first);
  EXPECT_EQ(first, "solid planet");
  size_t facets = 0, vertices = 0;
  std::string last;
  while (std::getline(ain, line)) {
    if (line.find("facet normal") != std::string::npos) ++facets;
    if (line.find("vertex") != std::string::npos) {
      if (vertices == 4) {  // second triangle, second vertex
        std::istringstream is(line);
        std::string word;
        double x, y, z;
        is >> word >> x >> y >> z;
        const Vec3& v = mesh.vertices[mesh.triangles[1][1]];
        EXPECT_NEAR(x, v.x(), 1e-9 * 0.02);
        EXPECT_NEAR(y, v.y(), 1e-9 * 0.02);
        EXPECT_NEAR(z, v.z(), 1e-9 * 0.02);
      }
      ++vertices;
    }
    last = line;
  }
  EXPECT_EQ(facets, n);
  EXPECT_EQ(vertices, 3 * n);
  EXPECT_EQ(last, "endsolid planet");
  std::filesystem::remove(bin);
  std::filesystem::remove(asc);
}

}  // namespace
}  // namespace orrery::gears

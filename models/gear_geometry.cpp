#include "models/gear_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

Vec2 Polar(double radius, double angle) { return {radius * std::cos(angle), radius * std::sin(angle)}; }

Vec2 Rotate(const Vec2& p, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

ProfilePoint Mirror(ProfilePoint q, ProfileSegment segment, double s) {
  q.p.y() = -q.p.y();
  q.n.y() = -q.n.y();
  q.segment = segment;
  q.s = s;
  return q;
}

double Deg(double rad) { return rad * 180.0 / kPi; }

[[noreturn]] void Fail(const std::string& what) { throw std::invalid_argument("gear geometry: " + what); }

template <typename... Args>
std::string Str(Args&&... args) {
  std::ostringstream os;
  os.precision(6);
  (os << ... << args);
  return os.str();
}

// Wraps an angle difference into (-pi, pi].
double WrapPi(double a) {
  while (a > kPi) a -= 2 * kPi;
  while (a <= -kPi) a += 2 * kPi;
  return a;
}

}  // namespace

double Involute(double alpha_rad) { return std::tan(alpha_rad) - alpha_rad; }

double InverseInvolute(double inv_alpha) {
  if (inv_alpha < 0) Fail(Str("inverse involute of a negative value ", inv_alpha));
  if (inv_alpha == 0) return 0;
  // Newton on tan(a) - a - y, started from the series inv(a) ~ a^3 / 3 (capped below pi/2).
  double a = std::min(std::cbrt(3 * inv_alpha), 1.4);
  for (int it = 0; it < 60; ++it) {
    const double t = std::tan(a);
    const double step = (t - a - inv_alpha) / (t * t);
    a -= step;
    if (a <= 0) a = 1e-8;
    if (std::abs(step) < 1e-16 * std::max(1.0, a)) break;
  }
  return a;
}

// ---- Gear ------------------------------------------------------------------------------------

Gear::Gear(const GearSpec& spec) : spec_(spec) {
  // Basic values.
  const int z = spec.teeth;
  const double mn = spec.normal_module_m, an = spec.normal_pressure_angle_rad;
  const double beta = spec.helix_angle_rad;
  if (z <= 0) Fail(Str("number of teeth z = ", z, " must be positive"));
  if (!(mn > 0)) Fail(Str("normal module m_n = ", mn, " m must be positive"));
  if (!(spec.face_width_m > 0)) Fail(Str("face width b = ", spec.face_width_m, " m must be positive"));
  if (!(an > 0 && an < kPi / 4)) Fail(Str("normal pressure angle ", Deg(an), " deg outside (0, 45)"));
  if (!(beta >= 0 && beta < kPi / 3)) Fail(Str("helix angle ", Deg(beta), " deg outside [0, 60)"));
  if (!(spec.addendum_coef >= 0 && spec.dedendum_coef > 0 && spec.root_fillet_coef >= 0))
    Fail(Str("rack coefficients h_aP* = ", spec.addendum_coef, ", h_fP* = ", spec.dedendum_coef,
             ", rho_fP* = ", spec.root_fillet_coef, " must be non-negative (h_fP* > 0)"));

  // Transverse quantities (ISO 21771).
  m_t_ = mn / std::cos(beta);
  alpha_t_ = std::atan(std::tan(an) / std::cos(beta));
  r_ = z * m_t_ / 2;
  r_b_ = r_ * std::cos(alpha_t_);
  beta_b_ = std::atan(std::tan(beta) * std::cos(alpha_t_));
  x_e_ = spec.profile_shift + spec.thickness_allowance_m / (2 * mn * std::tan(an));
  psi_ref_ = (kPi / 2 + 2 * x_e_ * std::tan(an)) / z;
  const double rho = spec.root_fillet_coef * mn;

  if (!spec.internal) {
    // Tip and root radii; the rack dedendum follows an explicit root radius.
    r_a_ = spec.tip_radius_m.value_or(r_ + (spec.addendum_coef + spec.profile_shift) * mn);
    r_f_ = spec.root_radius_m.value_or(r_ + (x_e_ - spec.dedendum_coef) * mn);
    const double hf_eff = (r_ + x_e_ * mn - r_f_) / mn;
    if (!(r_f_ > 0)) Fail(Str("root radius r_f = ", r_f_, " m is not positive"));
    if (!(hf_eff > 0)) Fail(Str("root radius r_f = ", r_f_, " m is above the rack datum line"));

    // Basic rack in the transverse section: datum at v = x_E m_n above the rolling line, tip at
    // v_t, tip fillet = ellipse (rho / cos(beta), rho) tangent to the tip line and the flank.
    rack_datum_v_ = x_e_ * mn;
    rack_tip_v_ = rack_datum_v_ - hf_eff * mn;
    const double u_c_n = kPi * mn / 4 - (hf_eff * mn - rho) * std::tan(an) - rho / std::cos(an);
    if (u_c_n < -1e-12 * mn)
      Fail(Str("rack tip radius rho_fP* = ", spec.root_fillet_coef, " too large: the fillets of the ",
               "rack tooth overlap (tip flat half-width ", u_c_n / mn, " m_n)"));
    rack_center_u_ = std::max(0.0, u_c_n) / std::cos(beta);
    rack_center_v_ = rack_tip_v_ + rho;
    rack_a_u_ = rho / std::cos(beta);
    rack_a_v_ = rho;
    rack_theta_max_ = kPi / 2 - an;

    // Undercut: the lowest point of the straight flank must not pass the interference point
    // (depth r sin^2(alpha_t) below the rolling line).
    const double depth_form = -(rack_tip_v_ + rho * (1 - std::sin(an)));
    const double depth_limit = r_ * std::sin(alpha_t_) * std::sin(alpha_t_);
    if (depth_form > depth_limit * (1 + 1e-12))
      Fail(Str("undercut: z = ", z, " < z_min = ", MinTeethWithoutUndercut(), " for x_E = ", x_e_,
               " (rack flank ends ", depth_form / mn, " m_n below the pitch line, limit ",
               depth_limit / mn, " m_n)"));
    const double lambda = depth_form / std::sin(alpha_t_);  // distance I -> form point on the LOA
    const double roll_form = std::max(0.0, r_ * std::sin(alpha_t_) - lambda);
    r_form_ = std::hypot(r_b_, roll_form);
    xi_form_ = roll_form / r_b_;
    root_half_angle_ = kPi / z - rack_center_u_ / r_;

    // Tip: above the form circle, not pointed.
    if (!(r_a_ > r_form_))
      Fail(Str("tip radius r_a = ", r_a_, " m is not above the form radius ", r_form_, " m"));
    xi_tip_ = std::sqrt(r_a_ * r_a_ - r_b_ * r_b_) / r_b_;
  } else {
    // Internal gear: tip towards the axis, root outside.
    r_a_ = spec.tip_radius_m.value_or(r_ - (spec.addendum_coef + spec.profile_shift) * mn);
    r_f_ = spec.root_radius_m.value_or(r_ + (spec.dedendum_coef - x_e_) * mn);
    if (!(r_a_ > r_b_))
      Fail(Str("internal gear tip radius r_a = ", r_a_, " m is inside the base circle r_b = ", r_b_,
               " m (no involute at the tip)"));
    if (!(r_f_ > r_a_)) Fail(Str("internal gear root radius r_f = ", r_f_, " m is not outside r_a"));

    // Circular fillet (approximation of the shaper trochoid): centre on the offset involute at
    // distance rho, on the circle r_f - rho.
    const double rc = r_f_ - rho;
    if (!(rc > r_b_)) Fail(Str("internal gear fillet radius ", rho, " m does not fit above the base circle"));
    const double psi_rb = psi_ref_ - Involute(alpha_t_);
    xi_form_ = (rho + std::sqrt(rc * rc - r_b_ * r_b_)) / r_b_;
    r_form_ = r_b_ * std::hypot(1.0, xi_form_);
    if (!(r_form_ > r_a_))
      Fail(Str("internal gear fillet reaches the tip: form radius ", r_form_, " m <= r_a = ", r_a_, " m"));
    const double tau = psi_rb + xi_form_;
    const Vec2 p_form = r_b_ * (Vec2(std::cos(tau), std::sin(tau)) + xi_form_ * Vec2(std::sin(tau), -std::cos(tau)));
    const Vec2 n_form(-std::sin(tau), std::cos(tau));
    fillet_center_ = p_form + rho * n_form;
    const double center_angle = std::atan2(fillet_center_.y(), fillet_center_.x());
    if (center_angle > kPi / z)
      Fail(Str("internal gear fillet radius rho_fP* = ", spec.root_fillet_coef,
               " too large: the fillets of one space overlap"));
    fillet_angle_start_ = std::atan2(-n_form.y(), -n_form.x());
    fillet_angle_end_ = fillet_angle_start_ + WrapPi(center_angle - fillet_angle_start_);
    root_half_angle_ = center_angle;
    xi_tip_ = std::sqrt(r_a_ * r_a_ - r_b_ * r_b_) / r_b_;
  }

  // Pointed tip.
  const double s_an = NormalTipThickness();
  if (!(s_an > spec.min_tip_thickness_coef * mn))
    Fail(Str("pointed tip: normal tip thickness s_an = ", s_an / mn, " m_n below the minimum ",
             spec.min_tip_thickness_coef, " m_n (r_a = ", r_a_, " m)"));
}

double Gear::twist_per_length() const {
  const double t = std::tan(spec_.helix_angle_rad) / r_;
  return spec_.hand == HelixHand::kRight ? t : -t;
}

double Gear::HalfToothAngle(double radius_m) const {
  const double alpha_r = std::acos(std::min(1.0, r_b_ / radius_m));
  const double d = Involute(alpha_t_) - Involute(alpha_r);
  return spec_.internal ? psi_ref_ - d : psi_ref_ + d;
}

double Gear::NormalTipThickness() const {
  const double beta_a = std::atan(std::tan(spec_.helix_angle_rad) * r_a_ / r_);
  return ToothThickness(r_a_) * std::cos(beta_a);
}

double Gear::SpanMeasurement(int k) const {
  if (spec_.internal) Fail("span measurement is defined here for external gears only");
  const double mn = spec_.normal_module_m, an = spec_.normal_pressure_angle_rad;
  return mn * std::cos(an) * (kPi * (k - 0.5) + spec_.teeth * Involute(alpha_t_)) +
         2 * x_e_ * mn * std::sin(an);
}

double Gear::MinTeethWithoutUndercut() const {
  const double mn = spec_.normal_module_m, an = spec_.normal_pressure_angle_rad;
  const double hf_eff = (r_ + x_e_ * mn - r_f_) / mn;
  const double h_lin = hf_eff - spec_.root_fillet_coef * (1 - std::sin(an));
  const double s = std::sin(alpha_t_);
  return 2 * (h_lin - x_e_) * std::cos(spec_.helix_angle_rad) / (s * s);
}

ProfilePoint Gear::Envelope(const Vec2& rack_point, const Vec2& rack_normal_out) const {
  // Equation of meshing: the rack normal passes through the pitch point I = (0, r).
  const double u = rack_point.x(), v = rack_point.y();
  const double phi = rack_normal_out.x() == 0.0
                         ? u / r_
                         : (u - v * rack_normal_out.x() / rack_normal_out.y()) / r_;
  // Rack point in the fixed frame, then in the gear frame (gear turned by phi, space on top).
  const Vec2 q(u - r_ * phi, r_ + v);
  ProfilePoint out;
  out.p = Rotate(q, -phi);
  out.n = Rotate(-rack_normal_out.normalized(), -phi);
  // Space centre from +y to +pi/z: the rack's right half generates the plus flank of tooth 0.
  const double frame = kPi / spec_.teeth - kPi / 2;
  out.p = Rotate(out.p, frame);
  out.n = Rotate(out.n, frame);
  return out;
}

ProfilePoint Gear::PlusInvolute(double t) const {
  // Uniform arc length: s = r_b xi^2 / 2.
  const double xi = std::sqrt(xi_tip_ * xi_tip_ + t * (xi_form_ * xi_form_ - xi_tip_ * xi_tip_));
  ProfilePoint out;
  if (!spec_.internal) {
    // Rack flank point whose contact lies at roll distance r_b xi from T on the line of action.
    const double lambda = r_ * std::sin(alpha_t_) - r_b_ * xi;
    const double v = -lambda * std::sin(alpha_t_);
    const double u = kPi * m_t_ / 4 - (rack_datum_v_ - v) * std::tan(alpha_t_);
    out = Envelope({u, v}, {std::cos(alpha_t_), -std::sin(alpha_t_)});
  } else {
    // Ring plus flank: polar angle psi_rb + inv(alpha_R), unwinding counter-clockwise.
    const double tau = psi_ref_ - Involute(alpha_t_) + xi;
    out.p = r_b_ * (Vec2(std::cos(tau), std::sin(tau)) + xi * Vec2(std::sin(tau), -std::cos(tau)));
    out.n = Vec2(-std::sin(tau), std::cos(tau));
  }
  out.segment = ProfileSegment::kInvolutePlus;
  out.s = 4 + t;
  return out;
}

ProfilePoint Gear::PlusFillet(double t) const {
  ProfilePoint out;
  if (!spec_.internal) {
    // Rack tip ellipse from the flank tangency (theta_max) down to the tip line (theta = 0).
    const double th = rack_theta_max_ * (1 - t);
    const Vec2 rp(rack_center_u_ + rack_a_u_ * std::sin(th), rack_center_v_ - rack_a_v_ * std::cos(th));
    Vec2 rn(rack_a_v_ * std::sin(th), -rack_a_u_ * std::cos(th));
    if (rn.norm() == 0.0) rn = Vec2(std::sin(th) * std::cos(spec_.helix_angle_rad), -std::cos(th));
    out = Envelope(rp, rn);
  } else {
    // Fillet circle: material outside, outward normal towards the centre.
    const double ang = fillet_angle_start_ + t * (fillet_angle_end_ - fillet_angle_start_);
    const double rho = spec_.root_fillet_coef * spec_.normal_module_m;
    const Vec2 d(std::cos(ang), std::sin(ang));
    out.p = fillet_center_ + rho * d;
    out.n = -d;
  }
  out.segment = ProfileSegment::kFilletPlus;
  out.s = 5 + t;
  return out;
}

ProfilePoint Gear::PlusRoot(double t) const {
  const double a0 = root_half_angle_, a1 = kPi / spec_.teeth;
  const double ang = a0 + t * (a1 - a0);
  ProfilePoint out;
  out.p = Polar(r_f_, ang);
  out.n = spec_.internal ? Vec2(-std::cos(ang), -std::sin(ang)) : Vec2(std::cos(ang), std::sin(ang));
  out.segment = ProfileSegment::kRootPlus;
  out.s = 6 + t;
  return out;
}

ProfilePoint Gear::TipArc(double t) const {
  const double psi_a = HalfToothAngle(r_a_);
  const double ang = -psi_a + 2 * t * psi_a;
  ProfilePoint out;
  out.p = Polar(r_a_, ang);
  out.n = spec_.internal ? Vec2(-std::cos(ang), -std::sin(ang)) : Vec2(std::cos(ang), std::sin(ang));
  out.segment = ProfileSegment::kTip;
  out.s = 3 + t;
  return out;
}

ProfilePoint Gear::ProfileAt(double s) const {
  const int seg = std::clamp(static_cast<int>(std::floor(s)), 0, kNumProfileSegments - 1);
  const double t = std::clamp(s - seg, 0.0, 1.0);
  switch (static_cast<ProfileSegment>(seg)) {
    case ProfileSegment::kRootMinus: return Mirror(PlusRoot(1 - t), ProfileSegment::kRootMinus, s);
    case ProfileSegment::kFilletMinus: return Mirror(PlusFillet(1 - t), ProfileSegment::kFilletMinus, s);
    case ProfileSegment::kInvoluteMinus: return Mirror(PlusInvolute(1 - t), ProfileSegment::kInvoluteMinus, s);
    case ProfileSegment::kTip: return TipArc(t);
    case ProfileSegment::kInvolutePlus: return PlusInvolute(t);
    case ProfileSegment::kFilletPlus: return PlusFillet(t);
    case ProfileSegment::kRootPlus: return PlusRoot(t);
  }
  return TipArc(t);
}

ProfilePoint Gear::InvolutePointAtRadius(double radius_m) const {
  // Invert the arc-length parametrization of PlusInvolute.
  const double xi = std::sqrt(std::max(0.0, radius_m * radius_m - r_b_ * r_b_)) / r_b_;
  const double den = xi_form_ * xi_form_ - xi_tip_ * xi_tip_;
  const double t = (xi * xi - xi_tip_ * xi_tip_) / den;
  return PlusInvolute(t);
}

std::vector<ProfilePoint> Gear::SampleToothOutline(const ProfileResolution& res) const {
  const int counts[kNumProfileSegments] = {res.root, res.fillet, res.involute, res.tip,
                                           res.involute, res.fillet, res.root};
  std::vector<ProfilePoint> pts;
  for (int seg = 0; seg < kNumProfileSegments; ++seg) {
    const int n = std::max(1, counts[seg]);
    // Zero-length segments (no rack tip flat, zero fillet radius) contribute no points.
    if ((ProfileAt(seg).p - ProfileAt(seg + 1.0).p).norm() < 1e-12 * r_) continue;
    const bool fillet = static_cast<ProfileSegment>(seg) == ProfileSegment::kFilletMinus ||
                        static_cast<ProfileSegment>(seg) == ProfileSegment::kFilletPlus;
    for (int j = 0; j < n; ++j) {
      const double s0 = seg + static_cast<double>(j) / n, s1 = seg + static_cast<double>(j + 1) / n;
      pts.push_back(ProfileAt(s0));
      if (fillet && res.fillet_max_sag_m > 0) RefineFillet(ProfileAt(s0), ProfileAt(s1), res.fillet_max_sag_m, 10, pts);
    }
  }
  return pts;
}

void Gear::RefineFillet(const ProfilePoint& a, const ProfilePoint& b, double max_sag_m, int depth,
                        std::vector<ProfilePoint>& out) const {
  // Deviation of the curve's middle from the chord a-b; halve while it exceeds the bound.
  const ProfilePoint m = ProfileAt(0.5 * (a.s + b.s));
  const Vec2 d = b.p - a.p;
  const double len = d.norm();
  const double sag = len > 0 ? std::abs(d.x() * (m.p - a.p).y() - d.y() * (m.p - a.p).x()) / len : 0.0;
  if (depth <= 0 || sag <= max_sag_m) return;
  RefineFillet(a, m, max_sag_m, depth - 1, out);
  out.push_back(m);
  RefineFillet(m, b, max_sag_m, depth - 1, out);
}

std::vector<ProfilePoint> Gear::SampleGearOutline(const ProfileResolution& res) const {
  const std::vector<ProfilePoint> tooth = SampleToothOutline(res);
  std::vector<ProfilePoint> pts;
  pts.reserve(tooth.size() * spec_.teeth);
  for (int i = 0; i < spec_.teeth; ++i) {
    const double ang = 2 * kPi * i / spec_.teeth;
    for (ProfilePoint q : tooth) {
      q.p = Rotate(q.p, ang);
      q.n = Rotate(q.n, ang);
      pts.push_back(q);
    }
  }
  return pts;
}

// ---- GearPair --------------------------------------------------------------------------------

GearPair::GearPair(const Gear& gear1, const Gear& gear2, std::optional<double> center_distance_m)
    : g1_(gear1), g2_(gear2) {
  const GearSpec& s1 = g1_.spec();
  const GearSpec& s2 = g2_.spec();
  const bool internal = s2.internal;
  // Compatibility of the two gears.
  if (s1.internal) Fail("gear pair: gear1 must be external (put the ring gear second)");
  if (std::abs(s1.normal_module_m - s2.normal_module_m) > 1e-12 * s1.normal_module_m)
    Fail(Str("gear pair: normal modules differ (", s1.normal_module_m, " vs ", s2.normal_module_m, " m)"));
  if (std::abs(s1.normal_pressure_angle_rad - s2.normal_pressure_angle_rad) > 1e-12)
    Fail("gear pair: normal pressure angles differ");
  if (std::abs(s1.helix_angle_rad - s2.helix_angle_rad) > 1e-12) Fail("gear pair: helix angles differ");
  if (s1.helix_angle_rad > 0 && (s1.hand == s2.hand) == !internal)
    Fail(internal ? "gear pair: an internal helical pair needs equal hands"
                  : "gear pair: an external helical pair needs opposite hands");
  if (internal && s2.teeth <= s1.teeth)
    Fail(Str("gear pair: ring teeth z2 = ", s2.teeth, " must exceed pinion teeth z1 = ", s1.teeth));

  const int z1 = s1.teeth, z2 = s2.teeth;
  const double tan_an = std::tan(s1.normal_pressure_angle_rad);
  const double alpha_t = g1_.transverse_pressure_angle_rad();
  const double rb1 = g1_.base_radius_m(), rb2 = g2_.base_radius_m();
  const double rb_sum = internal ? rb2 - rb1 : rb1 + rb2;
  // Zero-backlash distance from the nominal shifts, and the tight-mesh distance with allowances.
  auto distance_for = [&](double x1, double x2) {
    const double inv_w = internal ? Involute(alpha_t) - 2 * tan_an * (x1 + x2) / (z2 - z1)
                                  : Involute(alpha_t) + 2 * tan_an * (x1 + x2) / (z1 + z2);
    return rb_sum / std::cos(InverseInvolute(inv_w));
  };
  a0_ = distance_for(s1.profile_shift, s2.profile_shift);
  const double a_tight = distance_for(g1_.generating_shift(), g2_.generating_shift());
  a_ = center_distance_m.value_or(a0_);
  if (!(a_ > rb_sum)) Fail(Str("gear pair: center distance a = ", a_, " m is too small"));
  alpha_wt_ = std::acos(rb_sum / a_);
  r_w1_ = rb1 / std::cos(alpha_wt_);
  r_w2_ = rb2 / std::cos(alpha_wt_);

  // Backlash on the working pitch circles.
  j_wt_ = 2 * std::numbers::pi * r_w1_ / z1 - g1_.ToothThickness(r_w1_) - g2_.ToothThickness(r_w2_);
  if (j_wt_ < -1e-9 * s1.normal_module_m)
    Fail(Str("gear pair: center distance a = ", a_, " m is ", internal ? "above" : "below",
             " the tight-mesh distance ", a_tight, " m (negative backlash ", j_wt_, " m)"));

  // Contact path on the line of action.
  g_ = a_ * std::sin(alpha_wt_);
  r_b1_tan_ = rb1 * std::tan(alpha_wt_);
  const double ra1 = g1_.tip_radius_m(), ra2 = g2_.tip_radius_m();
  s_end_ = std::sqrt(ra1 * ra1 - rb1 * rb1);
  const double l2 = std::sqrt(ra2 * ra2 - rb2 * rb2);
  s_start_ = internal ? l2 - g_ : g_ - l2;
  if (s_start_ < 0)
    Fail(Str("gear pair: involute interference: the tip of gear 2 (r_a2 = ", ra2,
             " m) reaches past the interference point T1 of gear 1"));
  if (!internal && s_end_ > g_)
    Fail(Str("gear pair: involute interference: the tip of gear 1 (r_a1 = ", ra1,
             " m) reaches past the interference point T2 of gear 2"));
  // The fillets must stay outside the active profiles.
  const double sap1 = Gear1RadiusAt(s_start_);
  if (sap1 < g1_.form_radius_m() * (1 - 1e-12)) {
    // Tip radius of gear 2 that would put the start of contact on gear 1's form circle.
    const double roll_form1 = std::sqrt(std::pow(g1_.form_radius_m(), 2) - rb1 * rb1);
    const double ra2_limit = std::hypot(rb2, internal ? g_ + roll_form1 : g_ - roll_form1);
    Fail(Str("gear pair: the root fillet of gear 1 reaches the active involute: start of active ",
             "profile r = ", sap1, " m < form radius ", g1_.form_radius_m(), " m (gear 2 tip radius ",
             ra2, " m; it must be ", internal ? ">= " : "<= ", ra2_limit, " m)"));
  }
  const double ap2 = Gear2RadiusAt(s_end_);
  if (!internal && ap2 < g2_.form_radius_m() * (1 - 1e-12))
    Fail(Str("gear pair: the root fillet of gear 2 reaches the active involute: start of active ",
             "profile r = ", ap2, " m < form radius ", g2_.form_radius_m(), " m"));
  if (internal && ap2 > g2_.form_radius_m() * (1 + 1e-12))
    Fail(Str("gear pair: the root fillet of the internal gear reaches the active involute: ",
             "active profile up to r = ", ap2, " m > form radius ", g2_.form_radius_m(), " m"));

  // Trochoid interference of internal pairs (SDP/SI eq. 5-6 to 5-8).
  if (internal) {
    const double aa1 = std::acos(rb1 / ra1), aa2 = std::acos(rb2 / ra2);
    const double c1 = (ra2 * ra2 - ra1 * ra1 - a_ * a_) / (2 * a_ * ra1);
    const double c2 = (a_ * a_ + ra2 * ra2 - ra1 * ra1) / (2 * a_ * ra2);
    if (std::abs(c1) <= 1 && std::abs(c2) <= 1) {
      const double th1 = std::acos(c1) + Involute(aa1) - Involute(alpha_wt_);
      const double th2 = std::acos(c2);
      const double margin = th1 * z1 / z2 + Involute(alpha_wt_) - Involute(aa2) - th2;
      if (margin < 0)
        Fail(Str("gear pair: trochoid interference of the internal gear (z2 - z1 = ", z2 - z1,
                 " too small for these tips; margin ", margin, " rad)"));
    }
  }

  // Contact ratios.
  eps_alpha_ = (s_end_ - s_start_) / g1_.transverse_base_pitch_m();
  b_ = std::min(s1.face_width_m, s2.face_width_m);
  eps_beta_ = b_ * std::sin(s1.helix_angle_rad) / (std::numbers::pi * s1.normal_module_m);
  if (eps_alpha_ < 1)
    Fail(Str("gear pair: transverse contact ratio eps_alpha = ", eps_alpha_, " < 1"));
}

double GearPair::Gear1RadiusAt(double s_m) const { return std::hypot(g1_.base_radius_m(), s_m); }

double GearPair::Gear2RadiusAt(double s_m) const {
  return std::hypot(g2_.base_radius_m(), internal() ? g_ + s_m : g_ - s_m);
}

double GearPair::normal_backlash_m() const {
  return j_wt_ * std::cos(alpha_wt_) * std::cos(g1_.base_helix_angle_rad());
}

// ---- Meshes ------------------------------------------------------------------------------------

namespace {

// Appends a ruled strip: `profile` (open polyline, counter-clockwise) swept over n_face slices,
// each rotated by base_angle + twist z. Returns the index of the first vertex.
int AppendStrip(TriangleMesh& mesh, const std::vector<Vec2>& profile, bool closed, double base_angle,
                double twist, double width, int n_face, bool material_inside) {
  const int first = static_cast<int>(mesh.vertices.size());
  const int n = static_cast<int>(profile.size());
  for (int k = 0; k <= n_face; ++k) {
    const double z = width * k / n_face;
    const double ang = base_angle + twist * z;
    for (const Vec2& p : profile) {
      const Vec2 q = Rotate(p, ang);
      mesh.vertices.emplace_back(q.x(), q.y(), z);
    }
  }
  const int segments = closed ? n : n - 1;
  for (int k = 0; k < n_face; ++k) {
    for (int i = 0; i < segments; ++i) {
      const int a = first + k * n + i, b = first + k * n + (i + 1) % n;
      const int c = b + n, d = a + n;
      // Outward normal (tangent x z) when the material is inside the counter-clockwise curve.
      if (material_inside) {
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
      } else {
        mesh.triangles.push_back({a, c, b});
        mesh.triangles.push_back({a, d, c});
      }
    }
  }
  return first;
}

// Triangulates the annulus between an outer and an inner closed loop whose polar angles both
// increase from angle0 over one turn; `top` gives normal +z, otherwise -z.
void ZipAnnulus(TriangleMesh& mesh, int outer_first, const std::vector<double>& outer_angles,
                int inner_first, const std::vector<double>& inner_angles, double angle0, bool top) {
  const int no = static_cast<int>(outer_angles.size()), ni = static_cast<int>(inner_angles.size());
  auto angle = [&](const std::vector<double>& a, int i) {
    return i < static_cast<int>(a.size()) ? a[i] : angle0 + 2 * kPi;
  };
  auto add = [&](int p, int q, int r) {
    if (top) mesh.triangles.push_back({p, q, r});
    else mesh.triangles.push_back({p, r, q});
  };
  int i = 0, j = 0;
  while (i < no || j < ni) {
    const bool advance_outer = j == ni || (i < no && angle(outer_angles, i + 1) <= angle(inner_angles, j + 1));
    if (advance_outer) {
      add(outer_first + i, outer_first + (i + 1) % no, inner_first + j % ni);
      ++i;
    } else {
      add(inner_first + j, outer_first + i % no, inner_first + (j + 1) % ni);
      ++j;
    }
  }
}

}  // namespace

TriangleMesh MakeFlankMesh(const Gear& gear, int tooth, bool plus_flank, int n_profile, int n_face) {
  if (n_profile < 1 || n_face < 1) Fail("flank mesh needs n_profile >= 1 and n_face >= 1");
  const double seg = plus_flank ? 4.0 : 2.0;
  std::vector<Vec2> profile;
  for (int j = 0; j <= n_profile; ++j) profile.push_back(gear.ProfileAt(seg + static_cast<double>(j) / n_profile).p);
  TriangleMesh mesh;
  AppendStrip(mesh, profile, false, 2 * kPi * tooth / gear.teeth(), gear.twist_per_length(),
              gear.spec().face_width_m, n_face, !gear.internal());
  return mesh;
}

TriangleMesh MakeToothSurfaceMesh(const Gear& gear, int tooth, const ProfileResolution& res, int n_face) {
  if (n_face < 1) Fail("tooth mesh needs n_face >= 1");
  std::vector<Vec2> profile;
  for (const ProfilePoint& q : gear.SampleToothOutline(res)) profile.push_back(q.p);
  profile.push_back(gear.ProfileAt(7.0).p);
  TriangleMesh mesh;
  AppendStrip(mesh, profile, false, 2 * kPi * tooth / gear.teeth(), gear.twist_per_length(),
              gear.spec().face_width_m, n_face, !gear.internal());
  return mesh;
}

TriangleMesh MakeGearMesh(const Gear& gear, const ProfileResolution& res, int n_face, double rim_radius_m) {
  if (n_face < 1) Fail("gear mesh needs n_face >= 1");
  const bool internal = gear.internal();
  if (!internal && !(rim_radius_m > 0 && rim_radius_m < gear.root_radius_m()))
    Fail(Str("bore radius ", rim_radius_m, " m must lie in (0, r_f = ", gear.root_radius_m(), " m)"));
  if (internal && !(rim_radius_m > gear.root_radius_m()))
    Fail(Str("rim radius ", rim_radius_m, " m must exceed the internal root radius ", gear.root_radius_m(), " m"));

  // Outline with unwrapped polar angles (must increase: the outline is star-shaped).
  const double angle0 = -kPi / gear.teeth();
  std::vector<Vec2> outline;
  std::vector<double> outline_angles;
  for (const ProfilePoint& q : gear.SampleGearOutline(res)) {
    double a = std::atan2(q.p.y(), q.p.x());
    const double prev = outline_angles.empty() ? angle0 : outline_angles.back();
    while (a < prev - kPi) a += 2 * kPi;
    while (a > prev + kPi) a -= 2 * kPi;
    if (!outline_angles.empty() && !(a > prev))
      throw std::logic_error("gear mesh: outline polar angle not increasing (not star-shaped)");
    outline.push_back(q.p);
    outline_angles.push_back(a);
  }
  // Circle with about the same spacing as the outline's points near the root.
  const int m = std::max(3 * gear.teeth(), static_cast<int>(outline.size()) / 3);
  std::vector<Vec2> circle;
  std::vector<double> circle_angles;
  for (int j = 0; j < m; ++j) {
    const double a = angle0 + 2 * kPi * j / m;
    circle.push_back(Polar(rim_radius_m, a));
    circle_angles.push_back(a);
  }

  // Side surfaces, then the two end faces.
  TriangleMesh mesh;
  const double twist = gear.twist_per_length(), b = gear.spec().face_width_m;
  const int o = AppendStrip(mesh, outline, true, 0.0, twist, b, n_face, !internal);
  const int c = AppendStrip(mesh, circle, true, 0.0, twist, b, n_face, internal);
  const int no = static_cast<int>(outline.size()), nc = m;
  const int o_top = o + n_face * no, c_top = c + n_face * nc;
  if (!internal) {
    ZipAnnulus(mesh, o, outline_angles, c, circle_angles, angle0, false);
    ZipAnnulus(mesh, o_top, outline_angles, c_top, circle_angles, angle0, true);
  } else {
    ZipAnnulus(mesh, c, circle_angles, o, outline_angles, angle0, false);
    ZipAnnulus(mesh, c_top, circle_angles, o_top, outline_angles, angle0, true);
  }
  return mesh;
}

}  // namespace orrery::gears

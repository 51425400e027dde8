#include "models/mesh_stiffness.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

namespace orrery::gears {
namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void Fail(const std::string& what) { throw std::invalid_argument("mesh stiffness: " + what); }

// 8-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 8> kGlNodes = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                            -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                            0.7966664774136267,  0.9602898564975363};
constexpr std::array<double, 8> kGlWeights = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                              0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                              0.2223810344533745, 0.1012285362903763};

// One quadrature node of the tooth: centre-line coordinate, half thickness, weight (dx).
struct Section {
  double x, h, w;
};

// Composite Gauss-Legendre over [a, b] of a parametrized section map.
template <typename F>
void AppendSections(double a, double b, int intervals, F&& section_at, std::vector<Section>& out) {
  if (!(b > a)) return;
  const double step = (b - a) / intervals;
  for (int k = 0; k < intervals; ++k) {
    const double mid = a + (k + 0.5) * step;
    for (size_t q = 0; q < kGlNodes.size(); ++q) {
      Section s = section_at(mid + 0.5 * step * kGlNodes[q]);
      s.w *= 0.5 * step * kGlWeights[q];
      out.push_back(s);
    }
  }
}

// Beam integrals (header) over the sections.
BeamCompliance Integrate(const std::vector<Section>& sections, double x_c, double h_c, double alpha1,
                         double width, const GearMaterial& mat, double h_q) {
  const double e = mat.youngs_modulus_pa, g = e / (2 * (1 + mat.poisson_ratio));
  const double c = std::cos(alpha1), s = std::sin(alpha1);
  BeamCompliance out;
  for (const Section& sec : sections) {
    // Thickness 2h, or h + min(h, h_q) on a cracked tooth (Chen & Shao 2011).
    const double t = sec.h + (h_q > 0 ? std::min(sec.h, h_q) : sec.h);
    const double area = t * width, inertia = t * t * t * width / 12;
    const double arm = (x_c - sec.x) * c - h_c * s;
    out.bending += sec.w * arm * arm / (e * inertia);
    out.shear += sec.w * 1.2 * c * c / (g * area);
    out.axial += sec.w * s * s / (e * area);
  }
  return out;
}

// Sainsot, Velex & Duverger (2004) Table 1: rows L*, M*, P*, Q*; columns A..F.
constexpr double kSainsot[4][6] = {{-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045},
                                   {60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086},
                                   {-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236},
                                   {-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904}};

// Missing-height break radius of a tooth (contact above it is lost).
double BreakRadius(const Gear& g, double fraction) {
  const double ra = g.tip_radius_m(), rf = g.root_radius_m();
  return ra + fraction * (rf - ra);
}

}  // namespace

// ---- ISO 6336-1 method B ------------------------------------------------------------------

Iso6336Stiffness CalcIso6336Stiffness(const GearPair& pair, const Iso6336Options& options) {
  constexpr double c1 = 0.04723, c2 = 0.15551, c3 = 0.25791, c4 = -0.00635, c5 = -0.11654,
                   c6 = -0.00193, c7 = -0.24188, c8 = 0.00529, c9 = 0.00182;
  const bool internal = pair.internal();
  const bool swap = !internal && pair.gear1().teeth() > pair.gear2().teeth();
  const GearSpec& pinion = swap ? pair.gear2().spec() : pair.gear1().spec();
  const GearSpec& wheel = swap ? pair.gear1().spec() : pair.gear2().spec();
  const double beta = pinion.helix_angle_rad, beta_b = pair.gear1().base_helix_angle_rad();
  // Virtual tooth numbers.
  Iso6336Stiffness out;
  const double zn_factor = std::cos(beta_b) * std::cos(beta_b) * std::cos(beta);
  out.z_n1 = pinion.teeth / zn_factor;
  out.z_n2 = internal ? std::numeric_limits<double>::infinity() : wheel.teeth / zn_factor;
  // q' with z_n2 -> infinity for internal gears (the 1/z_n2 terms vanish).
  const double x1 = pinion.profile_shift, x2 = wheel.profile_shift;
  const double inv_zn2 = internal ? 0.0 : 1.0 / out.z_n2;
  out.q_prime = c1 + c2 / out.z_n1 + c3 * inv_zn2 + c4 * x1 + c5 * x1 / out.z_n1 + c6 * x2 +
                c7 * x2 * inv_zn2 + c8 * x1 * x1 + c9 * x2 * x2;
  out.c_th = 1 / out.q_prime;
  // Basic-rack factor, mean of both racks.
  const double an_deg = pinion.normal_pressure_angle_rad * 180 / kPi;
  auto cb = [&](const GearSpec& s) { return (1 + 0.5 * (1.2 - s.dedendum_coef)) * (1 - 0.02 * (20 - an_deg)); };
  out.c_b = 0.5 * (cb(pinion) + cb(wheel));
  out.c_single = out.c_th * options.c_m * options.c_r * out.c_b * std::cos(beta);
  out.c_gamma_alpha = out.c_single * (0.75 * pair.transverse_contact_ratio() + 0.25);
  out.c_gamma_beta = 0.85 * out.c_gamma_alpha;
  // N/(mm um) = 1e9 N/m^2, times the face width.
  const double to_si = 1e9 * pair.face_width_m();
  out.c_single_n_per_m = out.c_single * to_si;
  out.c_gamma_alpha_n_per_m = out.c_gamma_alpha * to_si;
  out.c_gamma_beta_n_per_m = out.c_gamma_beta * to_si;
  return out;
}

// ---- Potential-energy building blocks ---------------------------------------------------

double HertzStiffness(double width_m, const GearMaterial& m1, const GearMaterial& m2) {
  const double compliance = 2 / (kPi * width_m) *
                            ((1 - m1.poisson_ratio * m1.poisson_ratio) / m1.youngs_modulus_pa +
                             (1 - m2.poisson_ratio * m2.poisson_ratio) / m2.youngs_modulus_pa);
  return 1 / compliance;
}

BeamCompliance CalcBeamCompliance(const std::function<double(double)>& half_thickness, double x_root,
                                  double x_c, double h_c, double alpha1, double width_m,
                                  const GearMaterial& material, int intervals, double cracked_half_thickness) {
  std::vector<Section> sections;
  AppendSections(x_root, x_c, intervals, [&](double x) { return Section{x, half_thickness(x), 1.0}; }, sections);
  return Integrate(sections, x_c, h_c, alpha1, width_m, material, cracked_half_thickness);
}

ToothCompliance CalcToothCompliance(const Gear& gear, double contact_radius_m, double width_m,
                                    const GearMaterial& material, double rim_radius_m, const ToothFault* crack,
                                    int intervals) {
  const bool internal = gear.internal();
  const double rb = gear.base_radius_m(), rf = gear.root_radius_m();
  // Contact point and load direction (plus flank of tooth 0, centre line on +x). The beam
  // coordinate x runs from the root to the tip: x = X (external), x = -X (internal).
  const ProfilePoint c = gear.InvolutePointAtRadius(contact_radius_m);
  const double sign = internal ? -1.0 : 1.0;
  const double sin_a1 = sign * c.n.x(), cos_a1 = c.n.y();
  const double alpha1 = std::atan2(sin_a1, cos_a1);
  const double x_c = sign * c.p.x(), h_c = c.p.y();

  // Sections along the tooth: involute in the roll parameter xi (r = r_b sqrt(1 + xi^2)).
  auto involute_section = [&](double xi) {
    const double q = std::sqrt(1 + xi * xi), r = rb * q, psi = gear.HalfToothAngle(r);
    const double dr = rb * xi / q;  // dr/dxi
    // d(r cos psi)/dr = cos psi -+ sin psi tan(alpha_r), tan(alpha_r) = xi.
    const double dx = internal ? (std::cos(psi) - std::sin(psi) * xi) : (std::cos(psi) + std::sin(psi) * xi);
    return Section{sign * r * std::cos(psi), r * std::sin(psi), dx * dr};
  };
  const double xi_c = std::sqrt(std::max(0.0, contact_radius_m * contact_radius_m - rb * rb)) / rb;
  std::vector<Section> sections;
  if (!internal) {
    if (rf < rb) {
      // Straight extension from the root circle to the base circle, half thickness h_b.
      const double psi_b = gear.HalfToothAngle(rb), h_b = rb * std::sin(psi_b);
      const double x_f = std::sqrt(rf * rf - h_b * h_b), x_b = rb * std::cos(psi_b);
      AppendSections(x_f, x_b, std::max(1, intervals / 4), [&](double x) { return Section{x, h_b, 1.0}; }, sections);
      AppendSections(0.0, xi_c, intervals, involute_section, sections);
    } else {
      AppendSections(std::sqrt(rf * rf - rb * rb) / rb, xi_c, intervals, involute_section, sections);
    }
  } else {
    AppendSections(xi_c, std::sqrt(rf * rf - rb * rb) / rb, intervals, involute_section, sections);
  }

  // Root crack: cracked side limited to h_q = h_ref - q sin(nu).
  double h_q = 0;
  if (crack != nullptr && crack->kind == ToothFault::Kind::kRootCrack) {
    double h_ref = 0;
    for (const Section& s : sections) h_ref = std::max(h_ref, s.h);
    h_q = h_ref - crack->crack_depth_m * std::sin(crack->crack_angle_rad);
    if (!(h_q > 0)) Fail("root crack reaches past the tooth centre line (q sin(nu) >= h)");
  }
  const BeamCompliance beam = Integrate(sections, x_c, h_c, alpha1, width_m, material, h_q);
  ToothCompliance out{beam.bending, beam.shear, beam.axial, 0.0};

  // Fillet foundation (Sainsot et al. 2004).
  if (rim_radius_m > 0) {
    const double theta_f = gear.root_half_angle_rad(), s_f = 2 * rf * theta_f;
    const double h_f = internal ? rim_radius_m / rf : rf / rim_radius_m;
    double x[4];
    for (int i = 0; i < 4; ++i) {
      const double* k = kSainsot[i];
      x[i] = k[0] / (theta_f * theta_f) + k[1] * h_f * h_f + k[2] * h_f / theta_f + k[3] / theta_f +
             k[4] * h_f + k[5];
    }
    // Load line meets the centre line (y = 0) at X_int; u_f from the root circle.
    const double x_int = c.p.x() - c.p.y() / c.n.y() * c.n.x();
    const double u_f = internal ? rf - x_int : x_int - rf;
    const double ratio = u_f / s_f, t = std::tan(alpha1);
    out.foundation = cos_a1 * cos_a1 / (material.youngs_modulus_pa * width_m) *
                     (x[0] * ratio * ratio + x[1] * ratio + x[2] * (1 + x[3] * t * t));
  }
  return out;
}

// ---- TVMS ---------------------------------------------------------------------------------

Tvms CalcTvms(const GearPair& pair, const TvmsOptions& options) {
  const Gear& g1 = pair.gear1();
  const Gear& g2 = pair.gear2();
  const int z1 = g1.teeth(), z2 = g2.teeth();
  // Validate.
  if (options.samples_per_period < 1) Fail("samples_per_period must be >= 1");
  if (options.fillet_foundation && !(options.bore_radius1_m > 0 && options.rim_radius2_m > 0))
    Fail("fillet foundation needs bore_radius1_m and rim_radius2_m > 0");
  bool fault1 = false, fault2 = false;
  for (const ToothFault& f : options.faults) {
    if (f.gear != 1 && f.gear != 2) Fail("fault gear must be 1 or 2, got " + std::to_string(f.gear));
    const int z = f.gear == 1 ? z1 : z2;
    if (f.tooth < 0 || f.tooth >= z) Fail("fault tooth " + std::to_string(f.tooth) + " out of range");
    if (f.kind != ToothFault::Kind::kRootCrack && !(f.fraction >= 0 && f.fraction <= 1))
      Fail("broken-tooth fraction " + std::to_string(f.fraction) + " outside [0, 1]");
    if (f.kind == ToothFault::Kind::kRootCrack && f.crack_depth_m < 0)
      Fail("crack depth " + std::to_string(f.crack_depth_m) + " m is negative");
    (f.gear == 1 ? fault1 : fault2) = true;
  }
  int periods = options.periods;
  if (periods <= 0) periods = fault1 && fault2 ? std::lcm(z1, z2) : fault1 ? z1 : fault2 ? z2 : 1;

  // Contact path and slicing.
  const double pb = pair.transverse_base_pitch_m(), s0 = pair.contact_start_m(), s1 = pair.contact_end_m();
  const double b = pair.face_width_m();
  const bool helical = g1.spec().helix_angle_rad > 0;
  const int slices = options.face_slices > 0 ? options.face_slices : helical ? 40 : 1;
  const double dz = b / slices, tan_bb = std::tan(g1.base_helix_angle_rad());
  const double rim1 = options.fillet_foundation ? options.bore_radius1_m : 0.0;
  const double rim2 = options.fillet_foundation ? options.rim_radius2_m : 0.0;
  const double hertz_compliance = 1 / HertzStiffness(1.0, options.material1, options.material2);

  // Fault lookup per (gear, tooth).
  auto find_fault = [&](int gear, int tooth, ToothFault::Kind kind) -> const ToothFault* {
    for (const ToothFault& f : options.faults)
      if (f.gear == gear && f.tooth == tooth && f.kind == kind) return &f;
    return nullptr;
  };
  // Stiffness per unit width (N/m per m) of the pair (t1, t2) touching at s; 0 if a broken tooth
  // lost this contact.
  auto pair_stiffness = [&](double s, int t1, int t2) {
    const double r1 = pair.Gear1RadiusAt(s), r2 = pair.Gear2RadiusAt(s);
    if (const ToothFault* f = find_fault(1, t1, ToothFault::Kind::kBrokenHeight); f && r1 > BreakRadius(g1, f->fraction))
      return 0.0;
    if (const ToothFault* f = find_fault(2, t2, ToothFault::Kind::kBrokenHeight)) {
      const double rbreak = BreakRadius(g2, f->fraction);
      if (g2.internal() ? r2 < rbreak : r2 > rbreak) return 0.0;
    }
    const ToothCompliance c1 = CalcToothCompliance(g1, r1, 1.0, options.material1, rim1,
                                                   find_fault(1, t1, ToothFault::Kind::kRootCrack),
                                                   options.quadrature_intervals);
    const ToothCompliance c2 = CalcToothCompliance(g2, r2, 1.0, options.material2, rim2,
                                                   find_fault(2, t2, ToothFault::Kind::kRootCrack),
                                                   options.quadrature_intervals);
    return 1 / (hertz_compliance + c1.total() + c2.total());
  };
  // Remaining width fraction of slice [za, zb] for a tooth with a missing width fraction.
  auto width_left = [&](int gear, int tooth, double za, double zb) {
    const ToothFault* f = find_fault(gear, tooth, ToothFault::Kind::kBrokenWidth);
    if (f == nullptr) return 1.0;
    const double cut = f->fraction * b;
    return std::clamp((zb - std::max(za, cut)) / (zb - za), 0.0, 1.0);
  };
  auto mod = [](int e, int z) { return ((e % z) + z) % z; };

  // Sample the mesh cycle(s).
  Tvms out;
  out.mesh_period_rad = 2 * kPi / z1;
  const int n = periods * options.samples_per_period;
  for (int i = 0; i < n; ++i) {
    // Mesh phase in base pitches, split into whole periods and the fraction so that samples one
    // period apart see bit-identical contact positions.
    const int whole = i / options.samples_per_period;
    const double frac = static_cast<double>(i % options.samples_per_period) / options.samples_per_period;
    const double theta = out.mesh_period_rad * (whole + frac);
    std::map<int, ToothPairContact> touching;
    double k_total = 0;
    for (int j = 0; j < slices; ++j) {
      const double za = j * dz, zb = za + dz, phase = frac + (za + 0.5 * dz) * tan_bb / pb;
      // Pairs e = whole + e' with s = s0 + (phase - e') pb in [s0, s1).
      const int e_hi = static_cast<int>(std::floor(phase));
      const int e_lo = static_cast<int>(std::ceil(phase - (s1 - s0) / pb));
      for (int ep = e_lo; ep <= e_hi; ++ep) {
        const double s = s0 + (phase - ep) * pb;
        if (s < s0 || s >= s1) continue;
        const int e = whole + ep;
        const int t1 = mod(e, z1), t2 = mod(e, z2);
        const double w = dz * std::min(width_left(1, t1, za, zb), width_left(2, t2, za, zb));
        const double k = w > 0 ? pair_stiffness(s, t1, t2) * w : 0.0;
        if (k <= 0) continue;
        ToothPairContact& c = touching[e];
        c.tooth1 = t1;
        c.tooth2 = t2;
        c.position_m = s0 + (frac + 0.5 * b * tan_bb / pb - ep) * pb;
        c.stiffness_n_per_m += k;
        k_total += k;
      }
    }
    out.theta1_rad.push_back(theta);
    out.stiffness_n_per_m.push_back(k_total);
    out.pairs_in_contact.push_back(static_cast<int>(touching.size()));
    std::vector<ToothPairContact> list;
    for (const auto& [e, c] : touching) list.push_back(c);
    out.contacts.push_back(std::move(list));
  }
  // Statistics.
  const auto& k = out.stiffness_n_per_m;
  out.mean_n_per_m = std::accumulate(k.begin(), k.end(), 0.0) / k.size();
  out.min_n_per_m = *std::min_element(k.begin(), k.end());
  out.max_n_per_m = *std::max_element(k.begin(), k.end());
  return out;
}

}  // namespace orrery::gears

#include "models/mesh_stiffness.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

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

namespace {

// The tooth beam of one gear loaded at one contact radius: quadrature sections from the root to
// the contact point, the load point (x_c, h_c) and angle alpha1, and the contact point itself.
struct ToothBeam {
  std::vector<Section> sections;
  double x_c = 0, h_c = 0, alpha1 = 0, cos_a1 = 0;
  ProfilePoint contact;
};

ToothBeam MakeToothBeam(const Gear& gear, double contact_radius_m, int intervals) {
  const bool internal = gear.internal();
  const double rb = gear.base_radius_m(), rf = gear.root_radius_m();
  // Contact point and load direction (plus flank of tooth 0, centre line on +x). The beam
  // coordinate x runs from the root to the tip: x = X (external), x = -X (internal).
  ToothBeam beam;
  beam.contact = gear.InvolutePointAtRadius(contact_radius_m);
  const ProfilePoint& c = beam.contact;
  const double sign = internal ? -1.0 : 1.0;
  const double sin_a1 = sign * c.n.x();
  beam.cos_a1 = c.n.y();
  beam.alpha1 = std::atan2(sin_a1, beam.cos_a1);
  beam.x_c = sign * c.p.x();
  beam.h_c = c.p.y();
  // Sections along the tooth: involute in the roll parameter xi (r = r_b sqrt(1 + xi^2)).
  auto involute_section = [&](double xi) {
    const double q = std::sqrt(1 + xi * xi), r = rb * q, psi = gear.HalfToothAngle(r);
    const double dr = rb * xi / q;  // dr/dxi
    // d(r cos psi)/dr = cos psi -+ sin psi tan(alpha_r), tan(alpha_r) = xi.
    const double dx = internal ? (std::cos(psi) - std::sin(psi) * xi) : (std::cos(psi) + std::sin(psi) * xi);
    return Section{sign * r * std::cos(psi), r * std::sin(psi), dx * dr};
  };
  const double xi_c = std::sqrt(std::max(0.0, contact_radius_m * contact_radius_m - rb * rb)) / rb;
  if (!internal) {
    if (rf < rb) {
      // Straight extension from the root circle to the base circle, half thickness h_b.
      const double psi_b = gear.HalfToothAngle(rb), h_b = rb * std::sin(psi_b);
      const double x_f = std::sqrt(rf * rf - h_b * h_b), x_b = rb * std::cos(psi_b);
      AppendSections(x_f, x_b, std::max(1, intervals / 4), [&](double x) { return Section{x, h_b, 1.0}; },
                     beam.sections);
      AppendSections(0.0, xi_c, intervals, involute_section, beam.sections);
    } else {
      AppendSections(std::sqrt(rf * rf - rb * rb) / rb, xi_c, intervals, involute_section, beam.sections);
    }
  } else {
    AppendSections(xi_c, std::sqrt(rf * rf - rb * rb) / rb, intervals, involute_section, beam.sections);
  }
  return beam;
}

// Fillet foundation compliance (Sainsot et al. 2004) of the beam's load; 0 when rim_radius_m <= 0.
double FoundationCompliance(const Gear& gear, const ToothBeam& beam, double width_m, const GearMaterial& material,
                            double rim_radius_m) {
  if (!(rim_radius_m > 0)) return 0;
  const bool internal = gear.internal();
  const double rf = gear.root_radius_m();
  const double theta_f = gear.root_half_angle_rad(), s_f = 2 * rf * theta_f;
  const double h_f = internal ? rim_radius_m / rf : rf / rim_radius_m;
  double x[4];
  for (int i = 0; i < 4; ++i) {
    const double* k = kSainsot[i];
    x[i] = k[0] / (theta_f * theta_f) + k[1] * h_f * h_f + k[2] * h_f / theta_f + k[3] / theta_f + k[4] * h_f + k[5];
  }
  // Load line meets the centre line (y = 0) at X_int; u_f from the root circle.
  const ProfilePoint& c = beam.contact;
  const double x_int = c.p.x() - c.p.y() / c.n.y() * c.n.x();
  const double u_f = internal ? rf - x_int : x_int - rf;
  const double ratio = u_f / s_f, t = std::tan(beam.alpha1);
  return beam.cos_a1 * beam.cos_a1 / (material.youngs_modulus_pa * width_m) *
         (x[0] * ratio * ratio + x[1] * ratio + x[2] * (1 + x[3] * t * t));
}

// Cracked side half thickness h_q = h_root - q sin(nu) (0: no crack).
double CrackedHalfThickness(const Gear& gear, double crack_depth_m, double crack_angle_rad) {
  if (!(crack_depth_m > 0)) return 0;
  const double h_q = BeamRootHalfThickness(gear) - crack_depth_m * std::sin(crack_angle_rad);
  if (!(h_q > 0)) Fail("root crack reaches past the tooth centre line (q sin(nu) >= h)");
  return h_q;
}

}  // namespace

ToothCompliance CalcToothCompliance(const Gear& gear, double contact_radius_m, double width_m,
                                    const GearMaterial& material, double rim_radius_m, double crack_depth_m,
                                    double crack_angle_rad, int intervals) {
  const ToothBeam beam = MakeToothBeam(gear, contact_radius_m, intervals);
  const double h_q = CrackedHalfThickness(gear, crack_depth_m, crack_angle_rad);
  const BeamCompliance b = Integrate(beam.sections, beam.x_c, beam.h_c, beam.alpha1, width_m, material, h_q);
  return {b.bending, b.shear, b.axial, FoundationCompliance(gear, beam, width_m, material, rim_radius_m)};
}

// ---- TVMS ---------------------------------------------------------------------------------

TvmsFault::TvmsFault(const ToothFault& legacy) : gear(legacy.gear), on_loaded_flank(true) {
  fault.tooth = legacy.tooth;
  switch (legacy.kind) {
    case ToothFault::Kind::kRootCrack:
      fault.kind = ToothFaultSpec::Kind::kRootCrack;
      fault.crack_depth_m = legacy.crack_depth_m;
      fault.crack_angle_rad = legacy.crack_angle_rad;
      break;
    case ToothFault::Kind::kBrokenHeight:
      fault.kind = ToothFaultSpec::Kind::kBrokenTooth;
      fault.height_fraction = legacy.fraction;
      break;
    case ToothFault::Kind::kBrokenWidth:
      fault.kind = ToothFaultSpec::Kind::kBrokenTooth;
      fault.face_fraction = legacy.fraction;
      break;
  }
}

namespace {

// The faults of one tooth (mesh order) that act in this TVMS.
struct ToothFaults {
  const ToothFaultSpec* broken = nullptr;
  const ToothFaultSpec* crack = nullptr;  // on the loaded flank
  const ToothFaultSpec* spall = nullptr;  // on the loaded flank
};

// One face slice: [z0, z1] and its middle.
struct Slice {
  double z0, z1, z_mid;
};

// A touching (or spalled) slice of a tooth pair: its stiffness and offset d (header), and its
// two parts in series, the Hertzian contact dz / c_h and the teeth dz / (c_1 + c_2), for the
// coupled spall model.
struct SliceSpring {
  int pair_e;
  double k, d;
  double k_hertz = 0, k_teeth = 0;
};

// Everything CalcTvms derives once from the pair and the options.
struct TvmsSetup {
  const GearPair* pair = nullptr;
  const TvmsOptions* options = nullptr;
  std::vector<ToothFaults> faults1, faults2;  // per tooth in mesh order
  std::vector<Slice> slices;
  double hertz_compliance = 0;  // per unit width
  double rim1 = 0, rim2 = 0;
  double s0 = 0, s1 = 0, pb = 0, tan_bb = 0;
  int periods = 1;
};

// Legacy-free fault resolution: per gear and tooth, the faults acting on the loaded flanks.
void ResolveFaults(const GearPair& pair, const TvmsOptions& o, TvmsSetup& setup) {
  const Gear& g1 = pair.gear1();
  const Gear& g2 = pair.gear2();
  setup.faults1.assign(g1.teeth(), {});
  setup.faults2.assign(g2.teeth(), {});
  const ToothFaultSpec::Flank flank1 = o.loaded_flank1.value_or(ToothFaultSpec::Flank::kPlus);
  const ToothFaultSpec::Flank flank2 =
      o.loaded_flank2.value_or(pair.internal() ? ToothFaultSpec::Flank::kMinus : ToothFaultSpec::Flank::kPlus);
  std::vector<ToothFaultSpec> per_gear[2];
  for (const TvmsFault& f : o.faults) {
    if (f.gear != 1 && f.gear != 2) Fail("fault gear must be 1 or 2, got " + std::to_string(f.gear));
    per_gear[f.gear - 1].push_back(f.fault);
    std::vector<ToothFaults>& teeth = f.gear == 1 ? setup.faults1 : setup.faults2;
    const bool loaded = f.on_loaded_flank || f.fault.flank == (f.gear == 1 ? flank1 : flank2);
    const int t = f.fault.tooth;
    if (t < 0 || t >= static_cast<int>(teeth.size()))
      Fail("fault tooth " + std::to_string(t) + " out of range for gear " + std::to_string(f.gear));
    switch (f.fault.kind) {
      case ToothFaultSpec::Kind::kBrokenTooth: teeth[t].broken = &f.fault; break;
      case ToothFaultSpec::Kind::kRootCrack: if (loaded) teeth[t].crack = &f.fault; break;
      case ToothFaultSpec::Kind::kSpall: if (loaded) teeth[t].spall = &f.fault; break;
    }
  }
  ValidateToothFaults(g1, per_gear[0]);
  ValidateToothFaults(g2, per_gear[1]);
  const int z1 = g1.teeth(), z2 = g2.teeth();
  const bool f1 = !per_gear[0].empty(), f2 = !per_gear[1].empty();
  setup.periods = o.periods > 0 ? o.periods : f1 && f2 ? std::lcm(z1, z2) : f1 ? z1 : f2 ? z2 : 1;
}

// Face slices: uniform ones, split at the faults' axial limits, finer over varying cracks.
std::vector<Slice> MakeSlices(const GearPair& pair, const TvmsOptions& o) {
  const Gear& g1 = pair.gear1();
  const double b = pair.face_width_m();
  const bool helical = g1.spec().helix_angle_rad > 0;
  const int uniform = o.face_slices > 0 ? o.face_slices : helical ? 40 : 1;
  std::vector<double> edges;
  for (int j = 0; j <= uniform; ++j) edges.push_back(b * j / uniform);
  for (const TvmsFault& f : o.faults) {
    const Gear& g = f.gear == 1 ? pair.gear1() : pair.gear2();
    const auto [za, zb] = FaultAxialRange(g, f.fault);
    const double lo = std::clamp(za, 0.0, b), hi = std::clamp(zb, 0.0, b);
    const bool varying = f.fault.kind == ToothFaultSpec::Kind::kRootCrack && f.fault.crack_end_depth_m;
    const int n = varying ? std::max(1, o.crack_front_slices) : 1;
    for (int j = 0; j <= n; ++j) edges.push_back(lo + (hi - lo) * j / n);
  }
  std::sort(edges.begin(), edges.end());
  std::vector<Slice> slices;
  for (size_t j = 0; j + 1 < edges.size(); ++j)
    if (edges[j + 1] - edges[j] > 1e-12 * b) slices.push_back({edges[j], edges[j + 1], 0.5 * (edges[j] + edges[j + 1])});
  return slices;
}

// The spring of slice `sl` of the pair (t1, t2) touching at s (header): stiffness (N/m) and
// offset (0, a spall depth or infinity). healthy_c1/c2: the teeth's compliances per unit width
// at s without cracks (computed once per pair and sample).
SliceSpring SliceSpringAt(const TvmsSetup& st, const Slice& sl, double s, int t1, int t2, double healthy_c1,
                          double healthy_c2) {
  const GearPair& pair = *st.pair;
  const TvmsOptions& o = *st.options;
  const ToothFaults& f1 = st.faults1[t1];
  const ToothFaults& f2 = st.faults2[t2];
  const double r1 = pair.Gear1RadiusAt(s), r2 = pair.Gear2RadiusAt(s);
  constexpr double kNever = std::numeric_limits<double>::infinity();
  auto in_range = [&](const Gear& g, const ToothFaultSpec& f) {
    const auto [za, zb] = FaultAxialRange(g, f);
    return sl.z_mid >= za && sl.z_mid <= zb;
  };
  // Broken teeth: no contact beyond the fracture circle.
  if (f1.broken && in_range(pair.gear1(), *f1.broken) && r1 > BreakRadius(pair.gear1(), *f1.broken))
    return {0, 0, kNever};
  if (f2.broken && in_range(pair.gear2(), *f2.broken)) {
    const double rbreak = BreakRadius(pair.gear2(), *f2.broken);
    if (pair.internal() ? r2 < rbreak : r2 > rbreak) return {0, 0, kNever};
  }
  // Cracks: the cracked tooth's compliance at this slice's depth.
  auto cracked = [&](const Gear& g, const ToothFaultSpec* crack, double r, double rim, const GearMaterial& m,
                     double healthy) {
    if (crack == nullptr) return healthy;
    const double q = CrackDepthAt(g, *crack, sl.z_mid);
    if (!(q > 0)) return healthy;
    return CalcToothCompliance(g, r, 1.0, m, rim, q, crack->crack_angle_rad, o.quadrature_intervals).total();
  };
  const double c1 = cracked(pair.gear1(), f1.crack, r1, st.rim1, o.material1, healthy_c1);
  const double c2 = cracked(pair.gear2(), f2.crack, r2, st.rim2, o.material2, healthy_c2);
  const double dz = sl.z1 - sl.z0;
  const double k = dz / (st.hertz_compliance + c1 + c2);
  // Spalls: the flank lies `depth` below where the contact point would be.
  double d = 0;
  auto spalled = [&](const Gear& g, const ToothFaultSpec* spall, double roll) {
    return spall && in_range(g, *spall) && roll >= spall->roll_start_m && roll <= spall->roll_end_m;
  };
  const double g_len = pair.line_of_action_length_m();
  if (spalled(pair.gear1(), f1.spall, s)) d = std::max(d, f1.spall->depth_m);
  if (spalled(pair.gear2(), f2.spall, pair.internal() ? g_len + s : g_len - s)) d = std::max(d, f2.spall->depth_m);
  return {0, k, d, dz / st.hertz_compliance, dz / (c1 + c2)};
}

// A tooth pair with a spalled slice in the coupled model (header): the teeth's spring k_t (the
// slices' tooth springs in parallel: one tooth body across the width) in series with the
// slices' Hertzian springs in parallel, each touching beyond its offset. Its force at the mesh
// deflection delta solves k_t (delta - delta_h) = sum k_hj (delta_h - d_j)_+ for the contact
// approach delta_h (piecewise linear); *tangent = dF/d(delta) = k_t K_a / (k_t + K_a), K_a the
// touching Hertzian springs.
struct CoupledPair {
  double k_teeth = 0;
  std::vector<std::pair<double, double>> hertz;  // (k_h, d), sorted by d
  double Force(double delta, double* tangent) const {
    double ka = 0, kad = 0;
    for (size_t j = 0; j < hertz.size() && std::isfinite(hertz[j].second); ++j) {
      const double ka1 = ka + hertz[j].first, kad1 = kad + hertz[j].first * hertz[j].second;
      const double dh = (k_teeth * delta + kad1) / (k_teeth + ka1);
      if (!(dh > hertz[j].second)) break;  // spring j does not touch
      ka = ka1, kad = kad1;
    }
    if (!(ka > 0)) {
      if (tangent) *tangent = 0;
      return 0;
    }
    const double dh = (k_teeth * delta + kad) / (k_teeth + ka);
    if (tangent) *tangent = k_teeth * ka / (k_teeth + ka);
    return k_teeth * (delta - dh);
  }
};

// Mesh deflection under `load` of parallel springs k_j touching beyond offsets d_j:
// sum k_j (delta - d_j)_+ = load (piecewise linear, increasing). Returns {k tangent, delta};
// {0, inf} when no spring can touch.
std::pair<double, double> SolveDeflection(std::vector<SliceSpring> springs, double load) {
  std::sort(springs.begin(), springs.end(), [](const SliceSpring& a, const SliceSpring& b) { return a.d < b.d; });
  double k = 0, kd = 0;  // sum k_j and sum k_j d_j over the touching springs
  for (size_t j = 0; j < springs.size(); ++j) {
    if (!std::isfinite(springs[j].d)) break;
    k += springs[j].k;
    kd += springs[j].k * springs[j].d;
    const double delta = (load + kd) / k;
    const double next = j + 1 < springs.size() ? springs[j + 1].d : std::numeric_limits<double>::infinity();
    if (delta <= next) return {k, delta};
  }
  return {0.0, std::numeric_limits<double>::infinity()};
}

// The springs of one sample: every slice of every pair on the path of contact.
std::vector<SliceSpring> SampleSprings(const TvmsSetup& st, int whole, double frac,
                                       std::map<int, ToothPairContact>& touching) {
  const GearPair& pair = *st.pair;
  const TvmsOptions& o = *st.options;
  const int z1 = pair.gear1().teeth(), z2 = pair.gear2().teeth();
  auto mod = [](int e, int z) { return ((e % z) + z) % z; };
  std::vector<SliceSpring> springs;
  // Healthy compliances per (pair, contact point), reused across slices of a spur pair.
  std::map<std::pair<int, double>, std::pair<double, double>> healthy;
  for (const Slice& sl : st.slices) {
    const double phase = frac + sl.z_mid * st.tan_bb / st.pb;
    // Pairs e = whole + e' with s = s0 + (phase - e') pb in [s0, s1).
    const int e_hi = static_cast<int>(std::floor(phase));
    const int e_lo = static_cast<int>(std::ceil(phase - (st.s1 - st.s0) / st.pb));
    for (int ep = e_lo; ep <= e_hi; ++ep) {
      const double s = st.s0 + (phase - ep) * st.pb;
      if (s < st.s0 || s >= st.s1) continue;
      const int e = whole + ep, t1 = mod(e, z1), t2 = mod(e, z2);
      auto [it, fresh] = healthy.try_emplace({e, s});
      if (fresh) {
        it->second.first = CalcToothCompliance(pair.gear1(), pair.Gear1RadiusAt(s), 1.0, o.material1, st.rim1, 0, 0,
                                               o.quadrature_intervals).total();
        it->second.second = CalcToothCompliance(pair.gear2(), pair.Gear2RadiusAt(s), 1.0, o.material2, st.rim2, 0, 0,
                                                o.quadrature_intervals).total();
      }
      SliceSpring sp = SliceSpringAt(st, sl, s, t1, t2, it->second.first, it->second.second);
      sp.pair_e = e;
      springs.push_back(sp);
      ToothPairContact& c = touching[e];
      c.tooth1 = t1;
      c.tooth2 = t2;
      c.position_m = st.s0 + (frac + 0.5 * pair.face_width_m() * st.tan_bb / st.pb - ep) * st.pb;
    }
  }
  return springs;
}

// Pairs with a spalled slice under the coupled model (TvmsOptions::SpallModel::kHertzContact):
// their slices leave `springs` and become CoupledPairs (per pair e).
std::map<int, CoupledPair> SplitCoupledPairs(const TvmsOptions& o, std::vector<SliceSpring>& springs) {
  std::map<int, CoupledPair> coupled;
  if (o.spall_model != TvmsOptions::SpallModel::kHertzContact) return coupled;
  for (const SliceSpring& sp : springs)
    if (sp.d > 0 && std::isfinite(sp.d)) coupled[sp.pair_e];
  if (coupled.empty()) return coupled;
  std::vector<SliceSpring> rest;
  for (const SliceSpring& sp : springs) {
    auto it = coupled.find(sp.pair_e);
    if (it == coupled.end()) {
      rest.push_back(sp);
      continue;
    }
    it->second.k_teeth += sp.k_teeth;
    // Without a load a spalled slice carries nothing (its depth exceeds any deflection).
    const double d = o.load_n > 0 ? sp.d : (sp.d > 0 ? std::numeric_limits<double>::infinity() : 0.0);
    it->second.hertz.emplace_back(sp.k_hertz, d);
  }
  for (auto& [e, p] : coupled) std::sort(p.hertz.begin(), p.hertz.end(), [](auto& a, auto& b) { return a.second < b.second; });
  springs.swap(rest);
  return coupled;
}

// Mesh force and tangent at the deflection delta: independent slices plus coupled pairs.
double MeshForce(const std::vector<SliceSpring>& springs, const std::map<int, CoupledPair>& coupled, double delta,
                 double* tangent) {
  double f = 0, k = 0;
  for (const SliceSpring& sp : springs)
    if (delta > sp.d) f += sp.k * (delta - sp.d), k += sp.k;
  for (const auto& [e, p] : coupled) {
    double kp = 0;
    f += p.Force(delta, &kp);
    k += kp;
  }
  if (tangent) *tangent = k;
  return f;
}

// One sample of the TVMS at mesh phase whole + frac (base pitches).
void SampleTvms(const TvmsSetup& st, int whole, double frac, Tvms& out) {
  const TvmsOptions& o = *st.options;
  std::map<int, ToothPairContact> touching;
  std::vector<SliceSpring> springs = SampleSprings(st, whole, frac, touching);
  const std::map<int, CoupledPair> coupled = SplitCoupledPairs(o, springs);
  // The deflection: slices only, piecewise linear in closed form; with coupled pairs, bisection
  // on the monotone mesh force (to 1e-14 of the deflection) and the tangent there.
  double k = 0, e_nl = 0, delta = std::numeric_limits<double>::infinity();
  if (o.load_n > 0 && coupled.empty()) {
    std::tie(k, delta) = SolveDeflection(springs, o.load_n);
  } else if (o.load_n > 0) {
    double lo = 0, hi = 1e-9;
    while (MeshForce(springs, coupled, hi, nullptr) < o.load_n && hi < 1) hi *= 2;
    if (MeshForce(springs, coupled, hi, nullptr) >= o.load_n) {
      for (int it = 0; it < 200 && hi - lo > 1e-14 * hi; ++it)
        (MeshForce(springs, coupled, 0.5 * (lo + hi), nullptr) < o.load_n ? lo : hi) = 0.5 * (lo + hi);
      delta = hi;
      MeshForce(springs, coupled, delta, &k);
      // The exact deflection of the piece the bisection ended on.
      if (k > 0) delta -= (MeshForce(springs, coupled, delta, nullptr) - o.load_n) / k;
    }
  }
  if (o.load_n > 0 && k > 0) e_nl = delta - o.load_n / k;
  // Each pair's share: its touching slices (with a load: below the deflection), or its coupled
  // tangent.
  for (const SliceSpring& sp : springs) {
    const bool touches = o.load_n > 0 ? sp.d < delta : sp.d == 0;
    if (touches) touching[sp.pair_e].stiffness_n_per_m += sp.k;
  }
  for (const auto& [e, p] : coupled) {
    double kp = 0;
    if (o.load_n > 0) {
      p.Force(delta, &kp);
    } else {
      p.Force(1.0, &kp);  // linear without offsets: the tangent at any deflection
    }
    touching[e].stiffness_n_per_m += kp;
  }
  if (!(o.load_n > 0))
    for (const auto& [e, c] : touching) k += c.stiffness_n_per_m;
  out.stiffness_n_per_m.push_back(k);
  out.no_load_te_m.push_back(e_nl);
  if (o.load_n > 0) out.loaded_te_m.push_back(delta);
  std::vector<ToothPairContact> list;
  for (const auto& [e, c] : touching)
    if (c.stiffness_n_per_m > 0) list.push_back(c);
  out.pairs_in_contact.push_back(static_cast<int>(list.size()));
  out.contacts.push_back(std::move(list));
}

}  // namespace

Tvms CalcTvms(const GearPair& pair, const TvmsOptions& options) {
  const Gear& g1 = pair.gear1();
  // Validate.
  if (options.samples_per_period < 1) Fail("samples_per_period must be >= 1");
  if (options.fillet_foundation && !(options.bore_radius1_m > 0 && options.rim_radius2_m > 0))
    Fail("fillet foundation needs bore_radius1_m and rim_radius2_m > 0");
  if (!(options.load_n >= 0)) Fail("load_n = " + std::to_string(options.load_n) + " N must be >= 0");
  TvmsSetup st;
  st.pair = &pair;
  st.options = &options;
  ResolveFaults(pair, options, st);
  st.slices = MakeSlices(pair, options);
  st.pb = pair.transverse_base_pitch_m();
  st.s0 = pair.contact_start_m();
  st.s1 = pair.contact_end_m();
  st.tan_bb = std::tan(g1.base_helix_angle_rad());
  st.rim1 = options.fillet_foundation ? options.bore_radius1_m : 0.0;
  st.rim2 = options.fillet_foundation ? options.rim_radius2_m : 0.0;
  st.hertz_compliance = 1 / HertzStiffness(1.0, options.material1, options.material2);

  // Sample the mesh cycle(s). The phase in base pitches is split into whole periods and the
  // fraction so that samples one period apart see bit-identical contact positions.
  Tvms out;
  out.mesh_period_rad = 2 * kPi / g1.teeth();
  out.slices = static_cast<int>(st.slices.size());
  const int n = st.periods * options.samples_per_period;
  for (int i = 0; i < n; ++i) {
    const int whole = i / options.samples_per_period;
    const double frac = static_cast<double>(i % options.samples_per_period) / options.samples_per_period;
    out.theta1_rad.push_back(out.mesh_period_rad * (whole + frac));
    SampleTvms(st, whole, frac, out);
  }
  // Statistics.
  const auto& k = out.stiffness_n_per_m;
  out.mean_n_per_m = std::accumulate(k.begin(), k.end(), 0.0) / k.size();
  out.min_n_per_m = *std::min_element(k.begin(), k.end());
  out.max_n_per_m = *std::max_element(k.begin(), k.end());
  return out;
}

double InterpolateTvms(const Tvms& tvms, const std::vector<double>& samples, double theta1_rad) {
  const int n = static_cast<int>(samples.size());
  if (n == 0 || tvms.theta1_rad.size() < 2) return n ? samples[0] : 0.0;
  const double step = tvms.theta1_rad[1] - tvms.theta1_rad[0];
  double x = std::fmod(theta1_rad / step, static_cast<double>(n));
  if (x < 0) x += n;
  const int i = std::min(static_cast<int>(x), n - 1);
  const double f = x - i;
  return (1 - f) * samples[i] + f * samples[(i + 1) % n];
}

// ---- Sweep frames -------------------------------------------------------------------------

TvmsSweepFrame MakeTvmsSweepFrame(const GearPair& pair) {
  const Gear& g1 = pair.gear1();
  TvmsSweepFrame f;
  f.teeth1 = g1.teeth();
  f.teeth2 = pair.gear2().teeth();
  f.internal = pair.internal();
  const double psi_b1 = g1.HalfToothAngle(g1.base_radius_m());
  f.theta_offset_rad = psi_b1 + pair.working_pressure_angle_rad() - pair.contact_start_m() / g1.base_radius_m();
  return f;
}

int TvmsSweepFrame::MeshTooth(int gear, int frame_tooth) const {
  auto mod = [](int e, int z) { return ((e % z) + z) % z; };
  if (gear == 1) return mod(-frame_tooth, teeth1);
  return internal ? mod(-frame_tooth, teeth2) : mod(frame_tooth + 1, teeth2);
}

int TvmsSweepFrame::FrameTooth(int gear, int mesh_tooth) const {
  auto mod = [](int e, int z) { return ((e % z) + z) % z; };
  if (gear == 1) return mod(-mesh_tooth, teeth1);
  return internal ? mod(-mesh_tooth, teeth2) : mod(mesh_tooth - 1, teeth2);
}

std::vector<TvmsFault> TvmsFaultsInSweepFrame(const GearPair& pair, const std::vector<ToothFaultSpec>& gear1,
                                              const std::vector<ToothFaultSpec>& gear2) {
  const TvmsSweepFrame frame = MakeTvmsSweepFrame(pair);
  std::vector<TvmsFault> out;
  for (int g = 1; g <= 2; ++g)
    for (ToothFaultSpec f : g == 1 ? gear1 : gear2) {
      const int z = g == 1 ? frame.teeth1 : frame.teeth2;
      if (f.tooth < 0 || f.tooth >= z)
        Fail("fault tooth " + std::to_string(f.tooth) + " out of range for gear " + std::to_string(g));
      f.tooth = frame.MeshTooth(g, f.tooth);
      out.emplace_back(g, f);
    }
  return out;
}

double CrackStiffnessRatio(const GearPair& pair, int gear, const ToothFaultSpec& crack,
                           const GearMaterial& material, double rim_radius1_m, double rim_radius2_m, int points) {
  if (crack.kind != ToothFaultSpec::Kind::kRootCrack) Fail("CrackStiffnessRatio needs a root crack");
  if (gear != 1 && gear != 2) Fail("CrackStiffnessRatio: gear must be 1 or 2");
  const Gear& g = gear == 1 ? pair.gear1() : pair.gear2();
  ValidateToothFault(g, crack);
  // One tooth pair over the path of contact, healthy and with the cracked tooth on its loaded
  // flank; the crack's depth profile integrated over the face width (Chen & Shao's slices).
  TvmsOptions o;
  o.faults = {TvmsFault(gear, crack, true)};
  const std::vector<Slice> slices = MakeSlices(pair, o);
  const double hertz = 1 / HertzStiffness(1.0, material, material);
  const double s0 = pair.contact_start_m(), s1 = pair.contact_end_m();
  double healthy_sum = 0, cracked_sum = 0;
  for (int i = 0; i < points; ++i) {
    const double s = s0 + (i + 0.5) / points * (s1 - s0);
    const double r1 = pair.Gear1RadiusAt(s), r2 = pair.Gear2RadiusAt(s);
    const double c1 = CalcToothCompliance(pair.gear1(), r1, 1.0, material, rim_radius1_m).total();
    const double c2 = CalcToothCompliance(pair.gear2(), r2, 1.0, material, rim_radius2_m).total();
    const double b = pair.face_width_m();
    healthy_sum += b / (hertz + c1 + c2);
    for (const Slice& sl : slices) {
      const double q = CrackDepthAt(g, crack, sl.z_mid);
      const double cc = q > 0 ? CalcToothCompliance(g, gear == 1 ? r1 : r2, 1.0, material,
                                                    gear == 1 ? rim_radius1_m : rim_radius2_m, q,
                                                    crack.crack_angle_rad).total()
                              : (gear == 1 ? c1 : c2);
      cracked_sum += (sl.z1 - sl.z0) / (hertz + (gear == 1 ? cc + c2 : c1 + cc));
    }
  }
  return cracked_sum / healthy_sum;
}

}  // namespace orrery::gears

// Mesh stiffness: ISO 6336-1 method B and the potential-energy TVMS.
//
// Oracles:
// - ISO 6336-1 method B evaluated by hand below for seed 001 (docs/validation/iso6336_stiffness.md,
//   docs/validation/scenarios.md), and the standard's "typical" c' of 12-18 N/(mm um);
// - closed-form cantilever compliances of a rectangular tooth (Timoshenko beam: bending
//   F d^3 / (3 E I) with the axial-load moment, shear 1.2 F d / (G A), axial F d / (E A));
// - Tian's (2004) closed-form integrals in the involute angle for the involute tooth, evaluated
//   here by Simpson's rule (an independent variable and quadrature);
// - kinematics of the mesh cycle: period 2 pi / z1, double-contact share eps_alpha - 1;
// - fault invariants: a broken tooth changes k only while it is in mesh, a zero-depth crack
//   equals the healthy tooth, k decreases with crack depth.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "models/mesh_stiffness.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

GearSpec Seed001(int z, bool internal = false) {
  GearSpec s;
  s.teeth = z;
  s.normal_module_m = 1.5e-3;
  s.normal_pressure_angle_rad = 21.3 * kDeg;
  s.face_width_m = 0.030;
  s.internal = internal;
  // The paper gives no tips; a standard ring tip would reach into the planet's fillet
  // (gear_geometry_test.cpp), so the ring addendum is 0.9 m_n.
  if (internal) s.addendum_coef = 0.9;
  return s;
}

GearPair SunPlanet() { return GearPair(Gear(Seed001(18)), Gear(Seed001(34))); }
GearPair RingPlanet() { return GearPair(Gear(Seed001(18)), Gear(Seed001(70, true))); }

// Seed 001 gives no bores: planet bore 6 mm (on its pin), sun bore 10 mm, ring rim 58 mm.
TvmsOptions Seed001Options(bool ring) {
  TvmsOptions o;
  o.bore_radius1_m = 6e-3;
  o.rim_radius2_m = ring ? 58e-3 : 10e-3;
  return o;
}

// ---- ISO 6336-1 ---------------------------------------------------------------------------

TEST(Iso6336, HandCalculationSeed001) {
  // Sun-planet: pinion = planet (z_n1 = 18), wheel = sun (z_n2 = 34), x = 0, spur:
  //   q' = 0.04723 + 0.15551/18 + 0.25791/34 = 0.04723 + 0.0086394 + 0.0075856 = 0.0634550
  //   c'_th = 15.7592; C_B = (1 + 0.5 (1.2 - 1.25)) (1 - 0.02 (20 - 21.3)) = 0.975 * 1.026
  //   = 1.00035; c' = 15.7592 * 0.8 * 1.00035 = 12.6118 N/(mm um).
  // Ring-planet (z_n2 -> inf): q' = 0.04723 + 0.0086394 = 0.0558694, c'_th = 17.8989,
  //   c' = 17.8989 * 0.8 * 1.00035 = 14.3241 N/(mm um).
  const GearPair sp = SunPlanet(), rp = RingPlanet();
  const Iso6336Stiffness a = CalcIso6336Stiffness(sp), b = CalcIso6336Stiffness(rp);
  // Hand values rounded to 5-6 significant digits: relative tolerance 5e-5.
  EXPECT_NEAR(a.q_prime, 0.0634550, 5e-5 * 0.0634550);
  EXPECT_NEAR(a.c_th, 15.7592, 5e-5 * 15.7592);
  EXPECT_NEAR(a.c_b, 1.00035, 1e-12);
  EXPECT_NEAR(a.c_single, 12.6118, 5e-5 * 12.6118);
  EXPECT_NEAR(b.q_prime, 0.0558694, 5e-5 * 0.0558694);
  EXPECT_NEAR(b.c_single, 14.3241, 5e-5 * 14.3241);
  EXPECT_TRUE(std::isinf(b.z_n2));
  // c_gamma_alpha = c' (0.75 eps_alpha + 0.25), c_gamma_beta = 0.85 c_gamma_alpha.
  EXPECT_NEAR(a.c_gamma_alpha, 12.6118 * (0.75 * sp.transverse_contact_ratio() + 0.25), 5e-5 * a.c_gamma_alpha);
  EXPECT_NEAR(a.c_gamma_beta, 0.85 * a.c_gamma_alpha, 1e-12);
  // SI: N/(mm um) * 30 mm = N/um; 1 N/um = 1e6 N/m.
  EXPECT_NEAR(a.c_gamma_alpha_n_per_m, a.c_gamma_alpha * 30 * 1e6, 1e-6 * a.c_gamma_alpha_n_per_m);
  // Typical range of c' (ISO 6336-1, docs/validation/iso6336_stiffness.md): 12-18 N/(mm um).
  EXPECT_GT(a.c_single, 12.0);
  EXPECT_LT(b.c_single, 18.0);
  std::printf("ISO 6336 seed 001: sun-planet c' %.3f, c_ga %.3f N/(mm um) = %.1f N/um (paper 437); "
              "ring-planet c' %.3f, c_ga %.3f = %.1f N/um (paper 526)\n",
              a.c_single, a.c_gamma_alpha, a.c_gamma_alpha_n_per_m * 1e-6, b.c_single, b.c_gamma_alpha,
              b.c_gamma_alpha_n_per_m * 1e-6);
}

// ---- Closed forms --------------------------------------------------------------------------

TEST(ToothCompliance, RectangularCantileverAgainstBeamFormulas) {
  const GearMaterial steel;
  const double e = steel.youngs_modulus_pa, g = e / (2 * (1 + steel.poisson_ratio));
  const double h = 2e-3, L = 0.02, d = 5e-3, h_c = 1.7e-3;
  const double area = 2 * h * L, inertia = std::pow(2 * h, 3) * L / 12;
  for (double a1 : {0.0, 0.3, -0.2}) {
    const BeamCompliance c = CalcBeamCompliance([&](double) { return h; }, 0.0, d, h_c, a1, L, steel);
    const double cs = std::cos(a1), sn = std::sin(a1);
    // int_0^d [(d - x) c - h_c s]^2 dx = c^2 d^3/3 - c s h_c d^2 + s^2 h_c^2 d.
    const double bend = (cs * cs * d * d * d / 3 - cs * sn * h_c * d * d + sn * sn * h_c * h_c * d) / (e * inertia);
    EXPECT_NEAR(c.bending, bend, 1e-12 * bend);
    EXPECT_NEAR(c.shear, 1.2 * cs * cs * d / (g * area), 1e-12 * c.shear + 1e-30);
    EXPECT_NEAR(c.axial, sn * sn * d / (e * area), 1e-12 * c.axial + 1e-30);
  }
  // Hertz (Yang & Lin): k_h = pi E L / (4 (1 - nu^2)).
  EXPECT_NEAR(HertzStiffness(L, steel, steel), kPi * e * L / (4 * (1 - 0.09)), 1e-6);
}

// Tian (2004), involute in the angle alpha from -alpha1 (contact) to alpha2 (base circle):
//   1/k_b = int 3 {1 + cos a1 [(a2 - a) sin a - cos a]}^2 (a2 - a) cos a / (2 E L [sin a + (a2 - a) cos a]^3)
//   1/k_s = int 1.2 (1 + nu) (a2 - a) cos a cos^2 a1 / (E L [sin a + (a2 - a) cos a])
//   1/k_a = int (a2 - a) cos a sin^2 a1 / (2 E L [sin a + (a2 - a) cos a])
// plus, for r_f < r_b, the straight part from the root circle to the base circle (beam formulas).
TEST(ToothCompliance, InvoluteToothAgainstTianIntegrals) {
  const GearMaterial steel;
  const double e = steel.youngs_modulus_pa, nu = steel.poisson_ratio, L = 1.0;
  GearSpec high = Seed001(60);
  high.profile_shift = 0.5;  // root circle outside the base circle
  for (const GearSpec& spec : {Seed001(18), Seed001(34), high}) {
    const Gear gear(spec);
    const double rb = gear.base_radius_m(), rf = gear.root_radius_m();
    const double a2 = gear.HalfToothAngle(rb);
    for (double frac : {0.05, 0.4, 0.95}) {
      const double rc = gear.form_radius_m() + frac * (gear.tip_radius_m() - gear.form_radius_m());
      const double a1 = std::tan(std::acos(rb / rc)) - a2;
      const double lo = -a1, hi = rf > rb ? a2 - std::tan(std::acos(rb / rf)) : a2;
      // Simpson's rule, 20000 intervals.
      const int n = 20000;
      double kb = 0, ks = 0, ka = 0;
      for (int i = 0; i <= n; ++i) {
        const double a = lo + (hi - lo) * i / n, w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        const double den = std::sin(a) + (a2 - a) * std::cos(a), jac = (a2 - a) * std::cos(a);
        const double m = 1 + std::cos(a1) * ((a2 - a) * std::sin(a) - std::cos(a));
        kb += w * 3 * m * m * jac / (2 * e * L * den * den * den);
        ks += w * 1.2 * (1 + nu) * jac * std::cos(a1) * std::cos(a1) / (e * L * den);
        ka += w * jac * std::sin(a1) * std::sin(a1) / (2 * e * L * den);
      }
      const double step = (hi - lo) / n / 3;
      kb *= step, ks *= step, ka *= step;
      if (rf < rb) {
        // Straight extension of half thickness h_b = r_b sin(a2) from x_f to x_b.
        const double hb = rb * std::sin(a2), xf = std::sqrt(rf * rf - hb * hb), xb = rb * std::cos(a2);
        const double xc = rb * (std::cos(a1) + (a1 + a2) * std::sin(a1));  // Tian's x at the contact
        const double hc = rb * ((a1 + a2) * std::cos(a1) - std::sin(a1));
        const double c = std::cos(a1), s = std::sin(a1), I = 2 * hb * hb * hb * L / 3, A = 2 * hb * L;
        auto prim = [&](double x) { const double u = (xc - x) * c - hc * s; return -u * u * u / (3 * c); };
        kb += (prim(xb) - prim(xf)) / (e * I);
        ks += 1.2 * c * c * (xb - xf) * 2 * (1 + nu) / (e * A);
        ka += s * s * (xb - xf) / (e * A);
      }
      const ToothCompliance t = CalcToothCompliance(gear, rc, L, steel, 0.0);
      SCOPED_TRACE(testing::Message() << "z = " << spec.teeth << ", contact fraction " << frac);
      EXPECT_NEAR(t.bending, kb, 1e-8 * kb);
      EXPECT_NEAR(t.shear, ks, 1e-8 * ks);
      EXPECT_NEAR(t.axial, ka, 1e-8 * ka + 1e-22);
    }
  }
}

// ---- TVMS ------------------------------------------------------------------------------------

TEST(Tvms, PeriodAndContactZones) {
  const GearPair pair = SunPlanet();
  TvmsOptions o = Seed001Options(false);
  o.samples_per_period = 2000;
  o.periods = 2;
  const Tvms k = CalcTvms(pair, o);
  EXPECT_NEAR(k.mesh_period_rad, 2 * kPi / 18, 1e-15);
  const int n = o.samples_per_period;
  // Periodic with the mesh period.
  for (int i = 0; i < n; ++i) EXPECT_NEAR(k.stiffness_n_per_m[i + n], k.stiffness_n_per_m[i], 1e-9 * k.mean_n_per_m);
  // Double-contact share of the period = eps - 1, single = 2 - eps (1 < eps < 2), to one sample.
  const double eps = pair.transverse_contact_ratio();
  ASSERT_GT(eps, 1.0);
  ASSERT_LT(eps, 2.0);
  int doubles = 0, singles = 0;
  for (int i = 0; i < n; ++i) {
    doubles += k.pairs_in_contact[i] == 2;
    singles += k.pairs_in_contact[i] == 1;
  }
  EXPECT_EQ(doubles + singles, n);
  EXPECT_NEAR(static_cast<double>(doubles) / n, eps - 1, 1.0 / n);
  EXPECT_NEAR(static_cast<double>(singles) / n, 2 - eps, 1.0 / n);
  // In base-pitch lengths along the line of action: (eps - 1) p_b double, (2 - eps) p_b single.
  const double pb = pair.transverse_base_pitch_m();
  EXPECT_NEAR(doubles * pb / n, (eps - 1) * pb, pb / n);
  // Double contact is stiffer than single contact everywhere.
  double max_single = 0, min_double = 1e30;
  for (int i = 0; i < n; ++i) {
    if (k.pairs_in_contact[i] == 1) max_single = std::max(max_single, k.stiffness_n_per_m[i]);
    else min_double = std::min(min_double, k.stiffness_n_per_m[i]);
  }
  EXPECT_LT(max_single, min_double);
}

TEST(Tvms, MeanAgainstIso6336) {
  for (bool ring : {false, true}) {
    const GearPair pair = ring ? RingPlanet() : SunPlanet();
    const Tvms k = CalcTvms(pair, Seed001Options(ring));
    const Iso6336Stiffness iso = CalcIso6336Stiffness(pair);
    const double ratio = k.mean_n_per_m / iso.c_gamma_alpha_n_per_m;
    std::printf("%s: TVMS mean %.1f N/um (min %.1f, max %.1f), ISO c_gamma_alpha %.1f N/um, ratio %.3f; "
                "per unit width %.2f N/(mm um); paper %s\n",
                ring ? "ring-planet" : "sun-planet", k.mean_n_per_m * 1e-6, k.min_n_per_m * 1e-6,
                k.max_n_per_m * 1e-6, iso.c_gamma_alpha_n_per_m * 1e-6, ratio, k.mean_n_per_m / 0.030 * 1e-9,
                ring ? "526" : "437");
    // Agreement band: ISO's own spread of c' (12-18 N/(mm um), i.e. +-20 % about 15) applied to
    // c_gamma_alpha.
    EXPECT_GT(ratio, 0.8);
    EXPECT_LT(ratio, 1.2);
  }
}

TEST(Tvms, BrokenToothOnlyWhileInMesh) {
  const GearPair pair = SunPlanet();
  TvmsOptions healthy = Seed001Options(false);
  healthy.samples_per_period = 100;
  healthy.periods = 18;
  const Tvms k0 = CalcTvms(pair, healthy);
  for (auto kind : {ToothFault::Kind::kBrokenHeight, ToothFault::Kind::kBrokenWidth}) {
    TvmsOptions broken = healthy;
    broken.faults = {ToothFault{.kind = kind, .gear = 1, .tooth = 5, .fraction = 0.5}};  // legacy form
    const Tvms k1 = CalcTvms(pair, broken);
    int lowered = 0;
    for (size_t i = 0; i < k0.stiffness_n_per_m.size(); ++i) {
      bool in_mesh = false;
      for (const ToothPairContact& c : k0.contacts[i]) in_mesh |= c.tooth1 == 5;
      if (!in_mesh) {
        EXPECT_EQ(k1.stiffness_n_per_m[i], k0.stiffness_n_per_m[i]) << "sample " << i;
      } else {  // NOLINT
        EXPECT_LE(k1.stiffness_n_per_m[i], k0.stiffness_n_per_m[i]);
        lowered += k1.stiffness_n_per_m[i] < k0.stiffness_n_per_m[i];
      }
    }
    EXPECT_GT(lowered, 0);
    if (kind == ToothFault::Kind::kBrokenWidth) {
      // Half the face width: that pair's contribution halves exactly.
      for (size_t i = 0; i < k0.stiffness_n_per_m.size(); ++i) {
        for (const ToothPairContact& c : k0.contacts[i]) {
          if (c.tooth1 == 5) {
            EXPECT_NEAR(k0.stiffness_n_per_m[i] - k1.stiffness_n_per_m[i], 0.5 * c.stiffness_n_per_m,
                        1e-9 * k0.mean_n_per_m);
          }
        }
      }
    }
  }
  // Broken off at half height: the tooth loses contact where its contact radius exceeds the
  // break, i.e. over the part of the path near its tip (gear 1 tip end of the path).
  TvmsOptions broken = healthy;
  broken.faults = {TvmsFault(1, {.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 5, .height_fraction = 0.5})};
  const Tvms k1 = CalcTvms(pair, broken);
  const double rbreak = pair.gear1().tip_radius_m() - 0.5 * (pair.gear1().tip_radius_m() - pair.gear1().root_radius_m());
  for (size_t i = 0; i < k1.contacts.size(); ++i) {
    for (const ToothPairContact& c : k1.contacts[i]) {
      if (c.tooth1 == 5) {
        EXPECT_LE(pair.Gear1RadiusAt(c.position_m), rbreak + 1e-15);
      }
    }
  }
}

TEST(Tvms, CrackDepthZeroIsHealthyAndDeeperIsSofter) {
  const GearPair pair = SunPlanet();
  TvmsOptions o = Seed001Options(false);
  o.samples_per_period = 60;
  o.periods = 18;
  const Tvms healthy = CalcTvms(pair, o);
  double previous = healthy.mean_n_per_m;
  for (double q : {0.0, 0.2e-3, 0.5e-3, 1.0e-3, 1.4e-3}) {
    TvmsOptions c = o;
    c.faults = {TvmsFault(2, {.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 7, .crack_depth_m = q,
                              .crack_angle_rad = 45 * kDeg}, true)};
    const Tvms k = CalcTvms(pair, c);
    if (q == 0) {
      for (size_t i = 0; i < k.stiffness_n_per_m.size(); ++i) EXPECT_EQ(k.stiffness_n_per_m[i], healthy.stiffness_n_per_m[i]);
    } else {
      EXPECT_LT(k.mean_n_per_m, previous) << "q = " << q;
      // Only while the cracked tooth is in mesh.
      for (size_t i = 0; i < k.stiffness_n_per_m.size(); ++i) {
        bool in_mesh = false;
        for (const ToothPairContact& p : healthy.contacts[i]) in_mesh |= p.tooth2 == 7;
        if (!in_mesh) {
          EXPECT_EQ(k.stiffness_n_per_m[i], healthy.stiffness_n_per_m[i]);
        }
      }
    }
    previous = k.mean_n_per_m;
  }
  // Tooth compliance grows monotonically with depth at every contact radius.
  const Gear sun(Seed001(34));
  for (double frac : {0.1, 0.5, 0.9}) {
    const double rc = sun.form_radius_m() + frac * (sun.tip_radius_m() - sun.form_radius_m());
    double last = CalcToothCompliance(sun, rc, 0.03, {}, 0.0).total();
    for (double q : {0.3e-3, 0.6e-3, 0.9e-3, 1.2e-3}) {
      const double now = CalcToothCompliance(sun, rc, 0.03, {}, 0.0, q, 45 * kDeg).total();
      EXPECT_GT(now, last);
      last = now;
    }
  }
  // A crack past the centre line is rejected.
  TvmsOptions deep = o;
  deep.faults = {TvmsFault(2, {.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 7, .crack_depth_m = 5e-3,
                               .crack_angle_rad = 45 * kDeg}, true)};
  EXPECT_THROW(CalcTvms(pair, deep), std::invalid_argument);
}

TEST(Tvms, FullRevolutionWithFaultIndexesTeeth) {
  const GearPair pair = RingPlanet();
  TvmsOptions o = Seed001Options(true);
  o.samples_per_period = 20;
  o.faults = {TvmsFault(2, {.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 3, .height_fraction = 1.0})};
  const Tvms k = CalcTvms(pair, o);
  // One revolution of the faulty gear (the ring, 70 teeth) = 70 mesh periods.
  EXPECT_EQ(k.stiffness_n_per_m.size(), 70u * 20u);
  // Mesh-order indices: the pair entering at period e is (e mod 18, e mod 70).
  for (size_t i = 0; i < k.contacts.size(); ++i)
    for (const ToothPairContact& c : k.contacts[i]) {
      EXPECT_NE(c.tooth2, 3);  // fully broken: never touches
      EXPECT_EQ((c.tooth1 - c.tooth2) % 2, 0);  // 18 and 70 share the factor 2
    }
}

TEST(Tvms, HelicalSlicesSmoothTheMesh) {
  // Overlap ratio eps_beta = 1: b = pi m_n / sin(beta). The total contact length is then nearly
  // constant, so the fluctuation is far below that of the spur pair.
  auto spec = [](int z, double beta, HelixHand hand) {
    GearSpec s;
    s.teeth = z;
    s.normal_module_m = 2e-3;
    s.helix_angle_rad = beta;
    s.hand = hand;
    s.face_width_m = beta > 0 ? kPi * 2e-3 / std::sin(beta) : 0.0243;
    return s;
  };
  const double beta = 15 * kDeg;
  const GearPair helical(Gear(spec(21, beta, HelixHand::kRight)), Gear(spec(43, beta, HelixHand::kLeft)));
  EXPECT_NEAR(helical.overlap_ratio(), 1.0, 1e-12);
  const GearPair spur(Gear(spec(21, 0, HelixHand::kRight)), Gear(spec(43, 0, HelixHand::kLeft)));
  TvmsOptions o;
  o.bore_radius1_m = 8e-3;
  o.rim_radius2_m = 15e-3;
  o.samples_per_period = 50;
  const Tvms kh = CalcTvms(helical, o), ks = CalcTvms(spur, o);
  const double ripple_h = (kh.max_n_per_m - kh.min_n_per_m) / kh.mean_n_per_m;
  const double ripple_s = (ks.max_n_per_m - ks.min_n_per_m) / ks.mean_n_per_m;
  std::printf("ripple (max-min)/mean: helical eps_beta = 1 %.3f, spur %.3f\n", ripple_h, ripple_s);
  EXPECT_LT(ripple_h, 0.25 * ripple_s);
}


// ---- Faults: spall, crack front, sweep frames -----------------------------------------------

// Healthy and spalled TVMS of the sun-planet pair (planet = gear 1): a spall on the planet's
// loaded (plus) flank of mesh tooth 5 over the middle third of the face and the middle of its
// path of contact.
struct SpallCase {
  GearPair pair = SunPlanet();
  ToothFaultSpec spall;
  TvmsOptions options = Seed001Options(false);
  SpallCase() {
    const double s0 = pair.contact_start_m(), s1 = pair.contact_end_m();
    spall = {.kind = ToothFaultSpec::Kind::kSpall, .tooth = 5, .flank = ToothFaultSpec::Flank::kPlus,
             .roll_start_m = s0 + 0.35 * (s1 - s0), .roll_end_m = s0 + 0.6 * (s1 - s0), .axial_start_m = 0.01,
             .axial_end_m = 0.02, .depth_m = 20e-6};
    options.samples_per_period = 40;
    options.periods = 18;
  }
};

TEST(TvmsFaults, SpallLosesContactExactlyOverItsRollRange) {
  SpallCase c;
  const Tvms healthy = CalcTvms(c.pair, c.options);
  const double b = c.pair.face_width_m(), ch = 1 / HertzStiffness(1.0, {}, {});
  // The spalled pair (planet mesh tooth 5 with its contact in the roll range): its healthy
  // stiffness k_p = b / (c_h + c_t) gives the teeth's compliance c_t per unit width.
  auto spalled_pair = [&](size_t i) -> const ToothPairContact* {
    for (const ToothPairContact& p : healthy.contacts[i])
      if (p.tooth1 == 5 && p.position_m >= c.spall.roll_start_m && p.position_m <= c.spall.roll_end_m) return &p;
    return nullptr;
  };
  for (const auto model : {TvmsOptions::SpallModel::kSlices, TvmsOptions::SpallModel::kHertzContact}) {
    const bool slices = model == TvmsOptions::SpallModel::kSlices;
    TvmsOptions light = c.options;
    light.faults = {TvmsFault(1, c.spall)};
    light.spall_model = model;
    light.load_n = 1.0;  // deflection ~ 2 nm, far below the 20 um depth
    const Tvms k = CalcTvms(c.pair, light);
    int inside = 0;
    for (size_t i = 0; i < healthy.stiffness_n_per_m.size(); ++i) {
      double lost = 0;
      if (const ToothPairContact* p = spalled_pair(i)) {
        // Slices: a third of the face (uniform along a spur contact line) carries nothing.
        // Hertz contact: the teeth spring b / c_t in series with two thirds of the contact.
        const double kp = p->stiffness_n_per_m, ct = b / kp - ch;
        lost = slices ? kp / 3 : kp - 1 / (ct / b + ch / (2.0 / 3 * b));
      }
      inside += lost > 0;
      EXPECT_NEAR(k.stiffness_n_per_m[i], healthy.stiffness_n_per_m[i] - lost, 1e-9 * healthy.mean_n_per_m) << i;
      EXPECT_NEAR(k.no_load_te_m[i], 0.0, 1e-12 * k.loaded_te_m[i]);
      EXPECT_NEAR(k.loaded_te_m[i], 1.0 / k.stiffness_n_per_m[i], 1e-9 / k.stiffness_n_per_m[i]);
    }
    // The roll range covers a quarter of the path: a quarter of the samples of one passage.
    const double share = (c.spall.roll_end_m - c.spall.roll_start_m) / c.pair.transverse_base_pitch_m();
    EXPECT_NEAR(inside, share * light.samples_per_period, 1.0);
    // Heavy enough to reach the floor (slices: the mesh deflection passes the depth at 30 kN;
    // Hertz contact: the contact approach alone must, ~8 % of the deflection: 300 kN): the
    // tangent is the healthy one, and the TE rises by d k_spall / k (slices) or by
    // d k_t K_s / ((k_t + K_h) k) (Hertz contact: K_h the pair's contact, K_s its spalled third,
    // k_t its teeth), k (delta - e) = F.
    TvmsOptions heavy = light;
    heavy.load_n = slices ? 30e3 : 300e3;
    const Tvms kh = CalcTvms(c.pair, heavy);
    for (size_t i = 0; i < healthy.stiffness_n_per_m.size(); ++i) {
      const double kk = healthy.stiffness_n_per_m[i];
      double e = 0;
      if (const ToothPairContact* p = spalled_pair(i)) {
        const double kp = p->stiffness_n_per_m, ct = b / kp - ch, kt = b / ct, Kh = b / ch;
        e = slices ? c.spall.depth_m * (kp / 3) / kk : kt * (Kh / 3) * c.spall.depth_m / ((kt + Kh) * kk);
      }
      EXPECT_NEAR(kh.stiffness_n_per_m[i], kk, 1e-9 * kk) << i;
      EXPECT_NEAR(kh.no_load_te_m[i], e, 1e-9 * c.spall.depth_m) << i;
      EXPECT_NEAR(kh.stiffness_n_per_m[i] * (kh.loaded_te_m[i] - kh.no_load_te_m[i]), heavy.load_n, 1e-9 * heavy.load_n);
    }
  }
  // A spall on the unloaded (minus) flank changes nothing (up to the rounding of the three face
  // slices' sum against one).
  TvmsOptions other = c.options;
  other.faults = {TvmsFault(1, c.spall)};
  other.faults[0].fault.flank = ToothFaultSpec::Flank::kMinus;
  const Tvms unloaded_flank = CalcTvms(c.pair, other);
  for (size_t i = 0; i < healthy.stiffness_n_per_m.size(); ++i)
    EXPECT_NEAR(unloaded_flank.stiffness_n_per_m[i], healthy.stiffness_n_per_m[i], 1e-12 * healthy.mean_n_per_m);
}

TEST(TvmsFaults, CrackFrontIsIntegratedAcrossTheWidth) {
  // Chen & Shao's first-stage crack on the sun (gear 2), q^2 = q0^2 (1 - z / b), against an
  // independent Simpson integration over z of the slice stiffness at one contact position.
  const GearPair pair = SunPlanet();
  TvmsOptions o = Seed001Options(false);
  o.samples_per_period = 10;
  o.periods = 34;
  const ToothFaultSpec crack{.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 7, .crack_depth_m = 1.0e-3,
                             .crack_angle_rad = 45 * kDeg, .crack_face_fraction = 1.0, .crack_end_depth_m = 0.0,
                             .flank = ToothFaultSpec::Flank::kPlus};
  TvmsOptions c = o;
  c.faults = {TvmsFault(2, crack)};
  const Tvms healthy = CalcTvms(pair, o), cracked = CalcTvms(pair, c);
  const double b = pair.face_width_m(), hertz = 1 / HertzStiffness(1.0, {}, {});
  int checked = 0;
  for (size_t i = 0; i < healthy.contacts.size(); ++i)
    for (const ToothPairContact& p : healthy.contacts[i]) {
      if (p.tooth2 != 7) continue;
      const double r1 = pair.Gear1RadiusAt(p.position_m), r2 = pair.Gear2RadiusAt(p.position_m);
      const double c1 = CalcToothCompliance(pair.gear1(), r1, 1.0, {}, o.bore_radius1_m).total();
      auto slice = [&](double z) {
        const double q = 1.0e-3 * std::sqrt(std::max(0.0, 1 - z / b));
        return 1 / (hertz + c1 + CalcToothCompliance(pair.gear2(), r2, 1.0, {}, o.rim_radius2_m, q, 45 * kDeg).total());
      };
      const int n = 400;  // Simpson
      double sum = slice(0) + slice(b);
      for (int j = 1; j < n; ++j) sum += (j % 2 ? 4 : 2) * slice(b * j / n);
      const double exact = sum * b / (3 * n);
      const double loss_exact = p.stiffness_n_per_m - exact;
      const double loss = healthy.stiffness_n_per_m[i] - cracked.stiffness_n_per_m[i];
      // 16 midpoint slices against q ~ sqrt(b - z) near the front's end: measured 0.3 % of the loss.
      EXPECT_NEAR(loss, loss_exact, 0.01 * loss_exact) << "sample " << i;
      ++checked;
    }
  EXPECT_GT(checked, 5);
  // On the unloaded flank the crack closes: nothing changes.
  TvmsOptions closed = o;
  closed.faults = {TvmsFault(2, [&] {
    ToothFaultSpec f = crack;
    f.flank = ToothFaultSpec::Flank::kMinus;
    return f;
  }())};
  const Tvms closed_k = CalcTvms(pair, closed);
  for (size_t i = 0; i < healthy.stiffness_n_per_m.size(); ++i)
    EXPECT_NEAR(closed_k.stiffness_n_per_m[i], healthy.stiffness_n_per_m[i], 1e-12 * healthy.mean_n_per_m);
}

TEST(TvmsFaults, SweepFrameFollowsTheFlankGeometry) {
  // Independent geometry: in the sweep frame, tooth k of gear 1 turned by theta1 has its plus
  // flank where the involute crosses the line of action T1 P (T1 = r_b1 (cos, sin)(-alpha_w),
  // P = (r_w1, 0)); its distance from T1 is the contact position the TVMS reports for
  // MeshTooth(1, k) at theta1 + theta_offset.
  for (const GearPair& pair : {SunPlanet(), RingPlanet()}) {
    const Gear& g1 = pair.gear1();
    const TvmsSweepFrame frame = MakeTvmsSweepFrame(pair);
    TvmsOptions o = Seed001Options(pair.internal());
    o.samples_per_period = 64;
    const Tvms t = CalcTvms(pair, o);
    const double rb = g1.base_radius_m(), aw = pair.working_pressure_angle_rad();
    const Vec2 t1 = rb * Vec2(std::cos(-aw), std::sin(-aw)), p(pair.working_pitch_radius1_m(), 0);
    const Vec2 u = (p - t1).normalized();
    int checked = 0;
    for (size_t i = 0; i < t.theta1_rad.size(); i += 7)
      for (const ToothPairContact& c : t.contacts[i]) {
        const double theta1 = t.theta1_rad[i] - frame.theta_offset_rad;
        const int k = frame.FrameTooth(1, c.tooth1);
        // Bisection in the roll distance s along the LOA: the polar angle of the LOA point minus
        // that of the flank at the same radius.
        auto miss = [&](double s) {
          const Vec2 q = t1 + s * u;
          const double r = q.norm();
          return std::remainder(std::atan2(q.y(), q.x()) - (theta1 + 2 * kPi * k / g1.teeth() + g1.HalfToothAngle(r)),
                                2 * kPi);
        };
        double lo = 1e-6, hi = pair.line_of_action_length_m();
        if (pair.internal()) hi = std::sqrt(g1.tip_radius_m() * g1.tip_radius_m() - rb * rb) * 1.2;
        for (int it = 0; it < 200; ++it) ((miss(0.5 * (lo + hi)) > 0) == (miss(lo) > 0) ? lo : hi) = 0.5 * (lo + hi);
        EXPECT_NEAR(0.5 * (lo + hi), c.position_m, 1e-9) << "k " << k;
        EXPECT_EQ(frame.MeshTooth(1, k), c.tooth1);
        // Gear 2's tooth: -k - 1 (external) or k (internal) in its frame.
        const int j = frame.FrameTooth(2, c.tooth2);
        const int z2 = pair.gear2().teeth();
        EXPECT_EQ(j, pair.internal() ? ((k % z2) + z2) % z2 : (((-k - 1) % z2) + z2) % z2);
        ++checked;
      }
    EXPECT_GT(checked, 10);
  }
}

}  // namespace
}  // namespace orrery::gears

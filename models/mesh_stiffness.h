#pragma once
// Gear mesh stiffness: ISO 6336-1 method B (constant) and the time-varying mesh stiffness (TVMS)
// of the potential-energy method, with root cracks and broken teeth. Feeds the `lumped` mesh
// model (DESIGN.md, fidelity ladder). Geometry comes from gear_geometry.h.
//
// ISO 6336-1:2006 sec. 9 (method B), see docs/validation/iso6336_stiffness.md:
//   q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1^2 + C9 x2^2
//        [mm um / N], z_n = z / (cos^2(beta_b) cos(beta)), c'_th = 1/q',
//   c' = c'_th C_M C_R C_B cos(beta), C_B = [1 + 0.5 (1.2 - h_fP/m_n)][1 - 0.02 (20 - alpha_n)]
//   (alpha_n in degrees, averaged over both racks), c_gamma_alpha = c' (0.75 eps_alpha + 0.25),
//   c_gamma_beta = 0.85 c_gamma_alpha. Internal gears: z_n2 -> infinity (the C3 and C7 terms
//   vanish; the C6 x2 and C9 x2^2 terms stay, x2 in the ISO 21771 sign), as the standard's note
//   for internal gears prescribes. The load correction for F_t K_A / b < 100 N/mm is not applied.
//
// Potential-energy method (TVMS), per tooth pair in contact at a point of the line of action:
//   1/k = 1/k_h + sum over both teeth (1/k_b + 1/k_s + 1/k_a + 1/k_f)
//   Hertz (Yang & Lin 1987): 1/k_h = (2 / (pi L)) [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]
//     (= 4 (1 - nu^2) / (pi E L) for equal materials);
//   the tooth as a cantilever of half-thickness h(x) along its centre line x (Yang & Lin 1987;
//   Tian 2004; Chen & Shao 2011), loaded at the contact point (x_c, h_c) along the line of
//   action, at the load angle alpha1 to the normal of the centre line:
//     1/k_b = int [(x_c - x) cos(alpha1) - h_c sin(alpha1)]^2 / (E I_x) dx, I_x = (2h)^3 L / 12,
//     1/k_s = int 1.2 cos^2(alpha1) / (G A_x) dx,  1/k_a = int sin^2(alpha1) / (E A_x) dx,
//     A_x = 2 h L, G = E / (2 (1 + nu)), integrated from the root circle to the contact point.
//   h(x) is the involute above the base circle; where the root circle is inside the base circle
//   (r_f < r_b) the part between them is a straight extension of half-thickness r_b sin(alpha2)
//   (alpha2: half tooth angle on the base circle; Chen & Shao 2011, Wan et al. 2014); where
//   r_f > r_b the involute is integrated from the root circle. Internal (ring) teeth use the same
//   integrals on their own involute, from the root (outer) circle inwards.
//   Fillet foundation (Sainsot, Velex & Duverger 2004):
//     1/k_f = cos^2(alpha1)/(E L) [L* (u_f/S_f)^2 + M* (u_f/S_f) + P* (1 + Q* tan^2(alpha1))],
//     X* = A/theta_f^2 + B h_f^2 + C h_f/theta_f + D/theta_f + E h_f + F (their Table 1),
//     S_f = 2 r_f theta_f (theta_f: half tooth angle at the root circle from the rack-generated
//     profile), u_f = distance along the centre line from the root circle to the load line,
//     h_f = r_f / r_bore (external). For ring gears h_f = r_rim / r_f is used as the analogue of
//     the rim-thickness ratio (the published fit is for external disc gears: an approximation).
//   Root crack (Chen & Shao 2011): a crack of depth q at angle nu to the centre line starting at
//   the root section reduces the cracked side to h_q = h_ref - q sin(nu):
//     A_x = (h + min(h, h_q)) L, I_x = (h + min(h, h_q))^3 L / 12.
//   h_ref is the largest half-thickness between the crack and the contact point (the root
//   section in Chen & Shao, where the tooth is widest at the root), so a zero-depth crack leaves
//   the tooth unchanged. Cracks past the centre line (h_q < 0) are rejected.
//   Broken tooth: a missing fraction f of the tooth height (from the tip) removes the contact
//   wherever the contact point on that tooth lies above the break; a missing fraction f of the
//   face width (from the z = 0 face) removes that part of the tooth's contact lines.
//   Helical gears: the face width is cut into thin spur slices, slice j at z_j shifted along the
//   line of action by z_j tan(beta_b) (Wan et al. 2014 slicing); stiffness in the transverse
//   plane along the line of action.
//
// Usage:
//   GearPair pair(Gear(planet), Gear(sun));
//   Iso6336Stiffness iso = CalcIso6336Stiffness(pair);
//   TvmsOptions o{.bore_radius1_m = 5e-3, .rim_radius2_m = 10e-3};
//   Tvms k = CalcTvms(pair, o);  // k.stiffness_n_per_m over one mesh period
#include <functional>
#include <vector>

#include "models/gear_geometry.h"

namespace orrery::gears {

struct Iso6336Options {
  double c_m = 0.8;  // C_M, theoretical-to-measured correction for solid discs
  double c_r = 1.0;  // C_R, gear blank factor (1: solid blanks)
};

// Per unit face width in ISO units N/(mm um) (= 1e9 N/m^2); *_n_per_m: times the common face
// width, in N/m along the transverse line of action.
struct Iso6336Stiffness {
  double z_n1 = 0, z_n2 = 0;  // virtual tooth numbers (z_n2 = inf for internal gears)
  double q_prime = 0;         // mm um / N
  double c_th = 0;            // c'_th
  double c_b = 0;             // C_B
  double c_single = 0;        // c'
  double c_gamma_alpha = 0;   // c_gamma_alpha
  double c_gamma_beta = 0;    // c_gamma_beta
  double c_single_n_per_m = 0, c_gamma_alpha_n_per_m = 0, c_gamma_beta_n_per_m = 0;
};

// gear1 of the pair is taken as the pinion when it has fewer teeth (external pairs are swapped
// otherwise); the ring is always gear 2.
Iso6336Stiffness CalcIso6336Stiffness(const GearPair& pair, const Iso6336Options& options = {});

struct GearMaterial {
  double youngs_modulus_pa = 206e9;
  double poisson_ratio = 0.3;
};

struct ToothFault {
  enum class Kind { kRootCrack, kBrokenHeight, kBrokenWidth };
  Kind kind = Kind::kRootCrack;
  int gear = 1;                // 1 or 2
  int tooth = 0;               // tooth index in mesh order (see Tvms)
  double crack_depth_m = 0;    // kRootCrack: q
  double crack_angle_rad = 0;  // kRootCrack: nu, to the tooth centre line
  double fraction = 0;         // kBroken*: missing fraction of the height / face width, [0, 1]
};

struct TvmsOptions {
  GearMaterial material1, material2;
  bool fillet_foundation = true;
  double bore_radius1_m = 0;   // gear 1 bore (required when fillet_foundation)
  double rim_radius2_m = 0;    // gear 2 bore (external) or outer rim radius (internal)
  int samples_per_period = 200;
  int face_slices = 0;         // 0: 1 for spur, 40 for helical pairs
  int quadrature_intervals = 16;  // composite 8-point Gauss-Legendre along each tooth
  std::vector<ToothFault> faults;
  // Number of mesh periods sampled; 0: 1 without faults, otherwise one revolution of the
  // faulty gear (z of that gear; lcm(z1, z2) when both gears carry faults).
  int periods = 0;
};

struct ToothPairContact {
  int tooth1 = 0, tooth2 = 0;       // mesh-order tooth indices
  double position_m = 0;            // on the line of action from T1 (slice at mid face width)
  double stiffness_n_per_m = 0;     // this pair's contribution (all slices)
};

// Sampled mesh stiffness. Sample i is at gear-1 rotation theta1 = i * period / samples from the
// instant the pair (tooth1 = 0, tooth2 = 0) enters contact at the start of the contact path
// (in the slice at z = 0). Teeth are numbered in mesh order: tooth e of each gear is the e-th to
// enter contact (e mod z); their positions in the Gear frames depend on the sense of rotation.
struct Tvms {
  double mesh_period_rad = 0;                    // 2 pi / z1 (gear 1)
  std::vector<double> theta1_rad;                // samples
  std::vector<double> stiffness_n_per_m;         // k(theta1), along the transverse line of action
  std::vector<int> pairs_in_contact;             // number of tooth pairs touching (any slice)
  std::vector<std::vector<ToothPairContact>> contacts;
  double mean_n_per_m = 0, min_n_per_m = 0, max_n_per_m = 0;
};

// Throws std::invalid_argument for missing bore/rim radii, invalid faults (gear not 1/2, tooth
// out of range, fraction outside [0, 1], crack past the centre line), non-positive sample counts.
Tvms CalcTvms(const GearPair& pair, const TvmsOptions& options);

// ---- Building blocks (public for tests and the lumped mesh element) ------------------------

// Hertzian contact stiffness (N/m) of a line contact of length width_m.
double HertzStiffness(double width_m, const GearMaterial& m1, const GearMaterial& m2);

struct BeamCompliance {
  double bending = 0, shear = 0, axial = 0;  // m/N
};

// Cantilever compliances of a tooth of width L with half-thickness half_thickness(x) (and the
// cracked side min(h, cracked_half_thickness)) on x in [x_root, x_c], loaded at (x_c, h_c) at
// load angle alpha1 (integrals above), by composite Gauss-Legendre (8 points x intervals).
// cracked_half_thickness <= 0 means no crack.
BeamCompliance CalcBeamCompliance(const std::function<double(double)>& half_thickness, double x_root,
                                  double x_c, double h_c, double alpha1, double width_m,
                                  const GearMaterial& material, int intervals = 16,
                                  double cracked_half_thickness = 0);

// Compliances (m/N) of one tooth of `gear` loaded at the involute point of radius contact_radius_m:
// bending/shear/axial (beam) and fillet foundation (0 when rim_radius_m <= 0).
struct ToothCompliance {
  double bending = 0, shear = 0, axial = 0, foundation = 0;
  double total() const { return bending + shear + axial + foundation; }
};
ToothCompliance CalcToothCompliance(const Gear& gear, double contact_radius_m, double width_m,
                                    const GearMaterial& material, double rim_radius_m,
                                    const ToothFault* crack = nullptr, int intervals = 16);

}  // namespace orrery::gears

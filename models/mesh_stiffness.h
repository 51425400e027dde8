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
//   Faults (models/tooth_fault.h; docs/faults.md). The face width is cut into slices (below) whose
//   boundaries include every fault's axial limits, and each slice j of a tooth pair is a spring
//   k_j = dz_j / (1/k_h' + c_1 + c_2) (compliances per unit width) that touches once the mesh
//   deflection delta exceeds the slice's offset d_j:
//   - root crack (Chen & Shao 2011, Engineering Failure Analysis 18:2149-2164, after Tian 2004):
//     a crack of depth q(z) at angle nu to the centre line, from the root section on the loaded
//     flank's side, leaves the cracked side the half thickness h_q = h_root - q sin(nu)
//     (h_root: BeamRootHalfThickness) wherever the tooth is thicker than that:
//       A_x = (h + min(h, h_q)) L, I_x = (h + min(h, h_q))^3 L / 12,
//     in every section from the root to the contact point (Chen & Shao's eq. for h_q < h_x; the
//     sections thinner than h_q keep 2h). q(z) is Chen & Shao's parabolic front across the
//     width, evaluated at each slice's middle; the fillet foundation is unchanged. A zero-depth
//     crack leaves the tooth unchanged; a crack on the unloaded flank's side closes (no change);
//   - broken tooth: a slice of the broken axial range whose contact point on that tooth lies
//     beyond the fracture circle r_break never touches (d_j = infinity);
//   - spall: a slice inside the spall's axial range whose contact point lies within its roll
//     range on the loaded flank touches only once its contact approach reaches the spall depth
//     (offset d_j = depth): the Hertzian contact is lost over the spall's area while the depth
//     exceeds the local deflection. Two models (TvmsOptions::spall_model):
//       kHertzContact (default): only the contact is lost; the teeth stay one body across the
//       width, so a pair with a spalled slice is its teeth spring k_t = sum_j dz_j / (c_1 + c_2)
//       in series with its slices' Hertzian springs dz_j / c_h in parallel, each touching beyond
//       its offset (the FE contact level agrees: a third of the face spalled costs ~5 % of the
//       single-pair stiffness, the Hertzian share of the compliance, not a third);
//       kSlices: the slice carries nothing at all, k_j = 0 (the lost-width model of Chaari,
//       Baccar, Abbes & Haddar 2008, Eur. J. Mech. A/Solids 27:691; what rigid tooth contact
//       shows, its calibrated penalty standing for the whole pair).
//     Without a load (TvmsOptions::load_n = 0) spalled slices carry nothing; with a load F the
//     mesh deflection solves sum over pairs F_p(delta) = F (piecewise linear and increasing),
//     and the mesh is linearized there: k = dF/d(delta) (the tangent), no-load transmission
//     error e = delta - F / k (so that k (delta - e) = F), the static loaded TE delta. A spall
//     shallower than the deflection thus leaves k and raises the TE.
//   Helical gears: the face width is cut into thin spur slices, slice j at z_j shifted along the
//   line of action by z_j tan(beta_b) (Wan et al. 2014 slicing); stiffness in the transverse
//   plane along the line of action. Slices: face_slices uniform ones (default 1 spur, 40
//   helical), split further at every fault's axial limits and into crack_front_slices over a
//   crack whose depth varies across the width.
//
// Usage:
//   GearPair pair(Gear(planet), Gear(sun));
//   Iso6336Stiffness iso = CalcIso6336Stiffness(pair);
//   TvmsOptions o{.bore_radius1_m = 5e-3, .rim_radius2_m = 10e-3};
//   Tvms k = CalcTvms(pair, o);  // k.stiffness_n_per_m over one mesh period
//   o.faults = TvmsFaultsInSweepFrame(pair, {}, {{.kind = ToothFaultSpec::Kind::kSpall, ...}});
//   o.load_n = 1429;              // a revolution of the faulty gear, with e(theta1) of the spall
#include <functional>
#include <optional>
#include <vector>

#include "models/gear_geometry.h"
#include "models/tooth_fault.h"

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

// Legacy fault description (the train code's TrainToothFault), converted to TvmsFault: kRootCrack
// (a uniform through-width crack on the loaded flank), kBrokenHeight (a break over the whole
// face width at height fraction `fraction`), kBrokenWidth (the whole height over the face
// fraction `fraction` from the z = 0 face).
struct ToothFault {
  enum class Kind { kRootCrack, kBrokenHeight, kBrokenWidth };
  Kind kind = Kind::kRootCrack;
  int gear = 1;                // 1 or 2
  int tooth = 0;               // tooth index in mesh order (see Tvms)
  double crack_depth_m = 0;    // kRootCrack: q
  double crack_angle_rad = 0;  // kRootCrack: nu, to the tooth centre line
  double fraction = 0;         // kBroken*: missing fraction of the height / face width, [0, 1]
};

// A tooth fault on gear 1 or 2 of the pair. fault.tooth is in MESH ORDER (see Tvms): the
// fault.tooth-th tooth of that gear to enter contact; TvmsSweepFrame maps gear-frame indices of
// the pair sweeps to it. on_loaded_flank: a crack or spall on whichever flank carries the load
// (fault.flank is then ignored).
struct TvmsFault {
  int gear = 1;
  ToothFaultSpec fault;
  bool on_loaded_flank = false;
  TvmsFault() = default;
  TvmsFault(int gear_index, const ToothFaultSpec& spec, bool loaded = false)
      : gear(gear_index), fault(spec), on_loaded_flank(loaded) {}
  TvmsFault(const ToothFault& legacy);  // NOLINT(google-explicit-constructor): see ToothFault
};

struct TvmsOptions {
  GearMaterial material1, material2;
  bool fillet_foundation = true;
  double bore_radius1_m = 0;   // gear 1 bore (required when fillet_foundation)
  double rim_radius2_m = 0;    // gear 2 bore (external) or outer rim radius (internal)
  int samples_per_period = 200;
  int face_slices = 0;         // 0: 1 for spur, 40 for helical pairs
  int quadrature_intervals = 16;  // composite 8-point Gauss-Legendre along each tooth
  std::vector<TvmsFault> faults;
  // The flank of each gear that carries the load (cracks and spalls act there). Unset: the pair
  // sweeps' convention (gear 1 driving counter-clockwise on its plus flank; an external gear 2
  // is loaded on its plus flank, an internal one on its minus flank).
  std::optional<ToothFaultSpec::Flank> loaded_flank1, loaded_flank2;
  // > 0: the load (N, along the line of action) at which spalls are compared with the mesh
  // deflection and the mesh is linearized (header, "spall"); 0: spalled slices carry nothing.
  double load_n = 0;
  // How a spall's lost contact acts (header): kHertzContact loses the Hertzian contact of the
  // spalled slices while the teeth stay one body across the width (default; what the FE contact
  // shows, docs/faults.md); kSlices drops whole independent slices (the lost-width model of
  // Chaari et al. 2008; what rigid tooth contact, whose penalty lumps the whole pair, shows).
  enum class SpallModel { kHertzContact, kSlices };
  SpallModel spall_model = SpallModel::kHertzContact;
  // Number of mesh periods sampled; 0: 1 without faults, otherwise one revolution of the
  // faulty gear (z of that gear; lcm(z1, z2) when both gears carry faults).
  int periods = 0;
  // Slices per fault axial range whose crack depth varies across it (Chen & Shao's front).
  int crack_front_slices = 16;
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
  // e(theta1): the no-load transmission error of the linearized mesh, k (delta - e) = F at the
  // load (0 without a load or where no spall touches); along the line of action, m.
  std::vector<double> no_load_te_m;
  // delta(theta1) = e + F / k at the load (empty without a load; infinite where nothing touches).
  std::vector<double> loaded_te_m;
  std::vector<int> pairs_in_contact;             // number of tooth pairs touching (any slice)
  std::vector<std::vector<ToothPairContact>> contacts;
  double mean_n_per_m = 0, min_n_per_m = 0, max_n_per_m = 0;
  int slices = 0;                                // face slices used
};

// Throws std::invalid_argument for missing bore/rim radii, invalid faults (gear not 1/2,
// ValidateToothFaults of that gear), non-positive sample counts or a negative load.
Tvms CalcTvms(const GearPair& pair, const TvmsOptions& options);

// Linear interpolation of a sampled quantity of `tvms` (stiffness_n_per_m, no_load_te_m, ...)
// at gear-1 angle theta1 (rad, the Tvms frame), periodic over the sampled span.
double InterpolateTvms(const Tvms& tvms, const std::vector<double>& samples, double theta1_rad);

// The frames of the pair sweeps (contact/gear_contact.h SweepGearMesh, SweepFlexibleGearMesh):
// gear 1 at the origin turning counter-clockwise by theta1 from the position where its tooth 0
// is centred on the line of centres (+x), gear 2 at the kinematic angle with a space facing it.
// Gear 1's tooth k drives on its plus flank; it touches at s = r_b1 (theta1 + psi_b1 + alpha_w)
// + k p_b on the line of action (psi_b1: half tooth angle at the base circle), so
//   Tvms theta1 = sweep theta1 + psi_b1 + alpha_w - s_0 / r_b1,
//   mesh order e of gear 1 = -k mod z1, of an external gear 2 = j + 1 mod z2, of an internal
//   gear 2 = -j mod z2 (k, j: gear-frame tooth indices; derived for zero backlash, where tooth
//   k of gear 1 meets tooth -k - 1 of an external and tooth k of an internal gear 2).
struct TvmsSweepFrame {
  double theta_offset_rad = 0;   // Tvms theta1 - sweep theta1
  int teeth1 = 0, teeth2 = 0;
  bool internal = false;
  int MeshTooth(int gear, int frame_tooth) const;   // gear 1 or 2
  int FrameTooth(int gear, int mesh_tooth) const;
};
TvmsSweepFrame MakeTvmsSweepFrame(const GearPair& pair);

// The faults of each gear (gear-frame tooth indices, as in every other level) as TvmsFaults in
// mesh order for the sweep frame.
std::vector<TvmsFault> TvmsFaultsInSweepFrame(const GearPair& pair, const std::vector<ToothFaultSpec>& gear1,
                                              const std::vector<ToothFaultSpec>& gear2);

// Ratio k_cracked / k_healthy of one tooth pair's stiffness (Hertz, both teeth and their fillet
// foundations, integrated over the face width with the crack's depth profile) averaged over the
// contact path [s_0, s_1] of `pair`, the cracked tooth on gear `gear` (1 or 2) loaded on the
// crack's flank: the constant per-tooth factor of the tooth-contact level (docs/faults.md).
// rim radii as TvmsOptions (<= 0: no foundation). Throws std::invalid_argument for a fault that
// is not a root crack or is invalid.
double CrackStiffnessRatio(const GearPair& pair, int gear, const ToothFaultSpec& crack,
                           const GearMaterial& material, double rim_radius1_m, double rim_radius2_m,
                           int points = 24);

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
// A crack (depth q, angle nu, on the loaded side) as above; q = 0: healthy. Throws
// std::invalid_argument for a crack past the centre line.
ToothCompliance CalcToothCompliance(const Gear& gear, double contact_radius_m, double width_m,
                                    const GearMaterial& material, double rim_radius_m,
                                    double crack_depth_m = 0, double crack_angle_rad = 0,
                                    int intervals = 16);

}  // namespace orrery::gears

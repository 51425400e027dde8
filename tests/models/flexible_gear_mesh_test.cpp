// Quasi-static mesh stiffness with flexible (FE-reduced) gears (models/flexible_gear_mesh.cpp),
// seed 001's sun-planet pair (34/18, m = 1.5 mm, 21.3 deg, b = 30 mm; standard addenda here, so
// eps_alpha = 1.557) at 1429 N, on the default (coarse, CI) hex20 meshes. Oracles:
//   - the path of contact of the gear geometry: the number of tooth pairs on the unloaded path
//     [s_start, s_end] (p_b apart, phased by the first loaded contact) is the number in contact,
//     except where the load lengthens the contact past the end of the path (more, never fewer);
//   - the lumped models on the same blanks: ISO 6336 c' b (single pair) and c_gamma_alpha b (mean),
//     the potential-energy TVMS (mean, and its single- and double-pair levels min and max).
// The numbers are printed for the record; the bands are stated with each check.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "models/flexible_gear_mesh.h"
#include "models/mesh_stiffness.h"

namespace orrery::gears {
namespace {

using namespace orrery::contact;  // the engine the gear layer builds on

constexpr double kDeg = 3.14159265358979323846 / 180;

gears::GearPair Seed001SunPlanet() {
  gears::GearSpec sun{.teeth = 34, .normal_module_m = 1.5e-3,
                      .normal_pressure_angle_rad = 21.3 * kDeg, .face_width_m = 0.03};
  gears::GearSpec planet = sun;
  planet.teeth = 18;
  return {gears::Gear(sun), gears::Gear(planet)};
}

TEST(FlexibleGearMesh, Seed001SunPlanetZonesAndStiffness) {
  const gears::GearPair pair = Seed001SunPlanet();
  FlexibleGearMeshOptions o;
  if (const char* f = std::getenv("ORRERY_FLEX_FE_LEVEL")) {  // mesh-convergence runs by hand
    const int level = std::atoi(f);
    o.fe.flank_divisions *= level, o.fe.tooth_divisions *= level, o.fe.fillet_divisions *= level;
    o.fe.root_layer_divisions *= level, o.fe.rim_divisions *= level, o.fe.face_divisions *= level;
  }
  const FlexibleMeshSweep s = SweepFlexibleGearMesh(pair, o, 1429, 12);
  for (size_t i = 0; i < s.points.size(); ++i) {
    const MeshSweepPoint& p = s.points[i];
    std::printf("%8.5f TE %7.4f um k %6.1f N/um points %3d teeth %d (path %d) [%.3f %.3f] [%.3f %.3f]\n",
                p.roll_angle_rad, p.transmission_error_m * 1e6, p.stiffness_n_per_m * 1e-6,
                p.contact_points, p.teeth_in_contact, s.predicted_pairs[i], p.pattern_min_m[0] * 1e3,
                p.pattern_max_m[0] * 1e3, p.pattern_min_m[1] * 1e3, p.pattern_max_m[1] * 1e3);
  }
  gears::TvmsOptions to;
  to.bore_radius1_m = 0.4 * pair.gear1().reference_radius_m();
  to.rim_radius2_m = 0.4 * pair.gear2().reference_radius_m();
  const gears::Tvms tvms = gears::CalcTvms(pair, to);
  const gears::Iso6336Stiffness iso = gears::CalcIso6336Stiffness(pair);
  std::printf("eps_alpha %.4f, path %.3f..%.3f mm; mean %.1f N/um (single %.1f, double %.1f); "
              "ISO c'b %.1f, c_ga b %.1f; TVMS mean %.1f (min %.1f, max %.1f); modes %d + %d, "
              "FE nodes %d + %d, reduce %.1f s, sweep %.1f s\n",
              pair.transverse_contact_ratio(), pair.contact_start_m() * 1e3,
              pair.contact_end_m() * 1e3, s.mean_stiffness_n_per_m * 1e-6,
              s.single_zone_stiffness_n_per_m * 1e-6, s.double_zone_stiffness_n_per_m * 1e-6,
              iso.c_single_n_per_m * 1e-6, iso.c_gamma_alpha_n_per_m * 1e-6, tvms.mean_n_per_m * 1e-6,
              tvms.min_n_per_m * 1e-6, tvms.max_n_per_m * 1e-6, s.nf1, s.nf2, s.fe_nodes1,
              s.fe_nodes2, s.reduce_seconds, s.sweep_seconds);

  // The culling's inflation held throughout; Newton stalls rare and small.
  EXPECT_EQ(s.inflation_exceeded, 0);
  EXPECT_LE(s.unconverged_points, 2);
  std::printf("unconverged points %d (largest moment residual %.2g of the load)\n",
              s.unconverged_points, s.max_moment_residual);
  // Zones: as many pairs as the path of contact holds; where not, one more (the loaded contact
  // running past the end of the path), at most at one roll angle per zone boundary (2 here).
  int mismatches = 0, doubles = 0;
  for (size_t i = 0; i < s.points.size(); ++i) {
    const int n = s.points[i].teeth_in_contact, np = s.predicted_pairs[i];
    EXPECT_GE(n, 1);
    if (n != np) {
      ++mismatches;
      EXPECT_EQ(n, np + 1) << "roll angle " << s.points[i].roll_angle_rad;
    }
    doubles += n == 2;
  }
  EXPECT_LE(mismatches, 2);
  // Double-pair share of the period near eps_alpha - 1 (one roll angle is 1/12 of it).
  EXPECT_NEAR(doubles / 12.0, pair.transverse_contact_ratio() - 1, 1.5 / 12);
  // Stiffness: two pairs stiffer than one; the single-pair level between the lumped single-pair
  // figures and the mean near ISO's c_gamma_alpha b and the TVMS mean. Band: the coarse mesh
  // (one element across the face, four along the flank) measured against twice the divisions in
  // every direction; see the header of flexible_gear_mesh.h for the numbers.
  EXPECT_GT(s.double_zone_stiffness_n_per_m, 1.2 * s.single_zone_stiffness_n_per_m);
  EXPECT_NEAR(s.mean_stiffness_n_per_m, iso.c_gamma_alpha_n_per_m, 0.15 * iso.c_gamma_alpha_n_per_m);
  EXPECT_NEAR(s.mean_stiffness_n_per_m, tvms.mean_n_per_m, 0.15 * tvms.mean_n_per_m);
}

}  // namespace
}  // namespace orrery::gears

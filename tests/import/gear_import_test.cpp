// A gear exported by the project's own STL writer and imported back (models/gear_geometry.h
// MakeGearMesh, models/stl.h, import/surface_mesh.h, import/mass_properties.h).
//
// Oracles for a spur gear (an extrusion of its outline over the face width b):
// 1. The STL's polyhedron is the extrusion of two polygons, the sampled outline P and the bore
//    polygon Q, so its volume, centre and inertia follow from 2-D polygon integrals (Green's
//    theorem, an algorithm independent of the 3-D divergence sums):
//      A = sum c_i / 2, int x^2 dA = sum c_i (x_i^2 + x_i x_j + x_j^2) / 12 (c_i = x_i y_j - x_j y_i),
//      V = b (A_P - A_Q), I_zz = rho b (J_P - J_Q), I_xx = rho b (int y^2)_(P - Q) + m b^2 / 12.
//    The import (float32 millimetres in the file) must match these to the float rounding (1e-6).
// 2. The exact gear: the outline P samples the exact profile (Gear::ProfileAt); between two
//    samples the curve leaves the chord by at most d_i, so the region between the chord and the
//    curve has area at most s_i d_i (s_i the chord length) and polar moment at most s_i d_i R_i^2
//    (R_i the largest radius there): |A_exact - A_P| <= sum s_i d_i, |J_exact - J_P| <= sum s_i d_i R_i^2.
//    d_i is measured on the outline sampled 64 times finer (whose every 64th point is P's); the
//    exact area is that fine polygon's, plus the bore circle exactly (pi r^2 against Q's
//    m r^2 sin(2 pi / m) / 2). The fine polygon's own error is second order, 64^2 times smaller
//    than P's: the bound carries a factor 1.001 for it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>

#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/surface_mesh.h"
#include "models/gear_geometry.h"
#include "models/stl.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
using Vec2 = Eigen::Vector2d;

// Area, polar moment and int y^2 dA of a closed polygon (counter-clockwise).
struct PolygonMoments {
  double area = 0, polar = 0, yy = 0;
};
PolygonMoments Moments(const std::vector<Vec2>& p) {
  PolygonMoments m;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 &a = p[i], &b = p[(i + 1) % p.size()];
    const double c = a.x() * b.y() - b.x() * a.y();
    m.area += c / 2;
    const double xx = c * (a.x() * a.x() + a.x() * b.x() + b.x() * b.x()) / 12;
    m.yy += c * (a.y() * a.y() + a.y() * b.y() + b.y() * b.y()) / 12;
    m.polar += xx;
  }
  m.polar += m.yy;
  return m;
}

TEST(GearImportTest, StlOfAGeneratedGearHasTheExactProfilesMassPropertiesWithinTheFacetingBound) {
  // Seed 001's planet (18 teeth, m_n 1.5 mm, alpha_n 21.3 deg, b 30 mm), 7 mm bore
  const gears::Gear gear({.teeth = 18, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kPi / 180,
                          .face_width_m = 0.03});
  const double b = 0.03, r_bore = 7e-3, rho = 7850;
  const gears::ProfileResolution res{.root = 3, .fillet = 6, .involute = 12, .tip = 3};
  const TriangleMesh generated = gears::MakeGearMesh(gear, res, 4, r_bore);

  // Export in millimetres, import with the stated unit
  const fs::path dir = test_meshes::ScratchDir("gear_stl");
  gears::WriteStlBinary(generated, (dir / "planet.stl").string(), {.scale = 1000});
  SurfaceMesh imported = ReadSurfaceMesh(dir / "planet.stl", {.unit = LengthUnit::kMillimetre});
  fs::remove_all(dir);
  EXPECT_EQ(imported.mesh.vertices.size(), generated.vertices.size());
  const MeshCheckReport report = CheckMesh(imported.mesh);
  EXPECT_TRUE(report.valid_solid());
  EXPECT_TRUE(report.flipped.empty());
  const MassProperties p = MassPropertiesOfSolid(imported.mesh, rho, report, "planet.stl");

  // 1. The polyhedron from its two polygons
  std::vector<Vec2> outline;
  for (const gears::ProfilePoint& q : gear.SampleGearOutline(res)) outline.push_back(q.p);
  const int m_bore = std::max(3 * gear.teeth(), static_cast<int>(outline.size()) / 3);  // as MakeGearMesh
  std::vector<Vec2> bore;
  for (int j = 0; j < m_bore; ++j) {
    const double a = -kPi / gear.teeth() + 2 * kPi * j / m_bore;
    bore.push_back(r_bore * Vec2(std::cos(a), std::sin(a)));
  }
  const PolygonMoments P = Moments(outline), Q = Moments(bore);
  const double area = P.area - Q.area, mass = rho * b * area;
  const double Izz = rho * b * (P.polar - Q.polar), Ixx = rho * b * (P.yy - Q.yy) + mass * b * b / 12;
  EXPECT_NEAR(p.volume_m3, b * area, 1e-6 * b * area);
  EXPECT_NEAR(p.inertia_kg_m2(2, 2), Izz, 1e-6 * Izz);
  EXPECT_NEAR(p.inertia_kg_m2(0, 0), Ixx, 1e-6 * Ixx);
  EXPECT_NEAR(p.inertia_kg_m2(1, 1), Ixx, 1e-6 * Ixx);
  EXPECT_LT((p.center_of_mass_m - Vec3(0, 0, b / 2)).norm(), 1e-9);

  // 2. The exact gear: outline 64 times finer, chord deviations, bore circle exactly
  constexpr int kFine = 64;
  const gears::ProfileResolution fine{res.root * kFine, res.fillet * kFine, res.involute * kFine, res.tip * kFine};
  std::vector<Vec2> dense;
  for (const gears::ProfilePoint& q : gear.SampleGearOutline(fine)) dense.push_back(q.p);
  ASSERT_EQ(dense.size(), kFine * outline.size());
  double area_bound = 0, polar_bound = 0;
  for (std::size_t i = 0; i < outline.size(); ++i) {
    ASSERT_LT((dense[kFine * i] - outline[i]).norm(), 1e-15);
    const Vec2 a = outline[i], c = outline[(i + 1) % outline.size()];
    const double s = (c - a).norm();
    const Vec2 u = (c - a) / s;
    double d = 0, r_max = std::max(a.norm(), c.norm());
    for (int k = 1; k < kFine; ++k) {
      const Vec2 x = dense[kFine * i + k];
      d = std::max(d, std::abs(u.x() * (x - a).y() - u.y() * (x - a).x()));
      r_max = std::max(r_max, x.norm());
    }
    area_bound += s * d;
    polar_bound += s * d * r_max * r_max;
  }
  area_bound *= 1.001;
  polar_bound *= 1.001;
  const PolygonMoments exact_outline = Moments(dense);
  const double disk_area = kPi * r_bore * r_bore, disk_polar = kPi * std::pow(r_bore, 4) / 2;
  const double exact_area = exact_outline.area - disk_area;
  const double exact_Izz = rho * b * (exact_outline.polar - disk_polar);
  const double bore_area_error = disk_area - Q.area, bore_polar_error = disk_polar - Q.polar;
  const double v_bound = b * (area_bound + bore_area_error) + 1e-6 * b * area;  // + the float rounding
  const double izz_bound = rho * b * (polar_bound + bore_polar_error) + 1e-6 * Izz;
  std::printf("gear: V %.9g m^3 (exact %.9g, |error| %.3g <= bound %.3g); I_zz %.9g kg m^2 (exact %.9g, |error| "
              "%.3g <= bound %.3g)\n",
              p.volume_m3, b * exact_area, std::abs(p.volume_m3 - b * exact_area), v_bound, p.inertia_kg_m2(2, 2),
              exact_Izz, std::abs(p.inertia_kg_m2(2, 2) - exact_Izz), izz_bound);
  EXPECT_LE(std::abs(p.volume_m3 - b * exact_area), v_bound);
  EXPECT_LE(std::abs(p.inertia_kg_m2(2, 2) - exact_Izz), izz_bound);
  // The bound is not vacuous: a tenth of a per cent of the volume at this coarse sampling
  EXPECT_LT(v_bound, 2e-3 * b * exact_area);
}

}  // namespace
}  // namespace orrery

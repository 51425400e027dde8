// Faulty tooth surfaces (models/tooth_fault_geometry.h). Oracles:
// - a spall's floor lies on the flank's involute turned by depth / r_b towards the tooth centre
//   (involutes of one base circle are parallel curves: offsetting along the normal, the base
//   circle's tangent, by d turns the involute by d / r_b), from the closed-form polar angle
//   psi(R) of ISO 21771;
// - a broken tooth keeps no vertex above r_break inside the broken range and every vertex of the
//   healthy part outside it;
// - topology: the closed faulty gear mesh is watertight (every directed edge once, its reverse
//   once), and the open tooth surface's boundary lies only on the end faces and the root lines;
// - volume: the closed mesh's volume (divergence theorem) drops by the removed cross-section
//   (shoelace area of the outline above the chord, finely sampled) times the broken width.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "models/tooth_fault_geometry.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

Gear Planet(double helix = 0) {
  return Gear({.teeth = 18, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kDeg,
               .helix_angle_rad = helix, .face_width_m = 0.03});
}

double Volume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6;
  return v;
}

// Directed edge counts: a closed, consistently oriented surface has each directed edge once and
// its reverse once.
bool Watertight(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : edges) {
    auto it = edges.find({e.second, e.first});
    if (n != 1 || it == edges.end() || it->second != 1) return false;
  }
  return true;
}

TEST(FaultyToothGeometry, SpallFloorIsTheTurnedInvolute) {
  const Gear g = Planet();
  const double rb = g.base_radius_m();
  const double rho_f = RollDistance(g, g.form_radius_m()), rho_a = RollDistance(g, g.tip_radius_m());
  const ToothFaultSpec spall{.kind = ToothFaultSpec::Kind::kSpall, .tooth = 2, .flank = ToothFaultSpec::Flank::kPlus,
                             .roll_start_m = rho_f + 0.3 * (rho_a - rho_f), .roll_end_m = rho_f + 0.6 * (rho_a - rho_f),
                             .axial_start_m = 0.01, .axial_end_m = 0.02, .depth_m = 50e-6};
  const TriangleMesh healthy = MakeToothSurfaceMesh(g, 2, {}, 12);
  const TriangleMesh faulty = MakeFaultyToothSurfaceMesh(g, 2, {}, 12, {spall});
  const double tooth_angle = 2 * kPi * 2 / g.teeth();
  int floor = 0;
  for (const Vec3& v : faulty.vertices) {
    const double r = v.head<2>().norm(), rho = RollDistance(g, r);
    const double polar = std::atan2(v.y(), v.x()) - tooth_angle;
    // Plus flank: polar angle psi(r) on the surface, psi(r) - d / r_b on the floor.
    if (v.z() > 0.01 + 1e-9 && v.z() < 0.02 - 1e-9 && polar > 0 && rho > spall.roll_start_m + 1e-6 &&
        rho < spall.roll_end_m - 1e-6) {
      EXPECT_NEAR(polar, g.HalfToothAngle(r) - spall.depth_m / rb, 1e-9) << "r " << r << " z " << v.z();
      ++floor;
    }
  }
  EXPECT_GT(floor, 10);
  // Walls: four more vertex rows; the surface is one piece whose boundary is on the end faces or
  // the root lines; area grows by the walls.
  EXPECT_GT(faulty.vertices.size(), healthy.vertices.size());
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : faulty.triangles)
    for (int k = 0; k < 3; ++k) ++edges[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  for (const auto& [e, n] : edges) {
    EXPECT_LE(n, 2);
    if (n == 1) {
      const Vec3 &a = faulty.vertices[e.first], &b = faulty.vertices[e.second];
      const bool end_face = (a.z() == 0 && b.z() == 0) || (a.z() == 0.03 && b.z() == 0.03);
      const bool root = std::abs(a.head<2>().norm() - g.root_radius_m()) < 1e-12 &&
                        std::abs(b.head<2>().norm() - g.root_radius_m()) < 1e-12;
      EXPECT_TRUE(end_face || root) << a.transpose() << " -- " << b.transpose();
    }
  }
}

TEST(FaultyToothGeometry, BrokenToothLosesItsTipOverTheBrokenWidth) {
  for (double helix : {0.0, 15 * kDeg}) {
    const Gear g = Planet(helix);
    const ToothFaultSpec broken{.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0, .height_fraction = 0.6,
                                .face_fraction = 0.4, .from_face = ToothFaultSpec::FromFace::kZmax};
    const double rbreak = BreakRadius(g, broken), b = g.spec().face_width_m;
    const TriangleMesh t = MakeFaultyToothSurfaceMesh(g, 0, {}, 5, {broken});
    int above_outside = 0;
    for (const Vec3& v : t.vertices) {
      const double r = v.head<2>().norm();
      if (v.z() > 0.6 * b + 1e-9) {
        EXPECT_LE(r, rbreak * (1 + 1e-12));
      }
      if (v.z() < 0.6 * b - 1e-9 && r > rbreak + 1e-4) ++above_outside;
    }
    EXPECT_GT(above_outside, 0);
    // The closed gear: watertight, and its volume drops by the cross-section above the chord
    // times the broken width (the helical twist turns the section, not its area).
    const TriangleMesh h = MakeFaultyGearMesh(g, {}, 5, 5e-3, {});
    const TriangleMesh f = MakeFaultyGearMesh(g, {}, 5, 5e-3, {broken});
    EXPECT_TRUE(Watertight(h));
    EXPECT_TRUE(Watertight(f));
    // Removed section: the finely sampled outline between the break points, closed by the chord.
    const double sa = ProfileParameterAtRadius(g, rbreak, false), sb = ProfileParameterAtRadius(g, rbreak, true);
    double twice = 0;
    const int n = 20000;
    Vec2 prev = g.ProfileAt(sa).p;
    for (int k = 1; k <= n; ++k) {
      const Vec2 p = g.ProfileAt(sa + (sb - sa) * k / n).p;
      twice += prev.x() * p.y() - prev.y() * p.x();
      prev = p;
    }
    const Vec2 a = g.ProfileAt(sa).p;
    twice += prev.x() * a.y() - prev.y() * a.x();
    // The meshes are polygons of the default resolution (24 involute and 6 tip intervals: the
    // chords lose about 5e-4 of the tip section, measured 2.6e-4), and a helical strip's flat
    // triangles cut the helicoid between face levels 0.12 rad of twist apart (a sagitta of 1.8e-3
    // of the radius; measured 1.9e-3 of the removed volume).
    const double removed = 0.5 * twice * 0.4 * b;
    const double drop = Volume(h) - Volume(f);
    std::printf("helix %.0f deg: volume drop %.6e m^3, removed section x width %.6e m^3\n", helix / kDeg, drop, removed);
    EXPECT_NEAR(drop, removed, (helix > 0 ? 4e-3 : 1e-3) * removed);
  }
}

TEST(FaultyToothGeometry, RejectsWhatItCannotBuild) {
  const Gear g = Planet();
  const ToothFaultSpec spall_at_face{.kind = ToothFaultSpec::Kind::kSpall, .roll_start_m = 6e-3, .roll_end_m = 6.5e-3,
                                     .axial_start_m = 0, .axial_end_m = 0.01, .depth_m = 1e-5};
  EXPECT_NO_THROW(MakeFaultyToothSurfaceMesh(g, 0, {}, 4, {spall_at_face}));
  EXPECT_THROW(MakeFaultyGearMesh(g, {}, 4, 5e-3, {spall_at_face}), std::invalid_argument);
  EXPECT_THROW(MakeFaultyToothSurfaceMesh(g, 0, {}, 0, {}), std::invalid_argument);
  EXPECT_THROW(ProfileParameterAtRadius(g, 2 * g.tip_radius_m(), true), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::gears

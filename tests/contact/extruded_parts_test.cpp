// Extruded parts of a contact surface (contact_surface.h): which parts are found to be a profile
// swept along z, and the face ExtrudedFaceAt names for a point on one, against the closest face
// by brute force over the part's triangles (triangle_geometry.h ClosestPointOnTriangle).
#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "contact/contact_surface.h"
#include "contact/triangle_geometry.h"
#include "models/gear_contact.h"
#include "models/gear_geometry.h"

namespace orrery::contact {
namespace {

// A profile of four points swept over rows at z = 0, 1, 3 mm, each rectangle split along the
// diagonal (i, k)-(i + 1, k + 1) or, with `other_diagonal`, along (i + 1, k)-(i, k + 1).
TriangleMesh SweptProfile(bool other_diagonal) {
  const std::vector<Eigen::Vector2d> profile = {
      {0, 0}, {1e-3, 0.2e-3}, {2e-3, 0.1e-3}, {2.5e-3, 1e-3}};
  const std::vector<double> z = {0, 1e-3, 3e-3};
  TriangleMesh m;
  for (double zk : z)
    for (const Eigen::Vector2d& p : profile) m.vertices.emplace_back(p.x(), p.y(), zk);
  const int n = static_cast<int>(profile.size());
  for (int k = 0; k + 1 < static_cast<int>(z.size()); ++k)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = k * n + i, b = a + 1, c = b + n, d = a + n;
      if (other_diagonal) {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      } else {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      }
    }
  return m;
}

// The smallest distance from x to a triangle of `part`.
double DistanceToPart(const ContactSurface& s, int part, const Vec3& x) {
  double best = std::numeric_limits<double>::infinity();
  for (int t = s.part_triangle_start()[part]; t < s.part_triangle_start()[part + 1]; ++t) {
    const auto& tri = s.triangles()[t];
    const Vec3 q =
        ClosestPointOnTriangle(x, s.vertices()[tri[0]], s.vertices()[tri[1]], s.vertices()[tri[2]])
            .point;
    best = std::min(best, (q - x).norm());
  }
  return best;
}

// Random points on every rectangle column of every extruded part (random position along the
// column's segment and random height): the face ExtrudedFaceAt names holds the point (its
// distance to it is the least over the part's faces, zero to the rounding). Returns the points
// checked.
int ExpectFacesHoldTheirPoints(const ContactSurface& s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int part = 0; part < s.num_parts(); ++part) {
    const int rows = s.part_rows()[part], n = s.part_row_length()[part];
    if (rows < 2) continue;
    const int first = s.part_vertex_start()[part];
    const double z0 = s.vertices()[first].z(), z1 = s.vertices()[first + (rows - 1) * n].z();
    for (int column = 0; column + 1 < n; column += std::max(1, n / 7)) {
      for (int sample = 0; sample < 12; ++sample) {
        const double t = sample == 0 ? 0.0 : sample == 1 ? 1.0 : unit(rng);
        const double z = sample == 2 ? z0 : sample == 3 ? z1 : z0 + (z1 - z0) * unit(rng);
        Vec3 x = (1 - t) * s.vertices()[first + column] + t * s.vertices()[first + column + 1];
        x.z() = z;
        const int face = s.ExtrudedFaceAt(part, column, x);
        if (face < s.part_triangle_start()[part] || face >= s.part_triangle_start()[part + 1]) {
          ADD_FAILURE() << "part " << part << " column " << column << ": face " << face;
          continue;
        }
        EXPECT_EQ(s.face_cell()[face] % (n - 1), column);
        const auto& tri = s.triangles()[face];
        const Vec3 q = ClosestPointOnTriangle(x, s.vertices()[tri[0]], s.vertices()[tri[1]],
                                              s.vertices()[tri[2]])
                           .point;
        // On the face as on the surface: the point is made to about 1e-17 m, the thin facets'
        // closest points to about 1e-15 m.
        EXPECT_LT((q - x).norm(), 1e-14)
            << "part " << part << " column " << column << " t " << t << " z " << z;
        EXPECT_LE((q - x).norm(), DistanceToPart(s, part, x) + 1e-15);
        ++checked;
      }
    }
  }
  return checked;
}

TEST(ExtrudedParts, ASweptProfileIsFoundWithEitherDiagonal) {
  for (bool other : {false, true}) {
    const ContactSurface s({SweptProfile(other)}, 50e-6);
    ASSERT_EQ(s.part_rows()[0], 3) << other;
    EXPECT_EQ(s.part_row_length()[0], 4);
    for (int t = 0; t < s.num_triangles(); ++t) {
      EXPECT_GE(s.face_cell()[t], 0);
      EXPECT_EQ(s.face_missing_corner()[t] % 2, other ? 0 : 1) << t;
    }
    EXPECT_EQ(ExpectFacesHoldTheirPoints(s, 7), 3 * 12);
  }
}

TEST(ExtrudedParts, OtherMeshesAreNot) {
  // A vertex of the top row moved sideways: the rows are not one profile.
  TriangleMesh moved = SweptProfile(false);
  moved.vertices[9].x() += 1e-9;
  // A rectangle's second half (a, c, d) replaced by (a, b, d): it overlaps the first, (a, b, c),
  // and the corner region at d is not covered.
  TriangleMesh folded = SweptProfile(false);
  folded.triangles[1] = {0, 1, 4};
  // A triangle spanning two rows.
  TriangleMesh tall = SweptProfile(false);
  tall.triangles[0] = {0, 1, 9};
  // Rows out of order in z.
  TriangleMesh unordered = SweptProfile(false);
  for (int i = 0; i < 4; ++i) unordered.vertices[8 + i].z() = 0.5e-3;
  for (const TriangleMesh& m : {moved, folded, tall, unordered}) {
    const ContactSurface s({m, SweptProfile(true)}, 50e-6);
    EXPECT_EQ(s.part_rows()[0], 0);
    EXPECT_EQ(s.part_rows()[1], 3);
    for (int t = s.part_triangle_start()[0]; t < s.part_triangle_start()[1]; ++t)
      EXPECT_EQ(s.face_cell()[t], -1);
  }
}

TEST(ExtrudedParts, SpurCrackedAndBrokenTeethAreExtrudedHelicalAndPartlyBrokenTeethAreNot) {
  const gears::Gear spur(
      gears::GearSpec{.teeth = 19, .normal_module_m = 2e-3, .face_width_m = 0.01});
  const gears::Gear helical(gears::GearSpec{
      .teeth = 19, .normal_module_m = 2e-3, .helix_angle_rad = 0.2, .face_width_m = 0.01});
  gears::GearContactOptions o;
  o.involute_intervals = 16;
  o.face_intervals = 2;
  const auto teeth = gears::MakeGearContactSurface(spur, o, {}, Transform());
  for (int part = 0; part < teeth->num_parts(); ++part) EXPECT_EQ(teeth->part_rows()[part], 3);
  EXPECT_GT(ExpectFacesHoldTheirPoints(*teeth, 11), 19 * 7 * 12 - 1);
  const auto twisted = gears::MakeGearContactSurface(helical, o, {}, Transform());
  for (int part = 0; part < twisted->num_parts(); ++part) EXPECT_EQ(twisted->part_rows()[part], 0);
  // Tooth 4 broken across half the face width: its surface is split at the break's axial end.
  const gears::ToothFaultSpec broken{.kind = gears::ToothFaultSpec::Kind::kBrokenTooth,
                                     .tooth = 4,
                                     .height_fraction = 0.5,
                                     .face_fraction = 0.5};
  const auto faulty = gears::MakeGearContactSurface(spur, o, {}, Transform(), {broken});
  for (int part = 0; part < faulty->num_parts(); ++part)
    EXPECT_EQ(faulty->part_rows()[part], part == 4 ? 0 : 3) << part;
  // Broken across the whole width (seed 003's fault): the fracture is a profile swept along z.
  gears::ToothFaultSpec through = broken;
  through.face_fraction = 1.0;
  const auto snapped = gears::MakeGearContactSurface(spur, o, {}, Transform(), {through});
  for (int part = 0; part < snapped->num_parts(); ++part)
    EXPECT_EQ(snapped->part_rows()[part], 3) << part;
  EXPECT_LT(snapped->part_row_length()[4], snapped->part_row_length()[3]);
  EXPECT_GT(ExpectFacesHoldTheirPoints(*snapped, 17), 19 * 7 * 12 - 1 - 7 * 12);
  // A root crack splits its tooth into two parts (the halves either side of its centre line):
  // both extruded, their rows splitting the profile between them.
  const gears::ToothFaultSpec crack{.kind = gears::ToothFaultSpec::Kind::kRootCrack,
                                    .tooth = 2,
                                    .crack_depth_m = 0.5e-3,
                                    .crack_angle_rad = 0.5};
  const auto cracked = gears::MakeGearContactSurface(spur, o, {}, Transform(), {crack}, {{2, 0.8}});
  ASSERT_EQ(cracked->num_parts(), 20);
  for (int part = 0; part < cracked->num_parts(); ++part)
    EXPECT_EQ(cracked->part_rows()[part], 3) << part;
  EXPECT_EQ(cracked->part_row_length()[2] + cracked->part_row_length()[3] - 1,
            teeth->part_row_length()[2]);
  EXPECT_GT(ExpectFacesHoldTheirPoints(*cracked, 13), 20 * 7 * 12 - 1);
}

}  // namespace
}  // namespace orrery::contact

// Mass properties of closed meshes (import/mass_properties.h) against closed forms.
// Exact for polyhedra (to rounding): a tetrahedron (its integrals by hand: int x^2 = 1/60,
// int xy = 1/120 over the unit corner tetrahedron), a box moved and turned (COM = R c + t,
// I = R I R^T), regular prisms (polygon area n r^2 sin(t) / 2 and polar moment
// n r^4 sin(t) (2 + cos(t)) / 12, t = 2 pi / n, each of the n triangles from the centre giving
// A/6 (|p|^2 + |q|^2 + p.q)). Converging with refinement to the smooth solids the primitives
// approximate, as the square of the facet size (the chord error of a curve): a cylinder (V = pi r^2 h,
// I_zz = m r^2 / 2, I_xx = m (3 r^2 + h^2) / 12), a sphere (V = 4/3 pi r^3, I = 2/5 m r^2) and a
// torus (V = 2 pi^2 R r^2, I_zz = m (R^2 + 3/4 r^2), I_xx = m (R^2 / 2 + 5/8 r^2)): halving the facet
// size divides the error by 4 (ratio asserted in [3.5, 4.5]) and the extrapolated limit is the
// closed form; the sphere also lies between its inner and outer balls (a rigorous bracket).
#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>

#include <Eigen/Geometry>

#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

using namespace test_meshes;
constexpr double kPi = std::numbers::pi;

double Rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

TEST(MassPropertiesTest, TetrahedronByHand) {
  TriangleMesh t{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)},
                 {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
  const MassProperties p = CalcMassProperties(t, 2.0);
  EXPECT_NEAR(p.volume_m3, 1.0 / 6, 1e-16);
  EXPECT_NEAR(p.mass_kg, 1.0 / 3, 1e-16);
  EXPECT_LT((p.center_of_mass_m - Vec3::Constant(0.25)).norm(), 1e-16);
  // About the centre: I_xx = 2 (1/30 - 1/48), I_xy = 2 (-(1/120 - 1/96))
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.inertia_kg_m2(k, k), 2.0 / 80, 1e-16);
  EXPECT_NEAR(p.inertia_kg_m2(0, 1), 2.0 / 480, 1e-16);
  EXPECT_NEAR(p.inertia_kg_m2(1, 2), 2.0 / 480, 1e-16);
  EXPECT_NEAR(p.inertia_kg_m2(0, 2), 2.0 / 480, 1e-16);
}

TEST(MassPropertiesTest, BoxMovedAndTurnedIsExact) {
  const double a = 0.1, b = 0.05, c = 0.02, rho = 7850;
  const double m = rho * a * b * c;
  const Mat3 I_box = Vec3(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12).asDiagonal();
  const Mat3 R = (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) * Eigen::AngleAxisd(-1.1, Vec3::UnitX())).toRotationMatrix();
  const Vec3 t(12.5, -3.0, 40.0);  // far from the origin: the bounding-box shift keeps the digits
  TriangleMesh box = Box(a, b, c);
  for (Vec3& v : box.vertices) v = R * v + t;
  const MassProperties p = CalcMassProperties(box, rho);
  EXPECT_LT(Rel(p.volume_m3, a * b * c), 1e-12);
  EXPECT_LT(Rel(p.mass_kg, m), 1e-12);
  EXPECT_LT((p.center_of_mass_m - (R * Vec3(a / 2, b / 2, c / 2) + t)).norm(), 1e-12);
  EXPECT_LT((p.inertia_kg_m2 - R * I_box * R.transpose()).norm(), 1e-10 * I_box.norm());
  // Principal moments: the box's own, ascending, with axes that diagonalize I
  EXPECT_LT(Rel(p.principal_moments_kg_m2[0], I_box(0, 0)), 1e-9);
  EXPECT_LT(Rel(p.principal_moments_kg_m2[2], I_box(2, 2)), 1e-9);
  EXPECT_NEAR(p.principal_axes.determinant(), 1.0, 1e-12);
}

TEST(MassPropertiesTest, RegularPrismIsExactAndConvergesToTheCylinder) {
  const double r = 0.03, h = 0.02, rho = 2700;
  const double m_cyl = rho * kPi * r * r * h;
  double previous_error = 0;
  for (int n : {16, 32, 64, 128}) {
    const double t = 2 * kPi / n;
    const double area = n * r * r * std::sin(t) / 2, polar = n * std::pow(r, 4) * std::sin(t) * (2 + std::cos(t)) / 12;
    const double m = rho * area * h;
    const MassProperties p = CalcMassProperties(Prism(r, h, n), rho);
    // The polyhedron, exactly
    EXPECT_LT(Rel(p.volume_m3, area * h), 1e-13) << n;
    EXPECT_LT(Rel(p.inertia_kg_m2(2, 2), rho * h * polar), 1e-12) << n;
    EXPECT_LT(Rel(p.inertia_kg_m2(0, 0), rho * h * polar / 2 + m * h * h / 12), 1e-12) << n;
    EXPECT_LT(std::abs(p.inertia_kg_m2(0, 1)), 1e-12 * p.inertia_kg_m2(0, 0));
    EXPECT_LT((p.center_of_mass_m - Vec3(0, 0, h / 2)).norm(), 1e-14);
    // The cylinder, as (2 pi / n)^2 / 6 relative in the volume
    const double error = Rel(p.mass_kg, m_cyl);
    EXPECT_NEAR(error, t * t / 6, 0.02 * t * t / 6) << n;
    EXPECT_LT(Rel(p.inertia_kg_m2(2, 2), m_cyl * r * r / 2), 2.1 * t * t / 6) << n;
    if (previous_error > 0) {
      EXPECT_NEAR(previous_error / error, 4.0, 0.05);
    }
    previous_error = error;
  }
}

// Volume, I_zz, I_xx for a sequence of refinements that halve the facet size each time, against
// their closed forms: the error falls as h^2 (ratio near 4), and the Richardson extrapolation
// (4 f(h/2) - f(h)) / 3 of the two finest removes the h^2 term, leaving an error far below the
// finest mesh's (asserted below a tenth of it): the limit is the closed form.
void ExpectConvergence(const std::vector<std::array<double, 3>>& values, const std::array<double, 3>& exact) {
  for (int k = 0; k < 3; ++k) {
    for (std::size_t i = 1; i < values.size(); ++i) {
      const double ratio = (values[i - 1][k] - exact[k]) / (values[i][k] - exact[k]);
      EXPECT_GT(ratio, 3.5) << "refinement " << i << " quantity " << k;
      EXPECT_LT(ratio, 4.5) << "refinement " << i << " quantity " << k;
    }
    const std::size_t n = values.size();
    const double finest = Rel(values[n - 1][k], exact[k]);
    const double richardson = Rel((4 * values[n - 1][k] - values[n - 2][k]) / 3, exact[k]);
    EXPECT_LT(richardson, 0.1 * finest) << "quantity " << k;
    std::printf("  quantity %d: finest relative error %.3g, extrapolated %.3g\n", k, finest, richardson);
  }
}

TEST(MassPropertiesTest, SphereConvergesAsTheSquareOfTheFacetSize) {
  const double r = 0.05, rho = 7850;
  const double v = 4.0 / 3 * kPi * r * r * r, m = rho * v, I = 0.4 * m * r * r;
  std::vector<std::array<double, 3>> values;
  for (int n : {16, 32, 64, 128}) {
    const TriangleMesh s = Sphere(r, n, 2 * n);
    ASSERT_TRUE(CheckMesh(s).valid_solid());
    const MassProperties p = CalcMassProperties(s, rho);
    values.push_back({p.volume_m3, p.inertia_kg_m2(2, 2), p.inertia_kg_m2(0, 0)});
    EXPECT_LT(p.center_of_mass_m.norm(), 1e-15);
    // Bracket: the inscribed polyhedron contains the ball of radius r_in (its nearest face plane)
    // and lies in the ball of radius r; volume and inertia about the centre grow with the set
    double r_in = r;
    for (const auto& t : s.triangles) {
      const Vec3 nrm = (s.vertices[t[1]] - s.vertices[t[0]]).cross(s.vertices[t[2]] - s.vertices[t[0]]).normalized();
      r_in = std::min(r_in, nrm.dot(s.vertices[t[0]]));
    }
    const double q = r_in / r;
    EXPECT_GE(p.volume_m3, v * q * q * q * (1 - 1e-12));
    EXPECT_LE(p.volume_m3, v);
    EXPECT_GE(p.inertia_kg_m2(0, 0), I * std::pow(q, 5) * (1 - 1e-12));
    EXPECT_LE(p.inertia_kg_m2(0, 0), I);
  }
  ExpectConvergence(values, {v, I, I});
}

TEST(MassPropertiesTest, TorusConvergesAsTheSquareOfTheFacetSize) {
  const double R = 0.1, r = 0.03, rho = 1000;
  const double v = 2 * kPi * kPi * R * r * r, m = rho * v;
  const double Izz = m * (R * R + 0.75 * r * r), Ixx = m * (R * R / 2 + 5.0 / 8 * r * r);
  std::vector<std::array<double, 3>> values;
  for (int n : {24, 48, 96, 192}) {
    const MassProperties p = CalcMassProperties(Torus(R, r, n, n / 2), rho);
    values.push_back({p.volume_m3, p.inertia_kg_m2(2, 2), p.inertia_kg_m2(0, 0)});
  }
  ExpectConvergence(values, {v, Izz, Ixx});
}

TEST(MassPropertiesTest, OpenOrInvertedMeshesAreRefused) {
  TriangleMesh open = Box(1, 1, 1);
  open.triangles.pop_back();
  MeshCheckReport r = CheckMesh(open);
  try {
    MassPropertiesOfSolid(open, 7850, r, "open.stl");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "open.stl: mass properties need a closed surface, but the mesh is not watertight (3 "
                           "boundary edges, 0 non-manifold edges)");
  }
  TriangleMesh inside_out = Box(1, 1, 1);
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  r = CheckMesh(inside_out);
  EXPECT_THROW(MassPropertiesOfSolid(inside_out, 7850, r, "x.stl"), std::runtime_error);  // not oriented yet
  OrientMesh(inside_out, r);
  EXPECT_NEAR(MassPropertiesOfSolid(inside_out, 7850, r, "x.stl").mass_kg, 7850, 1e-9);
  EXPECT_THROW(CalcMassProperties(Box(1, 1, 1), -1), std::invalid_argument);
  EXPECT_THROW(CalcMassProperties(Box(1, 1, 1), std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace orrery

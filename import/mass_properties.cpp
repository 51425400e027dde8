#include "import/mass_properties.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace orrery {
namespace {

// Eberly's subexpressions of one coordinate over a triangle.
struct Sub {
  double f1, f2, f3, g0, g1, g2;
};

Sub Subexpressions(double w0, double w1, double w2) {
  Sub s;
  const double t0 = w0 + w1;
  s.f1 = t0 + w2;
  const double t1 = w0 * w0;
  const double t2 = t1 + w1 * t0;
  s.f2 = t2 + w2 * s.f1;
  s.f3 = w0 * t1 + w1 * t2 + w2 * s.f2;
  s.g0 = s.f2 + w0 * (s.f1 + w0);
  s.g1 = s.f2 + w1 * (s.f1 + w1);
  s.g2 = s.f2 + w2 * (s.f1 + w2);
  return s;
}

std::string Num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

}  // namespace

MassProperties CalcMassProperties(const TriangleMesh& mesh, double density_kg_m3) {
  if (!(density_kg_m3 > 0) || !std::isfinite(density_kg_m3))
    throw std::invalid_argument("density must be finite and > 0 (kg/m^3), got " + Num(density_kg_m3));
  // Shift by the bounding box centre
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const Vec3& p : mesh.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vec3 shift = mesh.vertices.empty() ? Vec3::Zero() : Vec3(0.5 * (lo + hi));

  // Integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the solid
  double in[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (const auto& t : mesh.triangles) {
    const Vec3 p0 = mesh.vertices[t[0]] - shift, p1 = mesh.vertices[t[1]] - shift, p2 = mesh.vertices[t[2]] - shift;
    const Vec3 d = (p1 - p0).cross(p2 - p0);
    const Sub x = Subexpressions(p0.x(), p1.x(), p2.x());
    const Sub y = Subexpressions(p0.y(), p1.y(), p2.y());
    const Sub z = Subexpressions(p0.z(), p1.z(), p2.z());
    in[0] += d.x() * x.f1;
    in[1] += d.x() * x.f2;
    in[2] += d.y() * y.f2;
    in[3] += d.z() * z.f2;
    in[4] += d.x() * x.f3;
    in[5] += d.y() * y.f3;
    in[6] += d.z() * z.f3;
    in[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    in[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    in[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  const double scale[10] = {1.0 / 6, 1.0 / 24, 1.0 / 24, 1.0 / 24, 1.0 / 60, 1.0 / 60, 1.0 / 60,
                            1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (int k = 0; k < 10; ++k) in[k] *= scale[k];

  // Volume, mass, centre, inertia about the centre (density rho)
  MassProperties p;
  p.volume_m3 = in[0];
  p.mass_kg = density_kg_m3 * in[0];
  const Vec3 c(in[1] / in[0], in[2] / in[0], in[3] / in[0]);
  const double rho = density_kg_m3, m = p.mass_kg;
  Mat3& I = p.inertia_kg_m2;
  I(0, 0) = rho * (in[5] + in[6]) - m * (c.y() * c.y() + c.z() * c.z());
  I(1, 1) = rho * (in[4] + in[6]) - m * (c.z() * c.z() + c.x() * c.x());
  I(2, 2) = rho * (in[4] + in[5]) - m * (c.x() * c.x() + c.y() * c.y());
  I(0, 1) = I(1, 0) = -(rho * in[7] - m * c.x() * c.y());
  I(1, 2) = I(2, 1) = -(rho * in[8] - m * c.y() * c.z());
  I(0, 2) = I(2, 0) = -(rho * in[9] - m * c.z() * c.x());
  p.center_of_mass_m = c + shift;

  // Principal moments and axes
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
  p.principal_moments_kg_m2 = eig.eigenvalues();
  p.principal_axes = eig.eigenvectors();
  if (p.principal_axes.determinant() < 0) p.principal_axes.col(2) *= -1;
  return p;
}

MassProperties MassPropertiesOfSolid(const TriangleMesh& mesh, double density_kg_m3, const MeshCheckReport& report,
                                     const std::string& source) {
  if (report.boundary_edges > 0 || report.non_manifold_edges > 0)
    throw std::runtime_error(source + ": mass properties need a closed surface, but the mesh is not watertight (" +
                             std::to_string(report.boundary_edges) + " boundary edges, " +
                             std::to_string(report.non_manifold_edges) + " non-manifold edges)");
  if (report.non_orientable_components > 0)
    throw std::runtime_error(source + ": mass properties need an orientable surface (" +
                             std::to_string(report.non_orientable_components) + " non-orientable components)");
  MassProperties p;
  try {
    p = CalcMassProperties(mesh, density_kg_m3);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + ": " + e.what());
  }
  if (!(p.volume_m3 > 0))
    throw std::runtime_error(source + ": the enclosed volume is " + Num(p.volume_m3) +
                             " m^3: not a solid (orient the mesh with CheckMesh / OrientMesh first)");
  return p;
}

}  // namespace orrery

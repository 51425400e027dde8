#include "models/imported_gear.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

std::string Mm(double m) { return std::to_string(m * 1e3) + " mm"; }

// Angle of p about z less the helix twist at its height, relative to tooth k's centre, wrapped
// into [-pi, pi).
double ToothRelativeAngle(const Vec3& p, double twist, double centre) {
  double d = std::atan2(p.y(), p.x()) - twist * p.z() - centre;
  return d - 2 * kPi * std::floor((d + kPi) / (2 * kPi));
}

// The radius and face checks of the header.
void CheckExtent(const TriangleMesh& mesh, const Gear& gear, const std::string& source) {
  double r_max = 0, z_min = 1e300, z_max = -1e300;
  for (const Vec3& v : mesh.vertices) {
    r_max = std::max(r_max, std::hypot(v.x(), v.y()));
    z_min = std::min(z_min, v.z());
    z_max = std::max(z_max, v.z());
  }
  const double tol = kImportedGearTolerance * gear.spec().normal_module_m;
  const double b = gear.spec().face_width_m;
  if (std::abs(r_max - gear.tip_radius_m()) > tol)
    throw std::invalid_argument(source + ": imported gear reaches " + Mm(r_max) +
                                " from its axis, the train's gear has " + "its tip at " +
                                Mm(gear.tip_radius_m()) +
                                " (is the unit right? the part in the gear " + "frame, axis z?)");
  if (std::abs(z_min) > tol || std::abs(z_max - b) > tol)
    throw std::invalid_argument(source + ": imported gear's faces lie at z = " + Mm(z_min) +
                                " and " + Mm(z_max) + ", the train's gear spans z = 0 to " + Mm(b) +
                                " (its face width)");
}

}  // namespace

std::vector<TriangleMesh> SplitImportedGearTeeth(const TriangleMesh& mesh, const Gear& gear,
                                                 const std::string& source) {
  if (gear.internal())
    throw std::invalid_argument(source + ": an imported internal gear (ring) is not supported");
  CheckExtent(mesh, gear, source);
  const int z = gear.teeth();
  const double pitch = 2 * kPi / z, twist = gear.twist_per_length();
  const double r_select = gear.root_radius_m() - 0.25 * gear.spec().normal_module_m;
  std::vector<TriangleMesh> teeth(z);
  std::vector<std::vector<int>> index(z, std::vector<int>(mesh.vertices.size(), -1));
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    // The toothed boundary only: beyond r_select, not an end face
    const Vec3 n = (b - a).cross(c - a);
    if (!(n.norm() > 0) || std::abs(n.z()) >= 0.5 * n.norm()) continue;
    if (std::min({std::hypot(a.x(), a.y()), std::hypot(b.x(), b.y()), std::hypot(c.x(), c.y())}) <
        r_select)
      continue;
    // The tooth sector of the centroid
    const double d = ToothRelativeAngle((a + b + c) / 3, twist, 0);
    const int k = ((static_cast<int>(std::lround(d / pitch)) % z) + z) % z;
    TriangleMesh& part = teeth[k];
    std::array<int, 3> out{};
    for (int j = 0; j < 3; ++j) {
      int& v = index[k][t[j]];
      if (v < 0) {
        v = static_cast<int>(part.vertices.size());
        part.vertices.push_back(mesh.vertices[t[j]]);
      }
      out[j] = v;
    }
    part.triangles.push_back(out);
  }
  // Every tooth present and centred where the train's teeth are
  for (int k = 0; k < z; ++k) {
    if (teeth[k].triangles.empty())
      throw std::invalid_argument(source + ": imported gear has no toothed surface about tooth " +
                                  std::to_string(k) + " (polar angle " +
                                  std::to_string(k * 360.0 / z) + " deg): is it a gear of " +
                                  std::to_string(z) + " teeth?");
    for (const Vec3& v : teeth[k].vertices) {
      if (std::hypot(v.x(), v.y()) <= gear.reference_radius_m()) continue;
      const double d = ToothRelativeAngle(v, twist, k * pitch);
      if (std::abs(d) > 0.4 * pitch)
        throw std::invalid_argument(
            source + ": imported gear's tooth " + std::to_string(k) + " is not centred on " +
            std::to_string(k * 360.0 / z) + " deg (a point above the reference circle lies " +
            std::to_string(d * 180 / kPi) +
            " deg from it): turn the part so that a tooth is centred on +x");
    }
  }
  return teeth;
}

}  // namespace orrery::gears

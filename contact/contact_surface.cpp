#include "contact/contact_surface.h"

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "contact/candidate_pairs.h"

namespace orrery::contact {

ContactSurface::ContactSurface(const std::vector<gears::TriangleMesh>& parts, double margin_m,
                               double slack_m, std::optional<ToothRing> tooth_ring)
    : tooth_ring_(std::move(tooth_ring)), margin_m_(margin_m), slack_m_(slack_m) {
  if (!(margin_m > 0))
    throw std::invalid_argument("ContactSurface: margin_m must be > 0, got " +
                                std::to_string(margin_m));
  if (!(slack_m >= 0))
    throw std::invalid_argument("ContactSurface: slack_m must be >= 0, got " +
                                std::to_string(slack_m));
  // Concatenate the parts, offsetting the vertex indices.
  part_triangle_start_.push_back(0);
  part_vertex_start_.push_back(0);
  for (size_t j = 0; j < parts.size(); ++j) {
    const gears::TriangleMesh& part = parts[j];
    if (part.triangles.empty())
      throw std::invalid_argument("ContactSurface: part " + std::to_string(j) + " is empty");
    const int offset = static_cast<int>(vertices_.size());
    const int nv = static_cast<int>(part.vertices.size());
    vertices_.insert(vertices_.end(), part.vertices.begin(), part.vertices.end());
    for (const auto& t : part.triangles) {
      for (int k = 0; k < 3; ++k)
        if (t[k] < 0 || t[k] >= nv)
          throw std::invalid_argument("ContactSurface: part " + std::to_string(j) +
                                      " has a triangle index out of range: " +
                                      std::to_string(t[k]));
      triangles_.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
    part_triangle_start_.push_back(static_cast<int>(triangles_.size()));
    part_vertex_start_.push_back(static_cast<int>(vertices_.size()));
  }
  if (triangles_.empty()) throw std::invalid_argument("ContactSurface: no triangles");

  // Face normals and the area weights of the vertices (one third of each incident triangle).
  vertex_areas_.assign(vertices_.size(), 0.0);
  vertex_normals_.assign(vertices_.size(), Vec3::Zero());
  face_normals_.reserve(triangles_.size());
  for (size_t t = 0; t < triangles_.size(); ++t) {
    const auto& tri = triangles_[t];
    const Vec3 n2 = (vertices_[tri[1]] - vertices_[tri[0]]).cross(vertices_[tri[2]] - vertices_[tri[0]]);
    const double area = 0.5 * n2.norm();
    if (!(area > 0))
      throw std::invalid_argument("ContactSurface: triangle " + std::to_string(t) +
                                  " is degenerate (zero area)");
    face_normals_.push_back(n2.normalized());
    total_area_ += area;
    for (int k = 0; k < 3; ++k) {
      vertex_areas_[tri[k]] += area / 3.0;
      vertex_normals_[tri[k]] += area * face_normals_.back();
    }
  }
  for (Vec3& n : vertex_normals_)
    if (n.squaredNorm() > 0) n.normalize();

  // Boundary edges: undirected edges used by one triangle only.
  std::map<std::pair<int, int>, int> edge_uses;
  for (const auto& tri : triangles_)
    for (int k = 0; k < 3; ++k)
      ++edge_uses[std::minmax(tri[k], tri[(k + 1) % 3])];
  boundary_edges_.assign(triangles_.size(), 0);
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (edge_uses[std::minmax(triangles_[t][k], triangles_[t][(k + 1) % 3])] == 1)
        boundary_edges_[t] |= static_cast<std::uint8_t>(1u << k);

  // Bounding sphere of every part (centre of its box, farthest vertex) and the largest radius.
  for (int j = 0; j < num_parts(); ++j) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int v = part_vertex_start_[j]; v < part_vertex_start_[j + 1]; ++v) {
      lo = lo.cwiseMin(vertices_[v]);
      hi = hi.cwiseMax(vertices_[v]);
    }
    const Vec3 c = 0.5 * (lo + hi);
    double r = 0;
    for (int v = part_vertex_start_[j]; v < part_vertex_start_[j + 1]; ++v)
      r = std::max(r, (vertices_[v] - c).norm());
    part_centers_.push_back(c);
    part_radii_.push_back(r);
  }
  for (const Vec3& v : vertices_) max_vertex_radius_m_ = std::max(max_vertex_radius_m_, v.norm());

  // Bounding sphere of every triangle: centroid and farthest vertex.
  triangle_centers_.reserve(triangles_.size());
  triangle_radii_.reserve(triangles_.size());
  for (const auto& tri : triangles_) {
    const Vec3 c = (vertices_[tri[0]] + vertices_[tri[1]] + vertices_[tri[2]]) / 3.0;
    double r = 0;
    for (int k = 0; k < 3; ++k) r = std::max(r, (vertices_[tri[k]] - c).norm());
    triangle_centers_.push_back(c);
    triangle_radii_.push_back(r);
  }

  if (tooth_ring_) {
    if (static_cast<int>(tooth_ring_->part_angles_rad.size()) != num_parts())
      throw std::invalid_argument("ContactSurface: the tooth ring has " +
                                  std::to_string(tooth_ring_->part_angles_rad.size()) +
                                  " part angles for " + std::to_string(num_parts()) + " parts");
    if (!(tooth_ring_->inner_radius_m >= 0 &&
          tooth_ring_->inner_radius_m < tooth_ring_->outer_radius_m))
      throw std::invalid_argument("ContactSurface: the tooth ring needs 0 <= inner < outer radius");
  }

  culling_ = BuildCullingGeometry(*this);
}

ContactSurface::~ContactSurface() = default;

}  // namespace orrery::contact

#include "contact/contact_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "contact/candidate_pairs.h"
#include "contact/triangle_geometry.h"

namespace orrery::contact {
namespace {
// An interior edge whose normals turn by more than this is sharp (header: the inner reach and
// the smoothed normals).
constexpr double kSharpEdgeDeg = 10.0;
}  // namespace

ContactSurface::ContactSurface(const std::vector<TriangleMesh>& parts, double margin_m,
                               double slack_m, std::optional<PartRing> part_ring,
                               std::vector<double> part_stiffness_scale, bool smooth_normals)
    : part_ring_(std::move(part_ring)), margin_m_(margin_m), slack_m_(slack_m) {
  if (!(margin_m > 0))
    throw std::invalid_argument("ContactSurface: margin_m must be > 0, got " +
                                std::to_string(margin_m));
  if (!(slack_m >= 0))
    throw std::invalid_argument("ContactSurface: slack_m must be >= 0, got " +
                                std::to_string(slack_m));
  ConcatenateParts(parts);
  CalcFaceNormalsAndAreas();
  CalcAdjacency();
  CalcBoundingSpheres();
  CalcRimFades();
  CalcInnerReach();
  if (smooth_normals) CalcCornerNormals();
  CheckPartRing();
  SetStiffnessScales(std::move(part_stiffness_scale));
  culling_ = BuildCullingGeometry(*this);
  CalcSharedRimEdges();
  FindExtrudedParts();
}

void ContactSurface::FindExtrudedParts() {
  part_rows_.assign(num_parts(), 0);
  part_row_length_.assign(num_parts(), 0);
  face_cell_.assign(triangles_.size(), -1);
  face_missing_corner_.assign(triangles_.size(), -1);
  part_cell_start_.assign(num_parts() + 1, 0);
  for (int j = 0; j < num_parts(); ++j) {
    const int first = part_vertex_start_[j], nv = part_vertex_start_[j + 1] - first;
    // Row 0: the vertices from the part's first at its height.
    int n = 0;
    while (n < nv && vertices_[first + n].z() == vertices_[first].z()) ++n;
    if (n >= 2 && nv % n == 0 && nv / n >= 2 && ExtrudedPart(j, nv / n, n)) {
      part_rows_[j] = nv / n;
      part_row_length_[j] = n;
    } else {
      for (int t = part_triangle_start_[j]; t < part_triangle_start_[j + 1]; ++t) {
        face_cell_[t] = -1;
        face_missing_corner_[t] = -1;
      }
    }
    part_cell_start_[j + 1] = static_cast<int>(cell_faces_.size());
  }
}

bool ContactSurface::ExtrudedPart(int j, int rows, int n) {
  const int first = part_vertex_start_[j];
  const int t0 = part_triangle_start_[j], t1 = part_triangle_start_[j + 1];
  const int cells = (rows - 1) * (n - 1);
  if (t1 - t0 != 2 * cells) return false;
  for (int k = 0; k < rows; ++k) {
    const double z = vertices_[first + k * n].z();
    if (k > 0 && !(z > vertices_[first + (k - 1) * n].z())) return false;
    for (int i = 0; i < n; ++i) {
      const Vec3& v = vertices_[first + k * n + i];
      const Vec3& v0 = vertices_[first + i];
      if (v.x() != v0.x() || v.y() != v0.y() || v.z() != z) return false;
    }
  }
  for (int i = 0; i + 1 < n; ++i)
    if (vertices_[first + i].x() == vertices_[first + i + 1].x() &&
        vertices_[first + i].y() == vertices_[first + i + 1].y())
      return false;
  // Every face a half of one rectangle, each rectangle split along one diagonal into two.
  const size_t start = cell_faces_.size();
  cell_faces_.resize(start + 2 * cells, -1);
  for (int t = t0; t < t1; ++t) {
    int k_lo = rows, k_hi = -1, i_lo = n, i_hi = -1;
    for (int c = 0; c < 3; ++c) {
      const int l = triangles_[t][c] - first;
      k_lo = std::min(k_lo, l / n);
      k_hi = std::max(k_hi, l / n);
      i_lo = std::min(i_lo, l % n);
      i_hi = std::max(i_hi, l % n);
    }
    if (k_hi != k_lo + 1 || i_hi != i_lo + 1) {
      cell_faces_.resize(start);
      return false;
    }
    // The corners (i, k), (i + 1, k), (i + 1, k + 1), (i, k + 1) as 0..3; the one not used.
    const int corner_vertex[4] = {first + k_lo * n + i_lo, first + k_lo * n + i_lo + 1,
                                  first + (k_lo + 1) * n + i_lo + 1, first + (k_lo + 1) * n + i_lo};
    int missing = -1;
    for (int c = 0; c < 4; ++c)
      if (std::find(triangles_[t].begin(), triangles_[t].end(), corner_vertex[c]) ==
          triangles_[t].end())
        missing = c;
    const int cell = k_lo * (n - 1) + i_lo;
    int* slot = &cell_faces_[start + 2 * cell];
    if (slot[0] >= 0 && slot[1] >= 0) {
      cell_faces_.resize(start);
      return false;
    }
    // The second half must leave out the opposite corner (the same diagonal).
    if (slot[0] >= 0 && (face_missing_corner_[slot[0]] + 2) % 4 != missing) {
      cell_faces_.resize(start);
      return false;
    }
    (slot[0] < 0 ? slot[0] : slot[1]) = t;
    face_cell_[t] = cell;
    face_missing_corner_[t] = static_cast<std::int8_t>(missing);
  }
  return true;
}

int ContactSurface::ExtrudedFaceAt(int part, int column, const Vec3& x_B) const {
  return ExtrudedFaceAt(part, column, ExtrudedColumnFraction(part, column, x_B), x_B.z());
}

double ContactSurface::ExtrudedColumnFraction(int part, int column, const Vec3& x_B) const {
  const int first = part_vertex_start_[part];
  const Vec3& a = vertices_[first + column];
  const Vec3& b = vertices_[first + column + 1];
  const double ex = b.x() - a.x(), ey = b.y() - a.y();
  return std::clamp(((x_B.x() - a.x()) * ex + (x_B.y() - a.y()) * ey) / (ex * ex + ey * ey), 0.0,
                    1.0);
}

int ContactSurface::ExtrudedFaceAt(int part, int column, double t, double z) const {
  return ExtrudedFaceAt(part, column, t, ExtrudedRowPlace(part, z));
}

ContactSurface::RowPlace ContactSurface::ExtrudedRowPlace(int part, double z) const {
  const int n = part_row_length_[part], rows = part_rows_[part];
  const int first = part_vertex_start_[part];
  int k = 0;
  while (k + 2 < rows && z >= vertices_[first + (k + 1) * n].z()) ++k;
  const double z0 = vertices_[first + k * n].z(), z1 = vertices_[first + (k + 1) * n].z();
  return {k, std::clamp((z - z0) / (z1 - z0), 0.0, 1.0)};
}

int ContactSurface::ExtrudedFaceAt(int part, int column, double t, RowPlace place) const {
  const int n = part_row_length_[part];
  const double u = place.u;
  const int* faces = &cell_faces_[part_cell_start_[part] + 2 * (place.interval * (n - 1) + column)];
  // The half that leaves out corner m holds the points on the other side of the diagonal.
  auto holds = [&](int face) {
    switch (face_missing_corner_[face]) {
      case 3: return u <= t;       // (i, k), (i + 1, k), (i + 1, k + 1)
      case 1: return u >= t;       // (i, k), (i + 1, k + 1), (i, k + 1)
      case 2: return t + u <= 1;   // (i, k), (i + 1, k), (i, k + 1)
      default: return t + u >= 1;  // (i + 1, k), (i + 1, k + 1), (i, k + 1)
    }
  };
  return holds(faces[0]) ? faces[0] : faces[1];
}

void ContactSurface::SetStiffnessScales(std::vector<double> part_scale) {
  // Stiffness scale of every vertex and face from its part.
  if (part_scale.empty()) part_scale.assign(num_parts(), 1.0);
  if (static_cast<int>(part_scale.size()) != num_parts())
    throw std::invalid_argument("ContactSurface: part_stiffness_scale has " + std::to_string(part_scale.size()) +
                                " values for " + std::to_string(num_parts()) + " parts");
  for (double f : part_scale)
    if (!(f > 0) || !std::isfinite(f))
      throw std::invalid_argument("ContactSurface: part_stiffness_scale values must be > 0 and finite, got " +
                                  std::to_string(f));
  vertex_stiffness_scale_.resize(vertices_.size());
  for (size_t v = 0; v < vertices_.size(); ++v) vertex_stiffness_scale_[v] = part_scale[vertex_parts_[v]];
  face_stiffness_scale_.resize(triangles_.size());
  for (int j = 0; j < num_parts(); ++j)
    std::fill(face_stiffness_scale_.begin() + part_triangle_start_[j],
              face_stiffness_scale_.begin() + part_triangle_start_[j + 1], part_scale[j]);
}

void ContactSurface::ConcatenateParts(const std::vector<TriangleMesh>& parts) {
  // Concatenate the parts, offsetting the vertex indices.
  part_triangle_start_.push_back(0);
  part_vertex_start_.push_back(0);
  for (size_t j = 0; j < parts.size(); ++j) {
    const TriangleMesh& part = parts[j];
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
}

void ContactSurface::CalcFaceNormalsAndAreas() {
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
}

void ContactSurface::CalcAdjacency() {
  // Boundary edges: undirected edges used by one triangle only. Neighbours: the other triangle
  // of an edge used by exactly two.
  std::map<std::pair<int, int>, std::vector<int>> edge_faces;
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k)
      edge_faces[std::minmax(triangles_[t][k], triangles_[t][(k + 1) % 3])].push_back(
          static_cast<int>(t));
  boundary_edges_.assign(triangles_.size(), 0);
  face_neighbors_.assign(triangles_.size(), {-1, -1, -1});
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& faces = edge_faces[std::minmax(triangles_[t][k], triangles_[t][(k + 1) % 3])];
      if (faces.size() == 1) boundary_edges_[t] |= static_cast<std::uint8_t>(1u << k);
      if (faces.size() == 2)
        face_neighbors_[t][k] = faces[0] == static_cast<int>(t) ? faces[1] : faces[0];
    }
  vertex_on_rim_.assign(vertices_.size(), 0);
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (boundary_edges_[t] & (1u << k))
        vertex_on_rim_[triangles_[t][k]] = vertex_on_rim_[triangles_[t][(k + 1) % 3]] = 1;
  // Triangles around each vertex (compressed rows, increasing triangle order).
  vertex_face_start_.assign(vertices_.size() + 1, 0);
  for (const auto& tri : triangles_)
    for (int k = 0; k < 3; ++k) ++vertex_face_start_[tri[k] + 1];
  for (size_t v = 0; v < vertices_.size(); ++v) vertex_face_start_[v + 1] += vertex_face_start_[v];
  vertex_faces_.resize(vertex_face_start_.back());
  {
    std::vector<int> next(vertex_face_start_.begin(), vertex_face_start_.end() - 1);
    for (size_t t = 0; t < triangles_.size(); ++t)
      for (int k = 0; k < 3; ++k) vertex_faces_[next[triangles_[t][k]]++] = static_cast<int>(t);
  }
  vertex_parts_.resize(vertices_.size());
  for (int j = 0; j < num_parts(); ++j)
    std::fill(vertex_parts_.begin() + part_vertex_start_[j],
              vertex_parts_.begin() + part_vertex_start_[j + 1], j);
}

void ContactSurface::CalcBoundingSpheres() {
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
    part_half_extents_.push_back(0.5 * (hi - lo));
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
}

void ContactSurface::CalcRimFades() {
  // Rim fade of every face with a rim edge (header): a tenth of its height 2 A / |edge| across
  // the edge.
  // The outward direction of a rim edge: in the face's plane, across the edge, away from the
  // face's third vertex.
  face_rim_fade_.assign(triangles_.size(), 0.0);
  face_rim_outward_.assign(triangles_.size(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  for (size_t t = 0; t < triangles_.size(); ++t) {
    const auto& tri = triangles_[t];
    const Vec3 &a = vertices_[tri[0]], &b = vertices_[tri[1]], &c = vertices_[tri[2]];
    const double twice_area = (b - a).cross(c - a).norm();
    double fade = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      if (!(boundary_edges_[t] & (1u << k))) continue;
      const Vec3& e0 = vertices_[tri[k]];
      const Vec3 edge = vertices_[tri[(k + 1) % 3]] - e0;
      fade = std::min(fade, 0.1 * twice_area / edge.norm());
      Vec3 m = edge.cross(face_normals_[t]).normalized();
      if (m.dot(vertices_[tri[(k + 2) % 3]] - e0) > 0) m = -m;
      face_rim_outward_[t][k] = m;
    }
    if (std::isfinite(fade)) face_rim_fade_[t] = fade;
  }
  vertex_rim_fade_.assign(vertices_.size(), std::numeric_limits<double>::infinity());
  for (size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (boundary_edges_[t] & (1u << k))
        for (const int v : {triangles_[t][k], triangles_[t][(k + 1) % 3]})
          vertex_rim_fade_[v] = std::min(vertex_rim_fade_[v], face_rim_fade_[t]);
  for (double& f : vertex_rim_fade_)
    if (!std::isfinite(f)) f = 0;
}

void ContactSurface::CalcCornerNormals() {
  // Around each vertex v: the faces joined across smooth edges at v (union-find over the
  // faces around v), then each group's angle-weighted normal sum (header).
  const double smooth = std::cos(kSharpEdgeDeg * 3.14159265358979323846 / 180.0);
  face_corner_normals_.assign(triangles_.size(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  std::vector<int> group;
  std::vector<Vec3> sum;
  std::vector<double> angle;
  std::vector<int> group_id;
  std::vector<std::vector<std::pair<int, double>>> groups(3 * triangles_.size());
  corner_group_.assign(3 * triangles_.size(), -1);
  num_corner_groups_ = 0;
  for (int v = 0; v < num_vertices(); ++v) {
    const int begin = vertex_face_start_[v], end = vertex_face_start_[v + 1];
    const int nf = end - begin;
    group.resize(nf);
    for (int i = 0; i < nf; ++i) group[i] = i;
    auto root = [&](int i) {
      while (group[i] != i) i = group[i] = group[group[i]];
      return i;
    };
    auto corner = [&](int t) {
      const auto& tri = triangles_[t];
      return tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
    };
    for (int i = 0; i < nf; ++i) {
      const int t = vertex_faces_[begin + i];
      const int k = corner(t);
      // The two edges of t at v: k (v, next) and k + 2 (previous, v).
      for (const int e : {k, (k + 2) % 3}) {
        const int n = face_neighbors_[t][e];
        if (n < 0 || face_normals_[t].dot(face_normals_[n]) < smooth) continue;
        const int j = static_cast<int>(
            std::lower_bound(vertex_faces_.begin() + begin, vertex_faces_.begin() + end, n) -
            (vertex_faces_.begin() + begin));
        group[root(i)] = root(j);
      }
    }
    sum.assign(nf, Vec3::Zero());
    angle.resize(nf);
    for (int i = 0; i < nf; ++i) {
      const int t = vertex_faces_[begin + i];
      const int k = corner(t);
      const auto& tri = triangles_[t];
      const Vec3 e1 = (vertices_[tri[(k + 1) % 3]] - vertices_[v]).normalized();
      const Vec3 e2 = (vertices_[tri[(k + 2) % 3]] - vertices_[v]).normalized();
      angle[i] = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      sum[root(i)] += angle[i] * face_normals_[t];
    }
    // One group id per root, in the order of the roots' first faces.
    group_id.assign(nf, -1);
    for (int i = 0; i < nf; ++i)
      if (group_id[root(i)] < 0) group_id[root(i)] = num_corner_groups_++;
    for (int i = 0; i < nf; ++i) {
      const int t = vertex_faces_[begin + i];
      const int k = corner(t);
      face_corner_normals_[t][k] = sum[root(i)].normalized();
      corner_group_[3 * t + k] = group_id[root(i)];
      auto& list = groups[3 * t + k];
      for (int j = 0; j < nf; ++j)
        if (root(j) == root(i)) list.emplace_back(vertex_faces_[begin + j], angle[j]);
    }
  }
  // The groups as compressed rows, corner by corner.
  corner_face_start_.assign(3 * triangles_.size() + 1, 0);
  for (size_t c = 0; c < groups.size(); ++c)
    corner_face_start_[c + 1] = corner_face_start_[c] + static_cast<int>(groups[c].size());
  corner_faces_.reserve(corner_face_start_.back());
  corner_weights_.reserve(corner_face_start_.back());
  for (const auto& list : groups)
    for (const auto& [f, a] : list) {
      corner_faces_.push_back(f);
      corner_weights_.push_back(a);
    }
}

void ContactSurface::CalcInnerReach() {
  // Inner reach of every face (header): sharp interior edges per part, then the distance of
  // each face from the nearest, capped by a quarter of the radius of curvature L / angle across
  // each edge (L: distance between the two centroids).
  const double sharp = std::cos(kSharpEdgeDeg * 3.14159265358979323846 / 180.0);
  face_inner_reach_.assign(triangles_.size(), std::numeric_limits<double>::infinity());
  for (int j = 0; j < num_parts(); ++j) {
    std::vector<std::pair<Vec3, Vec3>> sharp_edges;
    for (int t = part_triangle_start_[j]; t < part_triangle_start_[j + 1]; ++t)
      for (int k = 0; k < 3; ++k) {
        const int n = face_neighbors_[t][k];
        if (n < 0) continue;
        const double c = std::clamp(face_normals_[t].dot(face_normals_[n]), -1.0, 1.0);
        if (c < sharp && t < n)
          sharp_edges.emplace_back(vertices_[triangles_[t][k]],
                                   vertices_[triangles_[t][(k + 1) % 3]]);
        const double angle = std::acos(c);
        if (angle > 0) {
          const double L = (triangle_centers_[t] - triangle_centers_[n]).norm();
          face_inner_reach_[t] = std::min(face_inner_reach_[t], 0.25 * L / angle);
        }
      }
    // Distance of a triangle from an edge of its own surface (which cannot pierce it): the
    // least of the edge against the triangle's three edges and its ends against the triangle.
    for (int t = part_triangle_start_[j]; t < part_triangle_start_[j + 1]; ++t) {
      const Vec3& a = vertices_[triangles_[t][0]];
      const Vec3& b = vertices_[triangles_[t][1]];
      const Vec3& c = vertices_[triangles_[t][2]];
      for (const auto& [e0, e1] : sharp_edges) {
        double d2 = std::min({SegmentDistanceSquared(e0, e1, a, b),
                              SegmentDistanceSquared(e0, e1, b, c),
                              SegmentDistanceSquared(e0, e1, c, a)});
        for (const Vec3* e : {&e0, &e1})
          d2 = std::min(d2, (*e - ClosestPointOnTriangle(*e, a, b, c).point).squaredNorm());
        face_inner_reach_[t] = std::min(face_inner_reach_[t], std::sqrt(d2));
      }
    }
  }
}

PartRing MeasurePartRing(const std::vector<TriangleMesh>& parts, const Transform& X_BG,
                         std::vector<double> part_angles_rad) {
  if (part_angles_rad.size() != parts.size())
    throw std::invalid_argument("MeasurePartRing: " + std::to_string(part_angles_rad.size()) +
                                " angles for " + std::to_string(parts.size()) + " parts");
  constexpr double kPi = 3.14159265358979323846;
  PartRing ring{.X_BG = X_BG, .inner_radius_m = std::numeric_limits<double>::infinity()};
  const Transform X_GB = X_BG.Inverse();
  for (size_t j = 0; j < parts.size(); ++j)
    for (const Vec3& v_B : parts[j].vertices) {
      const Vec3 v = X_GB * v_B;
      const double r = std::hypot(v.x(), v.y());
      ring.inner_radius_m = std::min(ring.inner_radius_m, r);
      ring.outer_radius_m = std::max(ring.outer_radius_m, r);
      double d = std::atan2(v.y(), v.x()) - part_angles_rad[j];
      d -= 2 * kPi * std::floor((d + kPi) / (2 * kPi));
      ring.part_half_angle_rad = std::max(ring.part_half_angle_rad, std::abs(d));
    }
  ring.part_angles_rad = std::move(part_angles_rad);
  return ring;
}

void ContactSurface::CheckPartRing() const {
  if (part_ring_) {
    if (static_cast<int>(part_ring_->part_angles_rad.size()) != num_parts())
      throw std::invalid_argument("ContactSurface: the part ring has " +
                                  std::to_string(part_ring_->part_angles_rad.size()) +
                                  " part angles for " + std::to_string(num_parts()) + " parts");
    if (!(part_ring_->inner_radius_m >= 0 &&
          part_ring_->inner_radius_m < part_ring_->outer_radius_m))
      throw std::invalid_argument("ContactSurface: the part ring needs 0 <= inner < outer radius");
  }
}

void ContactSurface::CalcSharedRimEdges() {
  // Rim edges next to another part: the edge's midpoint within 2 (margin + slack) of a part
  // whose sphere reaches it.
  shared_rim_edges_.assign(triangles_.size(), 0);
  const double near = 2 * (margin_m_ + slack_m_);
  for (int j = 0; j < num_parts(); ++j)
    for (int t = part_triangle_start_[j]; t < part_triangle_start_[j + 1]; ++t)
      for (int k = 0; k < 3; ++k) {
        if (!(boundary_edges_[t] & (1u << k))) continue;
        const Vec3 mid = 0.5 * (vertices_[triangles_[t][k]] + vertices_[triangles_[t][(k + 1) % 3]]);
        for (int other = 0; other < num_parts(); ++other) {
          if (other == j || (mid - part_centers_[other]).norm() > part_radii_[other] + near)
            continue;
          ClosestFace c;
          FindClosestFaceInPart(*this, other, mid, &c);
          if (c.d2 <= near * near) {
            shared_rim_edges_[t] |= static_cast<std::uint8_t>(1u << k);
            break;
          }
        }
      }
}

ContactSurface::~ContactSurface() = default;

}  // namespace orrery::contact

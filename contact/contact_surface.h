#pragma once
// A rigid contact surface: a triangle mesh held in its body's frame B (tooth flanks, tips and
// fillets, or any surface), split into parts (for example one per tooth) that the broad phase
// culls separately. Built once; everything the step needs is precomputed here:
//   - face unit normals (right-hand rule, out of the material),
//   - vertex area weights A_i = sum over incident triangles of area / 3 (the nodal quadrature
//     weights of the contact pressure integral, seed 000 eq. 20: sum_i A_i = surface area),
//   - area-weighted vertex normals,
//   - boundary-edge flags (an edge used by one triangle only: the rim of an open surface),
//   - adjacency: the triangle across each edge and the triangles around each vertex (the walk
//     of tracked_gaps.h),
//   - a box per part (centre and half-extents in B): the motion bound of tracked_gaps.h,
//   - an inner reach per face: how deep a node below the face may lie with the face still
//     closest to it among its neighbours' local minima (tracked_gaps.h): the distance from the
//     face to the nearest sharp interior edge of its part (normals turning by more than 10
//     degrees, such as a tooth's tip corners), and at most a quarter of the radius of
//     curvature that the turning of the normals across its edges implies,
//   - the culling geometry (FCL bounding-volume hierarchies per part, inflated by the margin;
//     built by candidate_pairs.cpp, opaque here).
//
// margin_m: the contact search lists every triangle pair closer than this (candidate_pairs.h),
// so it bounds the penetration that can be seen; choose it above the largest expected
// penetration (penalty contacts: F_max / (k_A A)) and well below the tooth size.
// slack_m (>= 0): the search looks (margin + slack) far and keeps its pairs until the surfaces
// have moved relative to each other by more than the slack (candidate_pairs.h); a larger slack
// means fewer searches and more candidates per gap evaluation.
// tooth_ring (optional): the parts are the teeth of a gear; when both surfaces of a search have
// one, the broad phase keeps only the teeth inside the mesh zone of the two gears at their
// current angles (candidate_pairs.h).
//
// Usage:
//   auto flank = std::make_shared<const ContactSurface>(
//       std::vector{gears::MakeFlankMesh(gear, 0, true, 24, 8)}, 50e-6);
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "mbd/spatial.h"
#include "mbd/triangle_mesh.h"

namespace orrery::contact {

class CullingGeometry;  // candidate_pairs.cpp

// A surface whose parts are the teeth of a gear (gear_contact.h fills it): where the teeth are,
// in the gear frame G (axis z).
struct ToothRing {
  Transform X_BG;                    // gear frame in the body frame
  double inner_radius_m = 0;         // the teeth lie in inner <= r <= outer (distance from G's
  double outer_radius_m = 0;         // axis): root to tip circle (external), tip to root (ring)
  std::vector<double> part_angles_rad;  // #parts: a reference angle of every part about G's z
  double part_half_angle_rad = 0;    // every vertex of part j lies within this of its angle
};

class ContactSurface {
 public:
  // parts: at least one non-empty mesh, vertices in the body frame (m). Throws
  // std::invalid_argument for an empty surface, a triangle index out of range, a degenerate
  // triangle (zero area), margin_m <= 0, or a tooth ring whose angles do not match the parts or
  // whose radii are not 0 <= inner < outer.
  ContactSurface(const std::vector<TriangleMesh>& parts, double margin_m,
                 double slack_m = 0, std::optional<ToothRing> tooth_ring = std::nullopt);
  ~ContactSurface();
  ContactSurface(const ContactSurface&) = delete;
  ContactSurface& operator=(const ContactSurface&) = delete;

  int num_vertices() const { return static_cast<int>(vertices_.size()); }
  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  int num_parts() const { return static_cast<int>(part_triangle_start_.size()) - 1; }
  double margin_m() const { return margin_m_; }
  double slack_m() const { return slack_m_; }
  // Largest distance of a vertex from the body origin (m): bounds how far a rotation moves it.
  double max_vertex_radius_m() const { return max_vertex_radius_m_; }

  const std::vector<Vec3>& vertices() const { return vertices_; }                     // #V, B
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }     // #T
  const std::vector<Vec3>& face_normals() const { return face_normals_; }             // #T, B
  const std::vector<double>& vertex_areas() const { return vertex_areas_; }           // #V, m^2
  const std::vector<Vec3>& vertex_normals() const { return vertex_normals_; }         // #V, B
  // #T: bit k set if edge k (vertex k to vertex k+1 mod 3) of the triangle is a boundary edge.
  const std::vector<std::uint8_t>& boundary_edges() const { return boundary_edges_; }
  // #V: 1 for a vertex on a boundary edge (of any of its triangles), else 0.
  const std::vector<std::uint8_t>& vertex_on_rim() const { return vertex_on_rim_; }
  // #T: the boundary edges (bits as above) that lie within 2 (margin + slack) of another part:
  // where a node's closest face may pass from one part to the next (a tooth's root line; not
  // its face ends).
  const std::vector<std::uint8_t>& shared_rim_edges() const { return shared_rim_edges_; }
  // #T: the triangle across edge k of each triangle (-1 on the rim; an edge shared by more than
  // two triangles is treated as rim for the walk).
  const std::vector<std::array<int, 3>>& face_neighbors() const { return face_neighbors_; }
  // Triangles around vertex v: vertex_faces()[vertex_face_start()[v] .. [v + 1]), increasing.
  const std::vector<int>& vertex_face_start() const { return vertex_face_start_; }
  const std::vector<int>& vertex_faces() const { return vertex_faces_; }
  // #T: the inner reach of each face (m; infinite on a smooth open surface).
  const std::vector<double>& face_inner_reach() const { return face_inner_reach_; }
  // #T: the rim fade of each face with a rim edge (m; signed_gap.h): a tenth of the face's
  // height across its rim edge (the smallest, for several); 0 for faces without one.
  const std::vector<double>& face_rim_fade() const { return face_rim_fade_; }
  // #V: the rim fade at a rim vertex, the smallest of its faces' with a rim edge there; 0 off
  // the rim.
  const std::vector<double>& vertex_rim_fade() const { return vertex_rim_fade_; }
  // #T: for each rim edge k of each face, the unit direction in the face's plane, across the
  // edge and away from the face (B); zero for edges that are not rim edges.
  const std::vector<std::array<Vec3, 3>>& face_rim_outward() const { return face_rim_outward_; }
  // #V: the part of each vertex.
  const std::vector<int>& vertex_parts() const { return vertex_parts_; }
  // Triangles of part j are [part_triangle_start()[j], part_triangle_start()[j + 1]); #parts + 1.
  const std::vector<int>& part_triangle_start() const { return part_triangle_start_; }
  const std::vector<int>& part_vertex_start() const { return part_vertex_start_; }
  double total_area() const { return total_area_; }
  // #parts: a sphere around each part (body frame), the broad phase's per-part bounding test.
  const std::vector<Vec3>& part_centers() const { return part_centers_; }
  const std::vector<double>& part_radii() const { return part_radii_; }
  // #parts: half-extents of each part's axis-aligned box in B (its centre is part_centers()).
  const std::vector<Vec3>& part_half_extents() const { return part_half_extents_; }
  // #T: a sphere around each triangle (centroid, farthest vertex), the leaf pre-check.
  const std::vector<Vec3>& triangle_centers() const { return triangle_centers_; }
  const std::vector<double>& triangle_radii() const { return triangle_radii_; }
  const std::optional<ToothRing>& tooth_ring() const { return tooth_ring_; }

  const CullingGeometry& culling() const { return *culling_; }

 private:
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vec3> face_normals_;
  std::vector<double> vertex_areas_;
  std::vector<Vec3> vertex_normals_;
  std::vector<std::uint8_t> boundary_edges_, shared_rim_edges_, vertex_on_rim_;
  std::vector<std::array<int, 3>> face_neighbors_;
  std::vector<int> vertex_face_start_, vertex_faces_, vertex_parts_;
  std::vector<double> face_inner_reach_;
  std::vector<double> face_rim_fade_, vertex_rim_fade_;
  std::vector<std::array<Vec3, 3>> face_rim_outward_;
  std::vector<int> part_triangle_start_, part_vertex_start_;
  std::vector<Vec3> part_centers_;
  std::vector<double> part_radii_;
  std::vector<Vec3> part_half_extents_;
  std::optional<ToothRing> tooth_ring_;
  std::vector<Vec3> triangle_centers_;
  std::vector<double> triangle_radii_;
  double margin_m_ = 0, slack_m_ = 0, total_area_ = 0, max_vertex_radius_m_ = 0;
  std::shared_ptr<const CullingGeometry> culling_;
};

}  // namespace orrery::contact

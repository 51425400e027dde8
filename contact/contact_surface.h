#pragma once
// A rigid contact surface: a triangle mesh held in its body's frame B (any surface; for gears the
// tooth flanks, tips and fillets), split into parts (for example one per tooth) that the broad
// phase culls separately. Built once; everything the step needs is precomputed here:
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
// part_ring (optional): the parts lie in a ring about an axis, one after the other in angle (the
// teeth of a gear or a spline); when both surfaces of a search have one and their axes are
// parallel, the broad phase keeps only the parts inside the zone where the two rings' bands
// overlap at their current angles (candidate_pairs.h).
// part_stiffness_scale (optional, #parts values > 0; empty: all 1): a factor on the contact law
// of every contact point that involves the part. A node of part i of one surface pressing on a
// face of part j of the other carries s_i s_j times its law's force, stiffness and damping (the
// contact elements scale the node's area weight by it); e.g. a softer part (the gear layer's
// cracked tooth, models/gear_contact.h).
// Extruded parts (found here, whatever made the part): a part whose vertices are R >= 2 rows of
// one open profile of n >= 2 points, row k at height z_k along B's z (strictly increasing;
// vertex part_vertex_start + k n + i at the x and y of vertex part_vertex_start + i, to the
// bit), and whose faces are the rectangles between neighbouring profile points i, i + 1 and
// neighbouring rows k, k + 1, each split into two triangles along a diagonal: the profile's
// polyline swept along z from z_0 to z_{R-1} (a spur gear's tooth, models/gear_contact.h). The
// distance from such a surface to a point whose z lies in [z_0, z_{R-1}] is the distance in the
// xy plane to the polyline, whatever that z: tracked_gaps.h evaluates one row of a part's nodes
// against extruded parts and gives the other rows the same gaps.
// smooth_normals: the facets stand for a smooth surface (a gear's involute flanks, fillets and
// tips), and the contact force at a closest point q acts along the surface normal interpolated
// at q instead of q's facet normal (signed_gap.h ForceNormal). The corner normals are made here:
// at each corner of each face, the normal of the smooth surface through that vertex, the
// angle-weighted mean of the normals of the faces around the vertex that reach the face across
// smooth edges (normals turning by at most 10 degrees, the sharp-edge test of the inner reach);
// a sharp edge (a tooth's tip corners, its end faces) keeps each side's own normals. Across a
// smooth edge the two faces then share their corner normals at its ends, so the interpolated
// normal is continuous where a node's closest point passes from one facet to the next (a
// deformed surface makes them from its deformed face normals: signed_gap.h ForceNormal). With
// the facet normals the force turned there by the angle between the facets (about 1 degree on
// a 40-interval involute), and on a flexible gear by the deformation's turning of each face:
// a spur pair's mid-face row of nodes lies exactly on the other flank's mid-face edges (an FE
// element boundary of the planet, where the deformed faces' normals differ), its closest face
// flips between the two with the rounding of Newton's iterates, and the force with it. Newton
// then cycled between the two faces at 60 to 500 times its tolerance (seed 003's flexible stage:
// 8 failed and 100 backtracked steps in its first 10 ms; none with the smoothed normals).
//
// Usage:
//   auto flank = std::make_shared<const ContactSurface>(
//       std::vector<TriangleMesh>{mesh}, 50e-6);
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "mbd/spatial.h"
#include "mbd/triangle_mesh.h"

namespace orrery::contact {

class CullingGeometry;  // candidate_pairs.cpp

// A surface whose parts lie in a ring about an axis (a gear's teeth: the gear layer fills it,
// models/gear_contact.h): where the parts are, in the ring's frame G (axis z).
struct PartRing {
  Transform X_BG;                    // ring frame in the body frame
  double inner_radius_m = 0;         // the parts lie in inner <= r <= outer (distance from G's
  double outer_radius_m = 0;         // axis; a gear's teeth: root to tip circle or tip to root)
  std::vector<double> part_angles_rad;  // #parts: a reference angle of every part about G's z
  double part_half_angle_rad = 0;    // every vertex of part j lies within this of its angle
};

// The ring of parts (body-frame vertices) about the axis z of frame G (X_BG in the body frame),
// part j about angle part_angles_rad[j] (#parts): the radial band and the half angle measured
// on the vertices, so that every vertex lies inside whatever the reference angles. Throws
// std::invalid_argument when the angles do not match the parts.
PartRing MeasurePartRing(const std::vector<TriangleMesh>& parts, const Transform& X_BG,
                         std::vector<double> part_angles_rad);

class ContactSurface {
 public:
  // parts: at least one non-empty mesh, vertices in the body frame (m). Throws
  // std::invalid_argument for an empty surface, a triangle index out of range, a degenerate
  // triangle (zero area), margin_m <= 0, or a part ring whose angles do not match the parts or
  // whose radii are not 0 <= inner < outer.
  // Also throws for a part_stiffness_scale of the wrong size or with a value that is not a
  // positive finite number.
  ContactSurface(const std::vector<TriangleMesh>& parts, double margin_m, double slack_m = 0,
                 std::optional<PartRing> part_ring = std::nullopt,
                 std::vector<double> part_stiffness_scale = {}, bool smooth_normals = false);
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
  // The smoothed corner normals (header), #T x 3 in B; empty without smooth_normals.
  bool smooth_normals() const { return !face_corner_normals_.empty(); }
  const std::vector<std::array<Vec3, 3>>& face_corner_normals() const {
    return face_corner_normals_;
  }
  // The faces whose normals make corner k of face t, with their angle weights (a deformed
  // surface's corner normals from its deformed face normals):
  // corner_faces()[corner_face_start()[3 t + k] .. [3 t + k + 1]), corner_weights() alike.
  const std::vector<int>& corner_face_start() const { return corner_face_start_; }
  const std::vector<int>& corner_faces() const { return corner_faces_; }
  const std::vector<double>& corner_weights() const { return corner_weights_; }
  // The corner's group, #T x 3 (3 t + k): the corners at one vertex whose faces meet across
  // smooth edges there, which share their list of faces and weights above (the same faces in
  // the same order), so a deformed surface's corner normal made once serves every corner of the
  // group to the bit (signed_gap.h ForceNormal's cache); num_corner_groups() ids.
  const std::vector<int>& corner_group() const { return corner_group_; }
  int num_corner_groups() const { return num_corner_groups_; }
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
  const std::optional<PartRing>& part_ring() const { return part_ring_; }
  // #V and #T: the stiffness scale of each vertex's and each face's part (header; 1 by default).
  const std::vector<double>& vertex_stiffness_scale() const { return vertex_stiffness_scale_; }
  const std::vector<double>& face_stiffness_scale() const { return face_stiffness_scale_; }

  // Extruded parts (header), #parts: the rows R (0: the part is not extruded) and the row
  // length n; its row k is at z = vertices()[part_vertex_start()[j] + k n].z().
  const std::vector<int>& part_rows() const { return part_rows_; }
  const std::vector<int>& part_row_length() const { return part_row_length_; }
  // #T: for a face of an extruded part, its rectangle k (n - 1) + i (profile points i, i + 1,
  // rows k, k + 1) and the corner of the rectangle it leaves out (0: (i, k), 1: (i + 1, k),
  // 2: (i + 1, k + 1), 3: (i, k + 1)); -1 for the faces of other parts.
  const std::vector<int>& face_cell() const { return face_cell_; }
  const std::vector<std::int8_t>& face_missing_corner() const { return face_missing_corner_; }
  // The face of an extruded part that holds the point of B at x_B, which must lie on the part's
  // surface in its rectangles' column `column` (profile points i, i + 1) at a height in
  // [z_0, z_{R-1}] (clamped): the two faces of the rectangle of that height, the one whose half
  // holds the point (on the diagonal: either).
  int ExtrudedFaceAt(int part, int column, const Vec3& x_B) const;
  // The same in two stages, for points of one column at several heights: the point's fraction
  // t in [0, 1] along the column's profile segment (in xy), then the face at t and height z.
  double ExtrudedColumnFraction(int part, int column, const Vec3& x_B) const;
  int ExtrudedFaceAt(int part, int column, double t, double z) const;
  // The height z in rows: the row interval k (rows k, k + 1) that holds it (the last one holds
  // z_{R-1}) and its fraction u in [0, 1] up the interval (clamped); then the face at t in the
  // rectangle of column and interval k. The same face as ExtrudedFaceAt(part, column, t, z),
  // for points of many columns at one height.
  struct RowPlace {
    int interval = 0;
    double u = 0;
  };
  RowPlace ExtrudedRowPlace(int part, double z) const;
  int ExtrudedFaceAt(int part, int column, double t, RowPlace place) const;

  const CullingGeometry& culling() const { return *culling_; }

 private:
  // The constructor's stages, in order (contact_surface.cpp).
  void ConcatenateParts(const std::vector<TriangleMesh>& parts);  // vertices, triangles, parts
  void CalcFaceNormalsAndAreas();  // face and vertex normals, vertex areas, total area
  void CalcAdjacency();            // boundary edges, neighbours, vertex faces and parts
  void CalcBoundingSpheres();      // part spheres and boxes, triangle spheres
  void CalcRimFades();             // rim fades and outward directions
  void CalcInnerReach();           // inner reach of every face
  void CalcCornerNormals();        // smoothed corner normals (smooth_normals only)
  void CheckPartRing() const;
  void SetStiffnessScales(std::vector<double> part_scale);  // vertex and face stiffness scales
  void CalcSharedRimEdges();       // after the culling geometry
  void FindExtrudedParts();        // part rows and face cells (header: extruded parts)
  bool ExtrudedPart(int part, int rows, int n);  // checks part j as R x n rows, fills its cells

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
  std::vector<std::array<Vec3, 3>> face_corner_normals_;
  std::vector<int> corner_face_start_, corner_faces_;
  std::vector<double> corner_weights_;
  std::vector<int> corner_group_;
  int num_corner_groups_ = 0;
  std::vector<int> part_triangle_start_, part_vertex_start_;
  std::vector<Vec3> part_centers_;
  std::vector<double> part_radii_;
  std::vector<Vec3> part_half_extents_;
  std::optional<PartRing> part_ring_;
  std::vector<Vec3> triangle_centers_;
  std::vector<double> triangle_radii_;
  std::vector<double> vertex_stiffness_scale_, face_stiffness_scale_;
  std::vector<int> part_rows_, part_row_length_, face_cell_;
  std::vector<std::int8_t> face_missing_corner_;
  // Extruded parts: the two faces of each rectangle c of part j at
  // cell_faces_[part_cell_start_[j] + 2 c + {0, 1}] (#parts + 1 starts).
  std::vector<int> part_cell_start_, cell_faces_;
  double margin_m_ = 0, slack_m_ = 0, total_area_ = 0, max_vertex_radius_m_ = 0;
  std::shared_ptr<const CullingGeometry> culling_;
};

}  // namespace orrery::contact

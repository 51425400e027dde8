#pragma once
// The contact surface of a flexible (Craig-Bampton-reduced) body: triangles of its
// FlexibleBodyModes surface whose nodes move with the modal coordinates,
//   x_P(q_f) = s_P + Phi_P q_f          (body frame B, mbd/flexible_body.h),
// s_P the undeformed node position, Phi_P its 3 x nf translation shapes.
//
// The culling works on the UNDEFORMED surface and is never refitted (DESIGN.md, "Tooth
// contact"): the ContactSurface held here is built from s_P with its margin inflated by twice the
// deformation allowance u_max,
//   margin = gap_margin + 2 u_max,
// so that the candidate search (candidate_pairs.h: pairs within (margin_A + margin_B) / 2 at the
// search pose) lists every triangle pair within gap_margin + u_max,A + u_max,B, which contains
// every pair of DEFORMED triangles within gap_margin while no node has moved by more than its
// surface's u_max (a point of a triangle moves by a convex combination of its vertices'
// displacements, so triangle distances change by at most u_A + u_B).
// Deformation bound checked at every evaluation, in O(nf):
//   max_P |Phi_P q_f| <= sum_k |q_k| c_k,   c_k = max_P |Phi_P e_k|   (DeformationBound()).
// Gaps are then computed with the deformed positions on both sides (flexible_contact_element.h).
//
// Which triangles: the whole exported surface, or only those whose three nodes all lie in the
// given node sets (for a gear from models/gear_fe_mesh.h: the TOOTHk_FLANK_PLUS/MINUS, fillet and
// tip sets). Parts (the broad phase's unit): one, or one per angular sector of equal width about
// B's z axis, starting at part_angle_offset_rad (for a gear: one per tooth, sectors of 2 pi / z
// centred on the teeth).
//
// Embedded surfaces: a finer triangle mesh (for a gear the analytic flank mesh with many profile
// intervals, gear_geometry.h MakeToothSurfaceMesh) can carry the contact instead of the FE
// surface: each of its vertices v is attached to the closest FE surface triangle (of the node
// sets) and moves with it, Phi_v = sum_k w_k Phi_k (w the barycentric coordinates of v's
// projection). The contact then integrates the pressure on the fine mesh (a Hertzian strip is
// far narrower than an FE face) and hands the FE nodes the barycentric shares of the vertex
// forces. Vertices farther than embed_tolerance_m from the FE triangles are refused.
//
// Usage:
//   FlexibleContactSurfaceSpec s{.gap_margin_m = 30e-6, .deformation_allowance_m = 50e-6};
//   auto surface = std::make_shared<const FlexibleContactSurface>(modes, s);
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/contact_surface.h"
#include "mbd/flexible_body.h"
#include "mbd/triangle_mesh.h"

namespace orrery::contact {

// Phi x for one point's 3 x n block of a row-major shape matrix (rows a, a + stride, a + 2 stride;
// x of n entries): the numbers of Eigen's own product of that block, middleRows<3>(...) * x
// (Eigen 3.4 takes a 3-row, dynamic-depth product coefficient by coefficient, each row's dot
// product a vectorized sum: Redux.h, LinearVectorizedTraversal), in SSE2 with the three rows
// sharing each load of x (docs/performance.md, perf-flex6a). The order of Eigen's sum with
// packets of two: the products of columns (0, 1) and (2, 3) start two packets, each next four
// columns add to them in turn, the two packets are added, then a last full packet, then the
// packet's two lanes, then a last odd column. Without SSE2 packets of two (an AVX build): Eigen's
// product itself. Tested `==` against Eigen's product (flexible_contact_element_test.cpp).
Vec3 ThreeRowsTimes(const double* a, Eigen::Index stride, const double* x, Eigen::Index n);

struct FlexibleContactSurfaceSpec {
  std::vector<std::string> node_sets;   // empty: every surface triangle
  double gap_margin_m = 30e-6;          // > 0: the gap distance of the deformed surfaces
  double deformation_allowance_m = 50e-6;  // u_max >= 0: the inflation of the culling geometry
  double slack_m = 0;                   // >= 0: rigid relative motion kept (contact_surface.h)
  int angular_parts = 1;                // >= 1 sectors about z
  double part_angle_offset_rad = 0;     // sector k spans offset + (k -+ 1/2) 2 pi / angular_parts
  // Optional: the parts' ring (contact_surface.h PartRing; the undeformed vertices), for the
  // broad phase's ring zone (candidate_pairs.h; a deformed vertex lies within the part's
  // displacement bound of its own, which the tracked gaps add to the zone's reach). For a
  // gear the gear layer measures it as for its rigid surfaces (MeasurePartRing).
  std::optional<PartRing> part_ring;
  // Smoothed force normals (contact_surface.h smooth_normals): interpolated across the facets
  // from corner normals made of the deformed faces' normals (signed_gap.h ForceNormal).
  bool smooth_normals = false;
};

class FlexibleContactSurface {
 public:
  // Throws std::invalid_argument for no surface triangles, an unknown node set, no triangle in
  // the sets, a non-positive gap margin or a negative allowance or slack.
  FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                         const FlexibleContactSurfaceSpec& spec);
  // The embedded surface of the header: `parts` (body frame B) over the FE surface triangles of
  // spec.node_sets (angular_parts is ignored: the parts are given). Throws
  // std::invalid_argument as above, and for a vertex farther than embed_tolerance_m from them.
  FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                         const std::vector<TriangleMesh>& parts,
                         const FlexibleContactSurfaceSpec& spec, double embed_tolerance_m);

  // An embedded surface whose vertex shapes are given (3 #V x nf, rows in the parts' vertex
  // order), e.g. from the FE faces' own shape functions (flexible_gear_mesh.cpp: 8-node
  // serendipity faces of hex20). spec.node_sets and angular_parts are ignored.
  FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                         const std::vector<TriangleMesh>& parts, Eigen::MatrixXd shapes,
                         const FlexibleContactSurfaceSpec& spec);

  const FlexibleContactSurfaceSpec& spec() const { return spec_; }
  const FlexibleBodyModes& modes() const { return *modes_; }
  int nf() const { return modes_->nf; }
  // The undeformed surface (vertices s_P in B, margin inflated as above).
  const ContactSurface& undeformed() const { return *surface_; }
  // #V: index into modes().nodes of every surface vertex (-1 for an embedded surface).
  const std::vector<int>& vertex_node() const { return vertex_node_; }
  // 3 #V x nf: the translation shapes of the vertices stacked (rows 3 i .. 3 i + 2: vertex i).
  const Eigen::MatrixXd& shapes() const { return shapes_; }
  // nf: c_k = max over the vertices of |Phi_P e_k| (m per unit modal coordinate).
  const Eigen::VectorXd& mode_bounds() const { return mode_bounds_; }

  // sum_k |q_k| c_k >= max_P |Phi_P q_f| (m). q_f: nf.
  double DeformationBound(const Eigen::Ref<const Eigen::VectorXd>& q_f) const;
  // Deformed vertex positions s_P + Phi_P q_f (B) and the unit normals of the deformed faces;
  // *vertices and *normals must have #V and #T entries (no allocation).
  void Deform(const Eigen::Ref<const Eigen::VectorXd>& q_f, Eigen::VectorXd* displacement,
              std::vector<Vec3>* vertices, std::vector<Vec3>* normals) const;
  // Lazily deformed vertices (deformed_vertices.h, what the tracked gaps read): the displacement
  // u_v of vertex v at q_f from its bases' u_b = Phi_b q_f, each formed when
  // (*base_stamp)[b] != epoch (then stamped; *base_displacement and *base_stamp: num_bases()
  // entries). An embedded surface's vertices move with the FE nodes they are embedded in,
  // u_v = sum_k w_k u_b(k), which streams the shapes of the FE nodes instead of those of the
  // (several times more) vertices. Returns s_v + u_v (B). *bases_made counts the bases formed.
  Vec3 DeformVertex(int vertex, const Eigen::Ref<const Eigen::VectorXd>& q_f,
                    std::vector<Vec3>* base_displacement, std::vector<long>* base_stamp,
                    long epoch, int* bases_made) const;
  // Per part p (the broad phase's unit): c_pk = max over the part's vertices of |Phi_v e_k|
  // (#parts x nf), and the bound
  //   sum_k |x_k| c_pk (1 + 1e-12) + 1e-15 m (0 for x = 0)  >=  max over the part's v |Phi_v x|,
  // for a modal coordinate (the part's largest displacement) or a change of one (the largest
  // motion of its vertices between two evaluations: the tracked gaps' odometers, which may not
  // undercount). The factor and the 1e-15 m cover the rounding of the interpolated shapes and of
  // positions s_v + u_v (coordinates below 1 m: half an ulp is below 1.2e-16 m). It is the
  // triangle inequality mode by mode, so it exceeds the exact largest change by what the modes'
  // largest vertex motions add over their actual vector sum: 19 % on average in seed 003's
  // flexible run (docs/performance.md), where the whole surface's c_k gave 37 %.
  const Eigen::MatrixXd& part_mode_bounds() const { return part_mode_bounds_; }
  double PartDeformationBound(int part, const Eigen::Ref<const Eigen::VectorXd>& x) const;
  // PartDeformationBound(part, x) of every part into (*bounds)[part] (#parts entries): the same
  // numbers (each part's sum takes its terms in the same order), a column of part_mode_bounds()
  // at a time instead of a strided row per part.
  void PartDeformationBounds(const Eigen::Ref<const Eigen::VectorXd>& x,
                             std::vector<double>* bounds) const;
  // The points whose shapes DeformVertex forms (the FE nodes an embedded surface hangs on; the
  // vertices themselves otherwise).
  int num_bases() const { return static_cast<int>(BaseShapes().rows() / 3); }
  // Phi_P v for one vertex (a deformation rate from q_f-dot), and Q += Phi_P^T f (a vertex force
  // in B onto the modal forces).
  // (ThreeRowsTimes: the numbers of shapes_rows_.middleRows<3>(3 vertex) * v, VertexShapes.)
  Vec3 VertexShapeTimes(int vertex, const Eigen::Ref<const Eigen::VectorXd>& v) const {
    return ThreeRowsTimes(shapes_rows_.data() + 3 * vertex * shapes_rows_.cols(),
                          shapes_rows_.cols(), v.data(), v.size());
  }
  void AddVertexForce(int vertex, const Vec3& f_B, Eigen::VectorXd* modal_force) const {
    modal_force->noalias() += shapes_rows_.middleRows<3>(3 * vertex).transpose() * f_B;
  }
  // Phi_P of one vertex (3 x nf).
  auto VertexShapes(int vertex) const { return shapes_rows_.middleRows<3>(3 * vertex); }

 private:
  void Check(const std::string& what) const;
  void SetModeBounds();
  // The bases of DeformVertex: the vertices themselves (the node-set and given-shapes surfaces).
  void SetBasesToVertices();
  std::vector<std::array<int, 3>> SelectedTriangles(const std::string& what) const;

  std::shared_ptr<const FlexibleBodyModes> modes_;
  FlexibleContactSurfaceSpec spec_;
  std::shared_ptr<const ContactSurface> surface_;
  std::vector<int> vertex_node_;
  Eigen::MatrixXd shapes_;
  // The same, row-major: a vertex's three rows lie together (VertexShapeTimes).
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> shapes_rows_;
  Eigen::VectorXd mode_bounds_;
  Eigen::MatrixXd part_mode_bounds_;  // #parts x nf (SetModeBounds)
  // DeformVertex's interpolation: base shapes (3 #bases x nf, row-major; empty when the bases are
  // the vertices, whose shapes_rows_ then serve), each vertex's up to three bases and weights
  // (#V).
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajorMatrix& BaseShapes() const {
    return base_shapes_.size() > 0 ? base_shapes_ : shapes_rows_;
  }
  RowMajorMatrix base_shapes_;
  std::vector<std::array<int, 3>> vertex_bases_;
  std::vector<Vec3> vertex_base_weights_;
};

}  // namespace orrery::contact

#include "contact/flexible_contact_surface.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <limits>
#include <utility>

#include "contact/triangle_geometry.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace orrery::contact {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

Vec3 ThreeRowsTimes(const double* a, Eigen::Index stride, const double* x, Eigen::Index n) {
#if defined(__SSE2__)
  using Traits = Eigen::internal::packet_traits<double>;
  if constexpr (Traits::Vectorizable && Traits::size == 2) {
    const double* r[3] = {a, a + stride, a + 2 * stride};
    const Eigen::Index end = n / 2 * 2, end2 = n / 4 * 4;
    // The packet's lanes added (Eigen's predux of two), then the odd column.
    auto finish = [&](__m128d p, int k) {
      double res = _mm_cvtsd_f64(_mm_add_sd(p, _mm_unpackhi_pd(p, p)));
      if (end < n) res += r[k][end] * x[end];
      return res;
    };
    if (end > 2) {
      const __m128d x0 = _mm_loadu_pd(x), x1 = _mm_loadu_pd(x + 2);
      __m128d p0 = _mm_mul_pd(_mm_loadu_pd(r[0]), x0), q0 = _mm_mul_pd(_mm_loadu_pd(r[0] + 2), x1);
      __m128d p1 = _mm_mul_pd(_mm_loadu_pd(r[1]), x0), q1 = _mm_mul_pd(_mm_loadu_pd(r[1] + 2), x1);
      __m128d p2 = _mm_mul_pd(_mm_loadu_pd(r[2]), x0), q2 = _mm_mul_pd(_mm_loadu_pd(r[2] + 2), x1);
      for (Eigen::Index j = 4; j < end2; j += 4) {
        const __m128d xa = _mm_loadu_pd(x + j), xb = _mm_loadu_pd(x + j + 2);
        p0 = _mm_add_pd(p0, _mm_mul_pd(_mm_loadu_pd(r[0] + j), xa));
        q0 = _mm_add_pd(q0, _mm_mul_pd(_mm_loadu_pd(r[0] + j + 2), xb));
        p1 = _mm_add_pd(p1, _mm_mul_pd(_mm_loadu_pd(r[1] + j), xa));
        q1 = _mm_add_pd(q1, _mm_mul_pd(_mm_loadu_pd(r[1] + j + 2), xb));
        p2 = _mm_add_pd(p2, _mm_mul_pd(_mm_loadu_pd(r[2] + j), xa));
        q2 = _mm_add_pd(q2, _mm_mul_pd(_mm_loadu_pd(r[2] + j + 2), xb));
      }
      p0 = _mm_add_pd(p0, q0);
      p1 = _mm_add_pd(p1, q1);
      p2 = _mm_add_pd(p2, q2);
      if (end > end2) {
        const __m128d xe = _mm_loadu_pd(x + end2);
        p0 = _mm_add_pd(p0, _mm_mul_pd(_mm_loadu_pd(r[0] + end2), xe));
        p1 = _mm_add_pd(p1, _mm_mul_pd(_mm_loadu_pd(r[1] + end2), xe));
        p2 = _mm_add_pd(p2, _mm_mul_pd(_mm_loadu_pd(r[2] + end2), xe));
      }
      return Vec3(finish(p0, 0), finish(p1, 1), finish(p2, 2));
    }
    if (end == 2) {
      const __m128d x0 = _mm_loadu_pd(x);
      return Vec3(finish(_mm_mul_pd(_mm_loadu_pd(r[0]), x0), 0),
                  finish(_mm_mul_pd(_mm_loadu_pd(r[1]), x0), 1),
                  finish(_mm_mul_pd(_mm_loadu_pd(r[2]), x0), 2));
    }
    // Below one packet: Eigen's scalar sum.
    if (n == 0) return Vec3::Zero();
    return Vec3(r[0][0] * x[0], r[1][0] * x[0], r[2][0] * x[0]);
  }
#endif
  using Rows = Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>, 0,
                          Eigen::OuterStride<>>;
  return Rows(a, 3, n, Eigen::OuterStride<>(stride)) * Eigen::Map<const Eigen::VectorXd>(x, n);
}

void FlexibleContactSurface::Check(const std::string& what) const {
  if (!modes_) throw std::invalid_argument(what + "no modes");
  if (!(spec_.gap_margin_m > 0))
    throw std::invalid_argument(what + "gap_margin_m must be > 0, got " +
                                std::to_string(spec_.gap_margin_m));
  if (!(spec_.deformation_allowance_m >= 0))
    throw std::invalid_argument(what + "deformation_allowance_m must be >= 0, got " +
                                std::to_string(spec_.deformation_allowance_m));
  if (spec_.angular_parts < 1) throw std::invalid_argument(what + "angular_parts must be >= 1");
  if (modes_->surface_triangles.empty())
    throw std::invalid_argument(what + "the modes have no surface");
}

std::vector<std::array<int, 3>> FlexibleContactSurface::SelectedTriangles(
    const std::string& what) const {
  const FlexibleBodyModes& m = *modes_;
  // The nodes allowed (all, or the union of the node sets).
  std::vector<char> allowed(m.nodes.size(), spec_.node_sets.empty() ? 1 : 0);
  for (const std::string& name : spec_.node_sets) {
    const auto it = m.node_sets.find(name);
    if (it == m.node_sets.end()) throw std::invalid_argument(what + "no node set '" + name + "'");
    for (int i : it->second) allowed[i] = 1;
  }
  std::vector<std::array<int, 3>> out;
  for (const auto& t : m.surface_triangles)
    if (allowed[t[0]] && allowed[t[1]] && allowed[t[2]]) out.push_back(t);
  if (out.empty()) throw std::invalid_argument(what + "no surface triangle in the node sets");
  return out;
}

void FlexibleContactSurface::SetBasesToVertices() {
  base_shapes_.resize(0, 0);  // the vertices' own shapes_rows_ serve
  const int nv = surface_->num_vertices();
  vertex_bases_.resize(nv);
  vertex_base_weights_.assign(nv, Vec3(1, 0, 0));
  for (int i = 0; i < nv; ++i) vertex_bases_[i] = {i, i, i};
}

void FlexibleContactSurface::SetModeBounds() {
  shapes_rows_ = shapes_;
  const int nv = static_cast<int>(shapes_.rows() / 3);
  const int nf = modes_->nf;
  mode_bounds_ = Eigen::VectorXd::Zero(nf);
  for (int i = 0; i < nv; ++i)
    for (int k = 0; k < nf; ++k)
      mode_bounds_(k) = std::max(mode_bounds_(k), shapes_.block<3, 1>(3 * i, k).norm());
  // Per part: the same over its vertices.
  const ContactSurface& s = *surface_;
  part_mode_bounds_ = Eigen::MatrixXd::Zero(s.num_parts(), nf);
  for (int p = 0; p < s.num_parts(); ++p)
    for (int i = s.part_vertex_start()[p]; i < s.part_vertex_start()[p + 1]; ++i)
      for (int k = 0; k < nf; ++k)
        part_mode_bounds_(p, k) =
            std::max(part_mode_bounds_(p, k), shapes_.block<3, 1>(3 * i, k).norm());
}

FlexibleContactSurface::FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                                               const FlexibleContactSurfaceSpec& spec)
    : modes_(std::move(modes)), spec_(spec) {
  const std::string what = "FlexibleContactSurface: ";
  Check(what);
  const FlexibleBodyModes& m = *modes_;
  // Triangles in the sets, grouped by the angular sector of their centroid.
  const int np = spec_.angular_parts;
  std::vector<TriangleMesh> parts(np);
  std::vector<std::vector<int>> part_nodes(np);
  std::vector<std::vector<int>> local(np);  // node -> vertex of the part (-1: none)
  for (int p = 0; p < np; ++p) local[p].assign(m.nodes.size(), -1);
  for (const auto& t : SelectedTriangles(what)) {
    int p = 0;
    if (np > 1) {
      const Vec3 c = (m.nodes[t[0]].position + m.nodes[t[1]].position + m.nodes[t[2]].position) / 3;
      const double pitch = 2 * kPi / np;
      const double a = std::atan2(c.y(), c.x()) - spec_.part_angle_offset_rad + 0.5 * pitch;
      p = static_cast<int>(std::floor(a / pitch)) % np;
      if (p < 0) p += np;
    }
    std::array<int, 3> tri;
    for (int k = 0; k < 3; ++k) {
      int& v = local[p][t[k]];
      if (v < 0) {
        v = static_cast<int>(parts[p].vertices.size());
        parts[p].vertices.push_back(m.nodes[t[k]].position);
        part_nodes[p].push_back(t[k]);
      }
      tri[k] = v;
    }
    parts[p].triangles.push_back(tri);
  }
  // Drop empty sectors; the vertex order of the surface is the parts' order.
  std::vector<TriangleMesh> kept;
  for (int p = 0; p < np; ++p) {
    if (parts[p].triangles.empty()) continue;
    vertex_node_.insert(vertex_node_.end(), part_nodes[p].begin(), part_nodes[p].end());
    kept.push_back(std::move(parts[p]));
  }
  surface_ = std::make_shared<const ContactSurface>(
      kept, spec_.gap_margin_m + 2 * spec_.deformation_allowance_m, spec_.slack_m, spec_.part_ring,
      /*part_stiffness_scale=*/std::vector<double>{}, spec_.smooth_normals);
  // Stacked shapes and the per-mode bounds.
  const int nv = static_cast<int>(vertex_node_.size());
  shapes_.resize(3 * nv, m.nf);
  for (int i = 0; i < nv; ++i) shapes_.middleRows(3 * i, 3) = m.nodes[vertex_node_[i]].translation_shapes;
  SetModeBounds();
  SetBasesToVertices();
}

FlexibleContactSurface::FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                                               const std::vector<TriangleMesh>& parts,
                                               const FlexibleContactSurfaceSpec& spec,
                                               double embed_tolerance_m)
    : modes_(std::move(modes)), spec_(spec) {
  const std::string what = "FlexibleContactSurface (embedded): ";
  Check(what);
  const FlexibleBodyModes& m = *modes_;
  const std::vector<std::array<int, 3>> tris = SelectedTriangles(what);
  surface_ = std::make_shared<const ContactSurface>(
      parts, spec_.gap_margin_m + 2 * spec_.deformation_allowance_m, spec_.slack_m, spec_.part_ring,
      /*part_stiffness_scale=*/std::vector<double>{}, spec_.smooth_normals);
  const auto& verts = surface_->vertices();
  const int nv = static_cast<int>(verts.size());
  vertex_node_.assign(nv, -1);
  shapes_ = Eigen::MatrixXd::Zero(3 * nv, m.nf);
  vertex_bases_.resize(nv);
  vertex_base_weights_.resize(nv);
  std::vector<int> base_of_node(m.nodes.size(), -1), base_nodes;
  // Each vertex on its closest FE triangle (brute force: built once).
  for (int i = 0; i < nv; ++i) {
    double best = std::numeric_limits<double>::infinity();
    int best_t = -1;
    Vec3 best_q = Vec3::Zero();
    for (int t = 0; t < static_cast<int>(tris.size()); ++t) {
      const auto& tri = tris[t];
      const ClosestPoint c = ClosestPointOnTriangle(verts[i], m.nodes[tri[0]].position,
                                                    m.nodes[tri[1]].position, m.nodes[tri[2]].position);
      const double d = (c.point - verts[i]).norm();
      if (d < best) best = d, best_t = t, best_q = c.point;
    }
    if (!(best <= embed_tolerance_m))
      throw std::invalid_argument(what + "vertex " + std::to_string(i) + " lies " +
                                  std::to_string(best) + " m from the FE surface (tolerance " +
                                  std::to_string(embed_tolerance_m) + " m)");
    const auto& tri = tris[best_t];
    const Vec3 a = m.nodes[tri[0]].position, b = m.nodes[tri[1]].position,
               c = m.nodes[tri[2]].position;
    const Vec3 w = Barycentric(best_q, a, b, c);
    for (int k = 0; k < 3; ++k) {
      shapes_.middleRows(3 * i, 3) += w[k] * m.nodes[tri[k]].translation_shapes;
      int& base = base_of_node[tri[k]];
      if (base < 0) {
        base = static_cast<int>(base_nodes.size());
        base_nodes.push_back(tri[k]);
      }
      vertex_bases_[i][k] = base;
    }
    vertex_base_weights_[i] = w;
  }
  SetModeBounds();
  // The FE nodes are the bases of DeformVertex.
  base_shapes_.resize(3 * base_nodes.size(), m.nf);
  for (size_t b = 0; b < base_nodes.size(); ++b)
    base_shapes_.middleRows(3 * b, 3) = m.nodes[base_nodes[b]].translation_shapes;
}

FlexibleContactSurface::FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                                               const std::vector<TriangleMesh>& parts,
                                               Eigen::MatrixXd shapes,
                                               const FlexibleContactSurfaceSpec& spec)
    : modes_(std::move(modes)), spec_(spec), shapes_(std::move(shapes)) {
  const std::string what = "FlexibleContactSurface (given shapes): ";
  Check(what);
  surface_ = std::make_shared<const ContactSurface>(
      parts, spec_.gap_margin_m + 2 * spec_.deformation_allowance_m, spec_.slack_m, spec_.part_ring,
      /*part_stiffness_scale=*/std::vector<double>{}, spec_.smooth_normals);
  if (shapes_.rows() != 3 * surface_->num_vertices() || shapes_.cols() != modes_->nf)
    throw std::invalid_argument(what + "shapes are " + std::to_string(shapes_.rows()) + " x " +
                                std::to_string(shapes_.cols()) + ", expected " +
                                std::to_string(3 * surface_->num_vertices()) + " x " +
                                std::to_string(modes_->nf));
  vertex_node_.assign(surface_->num_vertices(), -1);
  SetModeBounds();
  SetBasesToVertices();
}

double FlexibleContactSurface::DeformationBound(
    const Eigen::Ref<const Eigen::VectorXd>& q_f) const {
  return q_f.cwiseAbs().dot(mode_bounds_);
}

void FlexibleContactSurface::Deform(const Eigen::Ref<const Eigen::VectorXd>& q_f,
                                    Eigen::VectorXd* displacement, std::vector<Vec3>* vertices,
                                    std::vector<Vec3>* normals) const {
  const ContactSurface& s = *surface_;
  displacement->noalias() = shapes_ * q_f;
  const auto& s0 = s.vertices();
  for (int i = 0; i < s.num_vertices(); ++i)
    (*vertices)[i] = s0[i] + displacement->segment<3>(3 * i);
  const auto& tris = s.triangles();
  const auto& v = *vertices;
  for (int t = 0; t < s.num_triangles(); ++t) {
    const auto& tri = tris[t];
    (*normals)[t] = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]).normalized();
  }
}

double FlexibleContactSurface::PartDeformationBound(
    int part, const Eigen::Ref<const Eigen::VectorXd>& x) const {
  const double bound = part_mode_bounds_.row(part).dot(x.cwiseAbs().transpose());
  return bound > 0 ? bound * (1 + 1e-12) + 1e-15 : bound;
}

void FlexibleContactSurface::PartDeformationBounds(const Eigen::Ref<const Eigen::VectorXd>& x,
                                                   std::vector<double>* bounds) const {
  // PartDeformationBound's row dot sums a strided row of the column-major part_mode_bounds_
  // one term at a time from index 0 (Eigen's scalar reduction); here every part's sum gains its
  // terms in that order, column by column (independent sums: the compiler may take two parts
  // per instruction), then the same rounding allowance.
  const Eigen::Index np = part_mode_bounds_.rows(), n = x.size();
  double* b = bounds->data();
  const double* c = part_mode_bounds_.data();
  if (n == 0) {
    std::fill(b, b + np, 0.0);
    return;
  }
  const double x0 = std::abs(x[0]);
  for (Eigen::Index p = 0; p < np; ++p) b[p] = c[p] * x0;
  for (Eigen::Index k = 1; k < n; ++k) {
    const double xk = std::abs(x[k]);
    const double* ck = c + k * np;
    for (Eigen::Index p = 0; p < np; ++p) b[p] += ck[p] * xk;
  }
  for (Eigen::Index p = 0; p < np; ++p) b[p] = b[p] > 0 ? b[p] * (1 + 1e-12) + 1e-15 : b[p];
}

Vec3 FlexibleContactSurface::DeformVertex(int vertex, const Eigen::Ref<const Eigen::VectorXd>& q_f,
                                          std::vector<Vec3>* base_displacement,
                                          std::vector<long>* base_stamp, long epoch,
                                          int* bases_made) const {
  std::vector<Vec3>& ub = *base_displacement;
  const RowMajorMatrix& base_shapes = BaseShapes();
  const std::array<int, 3>& vb = vertex_bases_[vertex];
  const Vec3& w = vertex_base_weights_[vertex];
  // The vertex's bases not yet formed in this evaluation (a base of weight 0 is not read).
  for (int k = 0; k < 3; ++k) {
    const int b = vb[k];
    if (w(k) == 0 || (*base_stamp)[b] == epoch) continue;
    ub[b] = ThreeRowsTimes(base_shapes.data() + 3 * b * base_shapes.cols(), base_shapes.cols(),
                           q_f.data(), q_f.size());  // the numbers of middleRows<3>(3 b) * q_f
    (*base_stamp)[b] = epoch;
    ++*bases_made;
  }
  // Interpolated; a base of weight 0 adds nothing (and may hold an older displacement).
  Vec3 u = Vec3::Zero();
  for (int k = 0; k < 3; ++k)
    if (w(k) != 0) u += w(k) * ub[vb[k]];
  return surface_->vertices()[vertex] + u;
}

}  // namespace orrery::contact

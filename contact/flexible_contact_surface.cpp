#include "contact/flexible_contact_surface.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

namespace orrery::contact {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

FlexibleContactSurface::FlexibleContactSurface(std::shared_ptr<const FlexibleBodyModes> modes,
                                               const FlexibleContactSurfaceSpec& spec)
    : modes_(std::move(modes)), spec_(spec) {
  const std::string what = "FlexibleContactSurface: ";
  if (!modes_) throw std::invalid_argument(what + "no modes");
  if (!(spec_.gap_margin_m > 0))
    throw std::invalid_argument(what + "gap_margin_m must be > 0, got " +
                                std::to_string(spec_.gap_margin_m));
  if (!(spec_.deformation_allowance_m >= 0))
    throw std::invalid_argument(what + "deformation_allowance_m must be >= 0, got " +
                                std::to_string(spec_.deformation_allowance_m));
  if (spec_.angular_parts < 1)
    throw std::invalid_argument(what + "angular_parts must be >= 1");
  const FlexibleBodyModes& m = *modes_;
  if (m.surface_triangles.empty()) throw std::invalid_argument(what + "the modes have no surface");
  // The nodes allowed (all, or the union of the node sets).
  std::vector<char> allowed(m.nodes.size(), spec_.node_sets.empty() ? 1 : 0);
  for (const std::string& name : spec_.node_sets) {
    const auto it = m.node_sets.find(name);
    if (it == m.node_sets.end()) throw std::invalid_argument(what + "no node set '" + name + "'");
    for (int i : it->second) allowed[i] = 1;
  }
  // Triangles in the sets, grouped by the angular sector of their centroid.
  const int np = spec_.angular_parts;
  std::vector<gears::TriangleMesh> parts(np);
  std::vector<std::vector<int>> part_nodes(np);
  std::vector<std::vector<int>> local(np);  // node -> vertex of the part (-1: none)
  for (int p = 0; p < np; ++p) local[p].assign(m.nodes.size(), -1);
  for (const auto& t : m.surface_triangles) {
    if (!(allowed[t[0]] && allowed[t[1]] && allowed[t[2]])) continue;
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
  std::vector<gears::TriangleMesh> kept;
  for (int p = 0; p < np; ++p) {
    if (parts[p].triangles.empty()) continue;
    vertex_node_.insert(vertex_node_.end(), part_nodes[p].begin(), part_nodes[p].end());
    kept.push_back(std::move(parts[p]));
  }
  if (kept.empty()) throw std::invalid_argument(what + "no surface triangle in the node sets");
  surface_ = std::make_shared<const ContactSurface>(
      kept, spec_.gap_margin_m + 2 * spec_.deformation_allowance_m, spec_.slack_m);
  // Stacked shapes and the per-mode bounds.
  const int nv = static_cast<int>(vertex_node_.size());
  shapes_.resize(3 * nv, m.nf);
  mode_bounds_ = Eigen::VectorXd::Zero(m.nf);
  for (int i = 0; i < nv; ++i) {
    const auto& phi = m.nodes[vertex_node_[i]].translation_shapes;
    shapes_.middleRows(3 * i, 3) = phi;
    for (int k = 0; k < m.nf; ++k)
      mode_bounds_(k) = std::max(mode_bounds_(k), phi.col(k).norm());
  }
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

}  // namespace orrery::contact

#include "contact/deformed_vertices.h"

#include "contact/flexible_contact_surface.h"

namespace orrery::contact {

DeformedVertices::DeformedVertices(const FlexibleContactSurface& surface)
    : surface_(&surface),
      vertex_stamp_(surface.undeformed().num_vertices(), -1),
      base_displacement_(surface.num_bases(), Vec3::Zero()),
      base_stamp_(surface.num_bases(), -1) {}

void DeformedVertices::Begin(const Eigen::VectorXd* q_f, std::vector<Vec3>* vertices) {
  q_f_ = q_f;
  vertices_ = vertices;
  ++epoch_;
  vertices_made_ = bases_made_ = 0;
}

const Vec3& DeformedVertices::Make(int v) {
  (*vertices_)[v] =
      surface_->DeformVertex(v, *q_f_, &base_displacement_, &base_stamp_, epoch_, &bases_made_);
  vertex_stamp_[v] = epoch_;
  ++vertices_made_;
  return (*vertices_)[v];
}

}  // namespace orrery::contact

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

VertexRates::VertexRates(const FlexibleContactSurface& surface)
    : surface_(&surface),
      rate_(surface.undeformed().num_vertices(), Vec3::Zero()),
      stamp_(surface.undeformed().num_vertices(), -1) {}

void VertexRates::Begin(const Eigen::VectorXd* q_f_dot, const Mat3& R_WB) {
  q_f_dot_ = q_f_dot;
  R_WB_ = R_WB;
  ++epoch_;
  made_ = 0;
}

const Vec3& VertexRates::Make(int v) {
  // The direct product's expression: the same numbers as without the cache.
  rate_[v] = Vec3(R_WB_ * surface_->VertexShapeTimes(v, *q_f_dot_));
  stamp_[v] = epoch_;
  ++made_;
  return rate_[v];
}

}  // namespace orrery::contact

#include "contact/candidate_pairs.h"

#include <cmath>
#include <string>
#include <utility>
#include <stdexcept>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/collision_request.h>
#include <fcl/narrowphase/collision_result.h>
#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>

#include "contact/triangle_geometry.h"

namespace orrery::contact {

using Bvh = fcl::BVHModel<fcl::OBBRSSd>;

class CullingGeometry {
 public:
  std::vector<std::shared_ptr<Bvh>> parts;  // one hierarchy per part, part-local triangle ids
  double inflate = 0;                       // m: margin / 2
};

namespace {

// The local AABB that the broad phase transforms, inflated by margin / 2. FCL's CollisionObject
// constructor recomputes the local AABB, so this runs again after every construction.
void InflateLocalAabb(Bvh& bvh, double inflate) {
  bvh.computeLocalAABB();
  bvh.aabb_local.min_.array() -= inflate;
  bvh.aabb_local.max_.array() += inflate;
  bvh.aabb_center = bvh.aabb_local.center();
  bvh.aabb_radius = (bvh.aabb_local.min_ - bvh.aabb_center).norm();
}

}  // namespace

std::shared_ptr<const CullingGeometry> BuildCullingGeometry(const ContactSurface& surface) {
  auto geometry = std::make_shared<CullingGeometry>();
  const double inflate = 0.5 * surface.margin_m();
  geometry->inflate = inflate;
  for (int j = 0; j < surface.num_parts(); ++j) {
    // The part's vertices and triangles, indices local to the part.
    const int v0 = surface.part_vertex_start()[j], v1 = surface.part_vertex_start()[j + 1];
    const int t0 = surface.part_triangle_start()[j], t1 = surface.part_triangle_start()[j + 1];
    std::vector<fcl::Vector3d> points(surface.vertices().begin() + v0,
                                      surface.vertices().begin() + v1);
    std::vector<fcl::Triangle> triangles;
    triangles.reserve(t1 - t0);
    for (int t = t0; t < t1; ++t) {
      const auto& tri = surface.triangles()[t];
      triangles.emplace_back(tri[0] - v0, tri[1] - v0, tri[2] - v0);
    }
    auto bvh = std::make_shared<Bvh>();
    if (bvh->beginModel(t1 - t0, v1 - v0) != fcl::BVH_OK ||
        bvh->addSubModel(points, triangles) != fcl::BVH_OK || bvh->endModel() != fcl::BVH_OK)
      throw std::runtime_error("ContactSurface: FCL could not build the BVH of part " +
                               std::to_string(j));
    // Inflate every bounding volume by margin / 2 (OBB half-extents and RSS radius): two
    // inflated volumes overlap whenever the originals are closer than the margin.
    for (int i = 0; i < bvh->getNumBVs(); ++i) {
      fcl::OBBRSSd& bv = bvh->getBV(i).bv;
      bv.obb.extent.array() += inflate;
      bv.rss.r += inflate;
    }
    InflateLocalAabb(*bvh, inflate);
    geometry->parts.push_back(std::move(bvh));
  }
  return geometry;
}

namespace {

fcl::Transform3d ToFcl(const Transform& X) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = X.R;
  tf.translation() = X.p;
  return tf;
}

bool SamePose(const Transform& X, const Transform& Y) { return X.R == Y.R && X.p == Y.p; }

// FCL's OBBRSS mesh-mesh traversal with our leaf test: record the triangle pair if it lies
// within the search distance; never stop early.
class PairCollector final : public fcl::detail::MeshCollisionTraversalNodeOBBRSS<double> {
 public:
  void leafTesting(int b1, int b2) const override {
    ++*leaf_tests;
    const int ta = triangle_start_a + this->model1->getBV(b1).primitiveId();
    const int tb = triangle_start_b + this->model2->getBV(b2).primitiveId();
    const auto& A = surface_a->triangles()[ta];
    const auto& B = surface_b->triangles()[tb];
    const auto& va = surface_a->vertices();
    const auto& vb = surface_b->vertices();
    // Exact distance in A's frame.
    const double d2 = TriangleDistanceSquared(va[A[0]], va[A[1]], va[A[2]], X_AB * vb[B[0]],
                                              X_AB * vb[B[1]], X_AB * vb[B[2]]);
    if (d2 <= search_distance2) pairs->push_back({ta, tb});
  }
  bool canStop() const override { return false; }

  const ContactSurface* surface_a = nullptr;
  const ContactSurface* surface_b = nullptr;
  int triangle_start_a = 0, triangle_start_b = 0;
  Transform X_AB;
  double search_distance2 = 0;
  std::vector<TrianglePair>* pairs = nullptr;
  int* leaf_tests = nullptr;
};

}  // namespace

struct CandidateSearch::Impl {
  // Broad phase: one collision object per part, one manager per surface.
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects_a, objects_b;
  std::vector<fcl::CollisionObjectd*> raw_a, raw_b;
  fcl::DynamicAABBTreeCollisionManagerd manager_a, manager_b;
  // User data of the objects: j for part j of A, -(j + 1) for part j of B.
  std::vector<int> id_a, id_b;
  // Overlapping part pairs of the last broad phase.
  std::vector<std::pair<int, int>> part_pairs;
  Transform X_WA, X_WB, X_AB_last;
  bool have_pose = false, have_pairs = false;
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
};

namespace {

bool CollectPartPair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
  auto* part_pairs = static_cast<std::vector<std::pair<int, int>>*>(data);
  int id1 = *static_cast<const int*>(o1->getUserData());
  int id2 = *static_cast<const int*>(o2->getUserData());
  if (id1 < 0) std::swap(id1, id2);
  if (id1 >= 0 && id2 < 0) part_pairs->emplace_back(id1, -id2 - 1);
  return false;  // keep going
}

}  // namespace

CandidateSearch::CandidateSearch(const ContactSurface& surface_a, const ContactSurface& surface_b)
    : impl_(std::make_unique<Impl>()), a_(surface_a), b_(surface_b),
      search_distance_(0.5 * (surface_a.margin_m() + surface_b.margin_m())) {
  Impl& m = *impl_;
  const int na = surface_a.num_parts(), nb = surface_b.num_parts();
  for (int j = 0; j < na; ++j) m.id_a.push_back(j);
  for (int j = 0; j < nb; ++j) m.id_b.push_back(-(j + 1));
  for (int j = 0; j < na; ++j) {
    m.objects_a.push_back(std::make_unique<fcl::CollisionObjectd>(surface_a.culling().parts[j]));
    InflateLocalAabb(*surface_a.culling().parts[j], surface_a.culling().inflate);
    m.objects_a.back()->computeAABB();
    m.objects_a.back()->setUserData(&m.id_a[j]);
    m.raw_a.push_back(m.objects_a.back().get());
  }
  for (int j = 0; j < nb; ++j) {
    m.objects_b.push_back(std::make_unique<fcl::CollisionObjectd>(surface_b.culling().parts[j]));
    InflateLocalAabb(*surface_b.culling().parts[j], surface_b.culling().inflate);
    m.objects_b.back()->computeAABB();
    m.objects_b.back()->setUserData(&m.id_b[j]);
    m.raw_b.push_back(m.objects_b.back().get());
  }
  m.manager_a.registerObjects(m.raw_a);
  m.manager_b.registerObjects(m.raw_b);
  m.manager_a.setup();
  m.manager_b.setup();
  m.part_pairs.reserve(static_cast<size_t>(na) * nb);
}

CandidateSearch::~CandidateSearch() = default;

int CandidateSearch::suggested_capacity() const {
  return 16 * (a_.num_triangles() + b_.num_triangles());
}

void CandidateSearch::UpdateBroadPhase(const Transform& X_WA, const Transform& X_WB) {
  Impl& m = *impl_;
  // Refit only the surfaces that moved.
  const bool moved_a = !m.have_pose || !SamePose(X_WA, m.X_WA);
  const bool moved_b = !m.have_pose || !SamePose(X_WB, m.X_WB);
  if (moved_a) {
    const fcl::Transform3d tf = ToFcl(X_WA);
    for (auto* o : m.raw_a) {
      o->setTransform(tf);
      o->computeAABB();
    }
    m.manager_a.update();
  }
  if (moved_b) {
    const fcl::Transform3d tf = ToFcl(X_WB);
    for (auto* o : m.raw_b) {
      o->setTransform(tf);
      o->computeAABB();
    }
    m.manager_b.update();
  }
  m.X_WA = X_WA;
  m.X_WB = X_WB;
  m.have_pose = true;
  // Overlapping parts, A's part first.
  m.part_pairs.clear();
  m.manager_a.collide(&m.manager_b, &m.part_pairs, CollectPartPair);
  stats_.part_pairs = static_cast<int>(m.part_pairs.size());
}

void CandidateSearch::FindPairs(std::vector<TrianglePair>* pairs) {
  Impl& m = *impl_;
  pairs->clear();
  stats_.leaf_tests = 0;
  const Transform X_AB = m.X_WA.Inverse() * m.X_WB;
  const fcl::Transform3d tf_a = ToFcl(m.X_WA), tf_b = ToFcl(m.X_WB);
  for (const auto& [pa, pb] : m.part_pairs) {
    // FCL's traversal over the two inflated hierarchies, our leaf test.
    PairCollector node;
    const Bvh& bvh_a = *a_.culling().parts[pa];
    const Bvh& bvh_b = *b_.culling().parts[pb];
    fcl::detail::initialize(node, bvh_a, tf_a, bvh_b, tf_b, m.request, m.result);
    node.surface_a = &a_;
    node.surface_b = &b_;
    node.triangle_start_a = a_.part_triangle_start()[pa];
    node.triangle_start_b = b_.part_triangle_start()[pb];
    node.X_AB = X_AB;
    node.search_distance2 = search_distance_ * search_distance_;
    node.pairs = pairs;
    node.leaf_tests = &stats_.leaf_tests;
    fcl::detail::collide(&node, nullptr);
  }
  stats_.candidate_pairs = static_cast<int>(pairs->size());
}

bool CandidateSearch::Find(const Transform& X_WA, const Transform& X_WB,
                           std::vector<TrianglePair>* pairs) {
  Impl& m = *impl_;
  const Transform X_AB = X_WA.Inverse() * X_WB;
  if (m.have_pairs && SamePose(X_AB, m.X_AB_last)) return false;
  UpdateBroadPhase(X_WA, X_WB);
  FindPairs(pairs);
  m.X_AB_last = X_AB;
  m.have_pairs = true;
  return true;
}

}  // namespace orrery::contact

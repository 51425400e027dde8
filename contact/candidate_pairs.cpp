#include "contact/candidate_pairs.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <stdexcept>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>
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
  double inflate = 0;                       // m: (margin + slack) / 2
};


std::shared_ptr<const CullingGeometry> BuildCullingGeometry(const ContactSurface& surface) {
  auto geometry = std::make_shared<CullingGeometry>();
  const double inflate = 0.5 * (surface.margin_m() + surface.slack_m());
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
    // Inflate every bounding volume by (margin + slack) / 2 (OBB half-extents and RSS radius):
    // two inflated volumes overlap whenever the originals are closer than d + s.
    for (int i = 0; i < bvh->getNumBVs(); ++i) {
      fcl::OBBRSSd& bv = bvh->getBV(i).bv;
      bv.obb.extent.array() += inflate;
      bv.rss.r += inflate;
    }
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
    // Pre-check: triangle spheres farther apart than the search distance (one transform).
    const Vec3 c_b = X_AB * surface_b->triangle_centers()[tb];
    const double r = surface_a->triangle_radii()[ta] + surface_b->triangle_radii()[tb] + reach;
    if ((surface_a->triangle_centers()[ta] - c_b).squaredNorm() > r * r) return;
    ++*exact_tests;
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
  double search_distance2 = 0, reach = 0;
  std::vector<TrianglePair>* pairs = nullptr;
  int* leaf_tests = nullptr;
  int* exact_tests = nullptr;
};

// Angle wrapped to [-pi, pi].
double Wrap(double a) {
  constexpr double kTwoPi = 6.283185307179586;
  return a - kTwoPi * std::floor((a + 0.5 * kTwoPi) / kTwoPi);
}

// The ring zone seen from ring G: the polar angles phi in [0, pi] (measured from the direction
// to the other ring's axis, at distance a) of the points of G's band inner <= r <= outer
// that lie in the other ring's band grown by `reach`:
//   lo' - reach <= |P - O'| <= hi' + reach,  |P - O'|^2 = a^2 + r^2 - 2 a r cos(phi).
// |P - O'| grows with phi, so at each r the angles form one interval; their hull over r sampled
// at 33 radii, padded by the largest change between neighbouring samples, bounds the zone.
// Returns false if the bands cannot meet.
bool ZoneWindow(double a, double inner, double outer, double lo_other, double hi_other,
                double reach, double* phi_min, double* phi_max) {
  constexpr int kSamples = 33;
  constexpr double kPi = 3.14159265358979323846;
  const double near = std::max(0.0, lo_other - reach), far = hi_other + reach;
  double lo = kPi, hi = 0, prev_lo = 0, prev_hi = 0, pad = 0;
  bool any = false, prev = false;
  for (int k = 0; k < kSamples; ++k) {
    const double r = inner + (outer - inner) * k / (kSamples - 1);
    if (r <= 0) continue;
    const double c_far = (a * a + r * r - far * far) / (2 * a * r);    // cos at |P - O'| = far
    const double c_near = (a * a + r * r - near * near) / (2 * a * r);  // cos at |P - O'| = near
    if (c_far > 1 || c_near < -1) {
      prev = false;
      continue;
    }
    const double p_lo = std::acos(std::clamp(c_near, -1.0, 1.0));
    const double p_hi = std::acos(std::clamp(c_far, -1.0, 1.0));
    if (prev) pad = std::max({pad, std::abs(p_lo - prev_lo), std::abs(p_hi - prev_hi)});
    prev_lo = p_lo, prev_hi = p_hi, prev = true, any = true;
    lo = std::min(lo, p_lo);
    hi = std::max(hi, p_hi);
  }
  if (!any) return false;
  // An interval appearing between two samples: pad by a whole sample step's worth as well.
  pad = std::max(pad, 2 * reach / std::max(inner, 1e-12));
  *phi_min = std::max(0.0, lo - pad);
  *phi_max = std::min(kPi, hi + pad);
  return true;
}

// Whether part j of a ring, of angular half-width h, reaches into the zone window seen from the
// other ring's direction beta (ring frame).
inline bool InZoneWindow(const PartRing& ring, double beta, double phi_min, double phi_max,
                         double h, int j) {
  const double delta = std::abs(Wrap(ring.part_angles_rad[j] - beta));
  return delta + h >= phi_min && delta - h <= phi_max;
}

// Flags the parts of a ring inside the zone window; returns how many.
int FlagZoneParts(const PartRing& ring, double beta, double phi_min, double phi_max,
                  double angular_reach, std::vector<char>* flags) {
  int n = 0;
  const double h = ring.part_half_angle_rad + angular_reach;
  for (size_t j = 0; j < ring.part_angles_rad.size(); ++j) {
    const bool in = InZoneWindow(ring, beta, phi_min, phi_max, h, static_cast<int>(j));
    (*flags)[j] = in;
    n += in;
  }
  return n;
}

// The same for the parts of the pairs `among` only (their first parts, or their second): the
// same flags for those parts (others are left); returns how many of the pairs' parts are in,
// counted once per pair.
int FlagZoneParts(const PartRing& ring, double beta, double phi_min, double phi_max,
                  double angular_reach, const std::vector<std::pair<int, int>>& among, bool first,
                  std::vector<char>* flags) {
  int n = 0;
  const double h = ring.part_half_angle_rad + angular_reach;
  for (const auto& pair : among) {
    const int j = first ? pair.first : pair.second;
    const bool in = InZoneWindow(ring, beta, phi_min, phi_max, h, j);
    (*flags)[j] = in;
    n += in;
  }
  return n;
}

}  // namespace

struct CandidateSearch::Impl {
  // Overlapping part pairs of the last broad phase (capacity #parts_A * #parts_B).
  std::vector<std::pair<int, int>> part_pairs;
  // B's part centres in A's frame (capacity #parts_B).
  std::vector<Vec3> centers_b_A;
  // Parts inside the ring zone (part rings on both surfaces): flags, #parts_A and #parts_B.
  std::vector<char> zone_a, zone_b;
  std::vector<char> zone_a_grown, zone_b_grown;  // the same at the grown reach
  Transform X_WA, X_WB, X_AB_search, X_AB_previous;
  bool have_pairs = false, have_previous = false;
  // Mesh-zone windows of the last two (centre distance, reach) seen.
  struct Window {
    double a = -1, reach = -1, a_min = 0, a_max = 0, b_min = 0, b_max = 0;
    bool meet = false;
  };
  Window windows[2];
  int next_window = 0;
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;

  // One pair's sphere tests (UpdateBroadPhase and UpdateBroadPhaseAmong, the same arithmetic):
  // into part_pairs at reach where both parts are in its zone, into *grown (if given) at
  // reach_grown where both are in the grown zone. center_b_A: B's part centre in A's frame.
  void TestSpheres(const ContactSurface& a, const ContactSurface& b, int i, int j,
                   const Vec3& center_b_A, double reach, double reach_grown,
                   std::vector<std::pair<int, int>>* grown) {
    const double d2 = (center_b_A - a.part_centers()[i]).squaredNorm();
    const double r = a.part_radii()[i] + reach + b.part_radii()[j];
    const double r_grown = a.part_radii()[i] + reach_grown + b.part_radii()[j];
    if (grown && zone_a_grown[i] && zone_b_grown[j] && d2 <= r_grown * r_grown)
      grown->emplace_back(i, j);
    if (zone_a[i] && zone_b[j] && d2 <= r * r) part_pairs.emplace_back(i, j);
  }
};

CandidateSearch::CandidateSearch(const ContactSurface& surface_a, const ContactSurface& surface_b)
    : impl_(std::make_unique<Impl>()), a_(surface_a), b_(surface_b),
      search_distance_(0.5 * (surface_a.margin_m() + surface_b.margin_m())),
      slack_(0.5 * (surface_a.slack_m() + surface_b.slack_m())) {
  impl_->part_pairs.reserve(static_cast<size_t>(surface_a.num_parts()) * surface_b.num_parts());
  impl_->centers_b_A.resize(surface_b.num_parts());
  impl_->zone_a.assign(surface_a.num_parts(), 1);
  impl_->zone_b.assign(surface_b.num_parts(), 1);
  impl_->zone_a_grown.assign(surface_a.num_parts(), 1);
  impl_->zone_b_grown.assign(surface_b.num_parts(), 1);
}

CandidateSearch::~CandidateSearch() = default;

int CandidateSearch::suggested_capacity() const {
  return 4 * (a_.num_triangles() + b_.num_triangles());
}

double CandidateSearch::MotionBound(const Transform& X_AB0, const Transform& X_AB1) const {
  return (X_AB1.R - X_AB0.R).norm() * b_.max_vertex_radius_m() + (X_AB1.p - X_AB0.p).norm();
}

void CandidateSearch::FlagZones(const Transform& X_WA, const Transform& X_WB, double reach,
                                std::vector<char>* zone_a, std::vector<char>* zone_b,
                                double reach_grown, std::vector<char>* zone_a_grown,
                                std::vector<char>* zone_b_grown,
                                const std::vector<std::pair<int, int>>* among) {
  Impl& m = *impl_;
  const int na = a_.num_parts(), nb = b_.num_parts();
  const bool grown = zone_a_grown && zone_b_grown;
  // Ring zone of two part rings on (nearly) parallel axes: only parts whose angular span meets
  // the overlap of the two bands (at the rings' current angles) go on.
  std::fill(zone_a->begin(), zone_a->end(), 1);
  std::fill(zone_b->begin(), zone_b->end(), 1);
  if (grown) {
    std::fill(zone_a_grown->begin(), zone_a_grown->end(), 1);
    std::fill(zone_b_grown->begin(), zone_b_grown->end(), 1);
  }
  stats_.zone_parts_a = na;
  stats_.zone_parts_b = nb;
  if (!a_.part_ring() || !b_.part_ring()) return;
  const PartRing& ra = *a_.part_ring();
  const PartRing& rb = *b_.part_ring();
  const Transform X_GaGb = (X_WA * ra.X_BG).Inverse() * (X_WB * rb.X_BG);
  const Vec3 o_b = X_GaGb.p;                       // B's axis origin in Ga
  const Vec3 o_a = X_GaGb.Inverse().p;             // A's axis origin in Gb
  const double a = std::hypot(o_b.x(), o_b.y());
  const bool parallel = X_GaGb.R(2, 2) > 1 - 1e-6;  // both axes +z (tilt below ~1.4 mrad)
  if (!parallel || !(a > 0)) return;
  // The windows depend on a and the reach only: kept (two reaches) while a stays within
  // kWindowTolerance of the a they were computed at, with the reach grown by as much (the
  // distances |P - O'| change by at most the change of a).
  constexpr double kWindowTolerance = 1e-6;
  auto window = [&](double r_zone) -> const Impl::Window& {
    Impl::Window* found = nullptr;  // the last that fits
    for (Impl::Window& c : m.windows)
      if (c.reach == r_zone && std::abs(c.a - a) <= kWindowTolerance) found = &c;
    if (found) return *found;
    Impl::Window& w = m.windows[m.next_window];
    m.next_window = (m.next_window + 1) % 2;
    w.a = a;
    w.reach = r_zone;
    const double r = r_zone + kWindowTolerance;
    w.meet = ZoneWindow(a, ra.inner_radius_m, ra.outer_radius_m, rb.inner_radius_m,
                        rb.outer_radius_m, r, &w.a_min, &w.a_max) &&
             ZoneWindow(a, rb.inner_radius_m, rb.outer_radius_m, ra.inner_radius_m,
                        ra.outer_radius_m, r, &w.b_min, &w.b_max);
    return w;
  };
  // The grown reach's window first (the order in which the cache of two was filled when each
  // reach had a call of its own).
  const double beta_a = std::atan2(o_b.y(), o_b.x()), beta_b = std::atan2(o_a.y(), o_a.x());
  auto flag = [&](const Impl::Window& w, double r_zone, std::vector<char>* za,
                  std::vector<char>* zb) {
    if (w.meet && among) {
      stats_.zone_parts_a = FlagZoneParts(ra, beta_a, w.a_min, w.a_max,
                                          r_zone / std::max(ra.inner_radius_m, 1e-12), *among,
                                          /*first=*/true, za);
      stats_.zone_parts_b = FlagZoneParts(rb, beta_b, w.b_min, w.b_max,
                                          r_zone / std::max(rb.inner_radius_m, 1e-12), *among,
                                          /*first=*/false, zb);
    } else if (w.meet) {
      stats_.zone_parts_a = FlagZoneParts(ra, beta_a, w.a_min, w.a_max,
                                          r_zone / std::max(ra.inner_radius_m, 1e-12), za);
      stats_.zone_parts_b = FlagZoneParts(rb, beta_b, w.b_min, w.b_max,
                                          r_zone / std::max(rb.inner_radius_m, 1e-12), zb);
    } else {
      // The bands cannot meet: no part pair.
      std::fill(za->begin(), za->end(), 0);
      stats_.zone_parts_a = 0;
      stats_.zone_parts_b = nb;
    }
  };
  if (grown) flag(window(reach_grown), reach_grown, zone_a_grown, zone_b_grown);
  flag(window(reach), reach, zone_a, zone_b);  // last: the stats are this reach's
}

void CandidateSearch::UpdateBroadPhase(const Transform& X_WA, const Transform& X_WB,
                                       double extra_reach_m) {
  UpdateBroadPhase(X_WA, X_WB, extra_reach_m, 0, nullptr);
}

void CandidateSearch::UpdateBroadPhase(const Transform& X_WA, const Transform& X_WB,
                                       double extra_reach_m, double grow_m,
                                       std::vector<std::pair<int, int>>* grown) {
  Impl& m = *impl_;
  m.X_WA = X_WA;
  m.X_WB = X_WB;
  const Transform X_AB = X_WA.Inverse() * X_WB;
  // Part spheres of B in A's frame, grown by d + s, against A's spheres; for *grown the zone
  // and the spheres at the grown reach, in the same loop.
  const double reach = search_distance_ + slack_ + extra_reach_m;
  const double reach_grown = search_distance_ + slack_ + (extra_reach_m + grow_m);
  const int na = a_.num_parts(), nb = b_.num_parts();
  if (grown)
    FlagZones(X_WA, X_WB, reach, &m.zone_a, &m.zone_b, reach_grown, &m.zone_a_grown,
              &m.zone_b_grown);
  else
    FlagZones(X_WA, X_WB, reach, &m.zone_a, &m.zone_b);
  m.part_pairs.clear();
  if (grown) grown->clear();
  auto in = [&](const std::vector<char>& zone, const std::vector<char>& zone_grown, int k) {
    return zone[k] || (grown && zone_grown[k]);
  };
  // The centres of B's parts in the zone only (a ring gear's 50 teeth: 3 or 4).
  for (int j = 0; j < nb; ++j)
    if (in(m.zone_b, m.zone_b_grown, j)) m.centers_b_A[j] = X_AB * b_.part_centers()[j];
  for (int i = 0; i < na; ++i) {
    if (!in(m.zone_a, m.zone_a_grown, i)) continue;
    for (int j = 0; j < nb; ++j)
      if (in(m.zone_b, m.zone_b_grown, j))
        m.TestSpheres(a_, b_, i, j, m.centers_b_A[j], reach, reach_grown, grown);
  }
  stats_.part_pairs = static_cast<int>(m.part_pairs.size());
}

void CandidateSearch::UpdateBroadPhaseAmong(const Transform& X_WA, const Transform& X_WB,
                                            double extra_reach_m, double grow_m,
                                            const std::vector<std::pair<int, int>>& among,
                                            std::vector<std::pair<int, int>>* grown) {
  // UpdateBroadPhase's zones and sphere tests, expression for expression, over `among` only.
  Impl& m = *impl_;
  m.X_WA = X_WA;
  m.X_WB = X_WB;
  const Transform X_AB = X_WA.Inverse() * X_WB;
  const double reach = search_distance_ + slack_ + extra_reach_m;
  const double reach_grown = search_distance_ + slack_ + (extra_reach_m + grow_m);
  FlagZones(X_WA, X_WB, reach, &m.zone_a, &m.zone_b, reach_grown, &m.zone_a_grown, &m.zone_b_grown,
            &among);
  m.part_pairs.clear();
  grown->clear();
  for (const auto& [i, j] : among)
    if ((m.zone_a[i] || m.zone_a_grown[i]) && (m.zone_b[j] || m.zone_b_grown[j]))
      m.TestSpheres(a_, b_, i, j, X_AB * b_.part_centers()[j], reach, reach_grown, grown);
  stats_.part_pairs = static_cast<int>(m.part_pairs.size());
}

void CandidateSearch::FindPairs(std::vector<TrianglePair>* pairs) {
  Impl& m = *impl_;
  pairs->clear();
  stats_.leaf_tests = 0;
  stats_.exact_tests = 0;
  const Transform X_AB = m.X_WA.Inverse() * m.X_WB;
  const fcl::Transform3d tf_a = ToFcl(m.X_WA), tf_b = ToFcl(m.X_WB);
  const double reach = search_distance_ + slack_;
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
    node.search_distance2 = reach * reach;
    node.reach = reach;
    node.pairs = pairs;
    node.leaf_tests = &stats_.leaf_tests;
    node.exact_tests = &stats_.exact_tests;
    fcl::detail::collide(&node, nullptr);
  }
  stats_.candidate_pairs = static_cast<int>(pairs->size());
}

bool CandidateSearch::Find(const Transform& X_WA, const Transform& X_WB,
                           std::vector<TrianglePair>* pairs) {
  Impl& m = *impl_;
  const Transform X_AB = X_WA.Inverse() * X_WB;
  // Largest motion between consecutive calls (what the slack must cover per step).
  if (m.have_previous)
    stats_.max_motion_between_calls_m =
        std::max(stats_.max_motion_between_calls_m, MotionBound(m.X_AB_previous, X_AB));
  m.X_AB_previous = X_AB;
  m.have_previous = true;
  if (m.have_pairs) {
    stats_.motion_since_search_m = MotionBound(m.X_AB_search, X_AB);
    if (stats_.motion_since_search_m <= slack_ &&
        (slack_ > 0 || SamePose(X_AB, m.X_AB_search)))
      return false;
  }
  UpdateBroadPhase(X_WA, X_WB);
  FindPairs(pairs);
  m.X_AB_search = X_AB;
  m.have_pairs = true;
  stats_.motion_since_search_m = 0;
  ++stats_.searches;
  return true;
}

const std::vector<std::pair<int, int>>& CandidateSearch::part_pairs() const {
  return impl_->part_pairs;
}

void FindClosestFaceInPart(const ContactSurface& surface, int part, const Vec3& p,
                           ClosestFace* best) {
  FindClosestFaceInPart(surface, part, p, best, surface.vertices(), 0.0);
}

void FindClosestFaceInPart(const ContactSurface& surface, int part, const Vec3& p,
                           ClosestFace* best, const std::vector<Vec3>& v, double deformation_m,
                           double* unseen_d2) {
  FindClosestFaceInPart(surface, part, p, best, SurfaceVertices{.own = &v}, deformation_m,
                        unseen_d2);
}

void FindClosestFaceInPart(const ContactSurface& surface, int part, const Vec3& p,
                           ClosestFace* best, const SurfaceVertices& v, double deformation_m,
                           double* unseen_d2) {
  double unseen = std::numeric_limits<double>::infinity();
  const Bvh& bvh = *surface.culling().parts[part];
  const int t0 = surface.part_triangle_start()[part];
  const auto& tris = surface.triangles();
  // Squared distance from p to a node's oriented box as built (0 inside): the boxes were
  // inflated by `inflate` for the pair search, which would loosen the bound here.
  const double inflate = surface.culling().inflate;
  auto box_d2 = [&](int node) {
    const fcl::OBBd& obb = bvh.getBV(node).bv.obb;
    const Vec3 local = obb.axis.transpose() * (p - obb.To);
    const double d2 = (local.cwiseAbs().array() - (obb.extent.array() - inflate))
                          .cwiseMax(0.0)
                          .matrix()
                          .squaredNorm();
    if (deformation_m == 0) return d2;
    const double d = std::max(0.0, std::sqrt(d2) - deformation_m);
    return d * d;
  };
  // Depth-first, nearer child first; a node is skipped when its box is farther than the best.
  // FCL's hierarchies are binary and balanced (depth about log2 #triangles), so 128 entries
  // hold any stack this descent builds.
  constexpr int kStack = 128;
  int stack_node[kStack];
  double stack_d2[kStack];
  int top = 0;
  stack_node[top] = 0;
  stack_d2[top++] = box_d2(0);
  while (top > 0) {
    --top;
    const int node = stack_node[top];
    if (stack_d2[top] > best->d2) {
      unseen = std::min(unseen, stack_d2[top]);
      continue;
    }
    const auto& bv = bvh.getBV(node);
    if (bv.isLeaf()) {
      const int face = t0 + bv.primitiveId();
      const auto& t = tris[face];
      const ClosestPoint c = ClosestPointOnTriangle(p, v[t[0]], v[t[1]], v[t[2]]);
      const double d2 = (p - c.point).squaredNorm();
      if (d2 < best->d2 || (d2 == best->d2 && face < best->face)) {
        best->face = face;
        best->d2 = d2;
        best->point = c;
      } else {
        unseen = std::min(unseen, d2);
      }
      continue;
    }
    if (top + 2 > kStack)
      throw std::logic_error("FindClosestFaceInPart: hierarchy deeper than the stack");
    const int l = bv.leftChild(), r = bv.rightChild();
    const double dl = box_d2(l), dr = box_d2(r);
    // Push the farther first so that the nearer is taken next.
    const bool left_first = dl <= dr;
    stack_node[top] = left_first ? r : l;
    stack_d2[top++] = left_first ? dr : dl;
    stack_node[top] = left_first ? l : r;
    stack_d2[top++] = left_first ? dl : dr;
  }
  if (unseen_d2) *unseen_d2 = std::min(*unseen_d2, unseen);
}

bool PartBoxesWithin(const ContactSurface& a, int part_a, const ContactSurface& b, int part_b,
                     const Transform& X_AB, double reach_m) {
  const fcl::OBBd& box_a = a.culling().parts[part_a]->getBV(0).bv.obb;
  const fcl::OBBd& box_b = b.culling().parts[part_b]->getBV(0).bv.obb;
  // Half-extents as built, A's grown by the reach; B's box in the frame of A's box.
  const Vec3 e_a = (box_a.extent.array() - a.culling().inflate + reach_m).matrix();
  const Vec3 e_b = (box_b.extent.array() - b.culling().inflate).matrix();
  const Mat3 R = box_a.axis.transpose() * X_AB.R * box_b.axis;
  const Vec3 T = box_a.axis.transpose() * (X_AB * Vec3(box_b.To) - box_a.To);
  return !fcl::obbDisjoint(R, T, e_a, e_b);
}

bool PartBoxesFacesWithin(const ContactSurface& a, int part_a, const ContactSurface& b, int part_b,
                          const Transform& X_AB, double reach_m) {
  const fcl::OBBd& box_a = a.culling().parts[part_a]->getBV(0).bv.obb;
  const fcl::OBBd& box_b = b.culling().parts[part_b]->getBV(0).bv.obb;
  const Vec3 e_a = (box_a.extent.array() - a.culling().inflate + reach_m).matrix();
  const Vec3 e_b = (box_b.extent.array() - b.culling().inflate).matrix();
  const Mat3 R = box_a.axis.transpose() * X_AB.R * box_b.axis;
  const Vec3 T = box_a.axis.transpose() * (X_AB * Vec3(box_b.To) - box_a.To);
  // fcl::obbDisjoint's tests of A's axes: |T_i| > a_i + (|R| + 1e-6)_i . b separates.
  constexpr double kReps = 1e-6;
  for (int i = 0; i < 3; ++i)
    if (std::abs(T[i]) > e_a[i] + (R.row(i).cwiseAbs().array() + kReps).matrix().dot(e_b))
      return false;
  return true;
}

std::array<Vec3, 8> PartBoxCorners(const ContactSurface& surface, int part) {
  const fcl::OBBd& box = surface.culling().parts[part]->getBV(0).bv.obb;
  std::array<Vec3, 8> corners;
  for (int k = 0; k < 8; ++k)
    corners[k] = box.To + box.axis.col(0) * ((k & 1) ? box.extent[0] : -box.extent[0]) +
                 box.axis.col(1) * ((k & 2) ? box.extent[1] : -box.extent[1]) +
                 box.axis.col(2) * ((k & 4) ? box.extent[2] : -box.extent[2]);
  return corners;
}

void CandidateSearch::Invalidate() { impl_->have_pairs = false; }

}  // namespace orrery::contact

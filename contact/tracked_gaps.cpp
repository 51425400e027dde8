#include "contact/tracked_gaps.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace orrery::contact {

namespace {

// Face changes a walk may take before the node is searched exactly instead.
constexpr int kMaxWalkSteps = 32;

// The far distance, the search's bound for the nodes of a pair that has just joined, in walk
// reaches d + s (header; the other searches are bounded by d + s).
constexpr double kFarReaches = 5;

// Odometer reading (m) at which the odometers start again from zero with every node seeded
// anew: a diverging Newton iterate can add 1e130 m in one call (or a NaN), after which the
// micrometre motions still to come no longer change the sum, and the nodes would sleep on.
// Ordinary runs reach it after some 1e5 evaluations (a restart then costs one seeding).
constexpr double kOdometerRestart = 1.0;

// The share of the slack s by which B may move from its pose at the last broad phase (with
// the deformed parts' bounds' change) before TrackPairs runs it again (header). A Newton
// correction moves the teeth by nanometres to a micrometre; a step by tens of micrometres.
constexpr double kBroadPhaseReuse = 1.0 / 16;

using Geometry = TrackedGaps::Geometry;

ClosestFace OnFace(const Geometry& g, int face, const Vec3& p) {
  const auto& t = g.s.triangles()[face];
  const auto& v = g.v;
  ClosestFace c;
  c.face = face;
  c.point = ClosestPointOnTriangle(p, v[t[0]], v[t[1]], v[t[2]]);
  c.d2 = (p - c.point.point).squaredNorm();
  return c;
}

// Rounding allowance of the walk's skip test (m): the distances it compares are computed to
// about 1e-17 m (coordinates below 1 m).
constexpr double kWalkRounding = 1e-12;
// Pass::walk_pair's marker of a margin recorded by a look along a profile (RunPass), which
// counts columns, not faces: the faces' walk does not read it, nor the look a face walk's.
constexpr int kColumnMargin = -2;
// Node rows within this many units of the rounding of a face part's heights count as within
// them (RunPass, extruded parts).
constexpr double kRowHeightUlps = 16;

// The row of an extruded part of `rows` rows whose nodes are evaluated when they share: the
// middle one, away from the rims.
int EvaluatedRow(int rows) { return (rows - 1) / 2; }

bool IsVertex(TriangleFeature f) {
  return f == TriangleFeature::kVertex0 || f == TriangleFeature::kVertex1 ||
         f == TriangleFeature::kVertex2;
}

// Whether the closest point's feature lies on a rim edge next to another part.
bool OnSharedRim(const ContactSurface& s, const ClosestFace& c) {
  return s.shared_rim_edges()[c.face] & FeatureEdges(c.point.feature);
}

// The triangle distances measured at one node position, for the tied pair's margin that
// follows a walk there (PairMargin): the walk's last round measured the faces across the edges
// of the face it settled on, and PairMargin reaches most of them again (and some twice). OnFace
// at the same position gives the same value, and the margin is a minimum, so taking a kept
// value leaves it unchanged to the bit. A fixed array: no allocation; full, a face is measured.
struct MeasuredFaces {
  static constexpr int kMax = 32;
  int n = 0;
  std::array<int, kMax> face;
  std::array<double, kMax> d2;
  void Add(int f, double d2_f) {
    if (n == kMax) return;
    face[n] = f;
    d2[n++] = d2_f;
  }
  // The squared distance of `f` to p, from the kept values or measured (and kept).
  double Of(const Geometry& g, int f, const Vec3& p) {
    for (int i = 0; i < n; ++i)
      if (face[i] == f) return d2[i];
    const double d2_f = OnFace(g, f, p).d2;
    Add(f, d2_f);
    return d2_f;
  }
};

// Local descent over the faces (header): at each step the faces across the current face's
// three edges, and around its vertex when the closest point is one, are tried, and the walk
// moves to the closest (ties to the lower index); a node below its face also tries the faces
// two edges away before it settles. False if it did not settle within kMaxWalkSteps.
// *margin_m: at the face it settled on, the smallest distance of the faces it tried there less
// the face's own (what lets a later evaluation skip the walk, RunPass). *measured: the faces
// tried in its last round (at the face it settled on) with their squared distances.
bool Walk(const Geometry& g, const Vec3& p, ClosestFace* current, long* steps, double* margin_m,
          MeasuredFaces* measured) {
  const ContactSurface& s = g.s;
  const auto& tris = s.triangles();
  for (int step = 0; step < kMaxWalkSteps; ++step) {
    ClosestFace best = *current;
    double tried_d2 = std::numeric_limits<double>::infinity();
    measured->n = 0;
    auto consider = [&](int face) {
      if (face < 0 || face == current->face) return;
      const ClosestFace c = OnFace(g, face, p);
      measured->Add(face, c.d2);
      tried_d2 = std::min(tried_d2, c.d2);
      if (c.d2 < best.d2 || (c.d2 == best.d2 && face < best.face)) best = c;
    };
    for (const int neighbor : s.face_neighbors()[current->face]) consider(neighbor);
    const TriangleFeature feature = current->point.feature;
    if (feature == TriangleFeature::kVertex0 || feature == TriangleFeature::kVertex1 ||
        feature == TriangleFeature::kVertex2) {
      const int k = feature == TriangleFeature::kVertex0   ? 0
                    : feature == TriangleFeature::kVertex1 ? 1
                                                           : 2;
      const int vertex = tris[current->face][k];
      for (int i = s.vertex_face_start()[vertex]; i < s.vertex_face_start()[vertex + 1]; ++i)
        consider(s.vertex_faces()[i]);
    }
    // Settled: a node below its face also tries the faces two edges away (where facets of
    // different length meet, such as at the start of the involute, the distance along the
    // profile can dip again one face further on).
    if (best.face == current->face && (p - current->point.point).dot(g.Normal(current->face)) < 0)
      for (const int neighbor : s.face_neighbors()[current->face])
        if (neighbor >= 0)
          for (const int second : s.face_neighbors()[neighbor]) consider(second);
    if (best.face == current->face) {
      *margin_m = std::sqrt(tried_d2) - std::sqrt(current->d2);
      return true;
    }
    *current = best;
    ++*steps;
  }
  return false;
}

// The margin of a tied pair (header): the smallest distance of the faces a walk from f or from
// h could try, other than f and h (their edge neighbours and the faces two edges away; a face
// reached twice, or measured by the walk before, is taken from *measured), less the larger of
// d2_f and d2_h's distances.
double PairMargin(const Geometry& g, const Vec3& p, int f, int h, double d2_f, double d2_h,
                  MeasuredFaces* measured) {
  const ContactSurface& s = g.s;
  double tried_d2 = std::numeric_limits<double>::infinity();
  auto consider = [&](int face) {
    if (face < 0 || face == f || face == h) return;
    tried_d2 = std::min(tried_d2, measured->Of(g, face, p));
  };
  for (const int start : {f, h})
    for (const int neighbor : s.face_neighbors()[start]) {
      consider(neighbor);
      if (neighbor >= 0)
        for (const int second : s.face_neighbors()[neighbor]) consider(second);
    }
  return std::sqrt(tried_d2) - std::sqrt(std::max(d2_f, d2_h));
}

// The closest point to p of column `column` of an extruded part's profile (`profile`: its row 0,
// n points; the column the segment from point `column` to the next), in the xy plane: the
// fraction t along the segment (clamped to [0, 1], ContactSurface::ExtrudedColumnFraction's
// expression), the point at p's height and the squared distance in xy, which is the distance
// to the column's rectangles when p's height lies within the part's rows.
struct ColumnPoint {
  int column = -1;
  double t = 0;
  Vec3 point = Vec3::Zero();
  double d2 = 0;
};

// The fraction t and the point of ColumnPoint (inline: the walk along the profile compares a
// few columns at every look).
inline double ColumnFraction(const Vec3& a, const Vec3& b, const Vec3& p) {
  const double ex = b.x() - a.x(), ey = b.y() - a.y();
  return std::clamp(((p.x() - a.x()) * ex + (p.y() - a.y()) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
}

inline ColumnPoint OnColumn(const Vec3* profile, int column, const Vec3& p) {
  const Vec3& a = profile[column];
  const Vec3& b = profile[column + 1];
  ColumnPoint c;
  c.column = column;
  c.t = ColumnFraction(a, b, p);
  c.point = Vec3(a.x() + c.t * (b.x() - a.x()), a.y() + c.t * (b.y() - a.y()), p.z());
  const double dx = p.x() - c.point.x(), dy = p.y() - c.point.y();
  c.d2 = dx * dx + dy * dy;
  return c;
}

// The edge (0, 1, 2) of an edge feature, -1 otherwise.
int FeatureEdge(TriangleFeature f) {
  return f == TriangleFeature::kEdge0 ? 0 : f == TriangleFeature::kEdge1 ? 1
                                      : f == TriangleFeature::kEdge2 ? 2 : -1;
}

}  // namespace

const Vec3& TrackedGaps::Geometry::MakeNormal(int face) const {
  const auto& t = s.triangles()[face];
  const Vec3 c = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
  (*lazy_n)[face] = c * (1.0 / c.norm());  // one division, not three
  (*stamp)[face] = epoch;
  return (*lazy_n)[face];
}

TrackedGaps::Pass::Pass(const ContactSurface& node_surface, bool keep_face_weights)
    : face(node_surface.num_vertices(), kUnseeded),
      reach(node_surface.num_vertices(), 0.0),
      distance(node_surface.num_vertices(), 0.0),
      wake(node_surface.num_vertices(), -std::numeric_limits<double>::infinity()),
      stamp_position(node_surface.num_vertices(), Vec3::Zero()),
      stamp_face_deformation(node_surface.num_vertices(), 0.0),
      walk_margin(node_surface.num_vertices(), 0.0),
      walk_position(node_surface.num_vertices(), Vec3::Zero()),
      walk_face_deformation(node_surface.num_vertices(), 0.0),
      walk_feature(node_surface.num_vertices(), TriangleFeature::kFace),
      walk_below(node_surface.num_vertices(), 0),
      walk_pair(node_surface.num_vertices(), {-1, -1}),
      face_weights(keep_face_weights ? node_surface.num_vertices() : 0, Vec3::Zero()),
      rows_shared(node_surface.num_parts(), 0) {
  const auto& start = node_surface.part_vertex_start();
  part_block_start.assign(start.size(), 0);
  for (size_t part = 0; part + 1 < start.size(); ++part)
    part_block_start[part + 1] =
        part_block_start[part] + (start[part + 1] - start[part] + kBlock - 1) / kBlock;
  block_wake.assign(part_block_start.back(), -std::numeric_limits<double>::infinity());
}

TrackedGaps::TrackedGaps(const ContactSurface& surface_a, const ContactSurface& surface_b,
                         bool keep_face_weights)
    : a_(surface_a),
      b_(surface_b),
      search_(surface_a, surface_b),
      pass_a_(surface_a, keep_face_weights),
      pass_b_(surface_b, keep_face_weights),
      keep_face_weights_(keep_face_weights) {
  const size_t all_pairs = static_cast<size_t>(a_.num_parts()) * b_.num_parts();
  tracked_.reserve(all_pairs);
  next_.reserve(all_pairs);
  keep_.reserve(all_pairs);
  by_part_.reserve(all_pairs);
  tracked_parts_a_.reserve(a_.num_parts());
  tracked_parts_b_.reserve(b_.num_parts());
  partners_.reserve(std::max(a_.num_parts(), b_.num_parts()));
  partner_places_.reserve(partners_.capacity());
  partner_heights_.reserve(partners_.capacity());
  active_b_.assign(b_.num_parts(), 0);
  odometer_a_.assign(a_.num_parts(), 0.0);
  odometer_b_.assign(b_.num_parts(), 0.0);
  motion_a_.assign(a_.num_parts(), 0.0);
  motion_b_.assign(b_.num_parts(), 0.0);
  row_groups_a_.reserve(a_.num_parts());
  row_groups_b_.reserve(b_.num_parts());
  part_box_corners_b_.reserve(b_.num_parts());
  for (int j = 0; j < b_.num_parts(); ++j) part_box_corners_b_.push_back(PartBoxCorners(b_, j));
  // The corners bound every point of the boxes (as inflated, which hold them as built); the
  // part centres are the spheres' (TrackPairs moves both by at most mu).
  for (const auto& corners : part_box_corners_b_)
    for (const Vec3& x : corners) box_radius_b_ = std::max(box_radius_b_, x.norm());
  for (const Vec3& c : b_.part_centers()) box_radius_b_ = std::max(box_radius_b_, c.norm());
  centers_b_A_.resize(b_.num_parts());
  candidates_.reserve(all_pairs);
  broad_phase_d_a_.reserve(a_.num_parts());
  broad_phase_d_b_.reserve(b_.num_parts());
}

void TrackedGaps::Reset() {
  for (Pass* pass : {&pass_a_, &pass_b_}) {
    std::fill(pass->face.begin(), pass->face.end(), kUnseeded);
    std::fill(pass->reach.begin(), pass->reach.end(), 0.0);
    std::fill(pass->wake.begin(), pass->wake.end(), -std::numeric_limits<double>::infinity());
    std::fill(pass->stamp_face_deformation.begin(), pass->stamp_face_deformation.end(), 0.0);
    std::fill(pass->block_wake.begin(), pass->block_wake.end(),
              -std::numeric_limits<double>::infinity());
    std::fill(pass->rows_shared.begin(), pass->rows_shared.end(), 0);
  }
}

void TrackedGaps::WarmStartFrom(const TrackedGaps& source) {
  if (&source == this) return;
  if (&source.a_ != &a_ || &source.b_ != &b_)
    throw std::invalid_argument("TrackedGaps::WarmStartFrom: the source tracks other surfaces");
  // Pairs and parts (capacities reserved for every pair and part: no allocation).
  tracked_.assign(source.tracked_.begin(), source.tracked_.end());
  tracked_parts_a_.assign(source.tracked_parts_a_.begin(), source.tracked_parts_a_.end());
  tracked_parts_b_.assign(source.tracked_parts_b_.begin(), source.tracked_parts_b_.end());
  std::copy(source.active_b_.begin(), source.active_b_.end(), active_b_.begin());
  X_AB_broad_phase_ = source.X_AB_broad_phase_;
  have_broad_phase_pose_ = source.have_broad_phase_pose_;
  broad_phase_deformed_ = source.broad_phase_deformed_;
  broad_phase_gap_distance_m_ = source.broad_phase_gap_distance_m_;
  broad_phase_d_a_.assign(source.broad_phase_d_a_.begin(), source.broad_phase_d_a_.end());
  broad_phase_d_b_.assign(source.broad_phase_d_b_.begin(), source.broad_phase_d_b_.end());
  // The nodes of the tracked parts, per pass.
  auto copy_parts = [](const ContactSurface& surface, const std::vector<int>& parts,
                       const Pass& from, Pass& to) {
    for (const int part : parts) {
      int v0 = surface.part_vertex_start()[part], v1 = surface.part_vertex_start()[part + 1];
      // A part sharing its rows reads its evaluated row alone (the others are seeded anew when
      // it stops: RunPass), so that row's nodes are the state there is to take.
      if (from.rows_shared[part]) {
        const int n = surface.part_row_length()[part];
        v0 += EvaluatedRow(surface.part_rows()[part]) * n;
        v1 = v0 + n;
      }
      auto range = [&](const auto& x, auto& y) {
        std::copy(x.begin() + v0, x.begin() + v1, y.begin() + v0);
      };
      range(from.face, to.face);
      range(from.reach, to.reach);
      range(from.distance, to.distance);
      range(from.wake, to.wake);
      range(from.stamp_position, to.stamp_position);
      range(from.stamp_face_deformation, to.stamp_face_deformation);
      range(from.walk_margin, to.walk_margin);
      range(from.walk_position, to.walk_position);
      range(from.walk_face_deformation, to.walk_face_deformation);
      range(from.walk_feature, to.walk_feature);
      range(from.walk_below, to.walk_below);
      range(from.walk_pair, to.walk_pair);
      to.rows_shared[part] = from.rows_shared[part];
      std::copy(from.block_wake.begin() + from.part_block_start[part],
                from.block_wake.begin() + from.part_block_start[part + 1],
                to.block_wake.begin() + to.part_block_start[part]);
    }
  };
  copy_parts(a_, source.tracked_parts_a_, source.pass_a_, pass_a_);
  copy_parts(b_, source.tracked_parts_b_, source.pass_b_, pass_b_);
  // Odometers and the pose they were last advanced to.
  X_AB_previous_ = source.X_AB_previous_;
  have_previous_ = source.have_previous_;
  odometer_ = source.odometer_;
  face_deformation_a_ = source.face_deformation_a_;
  face_deformation_b_ = source.face_deformation_b_;
  std::copy(source.odometer_a_.begin(), source.odometer_a_.end(), odometer_a_.begin());
  std::copy(source.odometer_b_.begin(), source.odometer_b_.end(), odometer_b_.begin());
  odometer_saturated_ = source.odometer_saturated_;
  largest_odometer_ = source.largest_odometer_;
}

void TrackedGaps::ResetPart(Pass& pass, const ContactSurface& node_surface, int part) {
  for (int v = node_surface.part_vertex_start()[part];
       v < node_surface.part_vertex_start()[part + 1]; ++v) {
    pass.face[v] = kUnseeded;
    pass.reach[v] = 0;
    pass.wake[v] = -std::numeric_limits<double>::infinity();
  }
  for (int block = pass.part_block_start[part]; block < pass.part_block_start[part + 1]; ++block)
    pass.block_wake[block] = -std::numeric_limits<double>::infinity();
}

double TrackedGaps::PartMotion(int part_b, const Mat3& dR, const Vec3& dp,
                               const Vec3& dR_column_norms) const {
  // The box's corners: a point of the part is a convex combination of them, and so is its
  // motion dR x + dp of theirs.
  double corners2 = 0;
  for (const Vec3& x : part_box_corners_b_[part_b])
    corners2 = std::max(corners2, (dR * x + dp).squaredNorm());
  // The axis-aligned box (the axial extent of a gear tooth drops out for rotations about the
  // gear axis; the oriented box may be the tighter when the part turns about another axis).
  const Vec3& h = b_.part_half_extents()[part_b];
  const double aligned = dR_column_norms.x() * h.x() + dR_column_norms.y() * h.y() +
                         dR_column_norms.z() * h.z() + (dR * b_.part_centers()[part_b] + dp).norm();
  return std::min(std::sqrt(corners2), aligned);
}

void TrackedGaps::Update(const Transform& X_WA, const Transform& X_WB, std::vector<NodeGap>* gaps_a,
                         std::vector<NodeGap>* gaps_b, bool defer_rows) {
  defer_rows_ = defer_rows;
  Update(X_WA, X_WB, {.vertices = &a_.vertices(), .normals = &a_.face_normals()},
         {.vertices = &b_.vertices(), .normals = &b_.face_normals()},
         search_.search_distance_m(), gaps_a, gaps_b);
  defer_rows_ = false;
}

void TrackedGaps::CompleteRows(const Transform& X_WA, const Transform& X_WB,
                               std::vector<NodeGap>* gaps, std::vector<RowGroup>* groups,
                               bool nodes_are_a) const {
  // The rows each pending run adds, and the list's size with them (within its capacity).
  size_t added = 0;
  for (const RowGroup& run : *groups)
    if (run.pending) added += static_cast<size_t>(run.rows - 1) * run.count;
  if (added == 0) return;
  const ContactSurface& node_surface = nodes_are_a ? a_ : b_;
  const ContactSurface& face_surface = nodes_are_a ? b_ : a_;
  const Transform& X_WN = nodes_are_a ? X_WA : X_WB;
  const Transform& X_WF = nodes_are_a ? X_WB : X_WA;
  const Transform X_FN = X_WF.Inverse() * X_WN;  // as ComputeGaps gives it to the pass
  const size_t old_size = gaps->size();
  gaps->resize(old_size + added);
  NodeGap* list = gaps->data();
  // From the last run back: the entries after a run move by the rows added up to and with it,
  // the run's own entries by those added before it, and a pending run's rows are then made in
  // its block (its evaluated row's entries first, ShareRows).
  size_t tail_end = old_size;  // the end of the entries after run j, before the moves
  size_t shift = added;        // how far they move
  auto move_right = [&](size_t from, size_t to, size_t by) {
    if (by > 0 && to > from) std::move_backward(list + from, list + to, list + to + by);
  };
  for (size_t j = groups->size(); j-- > 0;) {
    RowGroup& run = (*groups)[j];
    const size_t begin = static_cast<size_t>(run.begin);
    const size_t end = begin + static_cast<size_t>(run.pending ? 1 : run.rows) * run.count;
    move_right(end, tail_end, shift);
    if (run.pending) shift -= static_cast<size_t>(run.rows - 1) * run.count;
    move_right(begin, end, shift);
    run.begin = static_cast<int>(begin + shift);
    if (run.pending) {
      ShareRows(node_surface, face_surface, run, X_FN, X_WF, list + run.begin);
      run.pending = false;
    }
    tail_end = begin;
  }
}

void TrackedGaps::Update(const Transform& X_WA, const Transform& X_WB, const TrackedSide& side_a,
                         const TrackedSide& side_b, double gap_distance_m,
                         std::vector<NodeGap>* gaps_a, std::vector<NodeGap>* gaps_b) {
  // Rigid sides (their vertices are the surfaces' own): the parts' boxes bound them.
  TrackPairs(X_WA, X_WB, side_a.vertices == &a_.vertices() && side_b.vertices == &b_.vertices());
  ComputeGaps(X_WA, X_WB, side_a, side_b, gap_distance_m, gaps_a, gaps_b);
}

void TrackedGaps::UpdateTrackedSet(const Transform& X_WA, const Transform& X_WB,
                                   const Transform& X_AB, bool part_boxes,
                                   const DeformedParts* deformed) {
  const double s = search_.slack_m();
  // Tracked pairs: the broad phase's, plus tracked pairs still in the broad phase grown by s;
  // with the parts' boxes (rigid surfaces), a new pair's boxes within d + s, a tracked pair's
  // within d + 2 s (one box test per pair).
  // Deformed sides: the broad phase's reach holds deformations up to the surfaces' allowances
  // (their margins' share beyond the gap distance, flexible_contact_surface.h); beyond, it is
  // grown by the excess of the largest part bounds.
  double excess = 0, deformation_sum = 0;
  if (deformed) {
    auto largest = [](const std::vector<double>* v) {
      return v ? *std::max_element(v->begin(), v->end()) : 0.0;
    };
    deformation_sum = largest(deformed->a) + largest(deformed->b);
    excess =
        std::max(0.0, deformation_sum - (search_.search_distance_m() - deformed->gap_distance_m));
  }
  // Deformed sides: a part's deformed vertices lie within its displacement bound of its own, so
  // its box is grown by it (DeformedParts).
  const double reach = (deformed ? deformed->gap_distance_m : search_.search_distance_m()) + s;
  // Candidate pairs (header): made anew when the motion since they were made, plus the growth
  // of the deformation sum, exceeds the margin (or for a pose that is not finite: the full
  // broad phase). Rigid sides too: with the margin of a few millimetres a gear pair rolls for
  // tens of steps on one set (docs/performance.md, "candidates").
  if (part_boxes && pair_candidates_ && X_AB.R.allFinite() && X_AB.p.allFinite()) {
    const double mu =
        (X_AB.R - X_AB_candidates_.R).norm() * box_radius_b_ + (X_AB.p - X_AB_candidates_.p).norm();
    // The margin's last 1e-9 m covers the rounding of the tests and of mu.
    constexpr double kRounding = 1e-9;
    if (!have_candidates_ || candidates_reach_m_ != reach + s ||
        !(mu + std::max(0.0, deformation_sum - candidates_deformation_m_) <=
          kCandidateMargin - kRounding)) {
      // A pair the broad phase lists has its part spheres within d + 2 s + excess (the kept
      // pairs' reach) and its centres move by at most mu: the spheres within that + m now
      // (excess grows by at most what G does); then A's face axes of the box test.
      candidates_.clear();
      const double r0 = reach + s + deformation_sum + kCandidateMargin;
      const double r_spheres =
          search_.search_distance_m() + 2 * s + excess + kCandidateMargin + kRounding;
      for (int j = 0; j < b_.num_parts(); ++j) centers_b_A_[j] = X_AB * b_.part_centers()[j];
      for (int i = 0; i < a_.num_parts(); ++i) {
        const Vec3& c_a = a_.part_centers()[i];
        const double r_a = a_.part_radii()[i] + r_spheres;
        for (int j = 0; j < b_.num_parts(); ++j) {
          const double r = r_a + b_.part_radii()[j];
          if ((centers_b_A_[j] - c_a).squaredNorm() <= r * r &&
              PartBoxesFacesWithin(a_, i, b_, j, X_AB, r0))
            candidates_.emplace_back(i, j);
        }
      }
      X_AB_candidates_ = X_AB;
      candidates_deformation_m_ = deformation_sum;
      candidates_reach_m_ = reach + s;
      have_candidates_ = true;
      ++stats_.candidate_builds;
    }
    stats_.candidate_pairs = static_cast<int>(candidates_.size());
    search_.UpdateBroadPhaseAmong(X_WA, X_WB, excess, s, candidates_, &keep_);
  } else {
    have_candidates_ = false;
    search_.UpdateBroadPhase(X_WA, X_WB, excess, s, &keep_);
  }
  const auto& broad = search_.part_pairs();  // sorted: A's part, then B's
  auto grown = [&](const std::pair<int, int>& pair) {
    if (!deformed) return 0.0;
    return (deformed->a ? (*deformed->a)[pair.first] : 0.0) + (deformed->b ? (*deformed->b)[pair.second] : 0.0);
  };
  auto boxes_within = [&](const std::pair<int, int>& pair, double r) {
    return !part_boxes || PartBoxesWithin(a_, pair.first, b_, pair.second, X_AB, r + grown(pair));
  };
  next_.clear();
  for (const auto& pair : broad) {
    const bool tracked = std::binary_search(tracked_.begin(), tracked_.end(), pair);
    if (boxes_within(pair, tracked ? reach + s : reach)) next_.push_back(pair);
  }
  for (const auto& pair : tracked_)
    if (!std::binary_search(broad.begin(), broad.end(), pair) &&
        std::binary_search(keep_.begin(), keep_.end(), pair) && boxes_within(pair, reach + s))
      next_.push_back(pair);
  std::sort(next_.begin(), next_.end());
  // Pairs that joined or left: their parts' nodes start again.
  auto changed = [&](const std::pair<int, int>& pair) {
    ResetPart(pass_a_, a_, pair.first);
    ResetPart(pass_b_, b_, pair.second);
    ++stats_.pair_changes;
  };
  for (const auto& pair : next_)
    if (!std::binary_search(tracked_.begin(), tracked_.end(), pair)) changed(pair);
  for (const auto& pair : tracked_)
    if (!std::binary_search(next_.begin(), next_.end(), pair)) changed(pair);
  tracked_.swap(next_);
  std::fill(active_b_.begin(), active_b_.end(), 0);
  for (const auto& pair : tracked_) active_b_[pair.second] = 1;
  tracked_parts_a_.clear();
  tracked_parts_b_.clear();
  for (const auto& pair : tracked_)
    if (tracked_parts_a_.empty() || tracked_parts_a_.back() != pair.first)
      tracked_parts_a_.push_back(pair.first);
  for (int j = 0; j < b_.num_parts(); ++j)
    if (active_b_[j]) tracked_parts_b_.push_back(j);
}

double TrackedGaps::BoundsChange(const DeformedParts* deformed) const {
  const double never = std::numeric_limits<double>::infinity();
  if ((deformed != nullptr) != broad_phase_deformed_) return never;
  if (!deformed) return 0;
  if (deformed->gap_distance_m != broad_phase_gap_distance_m_) return never;
  // A side's parts' vertices lie within its bounds of their own: since the broad phase, a part
  // may have come closer by the growth of its bound (a side whose bounds came or went: never).
  auto change = [never](const std::vector<double>* now, const std::vector<double>& then) {
    if (!now) return then.empty() ? 0.0 : never;
    if (now->size() != then.size()) return never;
    double largest = 0;
    for (size_t i = 0; i < then.size(); ++i) {
      const double c = std::abs((*now)[i] - then[i]);
      if (!(c <= largest)) largest = c;  // a NaN too
    }
    return std::isfinite(largest) ? largest : never;
  };
  return change(deformed->a, broad_phase_d_a_) + change(deformed->b, broad_phase_d_b_);
}

void TrackedGaps::TrackPairs(const Transform& X_WA, const Transform& X_WB, bool part_boxes,
                             const DeformedParts* deformed) {
  const Transform X_AB = X_WA.Inverse() * X_WB;
  // The tracked set of the last broad phase stands while no point of B has moved by more than
  // kBroadPhaseReuse s from its place then, the deformed parts' bounds counted (header): a
  // Newton iterate's correction.
  const bool finite = X_AB.R.allFinite() && X_AB.p.allFinite();
  if (part_boxes && broad_phase_reuse_ && have_broad_phase_pose_ && finite &&
      search_.MotionBound(X_AB_broad_phase_, X_AB) + BoundsChange(deformed) <=
          kBroadPhaseReuse * search_.slack_m()) {
    ++stats_.broad_phase_reuses;
  } else {
    UpdateTrackedSet(X_WA, X_WB, X_AB, part_boxes, deformed);
    X_AB_broad_phase_ = X_AB;
    have_broad_phase_pose_ = finite;
    // The bounds it was made for (none: rigid sides).
    broad_phase_deformed_ = deformed != nullptr;
    if (deformed) {
      broad_phase_gap_distance_m_ = deformed->gap_distance_m;
      auto keep = [](const std::vector<double>* now, std::vector<double>& then) {
        if (now)
          then.assign(now->begin(), now->end());  // #parts: within the reserved capacity
        else
          then.clear();
      };
      keep(deformed->a, broad_phase_d_a_);
      keep(deformed->b, broad_phase_d_b_);
    }
  }

  // Odometers: each tracked part of B adds its motion since the last call, each part of A the
  // largest motion of its partners.
  if (have_previous_) {
    double largest = 0;
    const Mat3 dR = X_AB.R - X_AB_previous_.R;
    const Vec3 dp = X_AB.p - X_AB_previous_.p;
    const Vec3 dR_column_norms(dR.col(0).norm(), dR.col(1).norm(), dR.col(2).norm());
    // Parts in no tracked pair add nothing (their nodes are not read, and are reset when their
    // part joins): only the tracked parts are passed.
    for (const int j : tracked_parts_b_) {
      motion_b_[j] = PartMotion(j, dR, dp, dR_column_norms);
      Advance(odometer_b_[j], motion_b_[j]);
      largest = std::max(largest, motion_b_[j]);
    }
    for (const int i : tracked_parts_a_) motion_a_[i] = 0;
    for (const auto& [pa, pb] : tracked_) motion_a_[pa] = std::max(motion_a_[pa], motion_b_[pb]);
    for (const int i : tracked_parts_a_) Advance(odometer_a_[i], motion_a_[i]);
    odometer_ += largest;
    stats_.max_motion_between_calls_m = std::max(stats_.max_motion_between_calls_m, largest);
  }
  X_AB_previous_ = X_AB;
  have_previous_ = true;
  RestartIfSaturated();
}

void TrackedGaps::Advance(double& odometer, double by) {
  odometer += by;
  largest_odometer_ = std::max(largest_odometer_, odometer);
  odometer_saturated_ = odometer_saturated_ || !(odometer < kOdometerRestart);
}

void TrackedGaps::RestartIfSaturated() {
  auto below = [](double x) { return x < kOdometerRestart; };  // false for NaN
  // Every part's odometer below the restart reading: none has reached it since the last
  // restart (Advance; odometers only grow).
  if (!odometer_saturated_ && below(face_deformation_a_) && below(face_deformation_b_) &&
      X_AB_previous_.R.allFinite() && X_AB_previous_.p.allFinite())
    return;
  std::fill(odometer_a_.begin(), odometer_a_.end(), 0.0);
  std::fill(odometer_b_.begin(), odometer_b_.end(), 0.0);
  odometer_saturated_ = false;
  largest_odometer_ = 0;
  face_deformation_a_ = face_deformation_b_ = 0;
  // A pose that is not finite is no start for the next motion: the next call adds none (its
  // nodes are all seeded anyway).
  have_previous_ = X_AB_previous_.R.allFinite() && X_AB_previous_.p.allFinite();
  Reset();
  ++stats_.odometer_restarts;
}

void TrackedGaps::ComputeGaps(const Transform& X_WA, const Transform& X_WB,
                              const TrackedSide& side_a, const TrackedSide& side_b,
                              double gap_distance_m, std::vector<NodeGap>* gaps_a,
                              std::vector<NodeGap>* gaps_b) {
  const Transform X_AB = X_WA.Inverse() * X_WB;
  // Deformation (flexible sides) moves vertices by at most each side's change, on top of the
  // rigid motion; the faces' own part per pass (the look of RunPass measures the node's
  // displacement in the face frame, and the faces move by at most this since a node's stamp).
  const double deformation = side_a.deformation_change_m + side_b.deformation_change_m;
  if (deformation > 0) {
    for (double& o : odometer_a_) o += deformation;
    for (double& o : odometer_b_) o += deformation;
    // The largest odometer moves by as much (rounding is monotone: the largest sum is the
    // largest odometer's).
    largest_odometer_ += deformation;
    odometer_saturated_ = odometer_saturated_ || !(largest_odometer_ < kOdometerRestart);
  }
  face_deformation_a_ += side_b.deformation_change_m;  // pass A: faces of B
  face_deformation_b_ += side_a.deformation_change_m;
  RestartIfSaturated();
  stats_.evaluated_nodes = stats_.seeded_nodes = 0;
  auto vertices = [](const TrackedSide& side) {
    return SurfaceVertices{.own = side.vertices, .deformed = side.deformed_vertices};
  };
  auto geometry = [&](const ContactSurface& s, const TrackedSide& side) {
    return Geometry{.s = s,
                    .v = vertices(side),
                    .n = *side.normals,
                    .lazy_n = side.lazy_normals,
                    .stamp = side.normal_stamp,
                    .epoch = side.normal_epoch,
                    .lazy_corner = side.lazy_normals ? side.lazy_corner_normals : nullptr,
                    .corner_stamp = side.corner_stamp};
  };
  RunPass(a_, vertices(side_a), geometry(b_, side_b), side_b.deformation_m,
          side_b.part_deformation_m, face_deformation_a_, gap_distance_m, X_WB.Inverse() * X_WA, X_WB,
          /*nodes_are_a=*/true, odometer_a_, pass_a_, gaps_a);
  RunPass(b_, vertices(side_b), geometry(a_, side_a), side_a.deformation_m,
          side_a.part_deformation_m, face_deformation_b_, gap_distance_m, X_AB, X_WA, /*nodes_are_a=*/false, odometer_b_,
          pass_b_, gaps_b);
  stats_.tracked_pairs = static_cast<int>(tracked_.size());
  stats_.odometer_m = odometer_;
  ++stats_.updates;
}

void TrackedGaps::RunPass(const ContactSurface& node_surface, const SurfaceVertices& nodes,
                          const Geometry& faces, double face_deformation_m,
                          const std::vector<double>* face_part_deformation_m,
                          double face_deformation_odometer_m, double d, const Transform& X_FN,
                          const Transform& X_WF, bool nodes_are_a,
                          const std::vector<double>& odometers, Pass& pass,
                          std::vector<NodeGap>* gaps) {
  gaps->clear();
  std::vector<RowGroup>& row_groups = nodes_are_a ? row_groups_a_ : row_groups_b_;
  row_groups.clear();
  const ContactSurface& face_surface = faces.s;
  const double walk_reach = d + search_.slack_m();
  const double far_m = kFarReaches * walk_reach;
  // The tracked parts of the node surface in increasing order, each with its partners (the face
  // surface's parts paired with it): tracked_ is sorted by A's part; B's parts are gathered.
  by_part_.clear();
  for (const auto& [pa, pb] : tracked_)
    by_part_.emplace_back(nodes_are_a ? pa : pb, nodes_are_a ? pb : pa);
  if (!nodes_are_a) std::sort(by_part_.begin(), by_part_.end());
  // One row of an extruded part's nodes for all (header): rigid sides as the surfaces hold
  // them, without face weights, and the node frame's z axis along the face frame's with the
  // off-axis entries of R_FN zero to the bit (a node's x and y in the face frame do not
  // depend on its z; torsional models turn every gear about z exactly).
  const Mat3& R_FN = X_FN.R;
  const bool rows_may_share =
      shared_rows_ && !keep_face_weights_ && nodes.deformed == nullptr &&
      nodes.own == &node_surface.vertices() && faces.v.deformed == nullptr &&
      faces.v.own == &face_surface.vertices() && faces.lazy_n == nullptr &&
      face_deformation_m == 0 && face_part_deformation_m == nullptr && R_FN(0, 2) == 0 &&
      R_FN(1, 2) == 0 && R_FN(2, 0) == 0 && R_FN(2, 1) == 0 && R_FN(2, 2) > 0;
  // Columns for every node (header: node columns): the faces are the surface's own, rigid.
  const bool faces_rigid = node_columns_ && faces.v.deformed == nullptr &&
                           faces.v.own == &face_surface.vertices() && faces.lazy_n == nullptr &&
                           face_deformation_m == 0 && face_part_deformation_m == nullptr;
  // The heights of an extruded part of the face surface: its first and last rows' (the z range
  // of its columns' rectangles).
  auto part_heights = [&](int part_f) {
    const int first_f = face_surface.part_vertex_start()[part_f];
    const int last_f =
        first_f + (face_surface.part_rows()[part_f] - 1) * face_surface.part_row_length()[part_f];
    return std::pair{face_surface.vertices()[first_f].z(), face_surface.vertices()[last_f].z()};
  };
  for (size_t k = 0; k < by_part_.size();) {
    const int part = by_part_[k].first;
    partners_.clear();
    for (; k < by_part_.size() && by_part_[k].first == part; ++k)
      partners_.push_back(by_part_[k].second);
    const double odometer = odometers[part];
    const int v_begin = node_surface.part_vertex_start()[part];
    const int v_end = node_surface.part_vertex_start()[part + 1];
    const int rows = rows_may_share ? node_surface.part_rows()[part] : 0;
    const int row_n = node_surface.part_row_length()[part];
    bool one_row = rows >= 2;
    if (one_row) {
      // Every row within the heights of every partner, itself extruded.
      const double z_lo = R_FN(2, 2) * node_surface.vertices()[v_begin].z() + X_FN.p.z();
      const double z_hi =
          R_FN(2, 2) * node_surface.vertices()[v_begin + (rows - 1) * row_n].z() + X_FN.p.z();
      // Heights equal to their rounding count as equal (two gears of one face width, their
      // rows made by different sums): a node that far beyond a rim has the weight 1 - e / f of
      // signed_gap.h with e / f below 1e-13 (f a tenth of a row's height), and its gap moves by
      // e^2 / |gap|.
      const double tol = kRowHeightUlps * std::numeric_limits<double>::epsilon() *
                         std::max(std::abs(z_lo), std::abs(z_hi));
      for (const int part_f : partners_) {
        one_row = one_row && face_surface.part_rows()[part_f] >= 2;
        if (!one_row) break;
        const auto [z_lo_f, z_hi_f] = part_heights(part_f);
        one_row = z_lo >= z_lo_f - tol && z_hi <= z_hi_f + tol;
      }
    }
    // A part that stops sharing: its blocks' wake-up readings were gathered over the evaluated
    // row only (a block across a row boundary), so its nodes are seeded anew (rare: a torsional
    // model shares at every call).
    if (pass.rows_shared[part] && !one_row) ResetPart(pass, node_surface, part);
    pass.rows_shared[part] = one_row;
    // A part that does not share rows is looked at along its partners' columns, node by node at
    // the node's own height, while every partner is extruded and rigid (header: node columns).
    bool look_columns = one_row;
    partner_heights_.clear();
    if (!one_row && faces_rigid) {
      look_columns = true;
      for (const int part_f : partners_) {
        look_columns = look_columns && face_surface.part_rows()[part_f] >= 2;
        if (!look_columns) break;
        partner_heights_.push_back(part_heights(part_f));  // within the reserved capacity
      }
    }
    const int shared_row = one_row ? EvaluatedRow(rows) : 0;
    const int lo = one_row ? v_begin + shared_row * row_n : v_begin;
    const int hi = one_row ? lo + row_n : v_end;
    // The evaluated row is looked at halfway to the next row (header): between two rows of
    // nodes, so within every partner's heights, and off the partners' row edges where those
    // have the node rows' heights (a node on such an edge is as close to the faces above and
    // below it, a tied pair whose walks cost a second triangle distance at every look).
    const double z_eval =
        one_row ? 0.5 * (node_surface.vertices()[lo].z() + node_surface.vertices()[lo + row_n].z())
                : 0.0;
    // The evaluated row's height in the face frame (every node's, to the bit: R_FN's off-axis
    // entries are zero), and its place in each partner's rows, made when a node first needs it
    // (interval -1 until then: most tracked parts' nodes sleep through an evaluation).
    const double z_row = (X_FN * Vec3(0, 0, z_eval)).z();
    partner_places_.assign(one_row ? partners_.size() : 0,
                           ContactSurface::RowPlace{.interval = -1});
    auto place_in = [&](int partner) -> const ContactSurface::RowPlace& {
      ContactSurface::RowPlace& place = partner_places_[partner];
      if (place.interval < 0)
        place = face_surface.ExtrudedRowPlace(partners_[partner], z_row);
      return place;
    };
    // A shared row's node on the faces of a partner's column, however they were found (header:
    // profile looks): the closest point in the column's rectangles, in the xy plane at the
    // row's height (ColumnPoint), and the face that holds it (ExtrudedFaceAt), when it lies
    // inside the column (0 < t < 1; on a profile point, an edge two columns share or the
    // part's rim, the face's own closest point stands). One expression for the look along the
    // profile, the faces' walk and the search, so that a node comes out the same to the bit
    // whichever found its column (a recorder row warmed from the integrator's, or cold).
    // False for a face outside the partners.
    auto column_of = [&](int face, int* partner, int* columns, const Vec3** profile) {
      const int part_f = face_surface.vertex_parts()[face_surface.triangles()[face][0]];
      size_t j = 0;
      while (j < partners_.size() && partners_[j] != part_f) ++j;
      if (j == partners_.size()) return -1;
      *partner = static_cast<int>(j);
      *columns = face_surface.part_row_length()[part_f] - 1;
      *profile = &face_surface.vertices()[face_surface.part_vertex_start()[part_f]];
      return face_surface.face_cell()[face] % *columns;
    };
    // A node column's height within the partner's rows (its rectangles' heights), and its place
    // among them; a shared row's within every partner's (the part's test above).
    auto within_heights = [&](int partner, double z) {
      return one_row ||
             (z >= partner_heights_[partner].first && z <= partner_heights_[partner].second);
    };
    // Always inlined: with the per-node row place GCC made it a call of its own, +11.7 M
    // instructions over the rigid row's first 10 ms (docs/performance.md, "node-columns").
    auto onto_column = [&](const ColumnPoint& c, int partner, ClosestFace* out)
        __attribute__((always_inline)) {
      out->face = face_surface.ExtrudedFaceAt(
          partners_[partner], c.column, c.t,
          one_row ? place_in(partner)
                  : face_surface.ExtrudedRowPlace(partners_[partner], c.point.z()));
      out->point.point = c.point;
      out->point.feature = TriangleFeature::kFace;
      out->d2 = c.d2;
    };
    // A shared row's node looked at along its face's profile (header: profile looks): the
    // column of its face and, while a neighbouring column is closer, the walk to it (ties to the
    // lower column; a node below its column also tries the columns two away before it settles,
    // as Walk does). The walk records its margin as Walk does (the smallest distance of the
    // columns it tried at the end less the column's own), and a later look keeps the column
    // without walking while twice the node's motion since stays below it (and the node is
    // above the column, or was below it then: the tried columns are then no more). True with
    // *out the column's face, closest point and squared distance when the point lies inside
    // the column, not deeper below it than the face's inner reach; false (the faces' look and
    // walk then decide) for a point on a profile point, a walk that runs long, or a face
    // outside the partners.
    auto look_along_profile = [&](int v, const Vec3& p, int face, ClosestFace* out) {
      int partner = 0, columns = 0;
      const Vec3* profile = nullptr;
      const int column = column_of(face, &partner, &columns, &profile);
      if (column < 0 || !within_heights(partner, p.z())) return false;
      ColumnPoint c = OnColumn(profile, column, p);
      auto inside = [&] {
        return c.t > 0 && c.t < 1 &&
               (p - c.point).dot(faces.Normal(out->face)) >=
                   -face_surface.face_inner_reach()[out->face];
      };
      if (pass.walk_pair[v][0] == kColumnMargin && pass.walk_margin[v] > 0 &&
          2 * (p - pass.walk_position[v]).norm() + kWalkRounding < pass.walk_margin[v]) {
        onto_column(c, partner, out);
        if ((pass.walk_below[v] || (p - c.point).dot(faces.Normal(out->face)) >= 0) && inside()) {
          ++stats_.walks_skipped;
          return true;
        }
      }
      for (int step = 0;; ++step) {
        if (step == kMaxWalkSteps) return false;
        ColumnPoint next = c;
        double tried_d2 = std::numeric_limits<double>::infinity();
        auto consider = [&](int k) {
          if (k < 0 || k >= columns || k == c.column) return;
          const ColumnPoint o = OnColumn(profile, k, p);
          tried_d2 = std::min(tried_d2, o.d2);
          if (o.d2 < next.d2 || (o.d2 == next.d2 && k < next.column)) next = o;
        };
        consider(c.column - 1);
        consider(c.column + 1);
        bool below = false;
        if (next.column == c.column) {
          onto_column(c, partner, out);
          below = (p - c.point).dot(faces.Normal(out->face)) < 0;
          if (below) {
            consider(c.column - 2);
            consider(c.column + 2);
          }
          if (next.column == c.column) {
            pass.walk_margin[v] = std::sqrt(tried_d2) - std::sqrt(c.d2);
            pass.walk_position[v] = p;
            pass.walk_below[v] = below;
            pass.walk_pair[v] = {kColumnMargin, kColumnMargin};
            break;
          }
        }
        c = next;
        ++stats_.walk_steps;
      }
      return inside();
    };
    // A face the faces' walk or the search found for a shared row's node: its column's point
    // (true) when it lies inside the column.
    auto settle_in_column = [&](const Vec3& p, ClosestFace* best) {
      int partner = 0, columns = 0;
      const Vec3* profile = nullptr;
      const int column = column_of(best->face, &partner, &columns, &profile);
      if (column < 0 || !within_heights(partner, p.z())) return false;
      const ColumnPoint c = OnColumn(profile, column, p);
      if (!(c.t > 0 && c.t < 1)) return false;
      onto_column(c, partner, best);
      return true;
    };
    const size_t listed_from = gaps->size();
    // The node's position in the face frame (the evaluated row's at its look height). For the
    // evaluated row R_FN's off-axis entries are zero, so its nodes' x and y in the face frame
    // are R_FN's upper left block times their x and y, plus p, and z is the row's: the numbers
    // X_FN * (x, y, z_eval) gives, to the bit (its terms with the zero entries add exactly).
    auto position = [&](int v) {
      if (!one_row) return X_FN * nodes[v];
      const double x = nodes[v].x(), y = nodes[v].y();
      return Vec3(R_FN(0, 0) * x + R_FN(0, 1) * y + X_FN.p.x(),
                  R_FN(1, 0) * x + R_FN(1, 1) * y + X_FN.p.y(), z_row);
    };
    // A node awake by the odometer but not by its own displacement in the face frame since its
    // stamp: still out of reach, and the odometer may now advance by what is left before its
    // next look (true). In the node loop: half the nodes the odometer wakes go back to sleep
    // here (docs/performance.md, "evaluation-mix"), without the call below.
    auto still_asleep = [&](int v, const Vec3& p) {
      if (!(pass.reach[v] > 0)) return false;
      const double moved = (p - pass.stamp_position[v]).norm() + face_deformation_odometer_m -
                           pass.stamp_face_deformation[v];
      if (!(moved < pass.reach[v])) return false;
      pass.wake[v] = odometer + (pass.reach[v] - moved);
      return true;
    };
    // A node awake by the odometer and by its displacement: its look, walk or search, and its
    // gap. Kept out of the node loop (noinline): the loop then holds only the sleep tests and
    // the block's wake-up reading, and inlined it took 2.5 % more instructions over the rigid
    // scene (callgrind).
    auto evaluate = [&](int v, const Vec3& p) __attribute__((noinline)) {
      ClosestFace best;
      double unseen_d2 = far_m * far_m;
      bool search = pass.face[v] < 0 || pass.distance[v] > walk_reach;
      double walk_margin = 0;
      MeasuredFaces measured;  // by the walk, for its tied pair's margin
      const bool profile = look_columns && !search && look_along_profile(v, p, pass.face[v], &best);
      if (profile) ++stats_.profile_looks;
      if (look_columns && !search && !profile) ++stats_.profile_fallbacks;
      if (!profile && pass.face[v] >= 0) {
        best = OnFace(faces, pass.face[v], p);
        // The walk from the node's face stays there while every face it tried at its last
        // walk is farther than this one: their distances change by at most the node's motion
        // in the face frame plus the faces' deformation since, each (a face tried then is
        // tried now only if the closest point's vertex, if any, and its side, if below, are
        // those of then: the tried set is then no larger).
        const bool within_margin =
            !search && pass.walk_pair[v][0] != kColumnMargin && pass.walk_margin[v] > 0 &&
            2 * ((p - pass.walk_position[v]).norm() + face_deformation_odometer_m -
                 pass.walk_face_deformation[v]) +
                    kWalkRounding <
                pass.walk_margin[v];
        const std::array<int, 2> pair = pass.walk_pair[v];
        bool stays =
            within_margin && pair[0] < 0 &&
            (!IsVertex(best.point.feature) || best.point.feature == pass.walk_feature[v]) &&
            ((p - best.point.point).dot(faces.Normal(best.face)) >= 0 || pass.walk_below[v]);
        // A tied pair: the walk ends on the closer of its two faces (ties to the lower index).
        if (within_margin && pair[0] >= 0 && pair_skip_ && !IsVertex(best.point.feature) &&
            (best.face == pair[0] || best.face == pair[1])) {
          const ClosestFace other = OnFace(faces, pair[0] == best.face ? pair[1] : pair[0], p);
          if (!IsVertex(other.point.feature)) {
            if (other.d2 < best.d2 || (other.d2 == best.d2 && other.face < best.face)) {
              best = other;
              ++stats_.walk_steps;
            }
            stays = true;
            ++stats_.pair_walks_skipped;
          }
        }
        if (stays) {  // keeps the margin of the last walk
          walk_margin = -1;
          ++stats_.walks_skipped;
        }
        // A walk that ends on its part's rim next to another part may belong in that part.
        if (!search && !stays)
          search = !Walk(faces, p, &best, &stats_.walk_steps, &walk_margin, &measured) ||
                   OnSharedRim(face_surface, best);
        if (!search && stays) search = OnSharedRim(face_surface, best);
        // Inside the other body the distance has a local minimum on every face the node lies
        // under (a tip corner: flank and tip): deeper than the face's inner reach, the closest
        // needs the search, bounded by the walk's distance.
        if (!search && (p - best.point.point).dot(faces.Normal(best.face)) <
                           -face_surface.face_inner_reach()[best.face])
          search = true;
      }
      // The search's bound (header): a node not seeded yet (its pair has just joined) is
      // searched within the far distance, so that one already deep inside the other body is
      // still found; a node below its face (inside the other body, or a Newton iterate thrown
      // through it) within its face's distance, however deep; any other node (far at its last
      // search, or above its face and farther than d + s from it) within d + s, beyond which it
      // would not be listed, and it then sleeps on the descent's bound (unseen_d2).
      double bound_m = walk_reach;
      if (search) {
        const bool below =
            pass.face[v] >= 0 && (p - best.point.point).dot(faces.Normal(best.face)) < 0;
        if (pass.face[v] == kUnseeded) bound_m = far_m;
        if (pass.face[v] < 0 || (!below && best.d2 > bound_m * bound_m))
          best = ClosestFace{.d2 = bound_m * bound_m};
        unseen_d2 = std::numeric_limits<double>::infinity();
        for (const int part_f : partners_)
          FindClosestFaceInPart(
              face_surface, part_f, p, &best, faces.v,
              face_part_deformation_m ? (*face_part_deformation_m)[part_f] : face_deformation_m,
              &unseen_d2);
        ++stats_.seeded_nodes;
        ++stats_.seeds;
      }
      const bool in_column =
          look_columns && !profile && best.face >= 0 && settle_in_column(p, &best);
      // No face: the node's position is not finite (a diverging Newton iterate), and it
      // starts again at the next evaluation; or it is farther than the search's bound from
      // every face of its partners, and sleeps until it may have come within it.
      if (best.face < 0) {
        const bool far = p.allFinite();
        // The descent's bound on every face it passed by (at least the search's bound).
        const double reach = std::max(bound_m, std::sqrt(unseen_d2));
        pass.face[v] = far ? kFar : kUnseeded;
        pass.reach[v] = far ? reach : 0.0;
        pass.wake[v] = far ? odometer + reach : -std::numeric_limits<double>::infinity();
        pass.distance[v] = reach;
        pass.stamp_position[v] = p;
        pass.stamp_face_deformation[v] = face_deformation_odometer_m;
        return;
      }
      ++stats_.evaluated_nodes;
      ++stats_.node_evaluations;
      // The entry made in place (within the capacity a contact element reserves) and taken back
      // below if the node is not listed. A closest point inside its face (every profile
      // look's) has NodeGapFromClosest's first case, its numbers written here without the call.
      NodeGap& g = gaps->emplace_back();
      if (best.point.feature == TriangleFeature::kFace) {
        g.face = best.face;
        g.gap = (p - best.point.point).dot(faces.Normal(best.face));
      } else {
        g = NodeGapFromClosest(face_surface, best.face, faces.Normal(best.face), p,
                               best.point.point, best.point.feature);
      }
      pass.face[v] = best.face;
      pass.stamp_position[v] = p;
      pass.stamp_face_deformation[v] = face_deformation_odometer_m;
      // What a later evaluation needs to skip the walk (a search, a shared row's node moved
      // into its column, or a face new to the node: none).
      if (profile) {
        // The look along the profile kept its column margin, or recorded the walk's.
      } else if (search || in_column) {
        pass.walk_margin[v] = 0;
        pass.walk_pair[v] = {-1, -1};
      } else if (walk_margin >= 0) {
        // Settled on an edge shared with another face: that face is as close, so the margin
        // is the pair's (header).
        const int edge = FeatureEdge(best.point.feature);
        const int partner = edge >= 0 ? face_surface.face_neighbors()[best.face][edge] : -1;
        pass.walk_pair[v] = {-1, -1};
        if (partner >= 0 && pair_skip_) {
          walk_margin = PairMargin(faces, p, best.face, partner, best.d2,
                                   measured.Of(faces, partner, p), &measured);
          if (walk_margin > 0) pass.walk_pair[v] = {best.face, partner};
        }
        pass.walk_margin[v] = walk_margin;
        pass.walk_position[v] = p;
        pass.walk_face_deformation[v] = face_deformation_odometer_m;
        pass.walk_feature[v] = best.point.feature;
        pass.walk_below[v] = (p - best.point.point).dot(faces.Normal(best.face)) < 0;
      }
      // Reach: the motion before the node can press. Off the surface (beyond the rim) its
      // sideways distance must first come within the face's rim fade f (signed_gap.h), by at
      // least s - f; on it, its gap must close.
      pass.reach[v] = !g.on_surface ? std::max(0.0, g.rim_offset_m - g.rim_fade_m)
                      : g.gap > 0   ? g.gap
                                    : 0.0;
      pass.wake[v] = odometer + pass.reach[v];
      pass.distance[v] = std::sqrt(best.d2);
      if (best.d2 > d * d && !(g.gap < 0 && g.on_surface)) {
        gaps->pop_back();
        return;
      }
      g.node = v;
      g.p_W = X_WF * p;
      g.q_W = X_WF * best.point.point;
      // The force normal for a node in contact only (signed_gap.h NodeGap::n_W): the others'
      // would read the corners' faces for nothing.
      const auto& ft = face_surface.triangles()[g.face];
      g.n_W = X_WF.R * (!InContact(g) ? faces.Normal(g.face)
                                      : ForceNormal(
                                            face_surface, g.face, best.point.point, faces.v[ft[0]],
                                            faces.v[ft[1]], faces.v[ft[2]], faces.lazy_n != nullptr,
                                            [&](int f) -> const Vec3& { return faces.Normal(f); },
                                            [&](int f, int k) { return faces.CornerNormal(f, k); },
                                            keep_face_weights_ ? &pass.face_weights[v] : nullptr));
    };
    const int first_block = (lo - v_begin) / kBlock;
    for (int block = pass.part_block_start[part] + first_block, v0 = v_begin + first_block * kBlock;
         v0 < hi; ++block, v0 += kBlock) {
      // The whole block asleep by the odometer (the node test below, with room for the rounding
      // of the sum: odometers stay below 1 m).
      if (odometer < pass.block_wake[block] - 1e-12) continue;
      const int v1 = std::min(v0 + kBlock, hi);
      // The block's wake-up reading, the smallest odometer reading at which one of its nodes may
      // wake (Pass::block_wake), gathered as the nodes are passed (in node order: the value a
      // second loop over the block gave, to the bit); a node asleep by the odometer adds the
      // reading its test has just loaded.
      double wake = std::numeric_limits<double>::infinity();
      for (int v = std::max(v0, lo); v < v1; ++v) {
        // Asleep: the surfaces have not moved far enough for this node to touch, by the part's
        // odometer, or else by the node's own displacement in the face frame since its stamp. A
        // node not yet seeded is always evaluated.
        if (odometer < pass.wake[v]) {
          wake = std::min(wake, pass.wake[v]);
          continue;
        }
        const Vec3 p = position(v);
        if (!still_asleep(v, p)) evaluate(v, p);
        wake = std::min(wake, pass.wake[v]);
      }
      pass.block_wake[block] = wake;
    }
    if (one_row && gaps->size() > listed_from) {
      const RowGroup run{.begin = static_cast<int>(listed_from),
                         .count = static_cast<int>(gaps->size() - listed_from),
                         .rows = rows,
                         .part = part,
                         .shared_row = shared_row,
                         .pending = defer_rows_};
      row_groups.push_back(run);
      stats_.shared_row_nodes += static_cast<long>(rows - 1) * run.count;
      if (!defer_rows_) {  // the other rows' entries now (within the capacity for every node)
        gaps->resize(listed_from + static_cast<size_t>(rows) * run.count);
        ShareRows(node_surface, face_surface, run, X_FN, X_WF, gaps->data() + listed_from);
      }
    }
  }
}

void TrackedGaps::ShareRows(const ContactSurface& node_surface, const ContactSurface& face_surface,
                            const RowGroup& run, const Transform& X_FN, const Transform& X_WF,
                            NodeGap* block) const {
  const size_t m = static_cast<size_t>(run.count);
  const int rows = run.rows, n = node_surface.part_row_length()[run.part];
  const int first = node_surface.part_vertex_start()[run.part];
  // Rows in node order: the evaluated row's entries copied into every row's place, then each
  // row's made from them in place, the evaluated row's last.
  for (int k = 1; k < rows; ++k) std::copy(block, block + m, block + k * m);
  const Vec3 z_W = X_WF.R.col(2);  // the z axis of both frames, in the world
  const Transform X_FW = X_WF.Inverse();
  const Transform X_WN = X_WF * X_FN;
  // Row k's height in the face frame (as RunPass's row test has it), where its nodes' closest
  // points lie.
  auto height = [&](int k) {
    return X_FN.R(2, 2) * node_surface.vertices()[first + k * n].z() + X_FN.p.z();
  };
  for (size_t i = 0; i < m; ++i) {
    const NodeGap& g = block[run.shared_row * m + i];
    // Its closest point moved along z from the height the row was looked at to each row's
    // (the closest point's own height, to its rounding: a face of a spur tooth is a thin
    // triangle, 20 mm by 0.1 mm, whose closest points carry 1e-14 m of it along z): on the
    // same column of the face's part (the same fraction along it), in the rectangle of the
    // row's height.
    const Vec3 q_F = X_FW * g.q_W;
    const int part_f = face_surface.vertex_parts()[face_surface.triangles()[g.face][0]];
    const int column =
        face_surface.face_cell()[g.face] % (face_surface.part_row_length()[part_f] - 1);
    const double along = face_surface.ExtrudedColumnFraction(part_f, column, q_F);
    auto make_row = [&](int k) {
      NodeGap& t = block[k * m + i];  // a copy of g (or g)
      const double z_k = height(k);
      t.node = g.node + (k - run.shared_row) * n;
      t.p_W = X_WN * node_surface.vertices()[t.node];  // as its evaluation would
      t.q_W = g.q_W + (z_k - q_F.z()) * z_W;
      t.face = face_surface.ExtrudedFaceAt(part_f, column, along,
                                           face_surface.ExtrudedRowPlace(part_f, z_k));
    };
    for (int k = 0; k < rows; ++k)
      if (k != run.shared_row) make_row(k);
    make_row(run.shared_row);  // g itself, last
  }
}

}  // namespace orrery::contact

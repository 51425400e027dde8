#pragma once
// Signed gaps of two rigid surfaces by tracking each node's closest face from one evaluation to
// the next: the step's path of ContactElement (contact_element.h). It gives the gaps of
// signed_gap.h (seed 000 eqs. 6-9: closest face, signed distance, rim rule) at a cost that grows
// with the nodes near contact, not with the surfaces' resolution or with how far they roll.
//
// Why: a list of candidate triangle pairs (candidate_pairs.h) is valid while the surfaces move
// less than its slack. Gears roll through a tooth's length every mesh period, so at seed 003's
// speeds (tooth-local motion 2-10 um per 5 us step) a 100 um slack forces a search every 10 to 50
// steps, and each search (FCL traversal, exact triangle distances, node-face lists) costs
// milliseconds; the lists then hold ~20 faces per node, all tested at every evaluation.
//
// What is kept (per pass: the nodes of one surface against the faces of the other):
//   - the tracked part pairs: the broad phase of CandidateSearch (mesh zone and part spheres
//     within d + s; for rigid surfaces also the parts' oriented boxes within d + s,
//     PartBoxesWithin: the spheres of two 40 mm wide teeth overlap for every tooth pair in the
//     zone, the boxes for the two or three a tooth can touch), plus pairs already tracked that
//     stay in the broad phase grown by s (so a
//     pair at the edge of the zone does not come and go between Newton iterations). A node is
//     tracked while its part is in a tracked pair; its faces are searched in the paired parts only;
//   - per node: its closest face at its last evaluation, its distance to it then, the reach D
//     (that distance; 0 when it penetrated; beyond the rim, off the surface, its sideways
//     distance s less the face's rim fade, signed_gap.h),
//     and the odometer reading then;
//   - an odometer per part: a part of B adds up its own motion in A's frame from one evaluation
//     to the next (what moves its nodes against A's faces), a part of A the largest motion of
//     the parts of B it is paired with (what moves their faces against its nodes). For a part
//     with box centre c and half-extents h (B's frame), from relative pose (R0, p0) to (R1, p1):
//        delta = sum_k |(R1 - R0) e_k| h_k + |(R1 - R0) c + p1 - p0|,
//     a bound on the motion of every point of the part (the axial extent of a gear tooth drops
//     out for rotations about the gear axis, and the bound is about the tooth, not the gear),
//     or, when smaller, the largest motion |(R1 - R0) x + p1 - p0| of the eight corners x of
//     the part's oriented box (PartBoxCorners: every point of the part is a convex combination
//     of them; for a tooth turning about the gear axis about half the sum above).
// At an evaluation a node is skipped while its part's odometer has advanced by less than its D,
// or else while its own displacement in the face surface's frame since its last evaluation is
// below D (one transform; the odometer sums bounds along the way, the displacement is the
// chord; after such a look the odometer may advance by D less the displacement before the
// next): a node outside the other surface at distance D cannot reach it by a relative motion
// shorter than D (the distance is 1-Lipschitz in the node's position). A node off the surface
// beyond its rim gets a share of contact only once its sideways distance is within the fade
// f of signed_gap.h, which takes a motion of at least s - f. Otherwise:
//   - walk: from the node's face, move to the closest of the faces across its edges (and around
//     its vertex when the closest point is one) while one is closer (ties to the lower index);
//     for a node within d + s of the surface the walk ends at the closest face of the part
//     when the node lies outside it (checked against the candidate-pair gaps,
//     tests/contact/tracked_gaps_test.cpp), and another part can be closer only near the
//     part's rim (teeth are millimetres apart elsewhere),
//   - search: a node without a face, or that was farther than d + s from its face, or whose
//     walk runs long or ends on a rim edge next to another part (contact_surface.h), or that
//     lies below its face deeper than the face's inner reach (contact_surface.h; inside the
//     other body the distance has a local minimum on every face the node lies under, such as
//     flank and tip at a tip corner), is searched exactly in the paired parts' FCL
//     hierarchies (FindClosestFaceInPart) within the search's bound (below: the face it had,
//     d + s, or the far distance).
// A walk that settled records its margin (the smallest distance of the faces it tried at the
// end less the face's own); the next evaluations keep the face without walking while twice the
// node's motion in the face frame plus the faces' deformation since stays below the margin
// (and the closest point is on no other vertex, the node below the face only if it was then):
// the walk would try no face it did not try then, each still farther, and stay.
// A walk that settles on an edge its face f shares with a face g has no such margin (g is as
// close: a spur flank's mid-face row of nodes lies on the other flank's mid-face edges). It
// records the pair's margin instead: the smallest distance of the faces a walk from f or from g
// could try (their edge neighbours and the faces two edges away) less the larger of f's and
// g's. While twice the node's motion (+ deformation) since stays below it and neither closest
// point is on a vertex, a walk from either face can only end on f or g: the two triangle
// distances decide it as the walk would (the lower distance, then the lower index).
// The sleep test is also taken for blocks of 16 consecutive nodes of a part at once (the
// block's smallest wake-up reading), which passes a sleeping block in one comparison.
// Extruded parts (contact_surface.h): a part of the node surface whose nodes are rows of one
// profile along z, paired only with extruded parts of the face surface whose heights hold all
// its rows, is evaluated on its middle row alone when both sides are rigid (the surfaces' own
// vertices; no face weights kept) and R_FN maps z along z (its off-axis entries zero to the bit:
// a torsional model turns every gear about z exactly). The distance from a node to such faces
// is the distance in the xy plane whatever the node's height, so the row is looked at halfway
// up to the next row (z_eval: inside a partner's rectangles where the partners' rows have the
// node rows' heights, as two gears of one face width have; at a row's own height each node lay
// on a row edge of the partner, as close to the faces above as below it, a tied pair whose
// every look took two triangle distances), and each node of every row, the evaluated one's
// included, gets that entry with its own position, the closest point moved along z to its
// height and the face that holds it there (ContactSurface::ExtrudedFaceAt). Rows within 16
// units of the rounding of the faces' heights count as within them (two gears of one face
// width, their rows made by different sums): such a node lies e beyond a rim, with the weight
// 1 - e / f of signed_gap.h (f, the rim fade, a tenth of a row's height: 1 - e / f >
// 1 - 1e-13). A node beyond the profile's own ends (a tooth's root middle) takes the evaluated
// row's rim fade there, where its own row, next to the part's z ends, may meet a corner face
// with a smaller one: the weight of such a node (off the surface, never in a mesh's contact)
// is the z-invariant one. The other rows' nodes are not evaluated (their state stays as it
// was); a part that stops sharing (a pose that breaks a condition) has its nodes seeded anew. A
// spur tooth of face_intervals 2 has three rows, so two thirds of its node work goes
// (docs/performance.md, "shared-rows"). The lists say where rows were shared (RowGroup,
// row_groups_a/_b): ContactElement evaluates the contact law once per profile point for all its
// rows (contact_element.h ForEachContactPoint), and its model evaluations leave the other rows'
// entries pending (Update's defer_rows) until something reads them (CompleteRows).
// Profile looks: the distance from an evaluated row's node to a partner's extruded part is its
// distance in the xy plane to the part's profile polyline, so such a node with a face is
// looked at and walked along the partner's columns (the rectangles between two profile
// points, each two faces) instead of the faces: a segment distance per column, a descent over
// the neighbouring columns (and two away for a node below its column) with a margin that
// lets a later look keep the column without walking, as the faces' walk has. Its closest
// point is the segment's point at the row's height, and its face the half of the column's
// rectangle that holds it (ExtrudedFaceAt). A point on a profile point (an edge two columns
// share, a tip corner, the part's rim), a walk that runs long, or a node deeper below its
// column than the face's inner reach, is left to the faces' look, walk and search; a face
// those find inside a column takes the column's point too, so that a node comes out the same
// to the bit whichever way its column was found (a recorder row warmed from the integrator's,
// or cold). Against the tracking of every node (tests/contact/tracked_gaps_test.cpp
// SharedRowsGiveTheGapsOfEveryRow): gaps and points within 1e-15 m.
// Node columns: the same look serves the nodes of a part that does not share rows (a flexible
// planet's deformed nodes, or any node surface) when every partner of the part is extruded and
// the faces are rigid (the surface's own vertices and normals), each node at its own height:
// a node within a partner's heights is looked at and walked along its columns, its closest
// point the segment's point at the node's height and its face the half of the rectangle there
// (ExtrudedRowPlace, ExtrudedFaceAt); a node above or below the partner's rows (beyond its
// rim) is left to the faces' look, as are the cases above. Against the faces' looks
// (set_node_columns(false); tests/contact/tracked_gaps_test.cpp
// NodeColumnsGiveTheFacesGaps): the same faces, gaps and points to rounding.
// A search is bounded. A node of a pair that has just joined the tracked set (not seeded yet) is
// searched within the far distance 5 (d + s); a node below its face within the face's distance,
// however deep; any other node (far at its last search, or above its face and farther than d + s
// from it) within d + s, beyond which it would not be listed. A node with no face within the bound
// keeps none and sleeps on the smallest bound the descent passed by (the distance of a box it
// pruned or of a triangle it did not take, at least the search's bound: FindClosestFaceInPart's
// unseen_d2), so that the nodes of a tooth entering the mesh zone far from the other tooth's flanks
// (its back flank, tip and root), and the flank nodes of a tooth rolling out of it, are not
// searched down to a face millimetres away, nor searched again after every millimetre. Only a node
// already deeper than the far distance inside the other body when its pair joins would be missed
// (the run stops well before, at contact_outputs.h's default penetration limit d + s). A node that
// sleeps without a face wakes once it may have reached the surface, and is then at most one call's
// motion deep: it is missed only after a call that moved the teeth by more than d + s, far beyond
// the slack s the steps are made for (a diverging Newton iterate; the return to the step's states
// wakes it again).
// The gap then follows signed_gap.h (NodeGapFromClosest), and the node is listed when its
// distance is within d (as the candidate-pair path lists it) or when it penetrates, however
// deep: the search is exact, so unlike candidate pairs a penetration beyond the margin (a step
// that moved the teeth further than the margin) is still seen.
//
// A pair that joins or leaves the tracked set resets the nodes of both its parts (they are
// seeded at their next evaluation). The odometers only grow: once one reaches 1 m, or a
// diverging Newton iterate makes one huge or not finite (where later motions would no longer
// add to it), they all start again from zero and every node is seeded anew. Update()
// allocates nothing.
//
// Usage:
//   TrackedGaps tracked(surface_a, surface_b);
//   tracked.Update(X_WA, X_WB, &gaps_a, &gaps_b);   // gaps lists reserved to #V of each surface
#include <array>
#include <utility>
#include <vector>

#include "contact/candidate_pairs.h"
#include "contact/contact_surface.h"
#include "contact/deformed_vertices.h"
#include "contact/signed_gap.h"

namespace orrery::contact {

// A run of a gap list made by one part's shared rows (header: extruded parts): `rows` blocks of
// `count` entries from index `begin`, block k the part's row k in node order, and entry i of
// every block the same profile point: the same gap, face part, normal, weight and rim terms,
// each with its own node, position, closest point and face. Pending (Update with defer_rows):
// only the evaluated row's `count` entries are there, from `begin` (its nodes, looked at at the
// height between rows: their positions, closest points and faces are those of that height);
// TrackedGaps::CompleteRows makes the other rows.
struct RowGroup {
  int begin = 0;
  int count = 0;
  int rows = 0;
  int part = -1;       // of the node surface
  int shared_row = 0;  // the evaluated row
  bool pending = false;
};

struct TrackedGapStats {
  int tracked_pairs = 0;        // part pairs tracked at the last Update()
  int evaluated_nodes = 0;      // nodes whose gap was computed at the last Update()
  int seeded_nodes = 0;         // of which by a search of the hierarchies
  long updates = 0;             // Update() calls
  long node_evaluations = 0;    // since construction
  long seeds = 0;               // since construction
  long walk_steps = 0;          // face changes by walking, since construction
  long walks_skipped = 0;       // walks a node's margin made unnecessary, since construction
  long pair_walks_skipped = 0;  // of which by a tied pair's margin (header), since construction
  long pair_changes = 0;        // pairs that joined or left, since construction
  double odometer_m = 0;        // sum of the per-call largest part motion bounds
  double max_motion_between_calls_m = 0;  // largest per-call motion bound (tracked parts of B)
  long odometer_restarts = 0;   // odometers started again (RestartIfSaturated), since construction
  long candidate_builds = 0;    // candidate part pairs made (TrackPairs), since construction
  int candidate_pairs = 0;      // candidate part pairs at the last TrackPairs()
  long broad_phase_reuses = 0;  // TrackPairs() calls that kept the last broad phase's pairs
  long shared_row_nodes = 0;    // nodes listed from their part's evaluated row (extruded
                                // parts), since construction
  long profile_looks = 0;       // evaluated rows' nodes looked at along their face's profile
                                // (header: extruded parts), since construction
  long profile_fallbacks = 0;   // of the others with a face, those the faces' look and walk
                                // decided (a point on a profile point, a long walk), since
                                // construction
};

class TrackedGaps {
 public:
  // Keeps references to both surfaces, which must outlive it. keep_face_weights: whether the
  // passes keep the force normals' barycentric coordinates (face_weights_a(); what
  // FlexibleContactElement reads). ContactElement does not read them: without, the passes
  // store none and the arrays stay empty.
  TrackedGaps(const ContactSurface& surface_a, const ContactSurface& surface_b,
              bool keep_face_weights = true);

  // The gaps at these poses: *gaps_a the nodes of A on B's faces, *gaps_b the nodes of B on A's
  // faces, each in increasing node order: every evaluated node (or shared row's node) within the
  // search distance d and every penetrating node. Nodes that cannot touch are left out (their gaps
  // are positive).
  // defer_rows: the shared rows are left pending (RowGroup) for CompleteRows(), so a caller that
  // needs the evaluated rows alone (ContactElement's forces) does not pay for the others.
  void Update(const Transform& X_WA, const Transform& X_WB, std::vector<NodeGap>* gaps_a,
              std::vector<NodeGap>* gaps_b, bool defer_rows = false);
  // The pending runs of *gaps (gaps_a of an Update at X_WA, X_WB with nodes_are_a, else gaps_b;
  // *groups its row groups, as row_groups_a() / _b() gave them) made whole in place: the list
  // then holds what Update() without defer_rows gives, to the bit, and *groups its runs.
  // Allocation-free (the lists are reserved for every node of their surface).
  void CompleteRows(const Transform& X_WA, const Transform& X_WB, std::vector<NodeGap>* gaps,
                    std::vector<RowGroup>* groups, bool nodes_are_a) const;
  // The same with deformed surfaces (flexible_contact_element.h): each side's vertices and
  // face normals in its body frame (#V and #T of its surface), the largest displacement of a
  // vertex from the surface's own (the hierarchies' boxes are grown by it), and the largest
  // change of a vertex since the previous call (added to every motion bound); d the gap
  // distance.
  struct TrackedSide {
    const std::vector<Vec3>* vertices = nullptr;
    const std::vector<Vec3>* normals = nullptr;
    double deformation_m = 0;
    double deformation_change_m = 0;
    // Optional, #parts: the largest displacement of each tracked part's vertices (tighter than
    // deformation_m for the hierarchy bounds).
    const std::vector<double>* part_deformation_m = nullptr;
    // Optional, lazy normals: *normals is not current; a face's normal is made from the
    // vertices into (*lazy_normals)[face] when a pass first reads it with (*normal_stamp)[face]
    // != normal_epoch (the caller advances the epoch when the vertices change). A deformed
    // tooth's passes read the normals of the few faces their awake nodes end on, not the
    // thousands of the tracked parts.
    std::vector<Vec3>* lazy_normals = nullptr;
    std::vector<long>* normal_stamp = nullptr;  // #T
    long normal_epoch = 0;
    // Optional, lazy vertices: the vertices are made on first read (deformed_vertices.h) and
    // *vertices is not read; deformation_change_m must then bound the change of every vertex
    // of the tracked parts, made or not (flexible_contact_surface.h PartDeformationBound).
    DeformedVertices* deformed_vertices = nullptr;
    // Optional, with lazy normals on a surface with smoothed normals: the deformed corner
    // normals of signed_gap.h ForceNormal, one per corner group (contact_surface.h
    // corner_group, #groups), made on first read into (*lazy_corner_normals)[group] with
    // (*corner_stamp)[group] != normal_epoch. A listed node's force normal reads three corners
    // of about six face normals each, and the nodes next to it on the same faces the same
    // corners: made once per evaluation, the same numbers.
    std::vector<Vec3>* lazy_corner_normals = nullptr;
    std::vector<long>* corner_stamp = nullptr;  // #groups
  };
  void Update(const Transform& X_WA, const Transform& X_WB, const TrackedSide& a,
              const TrackedSide& b, double gap_distance_m, std::vector<NodeGap>* gaps_a,
              std::vector<NodeGap>* gaps_b);
  // Update() in two stages, for callers that prepare the surfaces in between: the tracked part
  // pairs and the odometers' rigid motion at these poses, then (deformation changes added) the
  // gaps at the same poses. Between the two, tracked_parts_a() / _b() are the parts whose nodes
  // and faces the gaps will read (only their vertices and normals need be current).
  // With part_boxes (the boxes bound the surfaces' own vertices; deformed ones below), a pair
  // of the broad phase is tracked only while the oriented boxes of its two parts are within
  // d + s (PartBoxesWithin; kept while within d + 2 s).
  // Deformed surfaces (`deformed`): a part's deformed vertices lie within (*deformed->a)[part]
  // (or ->b) of its own, so with part_boxes a pair is tracked only while its boxes are within
  // d + s + D_a + D_b (d = deformed->gap_distance_m; kept while within d + 2 s + D_a + D_b); a
  // null vector: that side is not deformed.
  struct DeformedParts {
    const std::vector<double>* a = nullptr;  // #parts of A: D_a per part (m)
    const std::vector<double>* b = nullptr;  // #parts of B
    double gap_distance_m = 0;
  };
  // With part_boxes the broad phase and the box tests run over candidate pairs made for a
  // motion margin m (kCandidateMargin): at the poses X_AB0 they were made at, the pairs whose
  // spheres are within the kept pairs' reach of the broad phase + m and whose boxes pass A's
  // three face axes of the box test (PartBoxesFacesWithin) at the largest reach of a tracked
  // pair, d + 2 s + G0 + m, with G0 = max D_a + max D_b then (rigid sides, no `deformed`:
  // G0 = G = 0 and d the search distance). They are made anew
  // unless mu + max(0, G - G0) <= m, where G is the same sum now and
  //   mu = |R1 - R0|_F rho_B + |p1 - p0|,
  // rho_B the largest distance of a corner of B's parts' boxes or of a part centre from B's
  // origin, bounds the motion in A's frame of every point of B's boxes and of the centres since
  // X_AB0. A pair the full broad phase would track has its spheres within the kept reach
  // (the excess grown by at most G - G0) and passes the box test at d + 2 s + D_a + D_b or less
  // now, hence the spheres' test and A's face axes at that reach + mu then
  // (PartBoxesFacesWithin): it is a candidate. So the broad phase's zones
  // and spheres and the box tests over the candidates only (UpdateBroadPhaseAmong) give the
  // pairs of the full broad phase, to the bit (test TrackedGapsTest.
  // CandidatePairsGiveTheFullBroadPhasesPairs).
  // With part_boxes, the tracked set of the last broad phase stands, and only the odometers
  // advance, while
  //   mu = |R1 - R0|_F r_B + |p1 - p0| + max_i |D_a,i - D0_a,i| + max_j |D_b,j - D0_b,j|
  //      <= s / 16
  // (B's relative pose then R0, p0; r_B the largest distance of a vertex of B from its origin:
  // the first two terms bound every point's rigid motion in A's frame; deformed sides: the
  // parts' bounds then D0, at the same gap distance): a Newton iterate's correction. The set
  // then differs from the one a broad phase would give only by pairs whose (grown) boxes are
  // within mu of the d + s and d + 2 s thresholds, and the excess of the deformed reach moves
  // by less, so every pair whose parts are within d + s - mu > d of each other is tracked:
  // no node that can be listed is left out, and a pair that joins at the next broad phase
  // (at the next step) resets its parts' nodes as before. What it saves: the zones, spheres
  // and box tests at every Newton iterate (about a fifth of an iterate's instructions in the
  // rigid scene, docs/performance.md "perf-rigid8").
  void TrackPairs(const Transform& X_WA, const Transform& X_WB, bool part_boxes = false,
                  const DeformedParts* deformed = nullptr);
  void ComputeGaps(const Transform& X_WA, const Transform& X_WB, const TrackedSide& a,
                   const TrackedSide& b, double gap_distance_m, std::vector<NodeGap>* gaps_a,
                   std::vector<NodeGap>* gaps_b);
  // The runs of shared rows in the lists of the last ComputeGaps() (gaps_a's, gaps_b's), in
  // list order; empty when no part shared its rows.
  const std::vector<RowGroup>& row_groups_a() const { return row_groups_a_; }
  const std::vector<RowGroup>& row_groups_b() const { return row_groups_b_; }
  // The tracked part pairs (part of A, part of B), sorted, of the last TrackPairs().
  const std::vector<std::pair<int, int>>& tracked_pairs() const { return tracked_; }
  const std::vector<int>& tracked_parts_a() const { return tracked_parts_a_; }
  const std::vector<int>& tracked_parts_b() const { return tracked_parts_b_; }
  // #V of A (of B): for each node of A (B) listed in contact (InContact) by the last
  // ComputeGaps() on B's (A's) faces with smoothed normals, the barycentric coordinates of its
  // closest point on its face, those its force normal n_W was interpolated with (signed_gap.h
  // ForceNormal); FlexibleContactElement takes them for the force's share of each face vertex.
  // Other entries are not current; empty when constructed without keep_face_weights.
  const std::vector<Vec3>& face_weights_a() const { return pass_a_.face_weights; }
  const std::vector<Vec3>& face_weights_b() const { return pass_b_.face_weights; }
  // Forget every node's face and distance (the next Update() seeds them all).
  void Reset();
  // Takes over the tracking state of `source`, a TrackedGaps of the same two surfaces (another
  // workspace of the same element): its tracked pairs, the faces, reaches, stamps, walk margins
  // (with the position, face deformation, feature, side and tied pair they were measured at)
  // and block wake-ups of the nodes of its tracked parts, its odometers, last relative pose and
  // that of its last broad phase, so that the next Update() continues from source's last one (a
  // workspace a step behind instead of an output interval: ExternalForceElement::WarmStart). The
  // gaps that Update() then lists are those the tracking finds from any start (the header: sleeping
  // nodes cannot have reached the other surface, the others are walked or searched exactly); only
  // the work differs. Nodes of parts source does not track are left: a pair that joins the tracked
  // set resets its parts' nodes before they are read; of a part sharing its rows, only the
  // evaluated row's nodes are taken (the rows it reads while it shares; when it stops, its nodes
  // are seeded anew). Not copied: the statistics and the broad phase's windows (a cache checked
  // against the poses). Allocation-free; throws std::invalid_argument when source tracks other
  // surfaces.
  void WarmStartFrom(const TrackedGaps& source);

  // A surface as the passes use it: its topology, and its vertices and normals (own or deformed;
  // lazy vertices and normals as TrackedSide's, made on first read).
  struct Geometry {
    const ContactSurface& s;
    SurfaceVertices v;           // #V
    const std::vector<Vec3>& n;  // #T
    std::vector<Vec3>* lazy_n = nullptr;
    std::vector<long>* stamp = nullptr;
    long epoch = 0;
    std::vector<Vec3>* lazy_corner = nullptr;  // TrackedSide's lazy_corner_normals (or none)
    std::vector<long>* corner_stamp = nullptr;
    // Inline for the surfaces' own normals and the made ones (the looks read it at every
    // evaluated node: out of line it cost 1.9 % of the rigid scene's instructions).
    const Vec3& Normal(int face) const {
      if (!lazy_n) return n[face];
      return (*stamp)[face] == epoch ? (*lazy_n)[face] : MakeNormal(face);
    }
    // The deformed face's normal, made and stamped (tracked_gaps.cpp).
    const Vec3& MakeNormal(int face) const;
    // Deformed corner normal k of `face` (signed_gap.h DeformedCornerNormal over Normal()),
    // made once per group and epoch when the cache is given.
    Vec3 CornerNormal(int face, int k) const {
      auto normal = [this](int f) -> const Vec3& { return Normal(f); };
      if (!lazy_corner) return DeformedCornerNormal(s, face, k, normal);
      const int group = s.corner_group()[3 * face + k];
      if ((*corner_stamp)[group] != epoch) {
        (*lazy_corner)[group] = DeformedCornerNormal(s, face, k, normal);
        (*corner_stamp)[group] = epoch;
      }
      return (*lazy_corner)[group];
    }
  };

  double search_distance_m() const { return search_.search_distance_m(); }
  const TrackedGapStats& stats() const { return stats_; }
  // Tests: whether walks of tied pairs may be skipped (default true; false walks them, which
  // must give the same faces, gaps and forces to the bit).
  void set_pair_skip(bool on) { pair_skip_ = on; }
  // Tests: whether an extruded part's rows may share one row's evaluation (default true; false
  // evaluates every node, which must give the same gaps to the rounding of the z terms).
  void set_shared_rows(bool on) {
    shared_rows_ = on;
    Reset();
  }
  // Tests: whether the nodes of parts that do not share rows are looked at along rigid
  // extruded partners' columns (default true; false looks at the faces, which must give the
  // same gaps to rounding: header, node columns).
  void set_node_columns(bool on) {
    node_columns_ = on;
    Reset();
  }
  // Tests: whether TrackPairs() may run over candidate pairs (default true; false runs the
  // full broad phase at every call, which must give the same pairs).
  void set_pair_candidates(bool on) {
    pair_candidates_ = on;
    have_candidates_ = false;
  }
  // Tests: whether TrackPairs() may keep the last broad phase's pairs for a small motion
  // (default true; false runs the broad phase at every call).
  void set_broad_phase_reuse(bool on) {
    broad_phase_reuse_ = on;
    have_broad_phase_pose_ = false;
  }
  // The candidates' motion margin m (m; TrackPairs). A larger margin makes the candidates less
  // often and tests more of them at each broad phase; seed 003's stage (module 4 mm, steps of
  // 10 us moving B by 50 to 120 um in A's frame by mu) ran the broad phase in the fewest
  // instructions at about 4 mm, rigid and flexible (docs/performance.md, "candidates").
  static constexpr double kCandidateMargin = 4e-3;

 private:
  // Nodes of one surface against the faces of the other; arrays over the node surface's
  // vertices.
  struct Pass {
    Pass(const ContactSurface& node_surface, bool keep_face_weights);
    std::vector<int> face;        // tracked closest face, or kUnseeded, or kFar
    std::vector<double> reach;    // D of the header (m)
    std::vector<double> distance; // to the closest face at the last evaluation (m)
    // The odometer reading up to which the node sleeps: the reading at its last evaluation or
    // look plus what the odometer may advance from there unseen (m; -inf for a node not yet
    // seeded, which is evaluated at every call). One array, so that the node test of RunPass
    // loads one number.
    std::vector<double> wake;
    std::vector<Vec3> stamp_position;  // the node in the face frame at the last evaluation
    std::vector<double> stamp_face_deformation;  // the pass's face deformation odometer then
    // At the node's last walk (RunPass skips the next walks while they cannot leave its face):
    // the margin of the faces it tried over its own (m; 0: none, walk), the node in the face
    // frame, the face deformation odometer, the closest point's feature, whether it was below.
    std::vector<double> walk_margin;
    std::vector<Vec3> walk_position;
    std::vector<double> walk_face_deformation;
    std::vector<TriangleFeature> walk_feature;
    std::vector<char> walk_below;
    // A tied pair (header): the two faces, walk_margin then the pair's; {-1, -1}: none;
    // {-2, -2} (kColumnMargin, tracked_gaps.cpp): walk_margin, walk_position and walk_below are
    // a look along a profile's (header: profile looks), over columns, not faces.
    std::vector<std::array<int, 2>> walk_pair;
    // The force normal's barycentric coordinates of a node listed in contact (face_weights_a;
    // empty without keep_face_weights).
    std::vector<Vec3> face_weights;
    // Blocks of kBlock consecutive nodes of one part (a part's first block starts at its first
    // node): the smallest wake reading of the block's nodes (-inf while one has no face), so
    // that a block whose nodes all sleep by the odometer is passed in one test.
    std::vector<int> part_block_start;  // #parts + 1
    std::vector<double> block_wake;     // per block (m)
    // #parts: 1 while the part's last evaluation ran one row for all (header; its other rows'
    // nodes hold no current state, and are seeded anew when the part leaves that mode).
    std::vector<char> rows_shared;
  };
  static constexpr int kBlock = 16;
  // Pass::face without a face: not seeded yet (always evaluated); farther than its search's
  // bound from every face of the node's partners at its last search (sleeps on that reach).
  static constexpr int kUnseeded = -1, kFar = -2;
  void ResetPart(Pass& pass, const ContactSurface& node_surface, int part);
  // TrackPairs' broad phase: the tracked pairs and parts at X_AB, their parts' nodes reset
  // where a pair joined or left.
  void UpdateTrackedSet(const Transform& X_WA, const Transform& X_WB, const Transform& X_AB,
                        bool part_boxes, const DeformedParts* deformed);
  // How much closer the parts may have come by their deformation since the last broad phase:
  // the largest change of a part's bound, per side, summed (infinite when the gap distance or
  // the sides' bounds are not comparable).
  double BoundsChange(const DeformedParts* deformed) const;
  void RunPass(const ContactSurface& node_surface, const SurfaceVertices& nodes,
               const Geometry& faces, double face_deformation_m,
               const std::vector<double>* face_part_deformation_m,
               double face_deformation_odometer_m, double d, const Transform& X_FN,
               const Transform& X_WF, bool nodes_are_a, const std::vector<double>& odometers,
               Pass& pass, std::vector<NodeGap>* gaps);
  // The evaluated row's entries of a run, at block[0, run.count), made every row's entries in
  // node order into block[0, run.rows run.count) (header: extruded parts).
  void ShareRows(const ContactSurface& node_surface, const ContactSurface& face_surface,
                 const RowGroup& run, const Transform& X_FN, const Transform& X_WF,
                 NodeGap* block) const;
  // The motion bound of part_b of B between two poses of B in A's frame, from their change
  // dR = R1 - R0, dp = p1 - p0 and dR's column norms (the same for every part: made once per call).
  double PartMotion(int part_b, const Mat3& dR, const Vec3& dp, const Vec3& dR_column_norms) const;
  // Starts the odometers (and the faces' deformation odometers) again from zero and seeds every
  // node anew when one has reached kOdometerRestart or is not finite, or the pose is not finite.
  void RestartIfSaturated();

  const ContactSurface& a_;
  const ContactSurface& b_;
  CandidateSearch search_;                 // its broad phase
  std::vector<std::pair<int, int>> tracked_, next_, keep_;  // sorted (part of A, part of B)
  std::vector<int> partners_;              // scratch: parts paired with one part
  std::vector<ContactSurface::RowPlace> partner_places_;  // scratch: the evaluated row's height
                                                          // in each partner's rows
  // scratch: each partner's first and last rows' heights, for node columns (RunPass)
  std::vector<std::pair<double, double>> partner_heights_;
  std::vector<std::pair<int, int>> by_part_;  // scratch: (node part, face part), sorted
  std::vector<char> active_b_;             // #parts of B: in a tracked pair
  std::vector<int> tracked_parts_a_, tracked_parts_b_;  // in a tracked pair, increasing
  Pass pass_a_, pass_b_;
  Transform X_AB_previous_;
  bool have_previous_ = false;
  double odometer_ = 0;                    // largest part motion per call, summed (stats)
  double face_deformation_a_ = 0, face_deformation_b_ = 0;  // per pass: faces' deformation, summed
  // Per part (tracked_gaps.h): B's parts their own motion, A's parts their partners' largest.
  std::vector<double> odometer_a_, odometer_b_, motion_a_, motion_b_;
  // Whether a part's odometer has reached the restart reading (or is not a number) since the
  // odometers last started from zero (RestartIfSaturated), and the largest of them.
  bool odometer_saturated_ = false;
  double largest_odometer_ = 0;
  // odometer += by, noting the largest and whether it reached the restart reading.
  void Advance(double& odometer, double by);
  std::vector<std::array<Vec3, 8>> part_box_corners_b_;  // #parts of B: PartBoxCorners
  TrackedGapStats stats_;
  bool pair_skip_ = true;
  bool shared_rows_ = true;
  bool node_columns_ = true;
  bool keep_face_weights_ = true;
  // Candidate pairs (TrackPairs): sorted, made at relative pose X_AB_candidates_ with the
  // deformation sum G0 and for the largest reach given; rho_B of B's part boxes.
  std::vector<std::pair<int, int>> candidates_;
  Transform X_AB_candidates_;
  double candidates_deformation_m_ = 0, candidates_reach_m_ = 0;
  bool have_candidates_ = false;
  bool pair_candidates_ = true;
  // The last broad phase (TrackPairs): its relative pose, whether it had deformed parts, and
  // their gap distance and bounds then (#parts of A and of B, or empty for a rigid side).
  Transform X_AB_broad_phase_;
  bool have_broad_phase_pose_ = false;
  bool broad_phase_reuse_ = true;
  bool broad_phase_deformed_ = false;
  double broad_phase_gap_distance_m_ = 0;
  std::vector<double> broad_phase_d_a_, broad_phase_d_b_;
  double box_radius_b_ = 0;        // rho_B: B's part boxes' corners and part centres
  std::vector<Vec3> centers_b_A_;  // scratch, #parts of B: their centres in A's frame
  std::vector<RowGroup> row_groups_a_, row_groups_b_;  // ComputeGaps(), #parts reserved
  bool defer_rows_ = false;                            // Update()'s, for its passes
};

}  // namespace orrery::contact

#pragma once
// Surface contact between two rigid bodies as an engine force element (mbd/external_force.h):
// what the `contact` mesh model of DESIGN.md puts between two gears' tooth surfaces.
//
// One Apply() (MuJoCo-style table of contents), with ContactGapMethod::kTracked (the default):
//   1-2. signed gaps both ways by tracking each node's closest face (tracked_gaps.h): the broad
//      phase of the candidate search picks the part pairs, nodes that cannot have reached the
//      other surface since their last evaluation are skipped, the others walk from their face or
//      are searched in the parts' FCL hierarchies; skipped when neither body moved;
// with ContactGapMethod::kCandidatePairs (the oracle of the tracked gaps, and what the flexible
// element uses):
//   1. candidate triangle pairs (candidate_pairs.h): part spheres (the ring zone), then the
//      inflated-BVH traversal; skipped while the relative motion since the last search is within
//      the surfaces' slack; after a search, the distinct node-face candidates of each pass;
//   2. signed gaps both ways (signed_gap.h, seed 000 eqs. 6-9): nodes of A against faces of B
//      and nodes of B against faces of A, over the node-face candidates; skipped when neither
//      body moved;
//   3. contact law at every penetrating node (contact_law.h): penalty per unit area, Hunt-
//      Crossley damping, regularized Coulomb friction, each pass weighted by 1/2 so that the two
//      passes together integrate the pressure once (seed 000 eq. 20);
//   4. the node force F on the node's body at the node P and -F on the other body at P
//      (spatial forces about the world origin in data.f_ext), elastic energy to
//      data.potential_energy, dissipation to data.power_dissipated.
// Its stiffness and damping reach the integrators analytically (AddTangents(), contact_tangents.h):
// finite differences through the element are never taken.
// Apply() allocates nothing once the workspace's lists have reached the size the scene needs
// (they are reserved for 4 pairs per triangle and never shrink; tests/contact/
// no_allocation_test.cpp counts).
// Relative velocity at a node P on body N against the face body F:
//   v_rel = v_N(P) - v_F(P), depth rate = -v_rel . n, slip v_t = v_rel - (v_rel . n) n.
//
// Outputs (/external/<name>/...): normal_force (N, sum of F_N), friction_force (N, sum of
// |F_T|), contact_points (penetrating nodes, both passes), max_penetration (m); then the
// outputs of spec.monitor (contact_monitor.h), if any; with spec.record_points = n,
// point_positions (n x 3) and point_normal_forces (n) of contact_point_record.h.
// Health (mbd/element_health.h, watched by the run-health monitor at every output row):
// "penetration", the largest penetration of the last evaluation against the gap distance
// d = (margin_A + margin_B) / 2: a penalty contact calibrated for micrometres that sinks deeper
// than the distance its search lists (a step that moved the surfaces through each other, a mesh
// load far above the calibration) gives forces outside the law's range: a warning;
// "penetration_limit", the same against spec.penetration_limit (default d + s, s = (slack_A +
// slack_B) / 2; a gear pair: half the thinner tooth, models/gear_contact.h): the surfaces have
// passed through each other further than their gaps can stand for: the run stops
// (contact_outputs.h).
//
// Usage:
//   auto plane = std::make_shared<const ContactSurface>(std::vector{plane_mesh}, 1e-3);
//   auto block = std::make_shared<const ContactSurface>(std::vector{bottom_mesh}, 1e-3);
//   builder.AddExternalForce(std::make_shared<ContactElement>(ContactElementSpec{
//       .name = "block_on_plane", .body_a = block_body, .body_b = kWorldBody,
//       .surface_a = block, .surface_b = plane,
//       .law = {.stiffness_per_area = 1e7, .friction_coefficient = 0.3}}));
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "contact/candidate_pairs.h"
#include "contact/contact_law.h"
#include "contact/contact_outputs.h"
#include "contact/contact_point_record.h"
#include "contact/contact_surface.h"
#include "contact/contact_tangents.h"
#include "contact/contact_monitor.h"
#include "contact/signed_gap.h"
#include "contact/tracked_gaps.h"
#include "mbd/element_health.h"
#include "mbd/external_force.h"
#include "mbd/model.h"

namespace orrery::contact {

// How the element finds its gaps (the header); both give the gaps of signed_gap.h.
enum class ContactGapMethod { kTracked, kCandidatePairs };

struct ContactElementSpec {
  std::string name;
  BodyIndex body_a = -1, body_b = -1;  // rigid bodies (kWorldBody for a fixed surface)
  std::shared_ptr<const ContactSurface> surface_a, surface_b;  // in the frames of body_a, body_b
  ContactLaw law;
  ContactGapMethod gap_method = ContactGapMethod::kTracked;
  // Optional: reads the contact points of every evaluation and adds its outputs after the
  // element's own (contact_monitor.h; a gear pair's transmission error, mesh stiffness and
  // contact pattern: models/gear_mesh_monitor.h).
  std::shared_ptr<const ContactMonitor> monitor;
  // > 0: the outputs also hold this many contact points per row (contact_point_record.h).
  int record_points = 0;
  // The penetration beyond which the gaps no longer stand for the surfaces: the run stops there
  // (contact_outputs.h PenetrationChecks; default: the search distance plus the slack).
  PenetrationLimit penetration_limit;
};

// Mutable state of one element in one Data: the search caches and the last evaluation.
class ContactWorkspace final : public ExternalForceWorkspace {
 public:
  // nv: the model's velocity count (0: a workspace for UpdateGaps and CalcForces alone);
  // monitor: the element's monitor, whose state the workspace then holds (nullptr: none).
  ContactWorkspace(const ContactSurface& a, const ContactSurface& b, int nv = 0,
                   const ContactMonitor* monitor = nullptr);

  TrackedGaps tracked;                   // kTracked
  // WarmStart(): the source's tracking state, taken over (TrackedGaps::WarmStartFrom) by the
  // next UpdateGaps() only when it must track, at poses other than the gaps' (a row at the
  // integrator's last positions keeps the gaps and copies nothing). That UpdateGaps() clears it
  // either way; until then the source must not change (external_force.h WarmStart).
  const TrackedGaps* warm_tracking = nullptr;
  CandidateSearch search;                // kCandidatePairs
  std::vector<TrianglePair> pairs;       // candidate pairs of the last search
  std::vector<NodeFaceCandidate> node_faces_a, node_faces_b;  // of the pairs, per pass
  GapScratch scratch_a, scratch_b;       // per-node scratch of the passes (nodes of A, of B)
  // Nodes of A on B's faces, nodes of B on A's faces (UpdateGaps()), and the runs of shared rows
  // in them (tracked_gaps.h RowGroup; kTracked only), which CalcForces() evaluates once per
  // profile point. A model's evaluation (Compute()) leaves the shared rows pending, only the
  // evaluated rows' entries listed: its forces need no more. Whatever reads the points (the
  // outputs, the tangents, UpdateGaps() at the same poses) completes them first
  // (ContactElement::CompleteRows), so they are mutable; a caller reading the lists after
  // Apply() or Compute() finds one entry per profile point of a shared part (its evaluated
  // row's nodes), and after UpdateGaps() every node.
  mutable std::vector<NodeGap> gaps_a, gaps_b;
  mutable std::vector<RowGroup> row_groups_a, row_groups_b;
  Transform X_WA, X_WB;                  // poses of the last gap computation
  bool have_gaps = false;
  ContactTangents tangents;              // AddTangents()
  // spec.monitor's state and spec.record_points' points of the last Apply(): CalcForces() fills
  // them; Compute() (the integrator's evaluations, whose outputs are seldom read) leaves them to
  // the first GetOutputs() after it, which makes them from the gaps, the poses, V_WA, V_WB and
  // f_A of that Compute() (the same calls in the same order: the same values to the bit).
  std::unique_ptr<ContactMonitorState> monitor;
  mutable ContactPointRecord points;
  mutable bool outputs_pending = false;           // Compute() left them; GetOutputs() clears it
  Vec6 V_WA = Vec6::Zero(), V_WB = Vec6::Zero();  // Compute()'s body velocities (world origin)
  // Results of the last Compute(), added to Data by AddTo(): spatial forces on A and B (world
  // origin), elastic energy (J) and dissipated power (W).
  Vec6 f_A = Vec6::Zero(), f_B = Vec6::Zero();
  double energy = 0, power_dissipated = 0;
  // Outputs of the last Apply().
  double normal_force = 0, friction_force = 0, max_penetration = 0;
  int contact_points = 0;
  // What the last Apply() recomputed (tests and benchmarks).
  bool searched = false, gaps_recomputed = false;  // searched: kCandidatePairs only
};

class ContactElement final : public ExternalForceElement, public ElementHealthReporter {
 public:
  // Throws std::invalid_argument for missing surfaces, the same body on both sides, an
  // invalid law or penetration limit. Body indices are checked against the model in MakeWorkspace().
  explicit ContactElement(ContactElementSpec spec);

  const std::string& name() const override { return spec_.name; }
  const ContactElementSpec& spec() const { return spec_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model& model) const override;
  void Apply(const Model& model, double t, Data& data,
             ExternalForceWorkspace& workspace) const override;
  // Apply() = Compute() (gaps and forces into the workspace) + AddTo() (external_force.h).
  bool SplitsApply() const override { return true; }
  void Compute(const Model& model, double t, const Data& data,
               ExternalForceWorkspace& workspace) const override;
  void AddTo(const Model& model, const ExternalForceWorkspace& workspace,
             Data& data) const override;
  // The tracking state of `source` into `target` (external_force.h; TrackedGaps::
  // WarmStartFrom), with source's last gaps and their poses (which target keeps while its poses
  // do not change: a row at the positions of the integrator's last evaluation computes no
  // gaps). The gaps are copied at once, the tracking state by target's next UpdateGaps() if it
  // tracks (ContactWorkspace::warm_tracking): the recorder's rows in a model with constraints
  // are at the positions of the integrator's last residual, and copying the tracked parts'
  // nodes for none of them cost 4 to 5 % of the rigid scene's CPU (docs/performance.md,
  // "warm-lazy"). Not copied: the monitor's state, the outputs. Nothing with candidate pairs.
  void WarmStart(const ExternalForceWorkspace& source,
                 ExternalForceWorkspace& target) const override;
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  void GetOutputs(const ExternalForceWorkspace& workspace, double* values) const override;
  // Health (the header): the penetration against the gap distance.
  std::vector<ElementHealthCheck> HealthChecks() const override;
  void GetHealthValues(const ExternalForceWorkspace& workspace, double* values) const override;
  // Stiffness and damping of the penetrating nodes of the last Apply() (contact_tangents.h).
  bool HasTangents() const override { return true; }
  void AddTangents(const Model& model, const Data& data, ExternalForceWorkspace& workspace,
                   Eigen::Ref<Eigen::MatrixXd> K, Eigen::Ref<Eigen::MatrixXd> C) const override;

  // Stages 1-2 of Apply() for given poses (also used by benchmarks): refreshes the pairs and
  // the gaps in `ws` if the poses changed; every listed node's entry (shared rows complete).
  void UpdateGaps(const Transform& X_WA, const Transform& X_WB, ContactWorkspace& ws) const;
  // Stages 3-4: forces from the gaps in `ws` and the body velocities (spatial, world origin),
  // returned as spatial forces on A and B about the world origin; fills the outputs of `ws`.
  void CalcForces(const Vec6& V_WA, const Vec6& V_WB, ContactWorkspace& ws, Vec6* f_A,
                  Vec6* f_B, double* energy, double* power_dissipated) const;

 private:
  // Calls fn(gap, p_W, v_rel, area_weight, points, node_on_a) for every penetrating node of
  // ws's gaps, both passes (nodes of A on B's faces, then nodes of B on A's faces), each with
  // its own position p_W = gap.p_W and points = 1, in list order.
  // group_rows: the nodes of a run of shared rows (ws.row_groups_a/_b) at one profile point
  // make one call instead, with their areas summed, p_W their area-weighted mean and points the
  // rows, where the pass's relative rotation is exactly about the rows' direction (so every row
  // has the same relative velocity, and the same gap and normal by the sharing): the contact
  // law is linear in the area (contact_law.h), so the force of the sum is the sum of the rows'
  // forces, and its moment about any point that of the rows' forces at their own positions.
  // A pending run's rows are read from its evaluated row (their nodes' areas and heights);
  // without group_rows the runs must be complete.
  template <class Fn>
  void ForEachContactPoint(const Vec6& V_WA, const Vec6& V_WB, const ContactWorkspace& ws,
                           bool group_rows, Fn&& fn) const;
  // UpdateGaps(), leaving the shared rows pending with defer_rows (Compute()).
  void UpdateGaps(const Transform& X_WA, const Transform& X_WB, ContactWorkspace& ws,
                  bool defer_rows) const;
  // The pending shared rows of ws's lists made (TrackedGaps::CompleteRows at ws's poses).
  void CompleteRows(const ContactWorkspace& ws) const;
  // CalcForces() with (outputs true) or without the monitor's state and the recorded points.
  void CalcForces(const Vec6& V_WA, const Vec6& V_WB, ContactWorkspace& ws, Vec6* f_A, Vec6* f_B,
                  double* energy, double* power_dissipated, bool outputs) const;
  // The monitor's state and the recorded points of the gaps in ws at these velocities, with
  // f_A the force on A they gave: one law call per contact point in list order, so the same
  // numbers whether CalcForces() makes them or GetOutputs() after a Compute().
  void MakeOutputs(const Vec6& V_WA, const Vec6& V_WB, const Vec6& f_A,
                   const ContactWorkspace& ws) const;
  // The monitor's state and the recorded points of the last Compute() (ContactWorkspace).
  void MakePendingOutputs(const ContactWorkspace& ws) const;

  ContactElementSpec spec_;
  std::vector<OutputDescription> outputs_;
  std::vector<ElementHealthCheck> health_checks_;
};

}  // namespace orrery::contact

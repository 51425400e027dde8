#pragma once
// Surface contact where either side (or both) may be a flexible, Craig-Bampton-reduced body: the
// ContactElement of contact_element.h with deformed surfaces (DESIGN.md, "Tooth contact":
// deformed node positions s_P + Phi_P q_f, an inflated BVH of the undeformed surface, exact
// deformed gaps).
//
// One Evaluate() (Apply() takes the poses, velocities and modal coordinates from Data):
//   1. deformation bound u = sum_k |q_k| c_k of each flexible side (flexible_contact_surface.h);
//      above the side's allowance the culling may miss pairs: counted in
//      inflation_exceeded and reported as an output (the surfaces must then be rebuilt with a
//      larger deformation_allowance_m; the step goes on with the pairs it has);
//   2. deformed vertices s_P + Phi_P q_f and deformed face normals of each flexible side (with
//      kTracked: those the tracked gaps read, made on first read, deformed_vertices.h);
//   3. (gap_method kCandidatePairs) candidate pairs of the UNDEFORMED surfaces
//      (candidate_pairs.h; kept while the rigid relative motion is within the slack), their
//      node-face lists per pass; with kTracked (the default) stages 3-4 are tracked_gaps.h over
//      the deformed vertices and normals;
//   4. signed gaps both ways with the deformed positions on both sides (signed_gap.h, explicit
//      vertices), listed within d = (g_A + g_B) / 2, g the gap margin of a flexible side and the
//      margin of a rigid one;
//   5. contact law at each penetrating node (contact_law.h, weights 1/2 A_P of the undeformed
//      surface, as contact_element.h); the relative velocity includes the deformation rates
//      R Phi_P q_f-dot of the node and of the face point;
//   6. the node force F (world): on the node's body as a spatial force about the world origin at
//      the deformed node position p_W, and -F on the face's body at the same point; in the body
//      frames the node takes F_B = R_WN^T F and the face's three vertices take -w_k R_WF^T F
//      (w_k the barycentric coordinates of the closest point on the deformed face), on the
//      flexible sides; the modal forces are Q = sum_P Phi_P^T F_P,B over the vertices of each
//      flexible side.
// For a node whose closest point lies inside a face, g = (p - sum w_k x_k) . n with p - q
// parallel to n, so dg/dx_P = n, dg/dx_k = -w_k n exactly (the rotation of n does not change g to
// first order): the forces above are then minus the gradient of the penalty energy, in the
// modal coordinates too (checked by finite differences in tests/contact/
// flexible_contact_element_test.cpp).
// For flexible bodies the penalty stands for the local contact compliance only (bending, shear
// and foundation are in the modes); the gear layer calibrates it for teeth
// (models/flexible_gear_mesh.h).
// Evaluate() and Apply() allocate nothing once the workspace's lists have reached the scene's
// size (tests/contact/no_allocation_test.cpp).
//
// Outputs (/external/<name>/...): normal_force (N), friction_force (N), contact_points,
// max_penetration (m), deformation_bound (m, the larger side's u), inflation_exceeded (count of
// evaluations whose u exceeded the allowance); then the outputs of spec.monitor
// (contact_monitor.h), if any; with spec.record_points = n,
// point_positions (n x 3, side a's body frame, deformed) and point_normal_forces (n) of
// contact_point_record.h.
// Health (mbd/element_health.h): "penetration", the largest penetration of the last evaluation
// against the gap distance d = (g_A + g_B) / 2 (as the rigid element's, contact_element.h): a
// warning; "penetration_limit", the same against spec.penetration_limit (default d + s, s the
// sides' mean slack): a stop.
//
// Usage:
//   auto block = std::make_shared<const FlexibleContactSurface>(modes, FlexibleContactSurfaceSpec{});
//   builder.AddExternalForce(std::make_shared<FlexibleContactElement>(FlexibleContactElementSpec{
//       .name = "block_on_plane", .a = {.body = block_body, .flexible = block},
//       .b = {.body = kWorldBody, .rigid = plane}, .law = {.stiffness_per_area = 1e13}}));
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/candidate_pairs.h"
#include "contact/contact_element.h"
#include "contact/contact_law.h"
#include "contact/contact_outputs.h"
#include "contact/contact_point_record.h"
#include "contact/contact_surface.h"
#include "contact/contact_tangents.h"
#include "contact/contact_monitor.h"
#include "contact/deformed_vertices.h"
#include "contact/flexible_contact_surface.h"
#include "contact/signed_gap.h"
#include "mbd/external_force.h"
#include "mbd/model.h"

namespace orrery::contact {

// One side: a rigid surface or a flexible one (exactly one of the two).
struct ContactSide {
  BodyIndex body = -1;
  std::shared_ptr<const ContactSurface> rigid;             // in the body frame
  std::shared_ptr<const FlexibleContactSurface> flexible;  // of the body's FlexibleBodyModes
  const ContactSurface& surface() const { return flexible ? flexible->undeformed() : *rigid; }
  double gap_margin_m() const {
    return flexible ? flexible->spec().gap_margin_m : rigid->margin_m();
  }
};

struct FlexibleContactElementSpec {
  std::string name;
  ContactSide a, b;
  ContactLaw law;
  // Stages 3-4 (header): kTracked tracks each node's closest deformed face (tracked_gaps.h; only
  // the vertices the gaps read are deformed, the hierarchies' boxes are lowered by a bound on
  // each tracked tooth's largest displacement and every motion bound is raised by a bound on
  // the largest vertex change since the last evaluation, both from the modal coordinates:
  // flexible_contact_surface.h PartDeformationBound); kCandidatePairs as described.
  ContactGapMethod gap_method = ContactGapMethod::kTracked;
  // Optional: reads the contact points of every evaluation and adds its outputs after the
  // element's own (contact_monitor.h; for gears the contact layer's mesh stiffness:
  // models/gear_mesh_monitor.h).
  std::shared_ptr<const ContactMonitor> monitor;
  // > 0: the outputs also hold this many contact points per row (contact_point_record.h).
  int record_points = 0;
  // The penetration beyond which the gaps no longer stand for the surfaces: the run stops there
  // (contact_outputs.h PenetrationChecks; default: the gap distance plus the slack).
  PenetrationLimit penetration_limit;
};

// The state of one side for Evaluate(): pose and spatial velocity (world origin) of the body
// frame; modal coordinates and rates (nf of a flexible side, ignored for a rigid one).
struct ContactSideState {
  Transform X_WB;
  Vec6 V_WB = Vec6::Zero();
  const Eigen::VectorXd* q_f = nullptr;
  const Eigen::VectorXd* q_f_dot = nullptr;  // nullptr: zero
};

// Per side of one workspace.
struct ContactSideBuffers {
  explicit ContactSideBuffers(const ContactSide& side);
  // #V: deformed vertices (B); the undeformed ones for a rigid side. With tracked gaps only
  // those the gaps read are current (made on first read by `deformed`; the others keep older
  // positions and are not read).
  std::vector<Vec3> vertices;
  DeformedVertices deformed;    // a flexible side's, with tracked gaps
  VertexRates rates;            // a flexible side's: R Phi_v q_f-dot per pass over the points
  std::vector<Vec3> normals;    // #T: deformed face normals (B); with tracked gaps made lazily
  std::vector<long> normal_stamp;  // #T: normal_epoch at which normals[face] was made (tracked)
  long normal_epoch = 0;           // advanced by every tracked deformation
  // #corner groups of a surface with smoothed normals (tracked gaps): the deformed corner
  // normals made at normal_epoch (tracked_gaps.h TrackedSide::lazy_corner_normals).
  std::vector<Vec3> corner_normals;
  std::vector<long> corner_stamp;
  Eigen::VectorXd displacement; // 3 #V: Phi q_f (flexible, candidate pairs)
  std::vector<Vec3> node_force;  // #V: contact force on each vertex, body frame (N; a flexible
                                 // side's: a rigid side's vertices take none, zero)
  Vec6 f_W = Vec6::Zero();      // spatial force on the body, world origin
  Eigen::VectorXd modal_force;  // nf: sum_P Phi_P^T node_force_P
  double deformation_bound = 0; // m
  double deformation_change = 0;  // m: largest vertex change since the last call (tracked gaps)
  const Eigen::VectorXd* q_f = nullptr;      // of the current Evaluate() (flexible, nf > 0)
  const Eigen::VectorXd* q_f_dot = nullptr;
  std::vector<char> has_force;  // #V: node_force[i] set in this evaluation
  std::vector<int> forced;      // those vertices (the others' node_force is zero)
  // #parts (tracked gaps): a bound on the largest displacement of each tracked part's vertices,
  // and whether the part was tracked at the last evaluation.
  std::vector<double> part_deformation;
  std::vector<char> part_current;
  // nf (tracked gaps, flexible): q_f at the last evaluation, and q_f less it (scratch).
  Eigen::VectorXd q_f_previous, q_f_change;
};

class FlexibleContactWorkspace final : public ExternalForceWorkspace {
 public:
  // modal_a / modal_b: the flexible surfaces of sides whose bodies have modal coordinates
  // (the tangents' modal rows), nv the model's velocity count (the defaults: a workspace for
  // Evaluate() alone, without tangents); monitor: the element's monitor, whose state the
  // workspace then holds (nullptr: none).
  FlexibleContactWorkspace(const ContactSide& a, const ContactSide& b,
                           const FlexibleContactSurface* modal_a = nullptr,
                           const FlexibleContactSurface* modal_b = nullptr, int nv = 0,
                           const ContactMonitor* monitor = nullptr);

  TrackedGaps tracked;                   // kTracked
  CandidateSearch search;                // kCandidatePairs
  std::vector<TrianglePair> pairs;
  std::vector<NodeFaceCandidate> node_faces_a, node_faces_b;
  GapScratch scratch_a, scratch_b;
  std::vector<NodeGap> gaps_a, gaps_b;  // nodes of A on B's faces, nodes of B on A's faces
  ContactSideBuffers side_a, side_b;
  ContactTangents tangents;             // AddTangents()
  // spec.monitor's state and spec.record_points' points of the last evaluation: Evaluate()
  // fills them; Compute() (the integrator's evaluations, whose outputs are seldom read) leaves
  // them to the first GetOutputs() after it, which makes them from that Compute()'s gaps, poses,
  // side a's force and each point's law stiffness and normal force (point_laws: the same calls
  // in the same order, the same values to the bit; as ContactWorkspace, contact_element.h).
  std::unique_ptr<ContactMonitorState> monitor;
  mutable ContactPointRecord points;
  mutable bool outputs_pending = false;  // Compute() left them; GetOutputs() clears it
  Transform X_WA, X_WB;                  // the poses of the last evaluation
  // Per contact point of the last Compute() (ForEachContactPoint's order): the law's normal
  // stiffness (N/m) and normal force (N). Reserved for every node of both surfaces.
  struct PointLaw {
    double stiffness = 0, normal = 0;
  };
  std::vector<PointLaw> point_laws;
  // Outputs of the last Evaluate().
  double normal_force = 0, friction_force = 0, max_penetration = 0;
  double energy = 0, power_dissipated = 0;
  int contact_points = 0;
  long inflation_exceeded = 0;
  bool searched = false;
};

class FlexibleContactElement final : public ExternalForceElement, public ElementHealthReporter {
 public:
  // Throws std::invalid_argument for a side with no surface or both, the same body on both
  // sides, or an invalid law. MakeWorkspace() checks that a flexible side's body is a flexible
  // body of the model with the surface's modes.
  explicit FlexibleContactElement(FlexibleContactElementSpec spec);

  const std::string& name() const override { return spec_.name; }
  const FlexibleContactElementSpec& spec() const { return spec_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model& model) const override;
  void Apply(const Model& model, double t, Data& data,
             ExternalForceWorkspace& workspace) const override;
  // Apply() = Compute() (Evaluate() into the workspace) + AddTo() (external_force.h).
  bool SplitsApply() const override { return true; }
  void Compute(const Model& model, double t, const Data& data,
               ExternalForceWorkspace& workspace) const override;
  void AddTo(const Model& model, const ExternalForceWorkspace& workspace,
             Data& data) const override;
  // The tracking state of `source` into `target` (external_force.h): the tracked gaps'
  // (TrackedGaps::WarmStartFrom) and each flexible side's modal coordinates and tracked parts
  // at its last evaluation (the deformation change bound is taken from them). Not copied: the
  // lazy vertices and normals with their stamps (target's own epochs say what is current), the
  // monitor's state, the outputs. Nothing with candidate pairs.
  void WarmStart(const ExternalForceWorkspace& source,
                 ExternalForceWorkspace& target) const override;
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  void GetOutputs(const ExternalForceWorkspace& workspace, double* values) const override;
  // Health (the header): the penetration against the gap distance.
  std::vector<ElementHealthCheck> HealthChecks() const override;
  void GetHealthValues(const ExternalForceWorkspace& workspace, double* values) const override;
  // Stiffness and damping of the penetrating nodes of the last Apply(), in the modal coordinates
  // too (contact_tangents.h).
  bool HasTangents() const override { return true; }
  void AddTangents(const Model& model, const Data& data, ExternalForceWorkspace& workspace,
                   Eigen::Ref<Eigen::MatrixXd> K, Eigen::Ref<Eigen::MatrixXd> C) const override;

  // Stages 1-6 for given states: fills ws.side_a / side_b (f_W; modal_force and node_force of
  // the flexible sides), ws.energy, ws.power_dissipated and the outputs; with outputs false the
  // monitor's state and the recorded points are left to the next GetOutputs()
  // (FlexibleContactWorkspace).
  void Evaluate(const ContactSideState& a, const ContactSideState& b, FlexibleContactWorkspace& ws,
                bool outputs = true) const;

 private:
  // A penetrating node of the last evaluation, with what its force and tangents need.
  struct ContactPoint {
    const NodeGap* gap = nullptr;
    bool node_on_a = true;
    std::array<int, 3> face_vertices = {0, 0, 0};  // of the face's side
    Vec3 face_weights = Vec3::Zero();  // barycentric, of the closest point on the deformed face
    Vec3 v_rel = Vec3::Zero();         // node relative to the face point, deformation rates in
    double area_weight = 0;            // 1/2 w A_P of the node (w: its rim weight, signed_gap.h)
  };
  // Calls fn(ContactPoint) for every penetrating node of ws's gaps, both passes; the vertices'
  // deformation rates from ws's rate caches (started again here: each call at its own q_f-dot).
  template <class Fn>
  void ForEachContactPoint(const ContactSideState& a, const ContactSideState& b,
                           FlexibleContactWorkspace& ws, Fn&& fn) const;
  // The monitor's state and the recorded points of the last Compute() (FlexibleContactWorkspace).
  void MakePendingOutputs(const FlexibleContactWorkspace& ws) const;
  // A side's state from the kinematics in data.
  static ContactSideState SideState(const Model& model, const Data& data, const ContactSide& side);

  FlexibleContactElementSpec spec_;
  std::vector<OutputDescription> outputs_;
  std::vector<ElementHealthCheck> health_checks_;
};

}  // namespace orrery::contact

#include "contact/contact_element.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "mbd/data.h"

namespace orrery::contact {

namespace {

bool SamePose(const Transform& X, const Transform& Y) { return X.R == Y.R && X.p == Y.p; }

}  // namespace

ContactWorkspace::ContactWorkspace(const ContactSurface& a, const ContactSurface& b, int nv,
                                   const ContactMonitor* monitor)
    : tracked(a, b, /*keep_face_weights=*/false),
      search(a, b),
      scratch_a(a),
      scratch_b(b),
      tangents(nullptr, nullptr, nv),
      monitor(monitor ? monitor->MakeState() : nullptr),
      points(a.num_vertices() + b.num_vertices()) {
  pairs.reserve(search.suggested_capacity());
  node_faces_a.reserve(3 * pairs.capacity());
  node_faces_b.reserve(3 * pairs.capacity());
  gaps_a.reserve(a.num_vertices());
  gaps_b.reserve(b.num_vertices());
  row_groups_a.reserve(a.num_parts());
  row_groups_b.reserve(b.num_parts());
}

ContactElement::ContactElement(ContactElementSpec spec) : spec_(std::move(spec)) {
  const std::string what = "ContactElement '" + spec_.name + "': ";
  if (!spec_.surface_a || !spec_.surface_b)
    throw std::invalid_argument(what + "both surfaces are required");
  if (spec_.body_a == spec_.body_b)
    throw std::invalid_argument(what + "body_a and body_b are the same body");
  if (spec_.record_points < 0)
    throw std::invalid_argument(what + "record_points must be >= 0, got " +
                                std::to_string(spec_.record_points));
  try {
    ValidateContactLaw(spec_.law);
    health_checks_ = PenetrationChecks(0.5 * (spec_.surface_a->margin_m() + spec_.surface_b->margin_m()),
                                       0.5 * (spec_.surface_a->slack_m() + spec_.surface_b->slack_m()),
                                       spec_.penetration_limit);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + e.what());
  }
  outputs_ = ContactOutputs({{.name = "normal_force", .unit = "N"},
                             {.name = "friction_force", .unit = "N"},
                             {.name = "contact_points", .unit = "1"},
                             {.name = "max_penetration", .unit = "m"}},
                            spec_.monitor.get(), spec_.record_points);
}

std::unique_ptr<ExternalForceWorkspace> ContactElement::MakeWorkspace(const Model& model) const {
  for (BodyIndex body : {spec_.body_a, spec_.body_b})
    if (body < 0 || body >= model.nbodies)
      throw std::invalid_argument("ContactElement '" + spec_.name + "': body index " +
                                  std::to_string(body) + " is not in the model");
  return std::make_unique<ContactWorkspace>(*spec_.surface_a, *spec_.surface_b, model.nv,
                                            spec_.monitor.get());
}

void ContactElement::UpdateGaps(const Transform& X_WA, const Transform& X_WB,
                                ContactWorkspace& ws) const {
  UpdateGaps(X_WA, X_WB, ws, /*defer_rows=*/false);
}

void ContactElement::UpdateGaps(const Transform& X_WA, const Transform& X_WB, ContactWorkspace& ws,
                                bool defer_rows) const {
  ws.searched = false;
  ws.gaps_recomputed = false;
  // A warm start's source (WarmStart): read now or never (its state moves on after this).
  const TrackedGaps* warm = std::exchange(ws.warm_tracking, nullptr);
  if (ws.have_gaps && SamePose(X_WA, ws.X_WA) && SamePose(X_WB, ws.X_WB)) {
    if (!defer_rows) CompleteRows(ws);
    return;
  }
  const ContactSurface& a = *spec_.surface_a;
  const ContactSurface& b = *spec_.surface_b;
  if (spec_.gap_method == ContactGapMethod::kTracked) {
    if (warm) ws.tracked.WarmStartFrom(*warm);
    ws.tracked.Update(X_WA, X_WB, &ws.gaps_a, &ws.gaps_b, defer_rows);
    ws.row_groups_a.assign(ws.tracked.row_groups_a().begin(), ws.tracked.row_groups_a().end());
    ws.row_groups_b.assign(ws.tracked.row_groups_b().begin(), ws.tracked.row_groups_b().end());
    ws.X_WA = X_WA;
    ws.X_WB = X_WB;
    ws.have_gaps = true;
    ws.gaps_recomputed = true;
    return;
  }
  // Candidate pairs (kept while the motion since the search is within the slack) and their
  // node-face combinations.
  ws.searched = ws.search.Find(X_WA, X_WB, &ws.pairs);
  if (ws.searched) {
    ListNodeFaceCandidates(a, ws.pairs, /*nodes_are_a=*/true, &ws.scratch_a, &ws.node_faces_a);
    ListNodeFaceCandidates(b, ws.pairs, /*nodes_are_a=*/false, &ws.scratch_b, &ws.node_faces_b);
  }
  // Gaps both ways.
  const double d = ws.search.search_distance_m();
  ComputeNodeGapsFromCandidates(a, X_WA, b, X_WB, ws.node_faces_a, d, &ws.gaps_a);
  ComputeNodeGapsFromCandidates(b, X_WB, a, X_WA, ws.node_faces_b, d, &ws.gaps_b);
  ws.row_groups_a.clear();
  ws.row_groups_b.clear();
  ws.X_WA = X_WA;
  ws.X_WB = X_WB;
  ws.have_gaps = true;
  ws.gaps_recomputed = true;
}

void ContactElement::CompleteRows(const ContactWorkspace& ws) const {
  ws.tracked.CompleteRows(ws.X_WA, ws.X_WB, &ws.gaps_a, &ws.row_groups_a, /*nodes_are_a=*/true);
  ws.tracked.CompleteRows(ws.X_WA, ws.X_WB, &ws.gaps_b, &ws.row_groups_b, /*nodes_are_a=*/false);
}

template <class Fn>
void ContactElement::ForEachContactPoint(const Vec6& V_WA, const Vec6& V_WB,
                                         const ContactWorkspace& ws, bool group_rows,
                                         Fn&& fn) const {
  // One pass: nodes on body N (velocity V_N, rotation R_WN) against faces on body F.
  // The node's area weight carries both parts' stiffness scales (contact_surface.h).
  auto pass = [&](const std::vector<NodeGap>& gaps, const std::vector<RowGroup>& groups,
                  const ContactSurface& node_surface, const ContactSurface& face_surface,
                  const Vec6& V_N, const Vec6& V_F, const Transform& X_WN, bool node_on_a) {
    const Mat3& R_WN = X_WN.R;
    // The area weight of node v with g's rim weight and face (a shared run's rows: one part
    // each side, so the same stiffness scales).
    auto area_of = [&](const NodeGap& g, int v) {
      const double scale =
          node_surface.vertex_stiffness_scale()[v] * face_surface.face_stiffness_scale()[g.face];
      return 0.5 * g.weight * node_surface.vertex_areas()[v] * scale;
    };
    auto one = [&](const NodeGap& g) {
      if (!InContact(g)) return;
      const Vec3 v_rel = PointVelocity(V_N, g.p_W) - PointVelocity(V_F, g.p_W);
      fn(g, g.p_W, v_rel, area_of(g, g.node), 1, node_on_a);
    };
    // The rows of a run lie along N's z axis (tracked_gaps.h): their relative velocities are
    // the same when the relative rotation is along it, here to the bit (a torsional model).
    const Vec3 turn = (V_N.head<3>() - V_F.head<3>()).cross(R_WN.col(2));
    const bool grouped = group_rows && turn.x() == 0 && turn.y() == 0 && turn.z() == 0;
    size_t i = 0;
    if (grouped) {
      for (const RowGroup& run : groups) {
        for (; i < static_cast<size_t>(run.begin); ++i) one(gaps[i]);
        const int n = node_surface.part_row_length()[run.part];
        for (int e = 0; e < run.count; ++e) {
          // The first listed row's entry: the rows' gap and normal.
          const NodeGap& g = gaps[run.begin + e];
          if (!InContact(g)) continue;
          // The rows' nodes from the run's first (pending: the evaluated row's), their areas
          // and heights: the same numbers from a pending run as from the run made whole.
          const int first = g.node - (run.pending ? run.shared_row * n : 0);
          double area = 0, height = 0;
          for (int k = 0; k < run.rows; ++k) {
            const int v = first + k * n;
            const double a = area_of(g, v);
            area += a;
            height += a * node_surface.vertices()[v].z();
          }
          const Vec3& x = node_surface.vertices()[g.node];  // every row's x and y, to the bit
          const Vec3 p_W = X_WN * Vec3(x.x(), x.y(), height / area);
          const Vec3 v_rel = PointVelocity(V_N, p_W) - PointVelocity(V_F, p_W);
          fn(g, p_W, v_rel, area, run.rows, node_on_a);
        }
        i = static_cast<size_t>(run.begin) +
            static_cast<size_t>(run.pending ? 1 : run.rows) * run.count;
      }
    }
    for (; i < gaps.size(); ++i) one(gaps[i]);
  };
  pass(ws.gaps_a, ws.row_groups_a, *spec_.surface_a, *spec_.surface_b, V_WA, V_WB, ws.X_WA, true);
  pass(ws.gaps_b, ws.row_groups_b, *spec_.surface_b, *spec_.surface_a, V_WB, V_WA, ws.X_WB, false);
}

void ContactElement::CalcForces(const Vec6& V_WA, const Vec6& V_WB, ContactWorkspace& ws,
                                Vec6* f_A, Vec6* f_B, double* energy,
                                double* power_dissipated) const {
  CalcForces(V_WA, V_WB, ws, f_A, f_B, energy, power_dissipated, /*outputs=*/true);
}

void ContactElement::CalcForces(const Vec6& V_WA, const Vec6& V_WB, ContactWorkspace& ws, Vec6* f_A,
                                Vec6* f_B, double* energy, double* power_dissipated,
                                bool outputs) const {
  ws.outputs_pending = false;
  f_A->setZero();
  f_B->setZero();
  *energy = 0;
  *power_dissipated = 0;
  ws.normal_force = ws.friction_force = ws.max_penetration = 0;
  ws.contact_points = 0;
  // The force of a node acts on the node's body N, its reaction on the face's body; a shared
  // run's rows at once (ForEachContactPoint).
  ForEachContactPoint(V_WA, V_WB, ws, /*group_rows=*/true,
                      [&](const NodeGap& g, const Vec3& p_W, const Vec3& v_rel, double area,
                          int points, bool node_on_a) {
                        const double depth = -g.gap;
                        const NodeForce f = EvaluateContactLaw(spec_.law, depth, -v_rel.dot(g.n_W),
                                                               g.n_W, v_rel, area);
                        // The force on A; B's is its negative, made once below (the same
                        // sums negated term by term: IEEE rounding is symmetric).
                        const Vec6 wrench = ForceAtPoint(p_W, f.f_W);
                        if (node_on_a)
                          *f_A += wrench;
                        else
                          *f_A -= wrench;
                        *energy += f.energy;
                        *power_dissipated += f.power_dissipated;
                        ws.normal_force += f.normal;
                        ws.friction_force += f.friction;
                        ws.max_penetration = std::max(ws.max_penetration, depth);
                        ws.contact_points += points;
                      });
  *f_B = -*f_A;
  // The monitor reads the points when the workspace has its state (MakeWorkspace() makes it).
  if (outputs) MakeOutputs(V_WA, V_WB, *f_A, ws);
}

void ContactElement::MakeOutputs(const Vec6& V_WA, const Vec6& V_WB, const Vec6& f_A,
                                 const ContactWorkspace& ws) const {
  CompleteRows(ws);  // every point on its own
  const ContactMonitor* monitor = ws.monitor ? spec_.monitor.get() : nullptr;
  if (monitor) monitor->Start(ws.X_WA, ws.X_WB, *ws.monitor);
  ws.points.Clear();
  const Transform X_AW = ws.X_WA.Inverse();
  ForEachContactPoint(V_WA, V_WB, ws, /*group_rows=*/false,
                      [&](const NodeGap& g, const Vec3& /*p_W*/, const Vec3& v_rel, double area,
                          int /*points*/, bool node_on_a) {
                        const NodeForce f = EvaluateContactLaw(spec_.law, -g.gap, -v_rel.dot(g.n_W),
                                                               g.n_W, v_rel, area);
                        if (monitor)
                          monitor->Add(node_on_a ? g.p_W : g.q_W, g.n_W, f.stiffness, *ws.monitor);
                        if (spec_.record_points > 0)
                          ws.points.Add(X_AW * (node_on_a ? g.p_W : g.q_W), f.normal);
                      });
  if (monitor) monitor->Finish(f_A, *ws.monitor);
}

void ContactElement::MakePendingOutputs(const ContactWorkspace& ws) const {
  ws.outputs_pending = false;
  MakeOutputs(ws.V_WA, ws.V_WB, ws.f_A, ws);
}

void ContactElement::AddTangents(const Model& model, const Data& data,
                                 ExternalForceWorkspace& workspace, Eigen::Ref<Eigen::MatrixXd> K,
                                 Eigen::Ref<Eigen::MatrixXd> C) const {
  auto& ws = static_cast<ContactWorkspace&>(workspace);
  const BodyIndex a = spec_.body_a, b = spec_.body_b;
  const Mat3& R_WA = data.X_WB[a].R;
  const Mat3& R_WB = data.X_WB[b].R;
  ws.tangents.Clear();
  CompleteRows(ws);  // every point on its own (the lever arms differ along the rows)
  ForEachContactPoint(
      data.V_WB[a], data.V_WB[b], ws, /*group_rows=*/false,
      [&](const NodeGap& g, const Vec3& /*p_W*/, const Vec3& v_rel, double area, int /*points*/,
          bool node_on_a) {
        const NodeForceTangent t =
            EvaluateContactLawTangent(spec_.law, -g.gap, -v_rel.dot(g.n_W), g.n_W, v_rel, area);
        ws.tangents.AddPoint({.p_W = g.p_W, .node_on_a = node_on_a}, t, g.n_W, R_WA, R_WB);
      });
  ws.tangents.Scatter(model, data, a, b, K, C);
}

void ContactElement::Compute(const Model& /*model*/, double /*t*/, const Data& data,
                             ExternalForceWorkspace& workspace) const {
  auto& ws = static_cast<ContactWorkspace&>(workspace);
  const BodyIndex a = spec_.body_a, b = spec_.body_b;
  UpdateGaps(data.X_WB[a], data.X_WB[b], ws, /*defer_rows=*/true);
  // The monitor and the recorded points wait for GetOutputs() (ContactWorkspace).
  CalcForces(data.V_WB[a], data.V_WB[b], ws, &ws.f_A, &ws.f_B, &ws.energy, &ws.power_dissipated,
             /*outputs=*/false);
  ws.V_WA = data.V_WB[a];
  ws.V_WB = data.V_WB[b];
  ws.outputs_pending = ws.monitor || spec_.record_points > 0;
}

void ContactElement::WarmStart(const ExternalForceWorkspace& source,
                               ExternalForceWorkspace& target) const {
  if (spec_.gap_method != ContactGapMethod::kTracked) return;
  const auto& from = static_cast<const ContactWorkspace&>(source);
  auto& to = static_cast<ContactWorkspace&>(target);
  // The tracking state when target's next UpdateGaps() tracks (header; a source warmed itself
  // and not yet evaluated passes its own source on).
  to.warm_tracking = from.warm_tracking ? from.warm_tracking : &from.tracked;
  // The last gaps with their poses: an evaluation at those very poses (a row at the step's
  // accepted positions) keeps them as the source would (UpdateGaps), the lists an Update of the
  // tracking state gives there. Within the capacity reserved at construction.
  to.gaps_a.assign(from.gaps_a.begin(), from.gaps_a.end());
  to.gaps_b.assign(from.gaps_b.begin(), from.gaps_b.end());
  to.row_groups_a.assign(from.row_groups_a.begin(), from.row_groups_a.end());
  to.row_groups_b.assign(from.row_groups_b.begin(), from.row_groups_b.end());
  to.X_WA = from.X_WA;
  to.X_WB = from.X_WB;
  to.have_gaps = from.have_gaps;
}

void ContactElement::AddTo(const Model& /*model*/, const ExternalForceWorkspace& workspace,
                           Data& data) const {
  const auto& ws = static_cast<const ContactWorkspace&>(workspace);
  // The world takes no forces.
  if (spec_.body_a != kWorldBody) data.f_ext[spec_.body_a] += ws.f_A;
  if (spec_.body_b != kWorldBody) data.f_ext[spec_.body_b] += ws.f_B;
  data.potential_energy += ws.energy;
  data.power_dissipated += ws.power_dissipated;
}

void ContactElement::Apply(const Model& model, double t, Data& data,
                           ExternalForceWorkspace& workspace) const {
  Compute(model, t, data, workspace);
  AddTo(model, workspace, data);
}

void ContactElement::GetOutputs(const ExternalForceWorkspace& workspace, double* values) const {
  const auto& ws = static_cast<const ContactWorkspace&>(workspace);
  if (ws.outputs_pending) MakePendingOutputs(ws);
  values[0] = ws.normal_force;
  values[1] = ws.friction_force;
  values[2] = ws.contact_points;
  values[3] = ws.max_penetration;
  WriteContactOutputs(spec_.monitor.get(), ws.monitor.get(), ws.points, spec_.record_points,
                      values + 4);
}

std::vector<ElementHealthCheck> ContactElement::HealthChecks() const { return health_checks_; }

void ContactElement::GetHealthValues(const ExternalForceWorkspace& workspace, double* values) const {
  values[0] = values[1] = static_cast<const ContactWorkspace&>(workspace).max_penetration;
}

}  // namespace orrery::contact

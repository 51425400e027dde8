#include "contact/flexible_contact_element.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "contact/triangle_geometry.h"
#include "mbd/data.h"

namespace orrery::contact {
namespace {

// The slack of one side's search (contact_surface.h, flexible_contact_surface.h).
double SideSlack(const ContactSide& side) {
  return side.flexible ? side.flexible->spec().slack_m : side.rigid->slack_m();
}

}  // namespace

ContactSideBuffers::ContactSideBuffers(const ContactSide& side)
    : vertices(side.surface().vertices()),
      normals(side.surface().face_normals()),
      normal_stamp(side.surface().num_triangles(), -1),
      corner_normals(side.surface().num_corner_groups(), Vec3::Zero()),
      corner_stamp(side.surface().num_corner_groups(), -1),
      node_force(side.surface().num_vertices(), Vec3::Zero()) {
  const int nv = side.surface().num_vertices();
  const int nf = side.flexible ? side.flexible->nf() : 0;
  displacement = Eigen::VectorXd::Zero(3 * nv);
  modal_force = Eigen::VectorXd::Zero(nf);
  has_force.assign(nv, 0);
  forced.reserve(nv);
  const int np = side.surface().num_parts();
  part_deformation.assign(np, 0.0);
  part_current.assign(np, 0);
  if (side.flexible) {
    deformed = DeformedVertices(*side.flexible);
    rates = VertexRates(*side.flexible);
    q_f_previous = Eigen::VectorXd::Zero(nf);
    q_f_change = Eigen::VectorXd::Zero(nf);
  }
}

FlexibleContactWorkspace::FlexibleContactWorkspace(const ContactSide& a, const ContactSide& b,
                                                   const FlexibleContactSurface* modal_a,
                                                   const FlexibleContactSurface* modal_b, int nv,
                                                   const ContactMonitor* monitor)
    : tracked(a.surface(), b.surface()),
      search(a.surface(), b.surface()),
      scratch_a(a.surface()),
      scratch_b(b.surface()),
      side_a(a),
      side_b(b),
      tangents(modal_a, modal_b, nv),
      monitor(monitor ? monitor->MakeState() : nullptr),
      points(a.surface().num_vertices() + b.surface().num_vertices()) {
  point_laws.reserve(a.surface().num_vertices() + b.surface().num_vertices());
  pairs.reserve(search.suggested_capacity());
  node_faces_a.reserve(3 * pairs.capacity());
  node_faces_b.reserve(3 * pairs.capacity());
  gaps_a.reserve(a.surface().num_vertices());
  gaps_b.reserve(b.surface().num_vertices());
}

FlexibleContactElement::FlexibleContactElement(FlexibleContactElementSpec spec)
    : spec_(std::move(spec)) {
  const std::string what = "FlexibleContactElement '" + spec_.name + "': ";
  for (const ContactSide* s : {&spec_.a, &spec_.b})
    if (!s->rigid == !s->flexible)
      throw std::invalid_argument(what + "each side needs exactly one of a rigid or a flexible "
                                         "surface");
  if (spec_.a.body == spec_.b.body)
    throw std::invalid_argument(what + "both sides are on the same body");
  if (spec_.record_points < 0)
    throw std::invalid_argument(what + "record_points must be >= 0, got " +
                                std::to_string(spec_.record_points));
  try {
    ValidateContactLaw(spec_.law);
    health_checks_ = PenetrationChecks(0.5 * (spec_.a.gap_margin_m() + spec_.b.gap_margin_m()),
                                       0.5 * (SideSlack(spec_.a) + SideSlack(spec_.b)), spec_.penetration_limit);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + e.what());
  }
  outputs_ = ContactOutputs({{.name = "normal_force", .unit = "N"},
                             {.name = "friction_force", .unit = "N"},
                             {.name = "contact_points", .unit = "1"},
                             {.name = "max_penetration", .unit = "m"},
                             {.name = "deformation_bound", .unit = "m"},
                             {.name = "inflation_exceeded", .unit = "1"}},
                            spec_.monitor.get(), spec_.record_points);
}

std::unique_ptr<ExternalForceWorkspace> FlexibleContactElement::MakeWorkspace(
    const Model& model) const {
  const std::string what = "FlexibleContactElement '" + spec_.name + "': ";
  for (const ContactSide* s : {&spec_.a, &spec_.b}) {
    if (s->body < 0 || s->body >= model.nbodies)
      throw std::invalid_argument(what + "body index " + std::to_string(s->body) +
                                  " is not in the model");
    if (!s->flexible) continue;
    const int fb = model.bodies[s->body].flexible;
    if (fb < 0)
      throw std::invalid_argument(what + "body " + std::to_string(s->body) +
                                  " has a flexible surface but is not a flexible body");
    const FlexibleBody& f = model.flexible_bodies[fb];
    if (f.modes.get() != &s->flexible->modes() && f.modes->nf != s->flexible->nf())
      throw std::invalid_argument(what + "the surface's modes are not those of body " +
                                  std::to_string(s->body));
  }
  // The tangents' modal rows: the flexible sides whose bodies have modal coordinates.
  auto modal = [&](const ContactSide& s) -> const FlexibleContactSurface* {
    if (!s.flexible) return nullptr;
    return model.flexible_bodies[model.bodies[s.body].flexible].nf > 0 ? s.flexible.get() : nullptr;
  };
  return std::make_unique<FlexibleContactWorkspace>(spec_.a, spec_.b, modal(spec_.a),
                                                    modal(spec_.b), model.nv,
                                                    spec_.monitor.get());
}

template <class Fn>
void FlexibleContactElement::ForEachContactPoint(const ContactSideState& a,
                                                 const ContactSideState& b,
                                                 FlexibleContactWorkspace& ws,
                                                 Fn&& fn) const {
  // Velocity (world) of a vertex's deformation rate, R Phi_P q_f-dot: each vertex's made once
  // in this call (deformed_vertices.h VertexRates), zero on a rigid side or without rates.
  const bool rates_a = spec_.a.flexible && ws.side_a.q_f_dot;
  const bool rates_b = spec_.b.flexible && ws.side_b.q_f_dot;
  if (rates_a) ws.side_a.rates.Begin(ws.side_a.q_f_dot, a.X_WB.R);
  if (rates_b) ws.side_b.rates.Begin(ws.side_b.q_f_dot, b.X_WB.R);
  auto vertex_rate = [](bool has_rates, ContactSideBuffers& buf, int i) {
    return has_rates ? buf.rates[i] : Vec3(Vec3::Zero());
  };
  // One pass: nodes of side N against faces of side F.
  auto pass = [&](const std::vector<NodeGap>& gaps, const ContactSide& node_side,
                  const ContactSide& face_side, const ContactSideState& N,
                  const ContactSideState& F, ContactSideBuffers& bn, ContactSideBuffers& bf,
                  bool node_rates, bool face_rates, bool node_on_a) {
    const ContactSurface& node_surface = node_side.surface();
    const auto& face_tris = face_side.surface().triangles();
    const Transform X_FW = F.X_WB.Inverse();
    const std::vector<Vec3>* kept_weights =
        spec_.gap_method == ContactGapMethod::kTracked && face_side.surface().smooth_normals()
            ? &(node_on_a ? ws.tracked.face_weights_a() : ws.tracked.face_weights_b())
            : nullptr;
    for (const NodeGap& g : gaps) {
      if (!(g.gap < 0) || !g.on_surface) continue;
      ContactPoint c{.gap = &g, .node_on_a = node_on_a, .face_vertices = face_tris[g.face]};
      // Barycentric coordinates of the closest point on the deformed face: with tracked gaps on
      // smoothed normals, those its force normal was made with (tracked_gaps.h face_weights_a).
      const auto& tri = c.face_vertices;
      c.face_weights = kept_weights ? (*kept_weights)[g.node]
                                    : Barycentric(X_FW * g.q_W, bf.vertices[tri[0]],
                                                  bf.vertices[tri[1]], bf.vertices[tri[2]]);
      Vec3 v_face = PointVelocity(F.V_WB, g.p_W);
      for (int k = 0; k < 3; ++k) v_face += c.face_weights(k) * vertex_rate(face_rates, bf, tri[k]);
      c.v_rel = PointVelocity(N.V_WB, g.p_W) + vertex_rate(node_rates, bn, g.node) - v_face;
      c.area_weight = 0.5 * g.weight * node_surface.vertex_areas()[g.node] *
                      node_surface.vertex_stiffness_scale()[g.node] *
                      face_side.surface().face_stiffness_scale()[g.face];
      fn(c);
    }
  };
  pass(ws.gaps_a, spec_.a, spec_.b, a, b, ws.side_a, ws.side_b, rates_a, rates_b, true);
  pass(ws.gaps_b, spec_.b, spec_.a, b, a, ws.side_b, ws.side_a, rates_b, rates_a, false);
}

void FlexibleContactElement::Evaluate(const ContactSideState& a, const ContactSideState& b,
                                      FlexibleContactWorkspace& ws, bool outputs) const {
  ws.outputs_pending = false;
  ws.X_WA = a.X_WB;
  ws.X_WB = b.X_WB;
  // Deformation bounds, deformed vertices and normals of the flexible sides.
  auto deform = [&](const ContactSide& side, const ContactSideState& st, ContactSideBuffers& buf) {
    buf.deformation_bound = 0;
    buf.deformation_change = 0;
    if (!side.flexible || !st.q_f || st.q_f->size() == 0) return;
    const FlexibleContactSurface& fs = *side.flexible;
    buf.deformation_bound = fs.DeformationBound(*st.q_f);
    if (buf.deformation_bound > fs.spec().deformation_allowance_m) ++ws.inflation_exceeded;
    buf.q_f = st.q_f;
    buf.q_f_dot = st.q_f_dot;
  };
  for (ContactSideBuffers* buf : {&ws.side_a, &ws.side_b}) buf->q_f = buf->q_f_dot = nullptr;
  deform(spec_.a, a, ws.side_a);
  deform(spec_.b, b, ws.side_b);
  const bool tracked = spec_.gap_method == ContactGapMethod::kTracked;
  const double d = 0.5 * (spec_.a.gap_margin_m() + spec_.b.gap_margin_m());
  if (tracked) {
    // Each flexible side's per-part displacement bound (flexible_contact_surface.h), for the
    // parts' boxes of the tracked pairs and the hierarchies' allowance.
    for (const auto& [side, buf] : {std::pair{&spec_.a, &ws.side_a}, std::pair{&spec_.b, &ws.side_b}}) {
      if (!side->flexible || !buf->q_f) continue;
      side->flexible->PartDeformationBounds(*buf->q_f, &buf->part_deformation);
    }
    const TrackedGaps::DeformedParts deformed{
        .a = ws.side_a.q_f ? &ws.side_a.part_deformation : nullptr,
        .b = ws.side_b.q_f ? &ws.side_b.part_deformation : nullptr,
        .gap_distance_m = d};
    ws.tracked.TrackPairs(a.X_WB, b.X_WB, /*part_boxes=*/true, &deformed);
  }
  // Deformed vertices and normals: those the tracked gaps read, made on first read, or of the
  // whole surface.
  for (const auto& [side, buf, parts] :
       {std::tuple{&spec_.a, &ws.side_a, &ws.tracked.tracked_parts_a()},
        std::tuple{&spec_.b, &ws.side_b, &ws.tracked.tracked_parts_b()}}) {
    if (!side->flexible || !buf->q_f) continue;
    if (tracked) {
      // Vertices made on first read (deformed_vertices.h), normals too (tracked_gaps.h).
      buf->deformed.Begin(buf->q_f, &buf->vertices);
      ++buf->normal_epoch;
      // Bounds from the modal coordinates, per tracked part (flexible_contact_surface.h): the
      // displacement (the hierarchies' boxes) and, for the parts tracked at the last evaluation
      // too, the change since then (a part new to the tracked set has its nodes and partners
      // started again). The change bound must hold for every vertex, made or not: the sleeping
      // nodes' odometers add it.
      const FlexibleContactSurface& fs = *side->flexible;
      buf->q_f_change = *buf->q_f - buf->q_f_previous;
      double change = 0;
      for (const int part : *parts) {
        if (buf->part_current[part])
          change = std::max(change, fs.PartDeformationBound(part, buf->q_f_change));
      }
      // A change that is not finite (a diverging Newton iterate now or before) is kept: the
      // tracked gaps then start every node again (tracked_gaps.h, RestartIfSaturated).
      if (!buf->q_f_change.allFinite()) change = std::numeric_limits<double>::infinity();
      buf->q_f_previous = *buf->q_f;
      std::fill(buf->part_current.begin(), buf->part_current.end(), 0);
      for (const int part : *parts) buf->part_current[part] = 1;
      buf->deformation_change = change;
    } else
      side->flexible->Deform(*buf->q_f, &buf->displacement, &buf->vertices, &buf->normals);
  }
  const ContactSurface& sa = spec_.a.surface();
  const ContactSurface& sb = spec_.b.surface();
  ws.searched = false;
  if (spec_.gap_method == ContactGapMethod::kTracked) {
    // Deformed gaps both ways, tracked node by node (tracked_gaps.h).
    // A rigid side as its surface holds it (its own vertices and normals, no part bounds: the
    // buffers hold the same numbers), so that the tracked gaps see it rigid (tracked_gaps.h,
    // node columns).
    auto side = [](const ContactSurface& surface, ContactSideBuffers& buf) {
      const bool lazy = buf.q_f != nullptr;  // deformed: normals made on first read
      return TrackedGaps::TrackedSide{.vertices = lazy ? &buf.vertices : &surface.vertices(),
                                      .normals = lazy ? &buf.normals : &surface.face_normals(),
                                      .deformation_m = buf.deformation_bound,
                                      .deformation_change_m = buf.deformation_change,
                                      .part_deformation_m = lazy ? &buf.part_deformation : nullptr,
                                      .lazy_normals = lazy ? &buf.normals : nullptr,
                                      .normal_stamp = lazy ? &buf.normal_stamp : nullptr,
                                      .normal_epoch = buf.normal_epoch,
                                      .deformed_vertices = lazy ? &buf.deformed : nullptr,
                                      .lazy_corner_normals = lazy ? &buf.corner_normals : nullptr,
                                      .corner_stamp = lazy ? &buf.corner_stamp : nullptr};
    };
    ws.tracked.ComputeGaps(a.X_WB, b.X_WB, side(sa, ws.side_a), side(sb, ws.side_b), d, &ws.gaps_a,
                           &ws.gaps_b);
  } else {
    // Candidates of the undeformed surfaces.
    ws.searched = ws.search.Find(a.X_WB, b.X_WB, &ws.pairs);
    if (ws.searched) {
      ListNodeFaceCandidates(sa, ws.pairs, /*nodes_are_a=*/true, &ws.scratch_a,
                             &ws.node_faces_a);
      ListNodeFaceCandidates(sb, ws.pairs, /*nodes_are_a=*/false, &ws.scratch_b,
                             &ws.node_faces_b);
    }
    // Deformed gaps both ways.
    ComputeNodeGapsFromCandidates(sa, ws.side_a.vertices, a.X_WB, sb, ws.side_b.vertices,
                                  ws.side_b.normals, b.X_WB, ws.node_faces_a, d, &ws.gaps_a);
    ComputeNodeGapsFromCandidates(sb, ws.side_b.vertices, b.X_WB, sa, ws.side_a.vertices,
                                  ws.side_a.normals, a.X_WB, ws.node_faces_b, d, &ws.gaps_b);
  }

  // Forces.
  for (ContactSideBuffers* buf : {&ws.side_a, &ws.side_b}) {
    buf->f_W.setZero();
    for (const int i : buf->forced) {
      buf->node_force[i].setZero();
      buf->has_force[i] = 0;
    }
    buf->forced.clear();
  }
  ws.energy = ws.power_dissipated = 0;
  ws.normal_force = ws.friction_force = ws.max_penetration = 0;
  ws.contact_points = 0;
  // The monitor reads the points when the workspace has its state (MakeWorkspace() makes it);
  // without outputs each point's law values are kept for it (MakePendingOutputs).
  const ContactMonitor* monitor = outputs && ws.monitor ? spec_.monitor.get() : nullptr;
  const bool record = outputs && spec_.record_points > 0;
  const bool keep_laws = !outputs && (ws.monitor || spec_.record_points > 0);
  if (monitor) monitor->Start(a.X_WB, b.X_WB, *ws.monitor);
  if (outputs) ws.points.Clear();
  ws.point_laws.clear();
  const Transform X_AW = a.X_WB.Inverse();
  // A vertex force (body frame), remembering the vertex for the modal forces and the reset.
  auto add_vertex_force = [](ContactSideBuffers& buf, int i, const Vec3& f_B) {
    if (!buf.has_force[i]) {
      buf.has_force[i] = 1;
      buf.forced.push_back(i);
    }
    buf.node_force[i] += f_B;
  };
  // The force of a node acts on the node's side N, its reaction on the face's side F.
  const bool flexible_a = spec_.a.flexible != nullptr, flexible_b = spec_.b.flexible != nullptr;
  ForEachContactPoint(a, b, ws, [&](const ContactPoint& c) {
    const NodeGap& g = *c.gap;
    const ContactSideState& N = c.node_on_a ? a : b;
    const ContactSideState& F = c.node_on_a ? b : a;
    ContactSideBuffers& bn = c.node_on_a ? ws.side_a : ws.side_b;
    ContactSideBuffers& bf = c.node_on_a ? ws.side_b : ws.side_a;
    const double depth = -g.gap;
    const NodeForce f =
        EvaluateContactLaw(spec_.law, depth, -c.v_rel.dot(g.n_W), g.n_W, c.v_rel, c.area_weight);
    // Spatial forces at the deformed node, and the vertex forces in the body frames of the
    // flexible sides (their modal forces below; a rigid side's vertices take none).
    const Vec6 wrench = ForceAtPoint(g.p_W, f.f_W);
    bn.f_W += wrench;
    bf.f_W -= wrench;
    if (c.node_on_a ? flexible_a : flexible_b)
      add_vertex_force(bn, g.node, N.X_WB.R.transpose() * f.f_W);
    if (c.node_on_a ? flexible_b : flexible_a) {
      const Vec3 f_F = F.X_WB.R.transpose() * f.f_W;
      for (int k = 0; k < 3; ++k)
        add_vertex_force(bf, c.face_vertices[k], -c.face_weights(k) * f_F);
    }
    ws.energy += f.energy;
    ws.power_dissipated += f.power_dissipated;
    ws.normal_force += f.normal;
    ws.friction_force += f.friction;
    ws.max_penetration = std::max(ws.max_penetration, depth);
    ++ws.contact_points;
    if (monitor) monitor->Add(c.node_on_a ? g.p_W : g.q_W, g.n_W, f.stiffness, *ws.monitor);
    if (record) ws.points.Add(X_AW * (c.node_on_a ? g.p_W : g.q_W), f.normal);
    if (keep_laws) ws.point_laws.push_back({.stiffness = f.stiffness, .normal = f.normal});
  });
  if (monitor) monitor->Finish(ws.side_a.f_W, *ws.monitor);
  ws.outputs_pending = keep_laws;
  // Modal forces Q = sum_P Phi_P^T F_P.
  for (const auto& [side, buf] : {std::pair{&spec_.a, &ws.side_a}, std::pair{&spec_.b, &ws.side_b}}) {
    if (!side->flexible) continue;
    buf->modal_force.setZero();
    for (const int i : buf->forced) side->flexible->AddVertexForce(i, buf->node_force[i], &buf->modal_force);
  }
}

void FlexibleContactElement::MakePendingOutputs(const FlexibleContactWorkspace& ws) const {
  ws.outputs_pending = false;
  // Evaluate()'s calls over the same points (ForEachContactPoint's order: the pressing nodes of
  // gaps_a, then of gaps_b) with the law values that evaluation kept.
  const ContactMonitor* monitor = ws.monitor ? spec_.monitor.get() : nullptr;
  if (monitor) monitor->Start(ws.X_WA, ws.X_WB, *ws.monitor);
  ws.points.Clear();
  const Transform X_AW = ws.X_WA.Inverse();
  size_t k = 0;
  for (const bool node_on_a : {true, false})
    for (const NodeGap& g : node_on_a ? ws.gaps_a : ws.gaps_b) {
      if (!(g.gap < 0) || !g.on_surface) continue;
      const FlexibleContactWorkspace::PointLaw& law = ws.point_laws[k++];
      if (monitor) monitor->Add(node_on_a ? g.p_W : g.q_W, g.n_W, law.stiffness, *ws.monitor);
      if (spec_.record_points > 0) ws.points.Add(X_AW * (node_on_a ? g.p_W : g.q_W), law.normal);
    }
  if (monitor) monitor->Finish(ws.side_a.f_W, *ws.monitor);
}

ContactSideState FlexibleContactElement::SideState(const Model& model, const Data& data,
                                                   const ContactSide& side) {
  ContactSideState s{.X_WB = data.X_WB[side.body], .V_WB = data.V_WB[side.body]};
  const int fb = model.bodies[side.body].flexible;
  if (side.flexible && fb >= 0 && model.flexible_bodies[fb].nf > 0) {
    s.q_f = &data.flex[fb].qf;
    s.q_f_dot = &data.flex[fb].qf_dot;
  }
  return s;
}

void FlexibleContactElement::Compute(const Model& model, double /*t*/, const Data& data,
                                     ExternalForceWorkspace& workspace) const {
  auto& ws = static_cast<FlexibleContactWorkspace&>(workspace);
  // The monitor and the recorded points wait for GetOutputs() (FlexibleContactWorkspace).
  Evaluate(SideState(model, data, spec_.a), SideState(model, data, spec_.b), ws,
           /*outputs=*/false);
}

void FlexibleContactElement::WarmStart(const ExternalForceWorkspace& source,
                                       ExternalForceWorkspace& target) const {
  if (spec_.gap_method != ContactGapMethod::kTracked) return;
  const auto& from = static_cast<const FlexibleContactWorkspace&>(source);
  auto& to = static_cast<FlexibleContactWorkspace&>(target);
  to.tracked.WarmStartFrom(from.tracked);
  // The modal coordinates and tracked parts the deformation change is measured from (same
  // sizes: copied into the existing storage).
  for (const auto& [f, t] : {std::pair{&from.side_a, &to.side_a}, std::pair{&from.side_b, &to.side_b}}) {
    t->q_f_previous = f->q_f_previous;
    std::copy(f->part_current.begin(), f->part_current.end(), t->part_current.begin());
  }
}

void FlexibleContactElement::AddTo(const Model& model, const ExternalForceWorkspace& workspace,
                                   Data& data) const {
  const auto& ws = static_cast<const FlexibleContactWorkspace&>(workspace);
  // Spatial forces on the bodies (the world takes none), modal forces on the modes of the
  // flexible sides that have modal coordinates (those Evaluate() deformed).
  auto scatter = [&](const ContactSide& side, const ContactSideBuffers& buf) {
    if (side.body == kWorldBody) return;
    data.f_ext[side.body] += buf.f_W;
    if (!buf.q_f) return;
    const FlexibleBody& f = model.flexible_bodies[model.bodies[side.body].flexible];
    data.tau_applied.segment(f.v_start, f.nf) += buf.modal_force;
  };
  scatter(spec_.a, ws.side_a);
  scatter(spec_.b, ws.side_b);
  data.potential_energy += ws.energy;
  data.power_dissipated += ws.power_dissipated;
}

void FlexibleContactElement::Apply(const Model& model, double t, Data& data,
                                   ExternalForceWorkspace& workspace) const {
  Compute(model, t, data, workspace);
  AddTo(model, workspace, data);
}

void FlexibleContactElement::AddTangents(const Model& model, const Data& data,
                                         ExternalForceWorkspace& workspace,
                                         Eigen::Ref<Eigen::MatrixXd> K,
                                         Eigen::Ref<Eigen::MatrixXd> C) const {
  auto& ws = static_cast<FlexibleContactWorkspace&>(workspace);
  const ContactSideState a = SideState(model, data, spec_.a), b = SideState(model, data, spec_.b);
  ws.tangents.Clear();
  ForEachContactPoint(a, b, ws, [&](const ContactPoint& c) {
    const NodeGap& g = *c.gap;
    const NodeForceTangent t = EvaluateContactLawTangent(spec_.law, -g.gap, -c.v_rel.dot(g.n_W),
                                                         g.n_W, c.v_rel, c.area_weight);
    ws.tangents.AddPoint({.p_W = g.p_W,
                          .node_on_a = c.node_on_a,
                          .node_vertex = g.node,
                          .face_vertices = c.face_vertices,
                          .face_weights = c.face_weights},
                         t, g.n_W, a.X_WB.R, b.X_WB.R);
  });
  ws.tangents.Scatter(model, data, spec_.a.body, spec_.b.body, K, C);
}

void FlexibleContactElement::GetOutputs(const ExternalForceWorkspace& workspace,
                                        double* values) const {
  const auto& ws = static_cast<const FlexibleContactWorkspace&>(workspace);
  if (ws.outputs_pending) MakePendingOutputs(ws);
  values[0] = ws.normal_force;
  values[1] = ws.friction_force;
  values[2] = ws.contact_points;
  values[3] = ws.max_penetration;
  values[4] = std::max(ws.side_a.deformation_bound, ws.side_b.deformation_bound);
  values[5] = static_cast<double>(ws.inflation_exceeded);
  WriteContactOutputs(spec_.monitor.get(), ws.monitor.get(), ws.points, spec_.record_points,
                      values + 6);
}

std::vector<ElementHealthCheck> FlexibleContactElement::HealthChecks() const { return health_checks_; }

void FlexibleContactElement::GetHealthValues(const ExternalForceWorkspace& workspace,
                                             double* values) const {
  values[0] = values[1] = static_cast<const FlexibleContactWorkspace&>(workspace).max_penetration;
}

}  // namespace orrery::contact

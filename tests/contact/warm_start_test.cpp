// Warm starts of the contacts' tracked gaps (ExternalForceElement::WarmStart, TrackedGaps::
// WarmStartFrom; mbd/force_elements.h WarmStartExternalWorkspaces): the result recorder copies
// the integrator's tracking state into its own workspaces before each row, so that its
// evaluation tracks from a step back instead of from the last row. The oracle: the same
// evaluation in a workspace that was not warmed (a cold one, tracking from the last row as the
// recorder did before), compared to the last bit; and the candidate-pair path (the flexible
// block). The warm evaluations must also do less work (fewer nodes evaluated), or the copy
// copied nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "contact/contact_element.h"
#include "contact/flexible_contact_element.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/box_mesher.h"
#include "flex/flexible_body_modes.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/force_elements.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "models/gear_contact.h"
#include "tests/contact/two_mesh_model.h"

namespace orrery::contact {
namespace {

bool BitEqual(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  return x.size() == y.size() &&
         std::memcmp(x.data(), y.data(), sizeof(double) * static_cast<size_t>(x.size())) == 0;
}

// Everything an evaluation hands to the recorder: generalized forces, body forces, energies and
// every element's outputs, bit for bit.
void ExpectSameEvaluation(const Model& m, const Data& warm, const Data& cold, int row) {
  ASSERT_TRUE(BitEqual(warm.tau_id, cold.tau_id)) << "row " << row;
  for (int b = 0; b < m.nbodies; ++b) ASSERT_TRUE(warm.f_ext[b] == cold.f_ext[b]) << "row " << row;
  ASSERT_EQ(warm.potential_energy, cold.potential_energy) << "row " << row;
  ASSERT_EQ(warm.power_dissipated, cold.power_dissipated) << "row " << row;
  for (size_t e = 0; e < m.external_forces.size(); ++e) {
    const ExternalForceElement& element = *m.external_forces[e];
    const int n = OutputValueCount(element.outputs());
    Eigen::VectorXd w(n), c(n);
    element.GetOutputs(*warm.external[e], w.data());
    element.GetOutputs(*cold.external[e], c.data());
    ASSERT_TRUE(BitEqual(w, c)) << "row " << row << ", element " << element.name();
  }
}

using test_scenes::TwoMeshModel;

// TwoMeshModel's gears turned by `turn` (pinion radians), the pinion pressed ahead at its pitch
// radius (13.5 mm) by 3 +- 2 um, varying with k, all turning at 20 rad/s of the pinion.
void PressedPose(double turn, int k, State& s) {
  s.q(0) = turn + (3e-6 + 2e-6 * std::sin(0.05 * k)) / 0.0135;
  s.q(1) = s.q(2) = -turn * 18.0 / 34.0;
  s.v << 20, -20 * 18.0 / 34.0, -20 * 18.0 / 34.0;
}

long NodeEvaluations(const Data& d, size_t e) {
  return static_cast<const ContactWorkspace&>(*d.external[e]).tracked.stats().node_evaluations;
}

// Whether both meshes of an evaluation carried load.
bool BothPressed(const Data& d) {
  return static_cast<const ContactWorkspace&>(*d.external[0]).contact_points > 0 &&
         static_cast<const ContactWorkspace&>(*d.external[1]).contact_points > 0;
}

// The gears rolled by `steps` small steps (PressedPose, 2 mrad of the pinion apart), each
// evaluated in `stepping` (an integrator's evaluations); every 10th is followed by `row(k, s)`
// at its state.
template <class Row>
void RollWithRows(const Model& m, int steps, Data& stepping, Row&& row) {
  State s = State::Initial(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  for (int k = 0; k <= steps; ++k) {
    PressedPose(2e-3 * k, k, s);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, stepping);
    if (k % 10 == 0) row(k, s);
  }
}

// The gears roll through two and a half pinion pitches in 400 small steps (an integrator's
// evaluations in `stepping`), the pinion pressed a little ahead (a few micrometres at the
// flanks, varying) so that teeth come in and out of contact on both meshes. Every 10th state is
// a row: `warm` is warmed from `stepping` and evaluated there, `cold` just evaluated there.
TEST(WarmStart, RigidGearRowsEqualColdRows) {
  const std::shared_ptr<const Model> model = TwoMeshModel();
  const Model& m = *model;
  Data stepping(m), warm(m), cold(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  int pressed = 0;
  RollWithRows(m, 400, stepping, [&](int k, State& s) {
    // The row, a step after the integrator's evaluation of a slightly different state.
    s.q(0) += 1e-4;
    s.q(1) -= 0.5e-4;
    WarmStartExternalWorkspaces(m, stepping, warm);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, warm);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, cold);
    ExpectSameEvaluation(m, warm, cold, k / 10);
    pressed += BothPressed(cold);
  });
  // Both meshes carried load at most rows (the comparison is not of zeros), and the warm rows
  // evaluated fewer nodes than the cold ones (they started from the step before).
  EXPECT_GT(pressed, 30);
  for (size_t e = 0; e < 2; ++e) {
    EXPECT_LT(NodeEvaluations(warm, e), NodeEvaluations(cold, e));
    std::printf("mesh %zu: node evaluations of 41 rows: warm %ld, cold %ld\n", e + 1,
                NodeEvaluations(warm, e), NodeEvaluations(cold, e));
  }
}

// What a tracked gap does at an evaluation follows from its state alone, so a workspace warmed
// from another and evaluated at the same poses does the same work: the same node evaluations,
// searches, walk steps, skipped walks and looks along a profile. A field that WarmStartFrom leaves
// out (the walk margins and what they were measured at, the stamps, the odometers) shows as
// different work, even where the gaps come out the same. The gears turn by small steps (a few
// micrometres at the flanks) so that walks are skipped. The warmed workspace is evaluated
// before its source moves on (the warm start's contract: it copies the tracking state then).
TEST(WarmStart, WarmedWorkspaceWorksLikeItsSource) {
  const std::shared_ptr<const Model> model = TwoMeshModel();
  const Model& m = *model;
  Data stepping(m), warm(m);
  State s = State::Initial(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  auto stats = [](const Data& d, size_t e) {
    return static_cast<const ContactWorkspace&>(*d.external[e]).tracked.stats();
  };
  long skipped = 0, looks = 0;
  for (int k = 0; k <= 600; ++k) {
    PressedPose(2e-4 * k, k, s);
    const bool row = k % 10 == 5;
    if (!row) {
      EvaluateDynamics(m, 0.0, s.q, s.v, vdot, stepping);
      continue;
    }
    WarmStartExternalWorkspaces(m, stepping, warm);
    TrackedGapStats source_before[2], warm_before[2];
    for (size_t e = 0; e < 2; ++e)
      source_before[e] = stats(stepping, e), warm_before[e] = stats(warm, e);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, warm);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, stepping);
    ExpectSameEvaluation(m, warm, stepping, k);
    for (size_t e = 0; e < 2; ++e) {
      const TrackedGapStats a = stats(stepping, e), b = stats(warm, e);
      EXPECT_EQ(a.node_evaluations - source_before[e].node_evaluations,
                b.node_evaluations - warm_before[e].node_evaluations) << "step " << k << ", mesh " << e;
      EXPECT_EQ(a.seeds - source_before[e].seeds, b.seeds - warm_before[e].seeds) << "step " << k;
      EXPECT_EQ(a.walk_steps - source_before[e].walk_steps, b.walk_steps - warm_before[e].walk_steps)
          << "step " << k;
      EXPECT_EQ(a.walks_skipped - source_before[e].walks_skipped,
                b.walks_skipped - warm_before[e].walks_skipped) << "step " << k << ", mesh " << e;
      EXPECT_EQ(a.profile_looks - source_before[e].profile_looks,
                b.profile_looks - warm_before[e].profile_looks)
          << "step " << k << ", mesh " << e;
      skipped += b.walks_skipped - warm_before[e].walks_skipped;
      looks += b.profile_looks - warm_before[e].profile_looks;
    }
  }
  // The comparison is not of zeros: the rows' nodes (the spur teeth's evaluated rows) were
  // looked at along the partner's profile, and skipped walks by the column margins the source
  // recorded.
  std::printf("walks skipped in the warmed rows: %ld, looks along the profile: %ld\n", skipped,
              looks);
  EXPECT_GT(skipped, 0);
  EXPECT_GT(looks, 0);
}

// A row at the positions of the integrator's last evaluation (with constraints the velocity
// projection changes only the velocities): the warmed workspace takes the source's gaps with
// their poses and computes none (no node evaluated), and its forces at the row's velocities
// equal a cold workspace's to the bit. Fails when WarmStart leaves the gaps or their poses out
// (the warm row then evaluates nodes). Such a row takes none of the source's tracking state
// (ContactWorkspace::warm_tracking): the warmed workspace then tracks on from its own older
// state, which must give the gaps of a cold workspace too (evaluated a little further on,
// without a warm start).
TEST(WarmStart, RowAtTheSourcesPositionsComputesNoGaps) {
  const std::shared_ptr<const Model> model = TwoMeshModel();
  const Model& m = *model;
  Data stepping(m), warm(m), cold(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  int pressed = 0;
  RollWithRows(m, 200, stepping, [&](int k, State& s) {
    s.v *= 1 + 1e-9;  // the row's velocities, projected
    WarmStartExternalWorkspaces(m, stepping, warm);
    long before[2];
    for (size_t e = 0; e < 2; ++e) before[e] = NodeEvaluations(warm, e);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, warm);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, cold);
    ExpectSameEvaluation(m, warm, cold, k / 10);
    for (size_t e = 0; e < 2; ++e) {
      const auto& ws = static_cast<const ContactWorkspace&>(*warm.external[e]);
      EXPECT_FALSE(ws.gaps_recomputed) << "row " << k / 10 << ", mesh " << e;
      EXPECT_EQ(NodeEvaluations(warm, e), before[e]) << "row " << k / 10 << ", mesh " << e;
      EXPECT_EQ(ws.warm_tracking, nullptr) << "row " << k / 10 << ", mesh " << e;
    }
    pressed += BothPressed(cold);
    // On from the workspace's own tracking state (the rows before took none of the source's).
    State on = s;
    on.q(0) += 1e-4;
    on.q(1) -= 0.5e-4;
    EvaluateDynamics(m, 0.0, on.q, on.v, vdot, warm);
    EvaluateDynamics(m, 0.0, on.q, on.v, vdot, cold);
    ExpectSameEvaluation(m, warm, cold, k / 10);
    for (size_t e = 0; e < 2; ++e)
      EXPECT_TRUE(static_cast<const ContactWorkspace&>(*warm.external[e]).gaps_recomputed);
  });
  EXPECT_GT(pressed, 15);
}

// A flexible block (hex8, 6 modes) over a rigid plane, sliding across it while its modes press
// its bottom face into the plane and release it: rows of a warmed workspace equal the rows of a
// cold one to the last bit (tracked gaps, lazy vertices and normals, the deformation-change
// bound from the copied modal coordinates), and the candidate-pair path's to its rounding.
TEST(WarmStart, FlexibleBlockRowsEqualColdRows) {
  flex::FeMesh mesh = flex::MakeBoxMesh({.origin_m = {-0.01, -0.01, 0}, .size_m = {0.02, 0.02, 0.01},
                                         .divisions = {4, 4, 2}, .type = flex::ElementType::kHex8});
  mesh.AssignMaterialToAll(
      {.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.0, .density_kg_m3 = 7850});
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "ZMAX", flex::InterfaceKind::kRbe2)};
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 6});
  auto modes = std::make_shared<const FlexibleBodyModes>(flex::MakeFlexibleBodyModes(mesh, sys, cb, ifs));
  auto surface = std::make_shared<const FlexibleContactSurface>(
      modes, FlexibleContactSurfaceSpec{.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6,
                                        .deformation_allowance_m = 60e-6});
  TriangleMesh plane;
  const int n = 9;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) plane.vertices.push_back(Vec3(-0.0225 + i * 5e-3, -0.0225 + j * 5e-3, 0));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      plane.triangles.push_back({v, v + 1, v + n + 2});
      plane.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  auto rigid = std::make_shared<const ContactSurface>(std::vector{plane}, 30e-6);
  auto element = [&](ContactGapMethod method) {
    return FlexibleContactElement({.name = "block_on_plane", .a = {.body = 1, .flexible = surface},
                                   .b = {.body = 0, .rigid = rigid},
                                   .law = {.stiffness_per_area = 2.1e13, .hunt_crossley_s_per_m = 0.4,
                                           .friction_coefficient = 0.2, .slip_velocity_m_s = 1e-2},
                                   .gap_method = method});
  };
  const FlexibleContactElement tracked = element(ContactGapMethod::kTracked);
  const FlexibleContactElement pairs = element(ContactGapMethod::kCandidatePairs);
  FlexibleContactWorkspace stepping(tracked.spec().a, tracked.spec().b);
  FlexibleContactWorkspace warm(tracked.spec().a, tracked.spec().b);
  FlexibleContactWorkspace cold(tracked.spec().a, tracked.spec().b);
  FlexibleContactWorkspace oracle(pairs.spec().a, pairs.spec().b);
  // A modal direction moving the bottom face down by 1 m per unit at its lowest vertex.
  const int nf = modes->nf;
  Eigen::VectorXd dir(nf);
  for (int k = 0; k < nf; ++k) dir(k) = std::sin(0.9 * k + 0.4);
  Eigen::VectorXd u(3 * surface->undeformed().num_vertices());
  std::vector<Vec3> xv(surface->undeformed().num_vertices());
  std::vector<Vec3> nv(surface->undeformed().num_triangles());
  surface->Deform(dir, &u, &xv, &nv);
  double down = 0;
  for (int v = 0; v < surface->undeformed().num_vertices(); ++v) down = std::min(down, u(3 * v + 2));
  ASSERT_LT(down, 0);
  dir /= -down;
  auto state = [&](int k, Eigen::VectorXd* q) {
    *q = (20e-6 + 12e-6 * std::sin(0.02 * k)) * dir;
    return Transform::Translation(Vec3(2e-6 * k, 1e-6 * k, 0.01 + 12e-6));
  };
  Eigen::VectorXd q(nf), q_row(nf);
  int pressed = 0;
  for (int k = 0; k <= 600; ++k) {
    const Transform X = state(k, &q);
    tracked.Evaluate({.X_WB = X, .q_f = &q}, {.X_WB = Transform()}, stepping);
    if (k % 20 != 0) continue;
    const Transform X_row = state(k + 1, &q_row);  // a step on
    tracked.WarmStart(stepping, warm);
    tracked.Evaluate({.X_WB = X_row, .q_f = &q_row}, {.X_WB = Transform()}, warm);
    tracked.Evaluate({.X_WB = X_row, .q_f = &q_row}, {.X_WB = Transform()}, cold);
    pairs.Evaluate({.X_WB = X_row, .q_f = &q_row}, {.X_WB = Transform()}, oracle);
    ASSERT_EQ(warm.contact_points, cold.contact_points) << k;
    ASSERT_EQ(warm.normal_force, cold.normal_force) << k;
    ASSERT_EQ(warm.friction_force, cold.friction_force) << k;
    ASSERT_EQ(warm.energy, cold.energy) << k;
    ASSERT_TRUE(BitEqual(warm.side_a.modal_force, cold.side_a.modal_force)) << k;
    ASSERT_TRUE(warm.side_a.f_W == cold.side_a.f_W) << k;
    EXPECT_EQ(warm.contact_points, oracle.contact_points) << k;
    EXPECT_NEAR(warm.normal_force, oracle.normal_force, 1e-9 * oracle.normal_force + 1e-12) << k;
    pressed += warm.contact_points > 0;
  }
  EXPECT_GT(pressed, 15);  // pressed at most of the 31 rows
  const long w = warm.tracked.stats().node_evaluations, c = cold.tracked.stats().node_evaluations;
  std::printf("flexible block: node evaluations of 31 rows: warm %ld, cold %ld\n", w, c);
  EXPECT_LT(w, c);
}

}  // namespace
}  // namespace orrery::contact

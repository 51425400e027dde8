// Contact evaluation allocates nothing once the workspace is sized (STYLE.md, "no allocation in
// a step"): the counting allocator of tests/common/counting_allocator.h (operator new and the
// malloc family), off unless a test turns it on.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <new>
#include <string>

#include "contact/flexible_contact_element.h"
#include "flex/box_mesher.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/flexible_body_modes.h"
#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/force_elements.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "models/gear_contact.h"

#include "tests/common/counting_allocator.h"
#include "tests/contact/two_mesh_model.h"

namespace orrery::contact {
namespace {

using namespace orrery::gears;  // gear surfaces as the workload

// Allocations of one call, with no warm-up call (the tests size their workspaces first).
template <class F>
long AllocationsIn(F&& f) {
  return test_support::AllocationsIn(f, 0);
}

TEST(ContactNoAllocation, CounterCountsVectorGrowth) {
  std::vector<int> v;
  EXPECT_GT(AllocationsIn([&] { v.assign(100, 1); }), 0);
}

// The iteration matrix's tangents at state s (differences without the contact elements, their
// analytic tangents) after one call has sized everything; the contact must press, with more
// than min_points points in element 0's tangents (Workspace: its workspace type).
template <class Workspace>
void ExpectTangentsWithoutAllocation(const Model& m, const State& s, int min_points) {
  DaeSystem dae(m);
  Eigen::MatrixXd K(m.nv, m.nv), C(m.nv, m.nv);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv), lambda;
  auto tangents = [&] { dae.Tangents(0.0, s.q, s.v, vdot, lambda, K, C); };
  tangents();
  EXPECT_EQ(AllocationsIn(tangents), 0);
  EXPECT_GT(K.norm(), 0);
  EXPECT_GT(static_cast<const Workspace&>(*dae.data().external[0]).tangents.points(), min_points);
}

// A 18/34 spur pair (seed 001's sun and planet) on revolute joints with gear contact: after one
// pass over the roll angles has sized the workspace's lists, a second pass (poses 0.1 nrad to
// 0.3 mrad apart: nodes walked and searched with tracked gaps, searches and kept pairs with
// candidate pairs) evaluates the dynamics without allocating.
// With threads > 1: the same contact twice (two elements), evaluated on that many threads
// (CalcExternalForces): after the first pass libgomp's team is made, and nothing is allocated.
void CheckGearContactEvaluation(ContactGapMethod method, int threads = 1) {
  ModelBuilder b;
  const test_scenes::SpurPair sp = test_scenes::AddSpurPair(b);
  const gears::GearPair& pair = sp.pair;
  const BodyIndex g1 = sp.pinion, g2 = sp.gear;
  const JointIndex ji1 = sp.pinion_joint;
  GearContactOptions o;
  o.involute_intervals = 16;
  o.face_intervals = 2;
  ContactElementSpec spec = MakeGearContactSpec("mesh", pair, g1, g2, o);
  spec.gap_method = method;
  b.AddExternalForce(std::make_shared<ContactElement>(spec));
  if (threads > 1) {
    spec.name = "mesh_twin";
    b.AddExternalForce(std::make_shared<ContactElement>(spec));
  }
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  const Model& m = *model;
  Data data(m);
  data.threads = threads;
  State s = State::Initial(m);
  s.v.setConstant(1.0);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  const int iq1 = m.joints[ji1].q_start;
  // Gear 1 ahead by 2 um along the line of action (flanks pressed), turned over half a mesh
  // period in steps that alternate between tiny (within the slack) and large (a search).
  auto pass = [&] {
    for (int k = 0; k < 60; ++k) {
      const double theta1 = 0.01 * (k / 2) + (k % 2) * 1e-10;
      s.q(iq1) = theta1 + 2e-6 / pair.gear1().base_radius_m();
      s.q(iq1 + 1) = -theta1 * 18.0 / 34.0;
      EvaluateDynamics(m, 0.0, s.q, s.v, vdot, data);
    }
  };
  pass();
  const auto& ws = static_cast<const ContactWorkspace&>(*data.external[0]);
  const long seeds = ws.tracked.stats().seeds, walks = ws.tracked.stats().walk_steps;
  const long searches = ws.search.stats().searches;
  EXPECT_EQ(AllocationsIn(pass), 0);
  // The result recorder's row: its Data warmed from this one (ExternalForceElement::WarmStart),
  // then evaluated a little further on, without allocating once sized.
  Data row(m);
  std::vector<double> outputs(OutputValueCount(m.external_forces[0]->outputs()));
  auto record = [&] {
    WarmStartExternalWorkspaces(m, data, row);
    s.q(iq1) += 1e-7;
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, row);
    // The outputs (the monitor's made on this read: ContactWorkspace).
    m.external_forces[0]->GetOutputs(*row.external[0], outputs.data());
  };
  record();
  pass();
  EXPECT_EQ(AllocationsIn(record), 0);
  if (method == ContactGapMethod::kTracked) {
    // Nodes were searched in the hierarchies and walked, under load.
    EXPECT_GT(ws.tracked.stats().seeds - seeds, 25);
    EXPECT_GT(ws.tracked.stats().walk_steps - walks, 25);
  } else {
    // Both kinds of evaluation happened.
    EXPECT_GE(ws.search.stats().searches - searches, 25);
  }
  EXPECT_GT(ws.normal_force, 0);
  ExpectTangentsWithoutAllocation<ContactWorkspace>(m, s, 0);
}

// ContactTangents over more points than a block of its gathered columns (contact_tangents.h:
// blocks multiplied out while points are added, then the scatter), two rigid bodies on revolute
// joints and a third on its own: no allocation after construction.
TEST(ContactNoAllocation, ContactTangentsOverSeveralBlocks) {
  ModelBuilder b;
  BodyIndex body[3];
  for (int i = 0; i < 3; ++i) {
    body[i] =
        b.AddBody("b" + std::to_string(i), 1.0, Vec3(0.01 * i, 0, 0), Mat3::Identity() * 1e-3);
    JointSpec j;
    j.name = "j" + std::to_string(i), j.type = JointType::kRevolute, j.child = body[i];
    j.parent = i == 1 ? body[0] : kWorldBody;
    j.axis = Vec3(0.1 * i, 0.2, 1).normalized();
    b.AddJoint(j);
  }
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  const Model& m = *model;
  Data data(m);
  data.J_WB.assign(m.nbodies, Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, m.nv));
  const State s = State::Initial(m);
  CalcPositionKinematics(m, s.q, data);
  CalcBodyJacobians(m, data);
  ContactTangents t(nullptr, nullptr, m.nv);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(m.nv, m.nv), C = K;
  auto tangents = [&] {
    t.Clear();
    for (int i = 0; i < 3 * ContactTangents::kBlock + 5; ++i) {
      NodeForceTangent law{.k_n = 1e8,
                           .c_n = 1e3,
                           .a = Vec3(0.1, 0.2, 1),
                           .slip_damping = 1e4,
                           .slip_directions = i % 3};
      law.slip_direction[0] = Vec3::UnitX();
      law.slip_direction[1] = Vec3::UnitY();
      t.AddPoint({.p_W = Vec3(0.001 * i, 0.01, 0), .node_on_a = i % 2 == 0}, law, Vec3::UnitZ(),
                 Mat3::Identity(), Mat3::Identity());
    }
    t.Scatter(m, data, body[1], body[2], K, C);
  };
  tangents();
  EXPECT_EQ(AllocationsIn(tangents), 0);
  EXPECT_EQ(t.points(), 3 * ContactTangents::kBlock + 5);
  EXPECT_GT(K.norm(), 0);
}

TEST(ContactNoAllocation, GearContactEvaluationTracked) {
  CheckGearContactEvaluation(ContactGapMethod::kTracked);
}

TEST(ContactNoAllocation, GearContactEvaluationTrackedTwoThreads) {
  CheckGearContactEvaluation(ContactGapMethod::kTracked, 2);
}

TEST(ContactNoAllocation, GearContactEvaluationCandidatePairs) {
  CheckGearContactEvaluation(ContactGapMethod::kCandidatePairs);
}

// A reduced steel block (hex8 4 x 4 x 2, 12 modes) on a vertical prismatic joint pressed onto a
// rigid plane through a FlexibleContactElement: after a first pass has sized the lists, a second
// pass over heights and modal states evaluates the dynamics, contact tracked on the deformed
// surfaces and modal forces included, without allocating; so does the tangents' pass (both
// tests). The block's surface has smoothed normals: the plane's nodes on its deformed faces take
// the force normal of the deformed corners (signed_gap.h ForceNormal), each corner group's made
// once per evaluation into the side's corner cache (sized with the workspace, tracked_gaps.h
// TrackedSide::lazy_corner_normals). The element records 4 points: the integrator's
// evaluations keep each point's law values, the recorder's row makes the points from them when
// its outputs are read (FlexibleContactWorkspace::point_laws).
TEST(ContactNoAllocation, FlexibleContactEvaluation) {
  flex::FeMesh mesh = flex::MakeBoxMesh({.origin_m = {-0.01, -0.01, 0}, .size_m = {0.02, 0.02, 0.01},
                                         .divisions = {4, 4, 2}, .type = flex::ElementType::kHex8});
  mesh.AssignMaterialToAll(
      {.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "ZMAX", flex::InterfaceKind::kRbe2)};
  const auto modes = std::make_shared<const FlexibleBodyModes>(flex::MakeFlexibleBodyModes(
      mesh, sys, flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 12}), ifs));
  TriangleMesh plane;
  plane.vertices = {Vec3(-0.03, -0.03, 0), Vec3(0.03, -0.03, 0), Vec3(0.03, 0.03, 0), Vec3(-0.03, 0.03, 0)};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  ModelBuilder b;
  const BodyIndex block = b.AddFlexibleBody("block", modes, {.damping_ratios = {0.02}});
  JointSpec j;
  j.name = "slider", j.type = JointType::kPrismatic, j.parent = kWorldBody, j.child = block;
  const JointIndex ji = b.AddJoint(j);
  b.AddExternalForce(std::make_shared<FlexibleContactElement>(FlexibleContactElementSpec{
      .name = "block_on_plane",
      .a = {.body = block,
            .flexible = std::make_shared<const FlexibleContactSurface>(
                modes,
                FlexibleContactSurfaceSpec{
                    .node_sets = {"ZMIN"}, .slack_m = 2e-6, .smooth_normals = true})},
      .b = {.body = kWorldBody,
            .rigid = std::make_shared<const ContactSurface>(std::vector{plane}, 30e-6)},
      .law = {.stiffness_per_area = 2e13,
              .hunt_crossley_s_per_m = 0.1,
              .friction_coefficient = 0.2},
      .record_points = 4}));
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  const Model& m = *model;
  Data data(m);
  State s = State::Initial(m);
  s.v.setConstant(1e-3);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  const int iq = m.joints[ji].q_start;
  const FlexibleBody& fb = m.flexible_bodies[0];
  auto pass = [&] {
    for (int k = 0; k < 40; ++k) {
      s.q(iq) = 0.01 - 1e-6 * (1 + k % 5) - 5e-6 * (k / 10);  // 5 um jumps: a new search
      for (int i = 0; i < fb.nf; ++i) s.q(fb.q_start + i) = 1e-9 * std::sin(0.3 * k + i);
      EvaluateDynamics(m, 0.0, s.q, s.v, vdot, data);
    }
  };
  pass();
  const auto& ws = static_cast<const FlexibleContactWorkspace&>(*data.external[0]);
  const long evaluations = ws.tracked.stats().node_evaluations;
  EXPECT_EQ(AllocationsIn(pass), 0);
  EXPECT_GT(ws.tracked.stats().node_evaluations - evaluations, 40);
  // The result recorder's row (as in the gear test above), with its outputs (the recorded
  // points made on this read: FlexibleContactWorkspace).
  Data row(m);
  std::vector<double> outputs(OutputValueCount(m.external_forces[0]->outputs()));
  auto record = [&] {
    WarmStartExternalWorkspaces(m, data, row);
    s.q(iq) -= 1e-8;
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, row);
    m.external_forces[0]->GetOutputs(*row.external[0], outputs.data());
  };
  record();
  pass();
  EXPECT_EQ(AllocationsIn(record), 0);
  EXPECT_GT(ws.normal_force, 0);
  EXPECT_GT(ws.side_a.modal_force.norm(), 0);
  ExpectTangentsWithoutAllocation<FlexibleContactWorkspace>(m, s, 0);
}

}  // namespace
}  // namespace orrery::contact

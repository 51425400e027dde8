// Contact with a flexible (Craig-Bampton-reduced) surface (contact/flexible_contact_element.cpp,
// contact/flexible_contact_surface.cpp). A steel block 20 x 20 x 10 mm (hex8, 4 x 4 x 2, Poisson
// ratio 0 so that a uniform pressure gives a uniform uniaxial strain), held by an RBE2 spider on
// its top face (the body frame B on the master), pressed by delta0 onto a rigid plane z = 0
// (45 x 45 mm, 9 x 9 cells of 5 mm offset by half a cell from the block's nodes, so that the
// plane nodes under the block carry exactly the block's area). Oracles:
//   - closed form: penalty k_A A in series with the bar E A / L, F = delta0 / (1/(k_A A) + L/(E A));
//   - the full FE static solution (every DOF, flex/geometric_stiffness.h
//     SolveStaticsHeldAtInterface) under the contact's own vertex forces, against Phi q_f;
//   - virtual work: the modal forces and the spatial force are minus the gradient of the contact
//     energy (central differences in q_f and in the body's height).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "contact/deformed_vertices.h"
#include "contact/flexible_contact_element.h"
#include "flex/box_mesher.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/flexible_body_modes.h"
#include "flex/geometric_stiffness.h"
#include "mbd/dae.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery::contact {
namespace {

constexpr double kE = 210e9, kA = 4e-4, kL = 0.01;

struct Block {
  flex::FeMesh mesh;
  flex::FeSystem sys;
  std::vector<flex::FeInterface> ifs;
  std::shared_ptr<const FlexibleBodyModes> modes;
};

Block MakeBlock(int num_modes) {
  Block b{.mesh = flex::MakeBoxMesh({.origin_m = {-0.01, -0.01, 0}, .size_m = {0.02, 0.02, kL},
                                     .divisions = {4, 4, 2}, .type = flex::ElementType::kHex8})};
  b.mesh.AssignMaterialToAll(
      {.name = "STEEL", .youngs_modulus_pa = kE, .poissons_ratio = 0.0, .density_kg_m3 = 7850});
  b.sys = flex::AssembleFeSystem(b.mesh);
  b.ifs = {flex::MakeInterface(b.mesh, "ZMAX", flex::InterfaceKind::kRbe2)};
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(b.mesh, b.sys, b.ifs, {.num_modes = num_modes});
  b.modes = std::make_shared<const FlexibleBodyModes>(flex::MakeFlexibleBodyModes(b.mesh, b.sys, cb, b.ifs));
  return b;
}

std::shared_ptr<const ContactSurface> Plane() {
  TriangleMesh m;
  const int n = 9;
  const double h = 5e-3, x0 = -0.0225;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back(Vec3(x0 + i * h, x0 + j * h, 0));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      m.triangles.push_back({v, v + 1, v + n + 2});
      m.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  return std::make_shared<const ContactSurface>(std::vector{m}, 30e-6);
}

// The block's bottom-face nodes only (its contact surface).
FlexibleContactElement MakeElement(const Block& b, double k_area) {
  auto block = std::make_shared<const FlexibleContactSurface>(
      b.modes, FlexibleContactSurfaceSpec{.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6,
                                          .deformation_allowance_m = 20e-6});
  return FlexibleContactElement({.name = "block_on_plane", .a = {.body = 1, .flexible = block},
                                 .b = {.body = 0, .rigid = Plane()},
                                 .law = {.stiffness_per_area = k_area}});
}

// Static equilibrium K q = Q(q) of the block held at height z0 (B's origin), by Newton with a
// central-difference Jacobian of Q.
Eigen::VectorXd SolveStatics(const FlexibleContactElement& e, FlexibleContactWorkspace& ws,
                             const Eigen::MatrixXd& K, double z0) {
  const int nf = static_cast<int>(K.rows());
  Eigen::VectorXd q = Eigen::VectorXd::Zero(nf);
  auto Q = [&](const Eigen::VectorXd& x) {
    e.Evaluate({.X_WB = Transform::Translation(Vec3(0, 0, z0)), .q_f = &x},
               {.X_WB = Transform()}, ws);
    return Eigen::VectorXd(ws.side_a.modal_force);
  };
  for (int it = 0; it < 8; ++it) {
    const Eigen::VectorXd r = K * q - Q(q);
    Eigen::MatrixXd J = K;
    for (int k = 0; k < nf; ++k) {
      const double h = 1e-9 / std::max(1e-12, e.spec().a.flexible->mode_bounds()(k));
      Eigen::VectorXd qp = q, qm = q;
      qp(k) += h, qm(k) -= h;
      J.col(k) -= (Q(qp) - Q(qm)) / (2 * h);
    }
    q -= J.lu().solve(r);
  }
  Q(q);  // leave the workspace at the solution
  return q;
}

TEST(FlexibleContactElement, PressedBlockMatchesClosedFormAndFullFeStatics) {
  // 140 of the 150 interior DOFs as modes: the static response to a pressure on the free end
  // converges slowly in fixed-interface modes (measured |Phi q - u_FE| / |u_FE| at the bottom:
  // 30 modes 25 %, 60 modes 19 %, 100 modes 10 %, 140 modes 0.4 %; the contact force is 7 % high
  // with 30 or 60 modes), so the oracle comparison keeps almost all of them.
  const Block b = MakeBlock(140);
  const FlexibleBodyModes& m = *b.modes;
  const double k_struct = kE * kA / kL;            // 8.4e9 N/m
  const double k_area = k_struct / kA;             // penalty as stiff as the bar
  const FlexibleContactElement e = MakeElement(b, k_area);
  FlexibleContactWorkspace ws(e.spec().a, e.spec().b);
  const double delta0 = 2e-6;
  const Eigen::VectorXd q = SolveStatics(e, ws, m.stiffness, kL - delta0);
  // Equilibrium.
  EXPECT_LT((m.stiffness * q - ws.side_a.modal_force).norm(), 1e-9 * ws.side_a.modal_force.norm());
  // Total force against the springs in series. The closed form assumes a uniform pressure; the
  // lumped vertex weights (A/3 and A/6 at the corners of the split quadrilaterals) and the plane
  // nodes' point loads make it non-uniform at the element scale (measured: 0.7 % below).
  const double f_closed = delta0 / (1 / (k_area * kA) + 1 / k_struct);
  EXPECT_NEAR(ws.normal_force, f_closed, 0.02 * f_closed);
  EXPECT_NEAR(ws.side_a.f_W(5), ws.normal_force, 1e-9 * ws.normal_force);  // pushed up (+z)
  EXPECT_EQ(ws.inflation_exceeded, 0);
  // Full FE statics under the same vertex forces (B frame = world axes).
  const FlexibleContactSurface& fs = *e.spec().a.flexible;
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(3 * b.mesh.num_nodes(), 1);
  for (int i = 0; i < fs.undeformed().num_vertices(); ++i) {
    const int n = *b.mesh.FindNode(m.nodes[fs.vertex_node()[i]].id);
    F.block<3, 1>(3 * n, 0) += ws.side_a.node_force[i];
  }
  const Eigen::MatrixXd u = flex::SolveStaticsHeldAtInterface(b.mesh, b.sys, b.ifs, 0, F);
  double err = 0, ref = 0, mean = 0;
  for (int i = 0; i < fs.undeformed().num_vertices(); ++i) {
    const int n = *b.mesh.FindNode(m.nodes[fs.vertex_node()[i]].id);
    err = std::max(err, (fs.shapes().middleRows(3 * i, 3) * q - u.block<3, 1>(3 * n, 0)).norm());
    ref = std::max(ref, u.block<3, 1>(3 * n, 0).norm());
    mean += u(3 * n + 2, 0) / fs.undeformed().num_vertices();
  }

  std::printf("F %.6g N (closed form %.6g), bottom u_FE mean %.4g um, max %.4g um, "
              "|Phi q - u_FE| max %.3g um\n", ws.normal_force, f_closed, mean * 1e6, ref * 1e6,
              err * 1e6);
  // Mean compression of the bottom = F / (E A / L) for the uniaxial bar (same 2 % as above).
  EXPECT_NEAR(mean, ws.normal_force / k_struct, 0.02 * ws.normal_force / k_struct);
  EXPECT_LT(err, 0.01 * ref);
}

TEST(FlexibleContactElement, ModalForcesAreMinusTheEnergyGradient) {
  const Block b = MakeBlock(12);
  const FlexibleContactElement e = MakeElement(b, 2.1e13);
  FlexibleContactWorkspace ws(e.spec().a, e.spec().b);
  const int nf = b.modes->nf;
  // A deformed, tilted state with every bottom node in contact, no node on a face's rim.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(nf);
  for (int k = 0; k < nf; ++k) q(k) = 0.3e-6 / e.spec().a.flexible->mode_bounds()(k) * std::sin(1.7 * k + 0.3);
  auto energy = [&](const Eigen::VectorXd& x, double z) {
    const Transform X(AxisAngle(Vec3(1, 2, 0).normalized(), 2e-5), Vec3(0.4e-3, -0.2e-3, z));
    e.Evaluate({.X_WB = X, .q_f = &x}, {.X_WB = Transform()}, ws);
    return ws.energy;
  };
  const double z0 = kL - 3e-6;
  energy(q, z0);
  const Eigen::VectorXd Q = ws.side_a.modal_force;
  const double fz = ws.side_a.f_W(5);
  ASSERT_GT(ws.contact_points, 20);
  // Rounding in the energy differences scales with the largest modal force, not with each one.
  const double scale = Q.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  for (int k = 0; k < nf; ++k) {
    // Central differences at h and h/2, Richardson-extrapolated (error O(h^4)).
    auto diff = [&](double h) {
      Eigen::VectorXd qp = q, qm = q;
      qp(k) += h, qm(k) -= h;
      return (energy(qp, z0) - energy(qm, z0)) / (2 * h);
    };
    const double h = 0.1 * 0.3e-6 / e.spec().a.flexible->mode_bounds()(k);
    const double dU = (4 * diff(h / 2) - diff(h)) / 3;
    EXPECT_NEAR(Q(k), -dU, 1e-7 * scale) << "mode " << k;
  }
  const double h = 1e-10;
  EXPECT_NEAR(fz, -(energy(q, z0 + h) - energy(q, z0 - h)) / (2 * h), 1e-5 * std::abs(fz));
}

// The element's analytic tangents (contact_tangents.h) through DaeSystem::Tangents against
// forward differences of the whole pipeline through it, for the block on a free joint with its
// 12 modal coordinates: deformed, tilted, sliding (sticking friction) and approaching. Left
// out by the tangents: the turning of the forces' directions and points of action with the
// block and with its deformation, terms of the order of the force F = k delta times the
// half-width L against the rotational stiffness k L^2 / 3, so a relative 3 delta / L.
TEST(FlexibleContactElement, TangentsMatchPipelineDifferences) {
  const Block b = MakeBlock(12);
  const int nf = b.modes->nf;
  auto block = std::make_shared<const FlexibleContactSurface>(
      b.modes, FlexibleContactSurfaceSpec{.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6,
                                          .deformation_allowance_m = 20e-6});
  const double tilt = 2e-5, delta = 3e-6;
  // The block with or without its contact (the tangents' common part: inertia, modal stiffness).
  auto make = [&](bool contact) {
    ModelBuilder mb;
    const BodyIndex body = mb.AddFlexibleBody("block", b.modes);
    const JointIndex free = mb.AddJoint({.name = "free", .type = JointType::kFree,
                                         .parent = kWorldBody, .child = body});
    const Vec3 axis = Vec3(1, 2, 0).normalized();
    Eigen::VectorXd q0(7), v0(6), qf(nf), vf(nf);
    q0 << 0.4e-3, -0.2e-3, kL - delta, std::cos(tilt / 2), std::sin(tilt / 2) * axis;
    v0 << 3e-4, 2e-4, -1e-3, 0.004, -0.002, 0.02;
    for (int k = 0; k < nf; ++k) {
      qf(k) = 0.3e-6 / block->mode_bounds()(k) * std::sin(1.7 * k + 0.3);
      vf(k) = 1e-3 / block->mode_bounds()(k) * std::cos(0.9 * k);
    }
    mb.SetJointPosition(free, q0);
    mb.SetJointVelocity(free, v0);
    mb.SetModalCoordinates(body, qf, vf);
    if (contact)
      mb.AddExternalForce(std::make_shared<FlexibleContactElement>(FlexibleContactElementSpec{
          .name = "block_on_plane", .a = {.body = body, .flexible = block},
          .b = {.body = kWorldBody, .rigid = Plane()},
          .law = {.stiffness_per_area = 2.1e13, .hunt_crossley_s_per_m = 0.4,
                  .friction_coefficient = 0.2, .slip_velocity_m_s = 1e-2}}));
    return std::shared_ptr<const Model>(std::move(mb).Finalize());
  };
  const std::shared_ptr<const Model> model = make(true), bare = make(false);
  const State s = State::Initial(*model);
  const int nv = model->nv;
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(nv), lambda;
  Eigen::MatrixXd K_an(nv, nv), C_an(nv, nv), K_fd(nv, nv), C_fd(nv, nv), K0(nv, nv), C0(nv, nv);
  DaeSystem dae(*model), dae0(*bare);
  dae0.Tangents(0, s.q, s.v, vdot, lambda, K0, C0);
  dae.Tangents(0, s.q, s.v, vdot, lambda, K_an, C_an);
  const auto& ws = static_cast<const FlexibleContactWorkspace&>(*dae.data().external[0]);
  ASSERT_GT(ws.contact_points, 20);
  EXPECT_GT(ws.friction_force, 0);
  dae.set_element_tangents(false);
  dae.Tangents(0, s.q, s.v, vdot, lambda, K_fd, C_fd);
  // The contact's shares, against the deepest penetration (centre, tilt, deformation).
  K_an -= K0, K_fd -= K0, C_an -= C0, C_fd -= C0;
  const double relative = 3 * (delta + 0.01 * tilt + 0.3e-6) / 0.01;
  EXPECT_LE((K_an - K_fd).norm(), relative * K_fd.norm()) << "K\n" << K_an << "\nfd\n" << K_fd;
  EXPECT_LE((C_an - C_fd).norm(), relative * C_fd.norm()) << "C\n" << C_an << "\nfd\n" << C_fd;
  std::printf("flexible block (%d modes): |K - K_fd| / |K_fd| = %.2e, |C - C_fd| / |C_fd| = %.2e "
              "(bound %.1e)\n", nf, (K_an - K_fd).norm() / K_fd.norm(),
              (C_an - C_fd).norm() / C_fd.norm(), relative);
}

// ContactTangents' gathered products and structured scatter (contact_tangents.h) against the
// formula written out densely: J_P (3 x m) from its definition (T_p rows + on the node's side,
// - on the face's; R Phi_node on a flexible node side, -sum_k w_k R Phi_k on a flexible face
// side), K_z = sum_P J_P^T K_P J_P with the law's dense 3 x 3 forms (NodeForceTangent::K, C),
// then L^T K_z L with L = [J_A; J_B; the modal selector] as a dense m x nv matrix. The bodies:
// a rigid hub on a revolute joint, the flexible block on a free joint on the hub (side B), a
// rigid body on its own prismatic joint (side A; its chain shares no coordinate with the
// block's), and a third body on the world whose column no Jacobian touches. 80 points (more
// than two blocks of columns) with every kind of law term, nodes on either side.
TEST(FlexibleContactElement, TangentsScatterEqualsDenseProducts) {
  const Block b = MakeBlock(6);
  const int nf = b.modes->nf;
  auto block = std::make_shared<const FlexibleContactSurface>(
      b.modes, FlexibleContactSurfaceSpec{
                   .node_sets = {"ZMIN"}, .gap_margin_m = 30e-6, .deformation_allowance_m = 20e-6});
  ModelBuilder mb;
  const BodyIndex other = mb.AddBody("other", 0.5, Vec3(0, 0, 0), Mat3::Identity() * 1e-3);
  mb.AddJoint({.name = "other",
               .type = JointType::kPrismatic,
               .parent = kWorldBody,
               .child = other,
               .axis = Vec3(1, 1, 0).normalized()});
  const BodyIndex side_a = mb.AddBody("rigid", 1.0, Vec3(0.01, 0, 0), Mat3::Identity() * 1e-3);
  const JointIndex slider = mb.AddJoint({.name = "slider",
                                         .type = JointType::kPrismatic,
                                         .parent = kWorldBody,
                                         .child = side_a,
                                         .axis = Vec3(0.3, -0.2, 1).normalized()});
  const BodyIndex hub = mb.AddBody("hub", 2.0, Vec3(0, 0.02, 0), Mat3::Identity() * 2e-3);
  const JointIndex turn = mb.AddJoint({.name = "hub",
                                       .type = JointType::kRevolute,
                                       .parent = kWorldBody,
                                       .child = hub,
                                       .axis = Vec3(0.1, 0.2, 1).normalized()});
  const BodyIndex side_b = mb.AddFlexibleBody("block", b.modes);
  const JointIndex free = mb.AddJoint({.name = "free",
                                       .type = JointType::kFree,
                                       .parent = hub,
                                       .child = side_b,
                                       .X_PF = Transform::Translation(Vec3(0.05, 0, 0))});
  Eigen::VectorXd q0(7), v0(6), qf(nf), vf(nf);
  const double tilt = 0.3;
  q0 << 0.01, -0.02, 0.03, std::cos(tilt / 2), std::sin(tilt / 2) * Vec3(1, 2, 2).normalized();
  v0.setZero();
  qf.setConstant(1e-7);
  vf.setZero();
  mb.SetJointPosition(free, q0);
  mb.SetJointPosition(turn, Eigen::VectorXd::Constant(1, 0.7));
  mb.SetJointPosition(slider, Eigen::VectorXd::Constant(1, 0.02));
  mb.SetModalCoordinates(side_b, qf, vf);
  // An element with tangents makes Data keep the body Jacobians.
  mb.AddExternalForce(std::make_shared<FlexibleContactElement>(
      FlexibleContactElementSpec{.name = "rigid_on_block",
                                 .a = {.body = side_a, .rigid = Plane()},
                                 .b = {.body = side_b, .flexible = block},
                                 .law = {.stiffness_per_area = 2.1e13}}));
  const std::shared_ptr<const Model> model = std::move(mb).Finalize();
  const int nv = model->nv;
  const State s = State::Initial(*model);
  Data data(*model);
  CalcPositionKinematics(*model, s.q, data);
  CalcBodyJacobians(*model, data);
  const Mat3 R_A = data.X_WB[side_a].R, R_B = data.X_WB[side_b].R;
  const FlexibleBody& fb = model->flexible_bodies[model->bodies[side_b].flexible];
  ASSERT_EQ(fb.nf, nf);

  const int m = 12 + nf;
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(m, nv);
  L.topRows<6>() = data.J_WB[side_a];
  L.middleRows<6>(6) = data.J_WB[side_b];
  for (int k = 0; k < nf; ++k) L(12 + k, fb.v_start + k) = 1;
  Eigen::MatrixXd K_z = Eigen::MatrixXd::Zero(m, m), C_z = Eigen::MatrixXd::Zero(m, m);
  ContactTangents t(nullptr, block.get(), nv);
  t.Clear();
  int pressing = 0;  // points with a nonzero term (the others are skipped)
  const int surface_vertices = block->undeformed().num_vertices();
  const auto& tris = block->undeformed().triangles();
  for (int i = 0; i < 80; ++i) {
    const double x = 0.37 * i;
    const Vec3 n = Vec3(std::sin(x), std::cos(1.3 * x), 2).normalized();
    NodeForceTangent law;
    law.k_n = i % 7 == 3 ? 0 : 1e8 * (1 + 0.5 * std::sin(2.1 * x));
    law.c_n = i % 5 == 1 ? 0 : 3e3 * (1 + 0.5 * std::cos(1.7 * x));
    law.a = n + 0.1 * Vec3(std::cos(x), 0.5, -std::sin(3 * x));
    law.slip_directions = i % 3;
    law.slip_damping = 2e4 * (1 + 0.3 * std::sin(x));
    law.slip_direction[0] = n.cross(Vec3::UnitX()).normalized();
    law.slip_direction[1] = n.cross(law.slip_direction[0]);
    TangentPoint point{.p_W = Vec3(0.01 * std::sin(x), 0.02 * std::cos(x), 0.005 * x),
                       .node_on_a = i % 2 == 0};
    Eigen::Matrix<double, 3, Eigen::Dynamic> modal = Eigen::MatrixXd::Zero(3, nf);
    if (point.node_on_a) {
      // The node on the rigid side A, the face on the flexible side B.
      const auto& tri = tris[(7 * i) % tris.size()];
      point.face_vertices = {tri[0], tri[1], tri[2]};
      point.face_weights = Vec3(0.2 + 0.1 * std::sin(x), 0.3, 0.0);
      point.face_weights(2) = 1 - point.face_weights(0) - point.face_weights(1);
      for (int k = 0; k < 3; ++k)
        modal -= point.face_weights(k) * R_B * block->VertexShapes(point.face_vertices[k]);
    } else {
      point.node_vertex = (11 * i) % surface_vertices;
      modal = R_B * block->VertexShapes(point.node_vertex);
    }
    t.AddPoint(point, law, n, R_A, R_B);
    if (law.k_n != 0 || law.c_n != 0 || law.slip_directions > 0) ++pressing;
    // J_P: v_rel = J_P z (node side minus face side).
    Eigen::MatrixXd J_P = Eigen::MatrixXd::Zero(3, m);
    const double sign_a = point.node_on_a ? 1 : -1;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? sign_a : -sign_a;
      J_P.block<3, 3>(0, 6 * side) = -sign * Skew(point.p_W);
      J_P.block<3, 3>(0, 6 * side + 3) = sign * Mat3::Identity();
    }
    J_P.rightCols(nf) = modal;
    K_z += J_P.transpose() * law.K(n) * J_P;
    C_z += J_P.transpose() * law.C(n) * J_P;
  }
  const Eigen::MatrixXd K_dense = L.transpose() * K_z * L, C_dense = L.transpose() * C_z * L;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nv, nv), C = Eigen::MatrixXd::Zero(nv, nv);
  t.Scatter(*model, data, side_a, side_b, K, C);
  EXPECT_EQ(t.points(), pressing);
  EXPECT_GT(pressing, 2 * ContactTangents::kBlock);
  EXPECT_GT(K_dense.norm(), 0);
  EXPECT_LE((K - K_dense).norm(), 1e-13 * K_dense.norm()) << "K\n" << K << "\ndense\n" << K_dense;
  EXPECT_LE((C - C_dense).norm(), 1e-13 * C_dense.norm()) << "C\n" << C << "\ndense\n" << C_dense;
  // The column of the body on its own (no Jacobian reaches it) stays empty: exact zeros.
  const int v_other = model->joints[0].v_start;
  EXPECT_EQ(K.col(v_other).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(K.row(v_other).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(C.col(v_other).cwiseAbs().maxCoeff(), 0.0);
}

TEST(FlexibleContactElement, ReportsDeformationBeyondTheInflation) {
  const Block b = MakeBlock(6);
  const FlexibleContactElement e = MakeElement(b, 2.1e13);
  FlexibleContactWorkspace ws(e.spec().a, e.spec().b);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(b.modes->nf);
  q(0) = 30e-6 / e.spec().a.flexible->mode_bounds()(0);  // 30 um > the 20 um allowance
  e.Evaluate({.X_WB = Transform::Translation(Vec3(0, 0, kL)), .q_f = &q}, {.X_WB = Transform()}, ws);
  EXPECT_EQ(ws.inflation_exceeded, 1);
  EXPECT_NEAR(ws.side_a.deformation_bound, 30e-6, 1e-12);
}


// Vertices made on first read equal the whole surface's deformation s_P + Phi_P q_f (to the
// rounding of the two summation orders), only those read are made, each base once; the per-part
// bounds hold for every vertex of their part and are the largest vertex motion for one mode.
TEST(FlexibleContactSurface, LazyVerticesAndPartBounds) {
  const Block b = MakeBlock(8);
  const FlexibleContactSurface surface(
      b.modes, {.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6, .angular_parts = 4,
                .part_angle_offset_rad = 0.25 * 3.14159265358979});
  const ContactSurface& s = surface.undeformed();
  ASSERT_EQ(s.num_parts(), 4);
  const int nf = surface.nf(), nv = s.num_vertices();
  Eigen::VectorXd q(nf), displacement(3 * nv);
  for (int k = 0; k < nf; ++k) q(k) = 1e-6 * std::sin(1.7 * k + 0.3) / surface.mode_bounds()(k);
  std::vector<Vec3> want(nv), normals(s.num_triangles()), got(nv, Vec3::Zero());
  surface.Deform(q, &displacement, &want, &normals);
  DeformedVertices lazy(surface);
  lazy.Begin(&q, &got);
  const double scale = displacement.cwiseAbs().maxCoeff();
  for (int v = 0; v < nv; v += 3) EXPECT_LT((lazy[v] - want[v]).norm(), 1e-12 * scale) << v;
  for (int v = 0; v < nv; v += 3) EXPECT_EQ(lazy[v], got[v]);  // read again: the same
  EXPECT_EQ(lazy.vertices_made(), (nv + 2) / 3);
  EXPECT_EQ(lazy.bases_made(), (nv + 2) / 3);  // node-set surface: each vertex its own base
  EXPECT_EQ(got[1], Vec3::Zero());             // not read, not made
  // A new evaluation makes them again, at its own q.
  const Eigen::VectorXd q2 = 2 * q;
  lazy.Begin(&q2, &got);
  // The expected 2 (s + u) - s carries the rounding of the positions themselves (a few ulp of |s|).
  const double position_rounding = 4 * std::numeric_limits<double>::epsilon() * s.vertices()[0].norm();
  EXPECT_LT((lazy[0] - (2 * want[0] - s.vertices()[0])).norm(), 1e-12 * scale + position_rounding);
  EXPECT_EQ(lazy.vertices_made(), 1);
  // Bounds per part: >= every vertex's |Phi_v x| for mixed x, the largest for one mode.
  auto largest = [&](int part, const Eigen::VectorXd& x) {
    Eigen::VectorXd u(3 * nv);
    std::vector<Vec3> xv(nv);
    surface.Deform(x, &u, &xv, &normals);
    double m = 0;
    for (int v = s.part_vertex_start()[part]; v < s.part_vertex_start()[part + 1]; ++v)
      m = std::max(m, u.segment<3>(3 * v).norm());
    return m;
  };
  int tighter = 0;
  for (int part = 0; part < 4; ++part) {
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd x(nf);
      for (int k = 0; k < nf; ++k) x(k) = std::cos(2.3 * k * (trial + 1) + part) / surface.mode_bounds()(k);
      const double exact = largest(part, x), bound = surface.PartDeformationBound(part, x);
      EXPECT_GE(bound, exact);
      // All parts at once: the same numbers (flexible_contact_surface.h).
      std::vector<double> all(4, -1.0);
      surface.PartDeformationBounds(x, &all);
      EXPECT_EQ(all[part], bound);
      // Within the whole surface's bound sum_k |x_k| c_k, and below it where the part's vertices
      // move less than the surface's largest in some mode.
      const double whole = surface.DeformationBound(x);
      EXPECT_LE(bound, whole * (1 + 1e-12) + 1e-15);
      tighter += bound < 0.99 * whole;
    }
    for (int k = 0; k < nf; ++k) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(nf, k);
      EXPECT_NEAR(surface.PartDeformationBound(part, e), largest(part, e), 1e-9 * largest(part, e));
    }
  }
  EXPECT_GT(tighter, 0);
  EXPECT_EQ(surface.PartDeformationBound(0, Eigen::VectorXd::Zero(nf)), 0.0);
  // Eigen's dot of a strided (column-major) row sums in index order, one term at a time: the
  // order PartDeformationBounds sums each part's terms in, checked for 1 to 30 modes.
  for (int n = 1; n <= 30; ++n) {
    const Eigen::MatrixXd c = Eigen::MatrixXd::NullaryExpr(
        7, n, [](Eigen::Index i, Eigen::Index j) { return std::exp(std::sin(1.1 * i + 2.3 * j)); });
    Eigen::VectorXd x(n);
    for (int k = 0; k < n; ++k) x(k) = std::cos(0.7 * k + n) * 1e-3 * (k % 2 ? -3 : 1);
    for (int p = 0; p < 7; ++p) {
      const double want = c.row(p).dot(x.cwiseAbs().transpose());
      double got = c(p, 0) * std::abs(x(0));
      for (int k = 1; k < n; ++k) got += c(p, k) * std::abs(x(k));
      EXPECT_EQ(got, want) << n << " " << p;
    }
  }
}

// ThreeRowsTimes (flexible_contact_surface.h) gives the numbers of Eigen's product of a 3-row
// block of a row-major matrix and a vector, for every depth (the packet loop's cases: below one
// packet, one, two, odd tails), and so do the surface's vertex rates and lazy vertices: `==`.
TEST(FlexibleContactSurface, ThreeRowsTimesIsEigensProductToTheBit) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (int n = 0; n <= 33; ++n) {
    RowMajor m(12, n);
    Eigen::VectorXd x(n);
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < n; ++j)
        m(i, j) = std::sin(1.3 * i + 0.7 * j + 0.1 * n) * std::exp(0.1 * j);
    for (int j = 0; j < n; ++j) x(j) = std::cos(2.1 * j + n) * 1e-3 * (j % 3 == 0 ? -1 : 7);
    const Eigen::Ref<const Eigen::VectorXd> xr = x;  // as DeformVertex reads q_f
    for (int b = 0; b < 4; ++b) {
      const Vec3 eigen = m.middleRows<3>(3 * b) * xr;
      EXPECT_EQ(ThreeRowsTimes(m.data() + 3 * b * n, n, x.data(), n), eigen) << n << " " << b;
    }
  }
  const Block b = MakeBlock(8);
  const FlexibleContactSurface surface(b.modes, {.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6});
  const ContactSurface& s = surface.undeformed();
  const int nf = surface.nf(), nv = s.num_vertices();
  Eigen::VectorXd q(nf);
  for (int k = 0; k < nf; ++k) q(k) = 1e-6 * std::sin(1.7 * k + 0.3) / surface.mode_bounds()(k);
  std::vector<Vec3> got(nv, Vec3::Zero());
  DeformedVertices lazy(surface);
  lazy.Begin(&q, &got);
  for (int v = 0; v < nv; ++v) {
    const Vec3 product = surface.VertexShapes(v) * q;
    EXPECT_EQ(surface.VertexShapeTimes(v, q), product) << v;
    // A node-set surface's vertex is its own base, of weight 1 (DeformVertex).
    Vec3 u = Vec3::Zero();
    u += 1.0 * product;
    EXPECT_EQ(lazy[v], Vec3(s.vertices()[v] + u)) << v;
  }
}

// Vertex rates made on first read (deformed_vertices.h VertexRates) are the direct product
// R Phi_v q_f-dot to the last bit, each made once per Begin(), and a Begin() at new rates (the
// same vector changed in place, as Data's q_f-dot is from one evaluation to the next) and a new
// rotation makes them again: a stamp that did not move would return the first rates.
TEST(FlexibleContactSurface, VertexRatesAreMadeOncePerPassAtThatPassRates) {
  const Block b = MakeBlock(8);
  const FlexibleContactSurface surface(b.modes, {.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6});
  const int nf = surface.nf(), nv = surface.undeformed().num_vertices();
  Eigen::VectorXd q_dot(nf);
  for (int k = 0; k < nf; ++k) q_dot(k) = 1e-3 * std::sin(1.3 * k + 0.2) / surface.mode_bounds()(k);
  Mat3 R = AxisAngle(Vec3(1, 2, 3).normalized(), 0.7);
  VertexRates rates(surface);
  rates.Begin(&q_dot, R);
  for (int v = 0; v < nv; ++v) EXPECT_EQ(rates[v], Vec3(R * surface.VertexShapeTimes(v, q_dot))) << v;
  for (int v = 0; v < nv; ++v) EXPECT_EQ(rates[v], Vec3(R * surface.VertexShapeTimes(v, q_dot))) << v;
  EXPECT_EQ(rates.made(), nv);  // read twice, made once
  // New rates in the same vector, a new rotation: every rate read is that of the new pass.
  const Eigen::VectorXd first = q_dot;
  for (int k = 0; k < nf; ++k) q_dot(k) = 1e-3 * std::cos(0.7 * k + 0.5) / surface.mode_bounds()(k);
  const Mat3 R_first = R;
  R = AxisAngle(Vec3(-2, 1, 0.5).normalized(), 1.1);
  rates.Begin(&q_dot, R);
  EXPECT_EQ(rates.made(), 0);
  int moved = 0;
  for (int v = 0; v < nv; v += 2) {
    EXPECT_EQ(rates[v], Vec3(R * surface.VertexShapeTimes(v, q_dot))) << v;
    moved += rates[v] != Vec3(R_first * surface.VertexShapeTimes(v, first));
  }
  EXPECT_EQ(rates.made(), (nv + 1) / 2);
  EXPECT_EQ(moved, (nv + 1) / 2);  // the two passes' rates differ at every vertex read
}

// The element reads the rates of each evaluation: the block pressed onto the plane and sliding,
// with damping and friction (both read the relative velocity, which holds the node's rate and
// the face vertices' rates), evaluated twice at one pose with two modal rates (one vector,
// changed in place). The second evaluation's forces equal, to the last bit, those of a workspace
// whose first evaluation had other rates, and differ from the first evaluation's; after it every
// vertex's rate in the cache is the direct product at the second rates.
TEST(FlexibleContactElement, ContactPointsReadTheRatesOfTheirEvaluation) {
  const Block b = MakeBlock(8);
  auto block = std::make_shared<const FlexibleContactSurface>(
      b.modes, FlexibleContactSurfaceSpec{.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6,
                                          .deformation_allowance_m = 20e-6});
  const FlexibleContactElement e({.name = "block_on_plane", .a = {.body = 1, .flexible = block},
                                  .b = {.body = 0, .rigid = Plane()},
                                  .law = {.stiffness_per_area = 2.1e13,
                                          .hunt_crossley_s_per_m = 0.5,
                                          .friction_coefficient = 0.3}});
  const int nf = b.modes->nf;
  Eigen::VectorXd q(nf), q_dot(nf);
  for (int k = 0; k < nf; ++k) q(k) = 0.5e-6 * std::sin(2.1 * k + 0.3) / block->mode_bounds()(k);
  auto set_rates = [&](double phase) {
    for (int k = 0; k < nf; ++k) q_dot(k) = 1e-3 * std::sin(1.7 * k + phase) / block->mode_bounds()(k);
  };
  Vec6 V = Vec6::Zero();
  V << 0, 0, 0.3, 2e-4, -1e-4, -1e-3;  // spinning about z, sliding, closing
  const ContactSideState plane{.X_WB = Transform()};
  const ContactSideState a{.X_WB = Transform::Translation(Vec3(0, 0, kL - 2e-6)), .V_WB = V,
                           .q_f = &q, .q_f_dot = &q_dot};
  struct Forces {
    double normal, friction;
    Vec6 f_W;
    Eigen::VectorXd modal;
  };
  auto forces = [](const FlexibleContactWorkspace& ws) {
    return Forces{ws.normal_force, ws.friction_force, ws.side_a.f_W, ws.side_a.modal_force};
  };
  FlexibleContactWorkspace ws1(e.spec().a, e.spec().b), ws2(e.spec().a, e.spec().b);
  set_rates(0.4);
  e.Evaluate(a, plane, ws1);
  const Forces first = forces(ws1);
  set_rates(2.9);
  e.Evaluate(a, plane, ws2);
  set_rates(1.1);
  e.Evaluate(a, plane, ws1);
  e.Evaluate(a, plane, ws2);
  const Forces one = forces(ws1), two = forces(ws2);
  ASSERT_GT(ws1.contact_points, 10);
  EXPECT_EQ(one.normal, two.normal);
  EXPECT_EQ(one.friction, two.friction);
  EXPECT_EQ(one.f_W, two.f_W);
  EXPECT_EQ(one.modal, two.modal);
  EXPECT_NE(one.friction, first.friction);  // the rates matter here
  EXPECT_NE(one.normal, first.normal);
  for (int v = 0; v < block->undeformed().num_vertices(); ++v)
    EXPECT_EQ(ws1.side_a.rates[v], Vec3(block->VertexShapeTimes(v, q_dot))) << v;
}

// A monitor that sums what the element gives it (each point's position, normal and stiffness,
// the poses and side a's force), for the test below.
class SummingMonitor final : public ContactMonitor {
 public:
  struct Sums final : ContactMonitorState {
    std::array<double, 8> v{};
  };
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  std::unique_ptr<ContactMonitorState> MakeState() const override {
    return std::make_unique<Sums>();
  }
  void Start(const Transform& X_WA, const Transform& X_WB,
             ContactMonitorState& state) const override {
    auto& s = static_cast<Sums&>(state).v;
    s.fill(0.0);
    s[0] = X_WA.p.z() - 3 * X_WB.p.x();
  }
  void Add(const Vec3& p, const Vec3& n, double k, ContactMonitorState& state) const override {
    auto& s = static_cast<Sums&>(state).v;
    s[1] += p.x();
    s[2] += p.y();
    s[3] += p.z();
    s[4] += n.dot(Vec3(1, 2, 3));
    s[5] += k;
    s[6] += 1;
  }
  void Finish(const Vec6& f_A_W, ContactMonitorState& state) const override {
    static_cast<Sums&>(state).v[7] = f_A_W.sum();
  }
  void Write(const ContactMonitorState& state, double* values) const override {
    const auto& s = static_cast<const Sums&>(state).v;
    std::copy(s.begin(), s.end(), values);
  }

 private:
  std::vector<OutputDescription> outputs_ = {{.name = "sums", .columns = 8}};
};

// The outputs of an evaluation without them (Evaluate with outputs false, as Compute: the
// monitor's state and the recorded points made when GetOutputs first reads them) against those
// of the same evaluation with them, in another workspace of the same element, to the bit: the
// flexible block pressed onto the plane, sliding and deforming (the law's stiffness and normal
// force read the deformation rates), its rates changed between the evaluation and the read.
TEST(FlexibleContactElement, OutputsMadeOnReadEqualThoseOfTheEvaluation) {
  const Block b = MakeBlock(8);
  auto block = std::make_shared<const FlexibleContactSurface>(
      b.modes, FlexibleContactSurfaceSpec{
                   .node_sets = {"ZMIN"}, .gap_margin_m = 30e-6, .deformation_allowance_m = 20e-6});
  const auto monitor = std::make_shared<const SummingMonitor>();
  const FlexibleContactElement e({.name = "block_on_plane",
                                  .a = {.body = 1, .flexible = block},
                                  .b = {.body = 0, .rigid = Plane()},
                                  .law = {.stiffness_per_area = 2.1e13,
                                          .hunt_crossley_s_per_m = 0.5,
                                          .friction_coefficient = 0.3},
                                  .monitor = monitor,
                                  .record_points = 5});
  const int nf = b.modes->nf;
  const int n = OutputValueCount(e.outputs());
  FlexibleContactWorkspace lazy(e.spec().a, e.spec().b, nullptr, nullptr, 0, monitor.get());
  FlexibleContactWorkspace eager(e.spec().a, e.spec().b, nullptr, nullptr, 0, monitor.get());
  std::vector<double> lazy_out(n), eager_out(n), again(n);
  Eigen::VectorXd q(nf), q_dot(nf);
  int pressed = 0;
  for (int step = 0; step < 12; ++step) {
    for (int k = 0; k < nf; ++k) {
      q(k) = 0.5e-6 * std::sin(2.1 * k + 0.3 * step) / block->mode_bounds()(k);
      q_dot(k) = 1e-3 * std::sin(1.7 * k + 0.5 * step) / block->mode_bounds()(k);
    }
    Vec6 V = Vec6::Zero();
    V << 0, 0, 0.3, 2e-4, -1e-4 * step, -1e-3;
    const ContactSideState a{
        .X_WB = Transform::Translation(Vec3(1e-5 * step, 0, kL - 1e-6 * (1 + step % 4))),
        .V_WB = V,
        .q_f = &q,
        .q_f_dot = &q_dot};
    const ContactSideState plane{.X_WB = Transform()};
    e.Evaluate(a, plane, lazy, /*outputs=*/false);
    EXPECT_TRUE(lazy.outputs_pending) << "step " << step;
    e.Evaluate(a, plane, eager);
    EXPECT_FALSE(eager.outputs_pending);
    ASSERT_TRUE(lazy.side_a.f_W == eager.side_a.f_W) << "step " << step;
    q_dot *= -3;  // the read must not look at the rates again
    e.GetOutputs(lazy, lazy_out.data());
    EXPECT_FALSE(lazy.outputs_pending);
    e.GetOutputs(eager, eager_out.data());
    e.GetOutputs(lazy, again.data());  // read twice: made once
    // Bit for bit (NaN where no point is recorded, in both).
    ASSERT_EQ(std::memcmp(lazy_out.data(), eager_out.data(), sizeof(double) * n), 0)
        << "step " << step;
    ASSERT_EQ(std::memcmp(again.data(), eager_out.data(), sizeof(double) * n), 0)
        << "step " << step;
    pressed += lazy.contact_points > 5;
  }
  EXPECT_GT(pressed, 8);
}

// The block held 20 um above the plane (within the gap distance d = 30 um) and deformed into
// it by its modes alone, 2 um per evaluation, the pose fixed: the tracked path (vertices made on
// first read; nodes sleep until the modal bound on the change has used up their reach) gives
// the forces of the candidate-pair path, which deforms every vertex and lets no node sleep. A
// change bound that undercounted would leave nodes asleep that press (the forces would differ).
TEST(FlexibleContactElement, TrackedLazyPathEqualsCandidatePairsWhileDeforming) {
  const Block b = MakeBlock(6);
  auto surface = std::make_shared<const FlexibleContactSurface>(
      b.modes, FlexibleContactSurfaceSpec{.node_sets = {"ZMIN"}, .gap_margin_m = 30e-6,
                                          .deformation_allowance_m = 60e-6});
  auto element = [&](ContactGapMethod method) {
    return FlexibleContactElement({.name = "block_on_plane", .a = {.body = 1, .flexible = surface},
                                   .b = {.body = 0, .rigid = Plane()},
                                   .law = {.stiffness_per_area = 2.1e13}, .gap_method = method});
  };
  const FlexibleContactElement tracked = element(ContactGapMethod::kTracked);
  const FlexibleContactElement pairs = element(ContactGapMethod::kCandidatePairs);
  FlexibleContactWorkspace ws_t(tracked.spec().a, tracked.spec().b);
  FlexibleContactWorkspace ws_p(pairs.spec().a, pairs.spec().b);
  // A direction in the modes whose bottom face moves down (-z) by 1 m per unit at its lowest
  // vertex.
  const int nf = b.modes->nf;
  Eigen::VectorXd dir = Eigen::VectorXd::Zero(nf);
  for (int k = 0; k < nf; ++k) dir(k) = std::sin(0.9 * k + 0.4);
  Eigen::VectorXd u(3 * surface->undeformed().num_vertices());
  std::vector<Vec3> xv(surface->undeformed().num_vertices());
  std::vector<Vec3> nv(surface->undeformed().num_triangles());
  surface->Deform(dir, &u, &xv, &nv);
  double down = 0;
  for (int v = 0; v < surface->undeformed().num_vertices(); ++v) down = std::min(down, u(3 * v + 2));
  ASSERT_LT(down, 0);
  dir /= -down;
  const Transform X_WB = Transform::Translation(Vec3(0, 0, kL + 20e-6));
  int pressed = 0;
  for (int k = 0; k <= 20; ++k) {
    const Eigen::VectorXd q = 2e-6 * k * dir;
    tracked.Evaluate({.X_WB = X_WB, .q_f = &q}, {.X_WB = Transform()}, ws_t);
    pairs.Evaluate({.X_WB = X_WB, .q_f = &q}, {.X_WB = Transform()}, ws_p);
    EXPECT_EQ(ws_t.contact_points, ws_p.contact_points) << k;
    EXPECT_NEAR(ws_t.normal_force, ws_p.normal_force, 1e-9 * ws_p.normal_force + 1e-12) << k;
    EXPECT_LT((ws_t.side_a.modal_force - ws_p.side_a.modal_force).norm(),
              1e-9 * ws_p.side_a.modal_force.norm() + 1e-12) << k;
    pressed += ws_p.contact_points > 0;
  }
  EXPECT_GT(pressed, 5);  // the block pressed for a good part of the sequence
  std::printf("tracked: %ld node evaluations in 21 calls, %d pressed\n",
              ws_t.tracked.stats().node_evaluations, pressed);
  EXPECT_LT(ws_t.tracked.stats().node_evaluations, 21L * 25 * 2);  // nodes slept on the way
}

}  // namespace
}  // namespace orrery::contact

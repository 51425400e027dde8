// Flexible-body data from a Craig-Bampton model (flex/flexible_body_modes.cpp). Box bar
// 1 x 0.1 x 0.15 m at an offset origin, interfaces XMIN (RBE2, reference = body frame B) and
// XMAX (RBE3). Oracles:
//   - mass, first moment I1 = m (centre - p_ref) and I3 = int rho x x^T of a box in closed form
//     (m c c^T + m diag(a^2, b^2, c^2) / 12). The consistent mass integrates these quadratic
//     fields exactly: rounding level, for hex20 and tet10.
//   - two independent routes to the same integrals: the invariants use the scalar mass M_s of the
//     nodal fields; the Craig-Bampton reduction's M (T^T M T with the full 3N mass) holds
//     int rho Phi (rows 0-2 of its rigid-elastic block), int rho x x Phi (rows 3-5) and, for
//     M-normalized modes, M_ff(k, l) = tr I5_kl = delta_kl; its rigid block gives m, S and the
//     inertia about the reference master, tr(I3) 1 - I3. Rounding level (1e-10 relative).
//   - surface: the triangles close (every edge shared by exactly two, with opposite directions)
//     and by the divergence theorem (1/6) sum det[p0 p1 p2] is the box volume, positive for
//     outward normals; exported surface nodes are exactly the union of the box mesher's six face
//     sets.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "flex/box_mesher.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/flexible_body_modes.h"

namespace orrery::flex {
namespace {

constexpr double kRho = 7850;
const Eigen::Vector3d kOrigin(0.2, -0.1, 0.3);
const Eigen::Vector3d kSize(1.0, 0.1, 0.15);

FeMesh Bar(ElementType t, std::array<int, 3> div = {10, 2, 2}) {
  FeMesh mesh = MakeBoxMesh({.origin_m = kOrigin, .size_m = kSize, .divisions = div, .type = t});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = kRho});
  return mesh;
}

struct Reduced {
  FeMesh mesh;
  FeSystem sys;
  std::vector<FeInterface> ifs;
  CraigBamptonModel cb;
  FlexibleBodyModes modes;
};

Reduced Reduce(ElementType t, const FlexibleBodyModesOptions& options, std::array<int, 3> div = {10, 2, 2}) {
  Reduced r{.mesh = Bar(t, div)};
  r.sys = AssembleFeSystem(r.mesh);
  r.ifs = {MakeInterface(r.mesh, "XMIN", InterfaceKind::kRbe2), MakeInterface(r.mesh, "XMAX", InterfaceKind::kRbe3)};
  r.cb = ReduceCraigBampton(r.mesh, r.sys, r.ifs, {.num_modes = 8});
  r.modes = MakeFlexibleBodyModes(r.mesh, r.sys, r.cb, r.ifs, options);
  return r;
}

TEST(FlexibleBodyModesTest, RigidInvariantsOfABox) {
  for (ElementType t : {ElementType::kHex20, ElementType::kTet10}) {
    const Reduced r = Reduce(t, {});
    const FlexibleBodyModes& m = r.modes;
    const double mass = kRho * kSize.prod();
    const Eigen::Vector3d p_ref = kOrigin + Eigen::Vector3d(0, kSize.y() / 2, kSize.z() / 2);
    const Eigen::Vector3d c = kOrigin + kSize / 2 - p_ref;
    const Eigen::Matrix3d I3 = mass * c * c.transpose() + mass / 12 * kSize.cwiseAbs2().asDiagonal().toDenseMatrix();
    EXPECT_NEAR(m.mass, mass, 1e-12 * mass) << CalculixName(t);
    EXPECT_LT((m.I1 - mass * c).norm(), 1e-12 * mass) << CalculixName(t);
    EXPECT_LT((m.I3 - I3).norm(), 1e-12 * I3.norm()) << CalculixName(t);
    // The reduction's rigid block (3N mass through the interface transform)
    EXPECT_NEAR(r.cb.mass_kg, m.mass, 1e-10 * mass);
    EXPECT_LT((r.cb.p_RoCm_m * r.cb.mass_kg - m.I1).norm(), 1e-10 * mass);
    const Eigen::Matrix3d J = m.I3.trace() * Eigen::Matrix3d::Identity() - m.I3;
    EXPECT_LT((r.cb.I_Ro_kgm2 - J).norm(), 1e-10 * J.norm());
  }
}

TEST(FlexibleBodyModesTest, ModalInvariantsAgreeWithTheReducedMassMatrix) {
  const Reduced r = Reduce(ElementType::kHex20, {});
  const FlexibleBodyModes& m = r.modes;
  const int nf = m.nf;
  ASSERT_EQ(nf, r.cb.num_elastic);
  ASSERT_EQ(nf, 6 + 8);
  ASSERT_EQ(static_cast<int>(m.I5.size()), nf * nf);
  ASSERT_EQ(static_cast<int>(m.I4.size()), nf);
  // M_ff(k, l) = tr I5_kl = identity; I5_kl = I5_lk^T
  double orth = 0, transp = 0;
  for (int k = 0; k < nf; ++k)
    for (int l = 0; l < nf; ++l) {
      orth = std::max(orth, std::abs(m.I5[k * nf + l].trace() - (k == l ? 1.0 : 0.0)));
      transp = std::max(transp, (m.I5[k * nf + l] - m.I5[l * nf + k].transpose()).norm());
    }
  EXPECT_LT(orth, 1e-10);
  EXPECT_LT(transp, 1e-12);
  // int rho Phi and int rho x x Phi from the reduced mass matrix's rigid-elastic coupling
  const Eigen::MatrixXd Mre = r.cb.M.topRightCorner(6, nf);
  const double scale = m.I2.norm();
  EXPECT_LT((Mre.topRows(3) - m.I2).norm(), 1e-10 * scale);
  for (int k = 0; k < nf; ++k) {
    const Eigen::Matrix3d& I4 = m.I4[k];  // int rho x Phi_k^T: (x x Phi)_i = e_ijk x_j Phi_k
    const Eigen::Vector3d xPhi(I4(1, 2) - I4(2, 1), I4(2, 0) - I4(0, 2), I4(0, 1) - I4(1, 0));
    EXPECT_LT((Mre.block<3, 1>(3, k) - xPhi).norm(), 1e-10 * scale) << "mode " << k;
  }
  // Stiffness and frequencies of the elastic block
  EXPECT_EQ(m.stiffness.rows(), nf);
  for (int k = 0; k < nf; ++k) {
    EXPECT_NEAR(std::sqrt(m.stiffness(k, k)) / (2 * std::numbers::pi), m.frequencies_hz[k], 1e-9 * m.frequencies_hz[k]);
  }
  EXPECT_EQ(m.damping.size(), 0);
}

TEST(FlexibleBodyModesTest, NodesSetsAndClosedSurface) {
  for (ElementType t : {ElementType::kTet4, ElementType::kTet10, ElementType::kHex8, ElementType::kHex20}) {
    for (bool split : {true, false}) {
      const Reduced r = Reduce(t, {.split_quadratic_faces = split, .stress_modes = true}, {6, 2, 2});
      const FlexibleBodyModes& m = r.modes;
      const int nf = m.nf;
      // Interface masters first, named after their interfaces
      ASSERT_EQ(m.node_sets.at("XMIN"), std::vector<int>{0});
      ASSERT_EQ(m.node_sets.at("XMAX"), std::vector<int>{1});
      EXPECT_EQ(m.nodes[0].id, *std::max_element(r.mesh.node_ids().begin(), r.mesh.node_ids().end()) + 1);
      EXPECT_LT(m.nodes[0].translation_shapes.norm() + m.nodes[0].rotation_shapes.norm(), 1e-12);  // held
      EXPECT_LT((m.nodes[1].translation_shapes - r.cb.master_shapes.block(6, 6, 3, nf)).norm(), 1e-14);
      EXPECT_LT((m.nodes[1].rotation_shapes - r.cb.master_shapes.block(9, 6, 3, nf)).norm(), 1e-14);
      // Surface nodes: the union of the six face sets; mesh sets carried over (renamed on clash)
      std::set<int> faces;
      for (const char* f : {"XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"})
        for (int a : r.mesh.NodeSet(f)) faces.insert(r.mesh.node_ids()[a]);
      std::set<int> exported;
      for (std::size_t i = 2; i < m.nodes.size(); ++i) exported.insert(m.nodes[i].id);
      EXPECT_EQ(exported, faces) << CalculixName(t);
      EXPECT_EQ(m.node_sets.at("XMIN_NODES").size(), r.mesh.NodeSet("XMIN").size());
      EXPECT_EQ(m.node_sets.at("YMAX").size(), r.mesh.NodeSet("YMAX").size());
      // An FE node's shapes are its rows of the elastic shapes
      const int i = m.node_sets.at("YMAX")[3];
      const int a = *r.mesh.FindNode(m.nodes[i].id);
      EXPECT_LT((m.nodes[i].translation_shapes - r.cb.shapes.block(3 * a, 6, 3, nf)).norm(), 1e-14);
      EXPECT_LT((m.nodes[i].position - (r.mesh.positions()[a] - r.cb.master_positions_m[0])).norm(), 1e-14);
      // Closed, outward oriented surface enclosing the box volume
      std::map<std::pair<int, int>, int> edges;
      double volume6 = 0;
      for (const auto& tri : m.surface_triangles) {
        Eigen::Matrix3d P;
        for (int j = 0; j < 3; ++j) P.col(j) = m.nodes[tri[j]].position;
        volume6 += P.determinant();
        for (int j = 0; j < 3; ++j) ++edges[{tri[j], tri[(j + 1) % 3]}];
      }
      int bad = 0;
      for (const auto& [e, n] : edges) bad += n != 1 || edges.count({e.second, e.first}) == 0;
      EXPECT_EQ(bad, 0) << CalculixName(t);
      EXPECT_NEAR(volume6 / 6, kSize.prod(), 1e-12) << CalculixName(t) << " split " << split;
      // Triangles per boundary face: quads 2 (6 split hex20), tets 1 (4 split tet10)
      const int quads = 2 * (6 * 2 + 2 * 2 + 2 * 6);
      const bool quad = t == ElementType::kHex8 || t == ElementType::kHex20;
      const int per = quad ? (split && t == ElementType::kHex20 ? 6 : 2) : (split && t == ElementType::kTet10 ? 4 : 1);
      EXPECT_EQ(static_cast<int>(m.surface_triangles.size()), quads * (quad ? 1 : 2) * per) << CalculixName(t);
      // Stress modes: one block of 6 rows per exported FE node
      EXPECT_EQ(m.stress_modes.rows(), 6 * static_cast<long>(m.stress_nodes.size()));
      EXPECT_EQ(m.stress_modes.cols(), nf);
      EXPECT_EQ(m.stress_nodes.size(), m.nodes.size() - 2);
      EXPECT_GT(m.stress_modes.norm(), 0);
      EXPECT_NO_THROW(ValidateFlexibleBodyModes("bar", m));
    }
  }
}

TEST(FlexibleBodyModesTest, OptionsAndErrors) {
  const Reduced r = Reduce(ElementType::kHex8, {.export_surface_nodes = false, .export_node_sets = {"ymin"},
                                                .master_ids = {900001, 900002}});
  EXPECT_EQ(r.modes.nodes[0].id, 900001);
  EXPECT_EQ(r.modes.nodes.size(), 2 + r.mesh.NodeSet("YMIN").size());
  // Only the YMIN face's triangles have all their nodes exported: 2 per quad
  EXPECT_EQ(r.modes.surface_triangles.size(), 2u * 10 * 2);
  EXPECT_TRUE(r.modes.geometric_stiffness.empty());
  EXPECT_TRUE(r.modes.stress_modes.size() == 0);
  EXPECT_THROW(MakeFlexibleBodyModes(r.mesh, r.sys, r.cb, r.ifs, {.master_ids = {1, 2}}), std::invalid_argument);
  EXPECT_THROW(MakeFlexibleBodyModes(r.mesh, r.sys, r.cb, r.ifs, {.master_ids = {900001}}), std::invalid_argument);
  EXPECT_THROW(MakeFlexibleBodyModes(r.mesh, r.sys, r.cb, std::span<const FeInterface>(r.ifs).first(1), {}),
               std::invalid_argument);
  EXPECT_THROW(MakeFlexibleBodyModes(r.mesh, r.sys, r.cb, r.ifs, {.export_node_sets = {"NOPE"}}), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::flex

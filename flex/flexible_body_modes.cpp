#include "flex/flexible_body_modes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>

#include "flex/geometric_stiffness.h"
#include "flex/stress_recovery.h"

namespace orrery::flex {
namespace {

// A face of an element: corners (3 or 4) counter-clockwise seen from outside, and the midside
// nodes between corner k and k + 1 (-1 for linear elements). Local node numbers (fe_mesh.h).
struct FaceDef {
  int corners = 0;
  std::array<int, 4> c;
  std::array<int, 4> m;
};

constexpr FaceDef kTetFaces[4] = {{3, {0, 2, 1, -1}, {6, 5, 4, -1}},
                                  {3, {0, 1, 3, -1}, {4, 8, 7, -1}},
                                  {3, {1, 2, 3, -1}, {5, 9, 8, -1}},
                                  {3, {0, 3, 2, -1}, {7, 9, 6, -1}}};
constexpr FaceDef kHexFaces[6] = {{4, {0, 3, 2, 1}, {11, 10, 9, 8}},   {4, {4, 5, 6, 7}, {12, 13, 14, 15}},
                                  {4, {0, 1, 5, 4}, {8, 17, 12, 16}},  {4, {1, 2, 6, 5}, {9, 18, 13, 17}},
                                  {4, {2, 3, 7, 6}, {10, 19, 14, 18}}, {4, {3, 0, 4, 7}, {11, 16, 15, 19}}};

std::span<const FaceDef> Faces(ElementType t) {
  if (IsTet(t)) return kTetFaces;
  return kHexFaces;
}

bool Quadratic(ElementType t) { return t == ElementType::kTet10 || t == ElementType::kHex20; }

// Key of a face: its sorted corner node indices (the 4th -1 for triangles).
struct FaceKey {
  std::array<int, 4> v;
  bool operator==(const FaceKey&) const = default;
};
struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::size_t h = 0;
    for (int x : k.v) h = h * 1000003u ^ static_cast<std::size_t>(x + 1);
    return h;
  }
};

// The scalar mass M_s of M = M_s (x) I3 (N x N); throws unless M has that structure.
Eigen::SparseMatrix<double> ScalarMass(const Eigen::SparseMatrix<double>& M) {
  const int n = static_cast<int>(M.rows() / 3);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(M.nonZeros() / 3);
  // Entries (3a+i, 3b+j): zero for i != j, equal for i = j
  double max_abs = 0;
  for (int c = 0; c < M.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(M, c); it; ++it) max_abs = std::max(max_abs, std::abs(it.value()));
  const double tol = 1e-12 * max_abs;
  for (int c = 0; c < M.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(M, c); it; ++it) {
      const int r = static_cast<int>(it.row());
      const bool same_component = r % 3 == c % 3;
      if (!same_component) {
        if (std::abs(it.value()) > tol)
          throw std::runtime_error("MakeFlexibleBodyModes: mass matrix couples DOF components (" + std::to_string(r) +
                                   ", " + std::to_string(c) + "): not of the form M_s (x) I3");
        continue;
      }
      if (r % 3 != 0) {
        if (std::abs(it.value() - M.coeff(r - r % 3, c - c % 3)) > tol)
          throw std::runtime_error("MakeFlexibleBodyModes: mass matrix differs between DOF components at (" +
                                   std::to_string(r) + ", " + std::to_string(c) + "): not of the form M_s (x) I3");
        continue;
      }
      t.emplace_back(r / 3, c / 3, it.value());
    }
  Eigen::SparseMatrix<double> Ms(n, n);
  Ms.setFromTriplets(t.begin(), t.end());
  return Ms;
}

}  // namespace

std::vector<BoundaryFace> BoundaryFaces(const FeMesh& mesh) {
  // Count every face by its corner set; remember one (element, face) per key
  struct Use {
    int count = 0, element = 0, face = 0;
  };
  std::unordered_map<FaceKey, Use, FaceKeyHash> faces;
  faces.reserve(4 * mesh.num_elements());
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    const std::span<const FaceDef> defs = Faces(e.type);
    for (int f = 0; f < static_cast<int>(defs.size()); ++f) {
      FaceKey k{{-1, -1, -1, -1}};
      for (int j = 0; j < defs[f].corners; ++j) k.v[j] = e.nodes[defs[f].c[j]];
      // Insertion sort of the 3 or 4 corners (std::sort trips GCC 12's -Warray-bounds here)
      for (int j = 1; j < defs[f].corners; ++j)
        for (int i = j; i > 0 && k.v[i - 1] > k.v[i]; --i) std::swap(k.v[i - 1], k.v[i]);
      Use& u = faces[k];
      if (u.count++ == 0) u.element = ei, u.face = f;
    }
  }
  // The faces used once, in element order for a deterministic result
  std::vector<std::pair<int, int>> boundary;
  for (const auto& [key, u] : faces)
    if (u.count == 1) boundary.emplace_back(u.element, u.face);
  std::sort(boundary.begin(), boundary.end());
  std::vector<BoundaryFace> out;
  out.reserve(boundary.size());
  for (const auto& [ei, f] : boundary) {
    const FeElement& e = mesh.elements()[ei];
    const FaceDef& d = Faces(e.type)[f];
    BoundaryFace b{.element = ei, .face = f, .corners = d.corners};
    for (int j = 0; j < d.corners; ++j) {
      b.corner_nodes[j] = e.nodes[d.c[j]];
      if (Quadratic(e.type)) b.midside_nodes[j] = e.nodes[d.m[j]];
    }
    out.push_back(b);
  }
  return out;
}

std::vector<std::array<int, 3>> BoundaryTriangles(const FeMesh& mesh, bool split_quadratic) {
  const std::vector<BoundaryFace> faces = BoundaryFaces(mesh);
  std::vector<std::array<int, 3>> tris;
  tris.reserve(6 * faces.size());
  for (const BoundaryFace& f : faces) {
    const int nc = f.corners;
    auto c = [&](int j) { return f.corner_nodes[j % nc]; };
    auto m = [&](int j) { return f.midside_nodes[j % nc]; };
    if (split_quadratic && f.midside_nodes[0] >= 0) {
      // Corner triangles, then the triangle / quadrilateral of the midside nodes
      for (int j = 0; j < nc; ++j) tris.push_back({c(j), m(j), m(j + nc - 1)});
      tris.push_back({m(0), m(1), m(2)});
      if (nc == 4) tris.push_back({m(0), m(2), m(3)});
    } else {
      tris.push_back({c(0), c(1), c(2)});
      if (nc == 4) tris.push_back({c(0), c(2), c(3)});
    }
  }
  return tris;
}

FlexibleBodyModes MakeFlexibleBodyModes(const FeMesh& mesh, const FeSystem& system, const CraigBamptonModel& cb,
                                        std::span<const FeInterface> interfaces,
                                        const FlexibleBodyModesOptions& options) {
  const int nn = mesh.num_nodes();
  const int nif = static_cast<int>(interfaces.size());
  const int nr = static_cast<int>(cb.K.rows());
  const int nf = cb.num_elastic;
  if (system.M.rows() != 3 * nn || system.K.rows() != 3 * nn)
    throw std::invalid_argument("MakeFlexibleBodyModes: system size differs from the mesh's " + std::to_string(3 * nn) +
                                " DOFs");
  if (cb.shapes.rows() != 3 * nn || cb.shapes.cols() != nr || nr != cb.num_rigid + nf || cb.num_rigid != 6 ||
      cb.master_shapes.rows() != 6 * nif || static_cast<int>(cb.master_positions_m.size()) != nif)
    throw std::invalid_argument("MakeFlexibleBodyModes: Craig-Bampton model does not match the mesh (" +
                                std::to_string(nn) + " nodes) and the " + std::to_string(nif) + " interfaces");
  if (!options.master_ids.empty() && static_cast<int>(options.master_ids.size()) != nif)
    throw std::invalid_argument("MakeFlexibleBodyModes: " + std::to_string(options.master_ids.size()) +
                                " master ids for " + std::to_string(nif) + " interfaces");

  FlexibleBodyModes r;
  r.nf = nf;
  const Eigen::Vector3d p_ref = cb.master_positions_m[cb.reference_interface];
  const Eigen::MatrixXd Phi = cb.shapes.rightCols(nf);

  // Positions in B, mode shapes per component
  Eigen::MatrixX3d X(nn, 3);
  for (int a = 0; a < nn; ++a) X.row(a) = (mesh.positions()[a] - p_ref).transpose();
  Eigen::MatrixXd P(nn, 3 * nf);
  for (int a = 0; a < nn; ++a)
    for (int k = 0; k < nf; ++k)
      for (int i = 0; i < 3; ++i) P(a, 3 * k + i) = Phi(3 * a + i, k);

  // Inertia invariants with M = M_s (x) I3
  const Eigen::SparseMatrix<double> Ms = ScalarMass(system.M);
  const Eigen::VectorXd Ms1 = Ms * Eigen::VectorXd::Ones(nn);
  const Eigen::MatrixX3d MsX = Ms * X;
  const Eigen::MatrixXd MsP = Ms * P;
  r.mass = Ms1.sum();
  r.I1 = X.transpose() * Ms1;
  r.I3 = X.transpose() * MsX;
  r.I3 = (0.5 * (r.I3 + r.I3.transpose())).eval();
  const Eigen::RowVectorXd onesMsP = Ms1.transpose() * P;  // M_s symmetric
  const Eigen::MatrixXd XMsP = MsX.transpose() * P;        // 3 x 3 nf
  const Eigen::MatrixXd PMsP = P.transpose() * MsP;        // 3 nf x 3 nf
  r.I2.resize(3, nf);
  r.I4.resize(nf);
  r.I5.resize(static_cast<std::size_t>(nf) * nf);
  for (int k = 0; k < nf; ++k) {
    for (int i = 0; i < 3; ++i) r.I2(i, k) = onesMsP(3 * k + i);
    r.I4[k] = XMsP.block<3, 3>(0, 3 * k);
    for (int l = 0; l < nf; ++l)
      r.I5[k * nf + l] = 0.5 * (PMsP.block<3, 3>(3 * k, 3 * l) + PMsP.block<3, 3>(3 * l, 3 * k).transpose());
  }

  // Modal stiffness and frequencies of the elastic block
  r.stiffness = cb.K.bottomRightCorner(nf, nf);
  r.frequencies_hz.assign(cb.frequencies_hz.end() - nf, cb.frequencies_hz.end());

  // Interface masters
  int max_id = 0;
  for (int id : mesh.node_ids()) max_id = std::max(max_id, id);
  for (int j = 0; j < nif; ++j) {
    FlexibleBodyModes::Node node;
    node.id = options.master_ids.empty() ? max_id + 1 + j : options.master_ids[j];
    if (mesh.FindNode(node.id))
      throw std::invalid_argument("MakeFlexibleBodyModes: master id " + std::to_string(node.id) + " of interface '" +
                                  interfaces[j].name + "' is an FE node id");
    node.position = cb.master_positions_m[j] - p_ref;
    node.translation_shapes = cb.master_shapes.block(6 * j, 6, 3, nf);
    node.rotation_shapes = cb.master_shapes.block(6 * j + 3, 6, 3, nf);
    r.nodes.push_back(std::move(node));
    r.node_sets[interfaces[j].name] = {j};
  }

  // Exported FE nodes: the surface's and the named sets', in mesh order
  std::vector<std::array<int, 3>> boundary;
  if (options.export_surface_nodes || options.surface_triangles)
    boundary = BoundaryTriangles(mesh, options.split_quadratic_faces);
  std::vector<char> exported(nn, 0);
  if (options.export_surface_nodes)
    for (const auto& t : boundary)
      for (int a : t) exported[a] = 1;
  if (options.export_surface_nodes && options.split_quadratic_faces == false) {
    // Midside nodes of boundary faces are surface nodes too
    for (const auto& t : BoundaryTriangles(mesh, true))
      for (int a : t) exported[a] = 1;
  }
  for (const std::string& set : options.export_node_sets)
    for (int a : mesh.NodeSet(set)) exported[a] = 1;
  std::vector<int> fe_nodes;        // exported FE node indices
  std::vector<int> node_slot(nn, -1);  // FE node index -> index into r.nodes
  for (int a = 0; a < nn; ++a) {
    if (!exported[a]) continue;
    node_slot[a] = static_cast<int>(r.nodes.size());
    fe_nodes.push_back(a);
    FlexibleBodyModes::Node node;
    node.id = mesh.node_ids()[a];
    node.position = X.row(a).transpose();
    node.translation_shapes = Phi.middleRows(3 * a, 3);
    node.rotation_shapes = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, nf);
    r.nodes.push_back(std::move(node));
  }
  // Mesh node sets restricted to the exported nodes
  for (const auto& [name, members] : mesh.node_sets()) {
    std::vector<int> idx;
    for (int a : members)
      if (node_slot[a] >= 0) idx.push_back(node_slot[a]);
    if (idx.empty()) continue;
    const std::string key = r.node_sets.count(name) ? name + "_NODES" : name;
    r.node_sets[key] = std::move(idx);
  }
  // Boundary triangles whose nodes are all exported
  if (options.surface_triangles)
    for (const auto& t : boundary)
      if (node_slot[t[0]] >= 0 && node_slot[t[1]] >= 0 && node_slot[t[2]] >= 0)
        r.surface_triangles.push_back({node_slot[t[0]], node_slot[t[1]], node_slot[t[2]]});

  // Modal stress shapes at the exported FE nodes
  if (options.stress_modes && !fe_nodes.empty()) {
    r.stress_modes = CalcNodalStresses(mesh, Phi, fe_nodes);
    r.stress_nodes.reserve(fe_nodes.size());
    for (int a : fe_nodes) r.stress_nodes.push_back(node_slot[a]);
  }

  // Geometric stiffness of the six unit inertial load cases, body held at the reference master
  if (options.geometric_stiffness) {
    // The reduction's own solution when it carries one (from its factorization), else a solve
    if (cb.inertial_load_statics.rows() == 3 * nn && cb.inertial_load_statics.cols() == 6) {
      r.geometric_stiffness = ProjectGeometricStiffness(mesh, cb.inertial_load_statics, Phi);
    } else {
      const Eigen::MatrixXd F = InertialLoadCases(mesh, system, p_ref);
      const Eigen::MatrixXd U = SolveStaticsHeldAtInterface(mesh, system, interfaces, cb.reference_interface, F);
      r.geometric_stiffness = ProjectGeometricStiffness(mesh, U, Phi);
    }
  }
  return r;
}

}  // namespace orrery::flex

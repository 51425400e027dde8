#include "flex/box_mesher.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include <Eigen/LU>

namespace orrery::flex {
namespace {

using Lattice = Eigen::Vector3i;

// Lattice offsets (0..2) of the hex20 nodes: natural coordinate + 1 (fe_mesh.h order).
constexpr int kHexOffsets[20][3] = {
    {0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}, {1, 0, 0}, {2, 1, 0},
    {1, 2, 0}, {0, 1, 0}, {1, 0, 2}, {2, 1, 2}, {1, 2, 2}, {0, 1, 2}, {0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1}};
constexpr int kTetEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};

class LatticeNodes {
 public:
  LatticeNodes(FeMesh& mesh, const BoxMeshSpec& s) : mesh_(mesh), spec_(s) {
    for (int d = 0; d < 3; ++d) n_[d] = 2 * s.divisions[d] + 1;
    node_id_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2], 0);
  }
  // The node id at lattice point p (created on first use).
  int Id(const Lattice& p) {
    int& id = node_id_[(static_cast<std::size_t>(p(2)) * n_[1] + p(1)) * n_[0] + p(0)];
    if (id == 0) {
      id = mesh_.num_nodes() + 1;
      Eigen::Vector3d x;
      for (int d = 0; d < 3; ++d) x(d) = spec_.origin_m(d) + spec_.size_m(d) * p(d) / (n_[d] - 1);
      mesh_.AddNode(id, x);
      for (int d = 0; d < 3; ++d) {
        if (p(d) == 0) faces_[2 * d].push_back(id - 1);
        if (p(d) == n_[d] - 1) faces_[2 * d + 1].push_back(id - 1);
      }
    }
    return id;
  }
  const std::vector<int>& face(int f) const { return faces_[f]; }

 private:
  FeMesh& mesh_;
  const BoxMeshSpec& spec_;
  int n_[3];
  std::vector<int> node_id_;
  std::vector<int> faces_[6];  // node indices on XMIN, XMAX, YMIN, YMAX, ZMIN, ZMAX
};

}  // namespace

FeMesh MakeBoxMesh(const BoxMeshSpec& s) {
  for (int d = 0; d < 3; ++d)
    if (s.divisions[d] < 1 || !(s.size_m(d) > 0))
      throw std::invalid_argument("MakeBoxMesh: divisions must be >= 1 and sizes > 0");
  FeMesh mesh;
  LatticeNodes nodes(mesh, s);
  const int n_el = NodeCount(s.type);
  std::vector<int> ids(n_el);
  int element_id = 0;
  for (int k = 0; k < s.divisions[2]; ++k)
    for (int j = 0; j < s.divisions[1]; ++j)
      for (int i = 0; i < s.divisions[0]; ++i) {
        const Lattice base(2 * i, 2 * j, 2 * k);
        if (!IsTet(s.type)) {
          for (int a = 0; a < n_el; ++a)
            ids[a] = nodes.Id(base + Lattice(kHexOffsets[a][0], kHexOffsets[a][1], kHexOffsets[a][2]));
          mesh.AddElement(++element_id, s.type, ids);
          continue;
        }
        // Kuhn split: corners 0, e_p0, e_p0 + e_p1, (1,1,1) for each permutation p of the axes
        std::array<int, 3> perm{0, 1, 2};
        do {
          std::array<Lattice, 4> c;
          c[0] = Lattice::Zero();
          c[1] = c[0], c[1](perm[0]) = 2;
          c[2] = c[1], c[2](perm[1]) = 2;
          c[3] = Lattice::Constant(2);
          Eigen::Matrix3d edges;
          for (int r = 0; r < 3; ++r) edges.col(r) = (c[r + 1] - c[0]).cast<double>();
          if (edges.determinant() < 0) std::swap(c[1], c[2]);
          for (int a = 0; a < 4; ++a) ids[a] = nodes.Id(base + c[a]);
          if (s.type == ElementType::kTet10)
            for (int m = 0; m < 6; ++m) ids[4 + m] = nodes.Id(base + (c[kTetEdges[m][0]] + c[kTetEdges[m][1]]) / 2);
          mesh.AddElement(++element_id, s.type, ids);
        } while (std::next_permutation(perm.begin(), perm.end()));
      }
  // Sets
  std::vector<int> all(mesh.num_elements());
  for (int e = 0; e < mesh.num_elements(); ++e) all[e] = e;
  mesh.AddToElementSet("EALL", all);
  std::vector<int> all_nodes(mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) all_nodes[n] = n;
  mesh.AddToNodeSet("NALL", all_nodes);
  const char* face_names[6] = {"XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"};
  for (int f = 0; f < 6; ++f) mesh.AddToNodeSet(face_names[f], nodes.face(f));
  return mesh;
}

}  // namespace orrery::flex

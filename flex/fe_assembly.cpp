#include "flex/fe_assembly.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

namespace orrery::flex {
namespace {

// Nodes coupled through an element, per node (itself included), ascending: the node graph whose
// 3 x 3 blocks are the nonzeros of K. CSR: neighbours of node a are adj[start[a] .. start[a+1]).
struct NodeGraph {
  std::vector<int> start;
  std::vector<int> adj;
  int Degree(int a) const { return start[a + 1] - start[a]; }
  // Position of node b in a's list (b must be a neighbour).
  int Find(int a, int b) const {
    const auto first = adj.begin() + start[a], last = adj.begin() + start[a + 1];
    return static_cast<int>(std::lower_bound(first, last, b) - first);
  }
};

NodeGraph MakeNodeGraph(const FeMesh& mesh) {
  const int nn = mesh.num_nodes();
  // Elements of each node (CSR)
  std::vector<int> estart(nn + 1, 0);
  for (const FeElement& e : mesh.elements())
    for (int k = 0; k < NodeCount(e.type); ++k) ++estart[e.nodes[k] + 1];
  for (int a = 0; a < nn; ++a) estart[a + 1] += estart[a];
  std::vector<int> elems(estart[nn]), fill(estart.begin(), estart.end() - 1);
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    for (int k = 0; k < NodeCount(e.type); ++k) elems[fill[e.nodes[k]]++] = ei;
  }
  // Neighbours: the nodes of those elements, sorted and unique
  NodeGraph g;
  g.start.assign(nn + 1, 0);
  std::vector<int> scratch;
  for (int a = 0; a < nn; ++a) {
    scratch.clear();
    for (int j = estart[a]; j < estart[a + 1]; ++j) {
      const FeElement& e = mesh.elements()[elems[j]];
      scratch.insert(scratch.end(), e.nodes.begin(), e.nodes.begin() + NodeCount(e.type));
    }
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    g.adj.insert(g.adj.end(), scratch.begin(), scratch.end());
    g.start[a + 1] = static_cast<int>(g.adj.size());
  }
  return g;
}

// Compressed (column-major) matrix of 3 num_nodes rows with the node graph's pattern, zeros:
// every 3 x 3 block (K) or its diagonal only (M: components do not couple). Rows sorted.
Eigen::SparseMatrix<double> MakePattern(const NodeGraph& g, bool full_blocks) {
  const int nn = static_cast<int>(g.start.size()) - 1;
  const int per = full_blocks ? 3 : 1;  // rows per neighbour in a column
  Eigen::SparseMatrix<double> A(3 * nn, 3 * nn);
  A.resizeNonZeros(static_cast<Eigen::Index>(g.adj.size()) * 3 * per);
  int* outer = A.outerIndexPtr();
  int* inner = A.innerIndexPtr();
  int nz = 0;
  for (int b = 0; b < nn; ++b)
    for (int j = 0; j < 3; ++j) {
      outer[3 * b + j] = nz;
      for (int k = g.start[b]; k < g.start[b + 1]; ++k)
        for (int i = 0; i < 3; ++i)
          if (full_blocks || i == j) inner[nz++] = 3 * g.adj[k] + i;
    }
  outer[3 * nn] = nz;
  std::fill(A.valuePtr(), A.valuePtr() + nz, 0.0);
  return A;
}

}  // namespace

FeSystem AssembleFeSystem(const FeMesh& mesh, const FeAssemblyOptions& options) {
  FeSystem sys;
  std::vector<Eigen::Matrix<double, 6, 6>> D(mesh.materials().size());
  for (std::size_t m = 0; m < D.size(); ++m)
    D[m] = IsotropicElasticity(mesh.materials()[m].youngs_modulus_pa, mesh.materials()[m].poissons_ratio);

  // The pattern from the node graph, then every element added in place, in element order (the
  // sums are those of summing the element contributions in order: no triplet list, whose 16-byte
  // entries for every element coefficient took twice the memory of K itself)
  const NodeGraph g = MakeNodeGraph(mesh);
  sys.K = MakePattern(g, true);
  sys.M = MakePattern(g, false);
  const int* k_outer = sys.K.outerIndexPtr();
  const int* m_outer = sys.M.outerIndexPtr();
  double* kv = sys.K.valuePtr();
  double* mv = sys.M.valuePtr();
  std::array<int, kMaxElementNodes * kMaxElementNodes> slot{};  // (a, b): a's place among b's neighbours
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    const int mat = mesh.element_material()[ei];
    if (mat < 0)
      throw std::runtime_error("element " + std::to_string(e.id) + " (" + CalculixName(e.type) +
                               ") has no material (no solid section covers it)");
    const Eigen::MatrixX3d X = mesh.ElementPositions(ei);
    // Quality first: an inverted element would add a negative-definite block
    const ElementQuality q = CalcElementQuality(e.type, X);
    CheckElementQuality(e.id, e.type, q, options.quality);
    const double rho = mesh.materials()[mat].density_kg_m3;
    sys.volume_m3 += q.volume_m3;
    sys.mass_kg += rho * q.volume_m3;

    const Eigen::MatrixXd Ke = CalcElementStiffness(e.type, X, D[mat]);
    const Eigen::MatrixXd Me = CalcElementMass(e.type, X, rho, options.mass_quadrature);
    // Add into the global DOFs 3 node + component: column (b, j), row (a, i)
    const int n = NodeCount(e.type);
    for (int b = 0; b < n; ++b)
      for (int a = 0; a < n; ++a) slot[a * n + b] = g.Find(e.nodes[b], e.nodes[a]);
    for (int b = 0; b < n; ++b)
      for (int j = 0; j < 3; ++j) {
        const int col = 3 * e.nodes[b] + j;
        for (int a = 0; a < n; ++a) {
          const int s = slot[a * n + b];
          double* k = kv + k_outer[col] + 3 * s;
          for (int i = 0; i < 3; ++i) k[i] += Ke(3 * a + i, 3 * b + j);
          mv[m_outer[col] + s] += Me(3 * a + j, 3 * b + j);
        }
      }
  }
  return sys;
}

std::vector<int> NodeDofs(std::span<const int> node_indices) {
  std::vector<int> dofs;
  dofs.reserve(3 * node_indices.size());
  for (int n : node_indices)
    for (int d = 0; d < 3; ++d) dofs.push_back(3 * n + d);
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  return dofs;
}

}  // namespace orrery::flex

#include "flex/fe_assembly.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace orrery::flex {

FeSystem AssembleFeSystem(const FeMesh& mesh, const FeAssemblyOptions& options) {
  const int ndof = 3 * mesh.num_nodes();
  FeSystem sys;
  std::vector<Eigen::Triplet<double>> k_triplets, m_triplets;
  std::size_t reserve = 0;
  for (const FeElement& e : mesh.elements()) reserve += 9 * NodeCount(e.type) * NodeCount(e.type);
  k_triplets.reserve(reserve);
  m_triplets.reserve(reserve / 3);

  std::vector<Eigen::Matrix<double, 6, 6>> D(mesh.materials().size());
  for (std::size_t m = 0; m < D.size(); ++m)
    D[m] = IsotropicElasticity(mesh.materials()[m].youngs_modulus_pa, mesh.materials()[m].poissons_ratio);

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
    // Scatter into the global DOFs 3 node + d
    const int n = NodeCount(e.type);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int i = 0; i < 3; ++i) {
          const int row = 3 * e.nodes[a] + i;
          for (int j = 0; j < 3; ++j) k_triplets.emplace_back(row, 3 * e.nodes[b] + j, Ke(3 * a + i, 3 * b + j));
          m_triplets.emplace_back(row, 3 * e.nodes[b] + i, Me(3 * a + i, 3 * b + i));
        }
  }
  sys.K.resize(ndof, ndof);
  sys.M.resize(ndof, ndof);
  sys.K.setFromTriplets(k_triplets.begin(), k_triplets.end());
  sys.M.setFromTriplets(m_triplets.begin(), m_triplets.end());
  sys.K.makeCompressed();
  sys.M.makeCompressed();
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

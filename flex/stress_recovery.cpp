#include "flex/stress_recovery.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "flex/fe_element.h"
#include "mbd/stress_hot_spot.h"

namespace orrery::flex {

double VonMises(const Stress6& s) { return orrery::VonMises(s.data()); }

Eigen::Matrix<double, 6, Eigen::Dynamic> CalcElementNodeStresses(ElementType t, const Eigen::MatrixX3d& X,
                                                                 const Eigen::Matrix<double, 6, 6>& D,
                                                                 const Eigen::Ref<const Eigen::VectorXd>& u_e) {
  const int n = NodeCount(t);
  const Eigen::MatrixX3d xi = NaturalNodeCoordinates(t);
  Eigen::Matrix<double, 6, Eigen::Dynamic> S(6, n);
  for (int a = 0; a < n; ++a) S.col(a) = D * (CalcStrainDisplacement(t, X, xi.row(a).transpose()) * u_e);
  return S;
}

Eigen::MatrixXd CalcNodalStresses(const FeMesh& mesh, const Eigen::Ref<const Eigen::MatrixXd>& U,
                                  std::span<const int> nodes) {
  const int nn = mesh.num_nodes();
  if (U.rows() != 3 * nn)
    throw std::invalid_argument("CalcNodalStresses: displacement field has " + std::to_string(U.rows()) +
                                " rows, the mesh " + std::to_string(3 * nn) + " DOFs");
  const int ncol = static_cast<int>(U.cols());
  // Output slot of every node (-1: not wanted)
  std::vector<int> slot(nn, -1);
  int nout = 0;
  if (nodes.empty()) {
    for (int i = 0; i < nn; ++i) slot[i] = i;
    nout = nn;
  } else {
    for (int k = 0; k < static_cast<int>(nodes.size()); ++k) {
      if (nodes[k] < 0 || nodes[k] >= nn)
        throw std::invalid_argument("CalcNodalStresses: node index " + std::to_string(nodes[k]) + " out of range");
      slot[nodes[k]] = k;
    }
    nout = static_cast<int>(nodes.size());
  }
  std::vector<Eigen::Matrix<double, 6, 6>> D(mesh.materials().size());
  for (std::size_t m = 0; m < D.size(); ++m)
    D[m] = IsotropicElasticity(mesh.materials()[m].youngs_modulus_pa, mesh.materials()[m].poissons_ratio);

  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * nout, ncol);
  std::vector<int> count(nout, 0);
  Eigen::MatrixXd Ue;
  for (int ei = 0; ei < mesh.num_elements(); ++ei) {
    const FeElement& e = mesh.elements()[ei];
    const int n = NodeCount(e.type);
    // Skip elements that touch no wanted node
    bool wanted = false;
    for (int a = 0; a < n && !wanted; ++a) wanted = slot[e.nodes[a]] >= 0;
    if (!wanted) continue;
    const int mat = mesh.element_material()[ei];
    if (mat < 0) throw std::runtime_error("CalcNodalStresses: element " + std::to_string(e.id) + " has no material");
    // Element displacements of every column, node-major
    Ue.resize(3 * n, ncol);
    for (int a = 0; a < n; ++a) Ue.middleRows(3 * a, 3) = U.middleRows(3 * e.nodes[a], 3);
    const Eigen::MatrixX3d X = mesh.ElementPositions(ei);
    const Eigen::MatrixX3d xi = NaturalNodeCoordinates(e.type);
    // sigma = D B(xi_a) u_e at each wanted element node, summed into its slot
    for (int a = 0; a < n; ++a) {
      const int k = slot[e.nodes[a]];
      if (k < 0) continue;
      const Eigen::MatrixXd DB = D[mat] * CalcStrainDisplacement(e.type, X, xi.row(a).transpose());
      S.middleRows(6 * k, 6).noalias() += DB * Ue;
      ++count[k];
    }
  }
  // Mean over the elements sharing each node
  for (int k = 0; k < nout; ++k) {
    if (count[k] == 0)
      throw std::invalid_argument("CalcNodalStresses: node " +
                                  std::to_string(mesh.node_ids()[nodes.empty() ? k : nodes[k]]) +
                                  " belongs to no element");
    S.middleRows(6 * k, 6) /= count[k];
  }
  return S;
}

}  // namespace orrery::flex

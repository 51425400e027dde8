#pragma once
// Sparse assembly of the global stiffness and consistent mass matrices of an FE mesh.
//
// DOF numbering: node index i (FeMesh order) owns DOFs 3 i + {0, 1, 2} = u_x, u_y, u_z (m).
// The pattern comes from the node graph (nodes sharing an element: a 3 x 3 block of K, the
// diagonal of that block in M, whose components do not couple), and element matrices
// (fe_element.h) are added into it in place, in element order. Every block of the pattern is
// stored, zeros included. K and M are symmetric (both triangles stored, compressed, rows sorted),
// K positive semi-definite with 6 rigid-body modes for a free connected mesh, M positive definite.
// Every element is checked first (CheckElementQuality): an inverted or degenerate element stops
// the assembly with its id and the offending value.
//
// Usage:
//   FeSystem sys = AssembleFeSystem(mesh);          // mesh with materials assigned
//   Eigen::VectorXd u = ...;  double energy = 0.5 * u.dot(sys.K * u);
#include <Eigen/SparseCore>

#include "flex/fe_element.h"
#include "flex/fe_mesh.h"

namespace orrery::flex {

struct FeAssemblyOptions {
  MassQuadrature mass_quadrature = MassQuadrature::kExact;
  QualityLimits quality;
};

// Filled by AssembleFeSystem.
struct FeSystem {
  Eigen::SparseMatrix<double> K;  // (3 num_nodes)^2, N/m
  Eigen::SparseMatrix<double> M;  // (3 num_nodes)^2, kg
  double volume_m3 = 0;           // sum of element volumes
  double mass_kg = 0;             // sum of rho * element volume
};

// Throws std::runtime_error if an element has no material or fails the quality check.
FeSystem AssembleFeSystem(const FeMesh& mesh, const FeAssemblyOptions& options = {});

// The DOFs of `node_indices` (3 per node, ascending, unique).
std::vector<int> NodeDofs(std::span<const int> node_indices);

}  // namespace orrery::flex

#pragma once
// Geometric (stress, initial-stress) stiffness of linear solid elements, and the static inertial
// load cases whose stress states give a flexible body its centrifugal stiffening
// (mbd/flexible_body.h, G_c).
//
// Math (Bathe, "Finite Element Procedures", 1996, sec. 6.3.2 (K_NL of the updated Lagrangian
// formulation); Cook, Malkus, Plesha & Witt, "Concepts and Applications of FEA", 4th ed., ch. 18):
// the second-order strain energy of displacements u in a prestress sigma is
//   U_sigma = 1/2 int sum_i (grad u_i)^T sigma (grad u_i) dV = 1/2 u^T K_sigma u,
//   K_sigma = int G^T S G dV,  G = d(u_x, u_y, u_z)/dx (9 x 3n),  S = diag(sigma, sigma, sigma),
// so that, with H_ab = int (dN_a/dx)^T sigma (dN_b/dx) dV (n x n), K_sigma = H (x) I3: block (a, b)
// is H_ab times the 3 x 3 identity (element DOFs node-major as fe_element.h). Tension (sigma > 0)
// stiffens; a compressive prestress -P/A along a column buckles it at the lowest lambda of
// (K + lambda K_sigma) phi = 0.
// Quadrature: GeometricStiffnessRule(t) = MassRule(t, kExact). On affine elements it is exact
// for a uniform stress, and for the stress of the element's own displacement field except hex20
// (grad N_a grad N_b sigma: tet4 degree 0, tet10 3 (rule 4), hex8 3 per direction (rule 3),
// hex20 6 per direction against the 3x3x3 rule's 5).
//
// Inertial load cases (the unit centrifugal body forces of mbd/flexible_body.h, per density, at
// x = p - p_origin in the mesh axes), in the order of the products
// p = (w_x^2, w_y^2, w_z^2, w_x w_y, w_y w_z, w_z w_x):
//   c = (i, i): v_c(x) = x - e_i x_i,   c = (i, j): v_c(x) = -(e_i x_j + e_j x_i),
// body force rho v_c. v_c is linear in x, so the isoparametric interpolation of its nodal values is
// exact and the consistent load vector is F_c = M v_c (M the consistent mass of fe_assembly.h).
//
// Usage:
//   Eigen::MatrixXd F = InertialLoadCases(mesh, sys, p_ref);                   // 3N x 6
//   Eigen::MatrixXd U = SolveStaticsHeldAtInterface(mesh, sys, ifs, 0, F);     // 3N x 6
//   std::vector<Eigen::MatrixXd> G = ProjectGeometricStiffness(mesh, U, Phi);  // 6 of nf x nf
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "flex/fe_assembly.h"
#include "flex/fe_element.h"
#include "flex/fe_interface.h"
#include "flex/fe_mesh.h"

namespace orrery::flex {

// The quadrature rule of the geometric stiffness (MassRule(t, kExact), see above).
const QuadratureRule& GeometricStiffnessRule(ElementType t);

// Element geometric stiffness (3n x 3n, symmetric). X: n x 3 node positions (m). stress: Voigt
// (xx, yy, zz, xy, yz, zx) Pa, one column per point of GeometricStiffnessRule(t), or a single
// column for a uniform stress. Throws std::invalid_argument for another column count.
Eigen::MatrixXd CalcElementGeometricStiffness(ElementType t, const Eigen::MatrixX3d& X,
                                              const Eigen::Ref<const Eigen::Matrix<double, 6, Eigen::Dynamic>>& stress);

// Global K_sigma ((3 num_nodes)^2, both triangles) of a uniform prestress `stress` (Voigt, Pa).
Eigen::SparseMatrix<double> AssembleUniformGeometricStiffness(const FeMesh& mesh,
                                                              const Eigen::Matrix<double, 6, 1>& stress);
// Global K_sigma of the stress field sigma = D B u of the displacements u (3 num_nodes, m),
// evaluated at the rule's points of every element. Throws std::invalid_argument for a wrong size,
// std::runtime_error for an element without material.
Eigen::SparseMatrix<double> AssembleGeometricStiffness(const FeMesh& mesh, const Eigen::Ref<const Eigen::VectorXd>& u);

// Projected geometric stiffness of several stress states without assembling K_sigma:
// G_c = Phi^T K_sigma(sigma(U.col(c))) Phi for every column c of U (3 num_nodes x ncase), summed
// element by element. Phi: 3 num_nodes x nf. Returns ncase symmetric nf x nf matrices.
std::vector<Eigen::MatrixXd> ProjectGeometricStiffness(const FeMesh& mesh, const Eigen::Ref<const Eigen::MatrixXd>& U,
                                                       const Eigen::Ref<const Eigen::MatrixXd>& Phi);

// Consistent nodal forces of the six unit inertial load cases (3 num_nodes x 6, N per
// (rad/s)^2), positions taken from p_origin_m (the body frame's origin).
Eigen::MatrixXd InertialLoadCases(const FeMesh& mesh, const FeSystem& system, const Eigen::Vector3d& p_origin_m);

// Static displacements (3 num_nodes x ncol) under the nodal loads F (3 num_nodes x ncol) with the
// master of interfaces[reference] held fixed and the other masters free: the body clamped as the
// Craig-Bampton reduction holds it (interface transform of fe_interface.h, reference master
// columns removed, sparse Cholesky). Throws std::invalid_argument for a bad reference or size,
// std::runtime_error if the held interface does not hold the body (singular stiffness).
Eigen::MatrixXd SolveStaticsHeldAtInterface(const FeMesh& mesh, const FeSystem& system,
                                            std::span<const FeInterface> interfaces, int reference,
                                            const Eigen::Ref<const Eigen::MatrixXd>& F);

}  // namespace orrery::flex

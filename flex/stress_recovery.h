#pragma once
// Stresses of a linear elastic FE solid from a nodal displacement field: at the nodes of each
// element, then averaged over the elements that share a node; von Mises equivalent stress.
//
// Math (Zienkiewicz & Taylor, "The Finite Element Method", vol. 1, 6th ed., ch. 6 and 14):
//   sigma = D B(xi_a) u_e at the natural coordinates xi_a of element node a (fe_element.h),
//   i.e. the element's own stress field evaluated at its nodes (no extrapolation from Gauss
//   points; both agree for fields the element represents exactly, e.g. linear strain in a
//   hex20). The nodal value is the unweighted mean over the elements sharing the node.
// Stress order (Voigt, engineering, as in mbd/flexible_body.h): (xx, yy, zz, xy, yz, zx), Pa.
//   von Mises: s_vm = sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2
//                          + 3 (s_xy^2 + s_yz^2 + s_zx^2)).
//
// Usage:
//   Eigen::MatrixXd S = CalcNodalStresses(mesh, u);          // u: 3 N x 1 -> S: 6 N x 1
//   double vm = VonMises(S.block<6, 1>(6 * i, 0));
//   Eigen::MatrixXd Sm = CalcNodalStresses(mesh, Phi, nodes);  // 6 n x nf stress modes
#include <span>

#include <Eigen/Core>

#include "flex/fe_mesh.h"

namespace orrery::flex {

using Stress6 = Eigen::Matrix<double, 6, 1>;

// Von Mises equivalent stress (Pa) of a stress in Voigt order (xx, yy, zz, xy, yz, zx): the
// formula of mbd/stress_hot_spot.h's VonMises, which the result recorder's hot spot uses.
double VonMises(const Stress6& s);

// Stresses at the nodes of one element (6 x NodeCount(t), one column per element node, Pa).
// X: node positions (NodeCount x 3, m); D: elasticity (6 x 6); u_e: element DOFs (3 NodeCount,
// node-major, m).
Eigen::Matrix<double, 6, Eigen::Dynamic> CalcElementNodeStresses(ElementType t, const Eigen::MatrixX3d& X,
                                                                 const Eigen::Matrix<double, 6, 6>& D,
                                                                 const Eigen::Ref<const Eigen::VectorXd>& u_e);

// Nodal stresses averaged over the elements sharing each node, for every column of U
// (3 num_nodes x ncol displacement fields, DOF 3 i + d as fe_assembly.h). `nodes` selects the
// output nodes (node indices; empty: all nodes in mesh order); only elements touching them are
// evaluated. Returns 6 n x ncol, rows 6 k .. 6 k + 5 for nodes[k] (Pa per unit of U's columns).
// Throws std::invalid_argument if U has the wrong number of rows, a node index is out of range
// or a node belongs to no element; std::runtime_error if an element has no material.
Eigen::MatrixXd CalcNodalStresses(const FeMesh& mesh, const Eigen::Ref<const Eigen::MatrixXd>& U,
                                  std::span<const int> nodes = {});

}  // namespace orrery::flex

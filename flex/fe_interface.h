#pragma once
// Interfaces of an FE body: a node set tied to a 6-DOF master node by an RBE2 (rigid spider) or an
// RBE3 (weighted average), and the coordinate change that makes the master DOFs independent
// coordinates (the boundary DOFs of a Craig-Bampton reduction, craig_bampton.h).
//
// Master DOFs: u_m = (u_x, u_y, u_z, theta_x, theta_y, theta_z) (m, rad), small rotations, at the
// master position p_m (default: the centroid of the slave nodes, unweighted).
// Rigid kinematic matrix of slave nodes s (3 ns x 6), r_s = x_s - p_m:
//   u_s = u_m + theta_m x r_s = G u_m,   G_s = [I3, -skew(r_s)].
//
// RBE2: the slaves follow the master rigidly, u_s = G u_m. The slave DOFs are dependent; the master
//   DOFs replace them. A fixed RBE2 master clamps its nodes.
// RBE3 (translational slave DOFs, weights w_s > 0 per node, W = diag(w_s I3)): the master motion is
//   the weighted least-squares rigid fit of the slave motions,
//     u_m = R u_s,   R = (G^T W G)^-1 G^T W   (6 x 3 ns),  R G = I6,
//   so the master translation is the weighted mean of the slave translations about p_m and its
//   rotation the weighted mean rotation. A master load f_m reaches the slaves as f_s = R^T f_m =
//   W G (G^T W G)^-1 f_m (the standard RBE3 load distribution, statically equivalent to f_m). The
//   RBE3 adds no stiffness: the slaves keep every deformation with R u_s = 0.
//   Coordinate change (Nastran's "UM" choice of dependent DOFs): pick 6 slave DOFs d for which
//   the 6 x 6 block R_d is best conditioned (column-pivoted QR of R); the other slave DOFs z stay
//   independent (interior) coordinates and u_d = R_d^-1 (u_m - R_z z). The map (u_m, z) -> u_s is
//   invertible (apply R to G u_m + N z = 0), so the RBE3-constrained model with a free master is
//   the original FE model; with the master fixed the slaves may deform freely but their weighted
//   rigid-fit motion is zero. This is exactly the RBE3 behaviour, and it lets the reduction treat
//   both kinds alike: boundary DOFs = the 6 master DOFs of each interface.
//
// Usage:
//   std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2),
//                                   MakeInterface(mesh, "XMAX", InterfaceKind::kRbe3)};
//   InterfaceTransform t = MakeInterfaceTransform(mesh, ifs);  // u = t.T q
//   Eigen::SparseMatrix<double> Kq = InterfaceCoordinatesMatrix(t, sys.K);  // T^T K T
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "flex/fe_mesh.h"

namespace orrery::flex {

enum class InterfaceKind { kRbe2, kRbe3 };

struct FeInterface {
  std::string name;
  InterfaceKind kind = InterfaceKind::kRbe2;
  std::vector<int> nodes;                            // slave node indices (FeMesh order)
  std::vector<double> weights;                       // RBE3 weight per slave node; empty: all 1
  std::optional<Eigen::Vector3d> master_position_m;  // nullopt: centroid of the slave nodes
};

// An interface over the node set `node_set` (throws std::invalid_argument if unknown).
FeInterface MakeInterface(const FeMesh& mesh, std::string_view node_set, InterfaceKind kind);

// The master position: the given one or the centroid of the slave nodes. Throws
// std::invalid_argument for an empty node list.
Eigen::Vector3d InterfaceMasterPosition(const FeMesh& mesh, const FeInterface& interface);

// G (3 ns x 6): u_s = G u_m for a rigid motion u_m of the master at p_master_m.
Eigen::MatrixXd RigidKinematicMatrix(const FeMesh& mesh, std::span<const int> nodes,
                                     const Eigen::Vector3d& p_master_m);

// R (6 x 3 ns): the RBE3 master motion u_m = R u_s of the slave translations (any interface kind;
// the weights of `interface` are used). Throws std::invalid_argument if the slaves do not fix a
// rigid motion (fewer than 3 non-collinear nodes) or a weight is not positive.
Eigen::MatrixXd Rbe3AveragingMatrix(const FeMesh& mesh, const FeInterface& interface);

// Filled by MakeInterfaceTransform.
struct InterfaceTransform {
  // (3 num_nodes x num_coordinates): u = T q, q = [6 master DOFs of interface 0, 1, ... | interior].
  Eigen::SparseMatrix<double> T;
  int num_boundary = 0;                           // 6 x number of interfaces
  std::vector<Eigen::Vector3d> master_positions;  // (num interfaces) m
  std::vector<int> interior_dofs;                 // FE DOF of each interior coordinate (num_coord - nb)
};

// The coordinate change of the interfaces (header). Throws std::invalid_argument if interfaces
// share a node or an RBE3 is degenerate (Rbe3AveragingMatrix).
InterfaceTransform MakeInterfaceTransform(const FeMesh& mesh, std::span<const FeInterface> interfaces);

// T^T A T: a symmetric FE matrix A (both triangles stored, 3 num_nodes square) in the coordinates q
// of `t` (K_q, M_q; sorted columns), both triangles or (`upper_only`) the upper one, which is half
// the work and the storage. One pass over A's entries, each multiplied by the few entries of T's
// rows and columns that meet it (an interior coordinate is one FE DOF): the same terms as Eigen's
// product T.transpose() * A * T, summed in another order. Throws std::invalid_argument if A's
// size is not T's row count.
Eigen::SparseMatrix<double> InterfaceCoordinatesMatrix(const InterfaceTransform& t,
                                                       const Eigen::SparseMatrix<double>& A,
                                                       bool upper_only = false);

}  // namespace orrery::flex

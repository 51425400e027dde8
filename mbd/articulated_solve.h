#pragma once
// x = M(q)^-1 tau for a tree of rigid bodies without forming the mass matrix M: the
// articulated-body algorithm with zero velocities and no gravity, where its accelerations are
// M^-1 tau (Featherstone, Rigid Body Dynamics Algorithms, 2008, Sec. 7.3 and Table 7.1, here in
// world coordinates about the world origin as the rest of the pipeline, so no frame changes):
//   leaves to root:  U_j = I^A_b S_j,  D_j = S_j^T U_j,
//                    I^A_parent += I^A_b - U_j D_j^-1 U_j^T          (Factorize: positions only)
//                    u_j = tau_j - S_j^T p^A_b,  p^A_parent += p^A_b + U_j D_j^-1 u_j
//   root to leaves:  x_j = D_j^-1 (u_j - U_j^T a_parent),  a_b = a_parent + S_j x_j     (Solve)
// with I^A_b starting at the body's own inertia I_W[b], p^A_b at zero and a_world = 0; b is
// joint j's child body. A fixed joint (no coordinates) carries its child rigidly. The D_j are
// the pivots of a sparse block LDL^T of M (leaves eliminated first), positive definite exactly
// when M is.
// A 6-DOF joint (S square and invertible) hands its parent no inertia: I^A - U D^-1 U^T =
// I^A - I^A S S^-1 (I^A)^-1 S^-T S^T I^A = 0 exactly, so that term is not formed (its rounding
// would be all it adds).
// D_j is kept as its Cholesky factor (D_j^-1 applied by two triangular solves in Solve).
// Cost: Factorize about 500 flops per 6-DOF joint (U, D, the factor), Solve about 250 flops
// per 6-DOF joint, against forming M (composite inertias and nv^2 / 2 entries)
// and a dense LU of n^3 / 3. Used by generalized-alpha's velocity projection, which needs
// M^-1 G^T for the few constraint rows only.
// Sizes: per body and joint 6 x 6 blocks, sized by the constructor; Factorize and Solve never
// allocate. Preconditions: data holds CalcPositionKinematics at the positions (data.S,
// data.I_W); Solve after a successful Factorize at the same positions. Applies only to models
// without flexible bodies (their coordinates add terms to M that the recursion does not carry):
// applies() says so.
#include <vector>

#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

class ArticulatedSolve {
 public:
  explicit ArticulatedSolve(const Model& model);

  // Whether the recursion gives M^-1 for the model (no flexible bodies).
  bool applies() const { return applies_; }

  // The articulated inertias at data's positions, in the subtrees below the world where some
  // column of `rows` (n x nv: the right-hand sides Solve will be given, as rows) has a non-zero
  // entry: M is block diagonal over the world's subtrees, so M^-1 tau vanishes in the others.
  // false (Solve unusable) when a D_j is not numerically positive definite (its Cholesky pivots
  // not above 1e-13 of its largest diagonal entry): a subtree without mass or inertia along a
  // joint's motion, where M is singular.
  bool Factorize(const Model& model, const Data& data,
                 const Eigen::Ref<const Eigen::MatrixXd>& rows);

  // x = M^-1 tau (nv; x must not alias tau; tau zero outside the subtrees Factorize took).
  void Solve(const Model& model, const Data& data, const Eigen::Ref<const Eigen::VectorXd>& tau,
             Eigen::Ref<Eigen::VectorXd> x);

 private:
  using Block = Eigen::Matrix<double, 6, 6>;
  bool applies_ = false;
  std::vector<Block> inertia_;   // nbodies: articulated inertia I^A of each body's subtree
  std::vector<Block> u_block_;   // njoints: U_j (6 x nv_j in the left columns)
  std::vector<Block> cholesky_;  // njoints: L_j, D_j = L_j L_j^T (nv_j x nv_j lower, top left)
  std::vector<Eigen::Matrix<double, 6, 1>> bias_;   // nbodies: p^A (Solve)
  std::vector<Eigen::Matrix<double, 6, 1>> accel_;  // nbodies: a (Solve)
  std::vector<Eigen::Matrix<double, 6, 1>> u_;      // njoints: u_j (Solve)
  std::vector<JointIndex> root_;  // njoints: the joint on the world whose subtree holds joint j
  std::vector<char> active_;      // njoints: joint j's subtree below the world is factored
};

}  // namespace orrery

#pragma once
// Craig-Bampton reduction of an FE body with RBE2 / RBE3 interfaces (fe_interface.h), with the body
// frame attached to one interface (the reference) for the floating-frame formulation.
//
// Method (Craig & Bampton, AIAA J. 6, 1968; coordinates q = [u_b | u_i] of MakeInterfaceTransform,
// u_b the 6 master DOFs of every interface, K_q = T^T K T, M_q = T^T M T):
//   1. static constraint modes  Psi = -K_ii^-1 K_ib  (one sparse Cholesky of K_ii, one solve of
//      its 6 n_if columns);
//   2. fixed-interface normal modes  K_ii phi = w^2 M_ii phi  (SolveLowestModes: shift-invert
//      Lanczos through the same factorization, sigma = 0), kept by count and optionally by a
//      cutoff frequency;
//   3. basis  T_cb = [[I, 0], [Psi, Phi]],  K_cb = T_cb^T K_q T_cb,  M_cb = T_cb^T M_q T_cb;
//   4. body frame on the reference interface r: the rigid motions of the body are the columns
//      R = [Gamma_1; ...; Gamma_n; 0] (Gamma_j = [[I, -skew(p_j - p_r)], [0, I]]: the master
//      motion of interface j under a rigid motion u_r of the reference master; Psi maps rigid
//      boundary motions to rigid interior motions and the modal part is zero). They replace the
//      6 constraint modes of the reference interface (same span), and carry no strain energy;
//   5. re-orthogonalization: the remaining (elastic) columns E (the other interfaces' constraint
//      modes and the normal modes, i.e. the basis of the body clamped at the reference master)
//      are combined by the dense generalized eigenproblem E^T K_cb E v = w^2 E^T M_cb E v,
//      M-normalized.
// With the same factorization: the static response to the six unit centrifugal load cases with
// the reference master held (inertial_load_statics, for the geometric stiffness of
// flexible_body_modes.h), by block elimination of the other masters.
// Final coordinates: 6 rigid (translation, rotation of the reference master) followed by the
// elastic modes in ascending frequency. Reduced K = diag(0 (6), w^2); reduced M has the rigid-body
// mass matrix about the reference master in its 6 x 6 block, identity on the elastic block, and
// the inertial coupling between them. The elastic frequencies are Rayleigh-Ritz upper bounds of
// the FE model clamped at the reference master (other masters free).
// Exact for static interface loads: the constraint modes are the static response to master motion.
//
// Usage:
//   std::vector<FeInterface> ifs = {MakeInterface(mesh, "BORE", InterfaceKind::kRbe2), ...};
//   CraigBamptonModel cb = ReduceCraigBampton(mesh, AssembleFeSystem(mesh), ifs, {.num_modes = 20});
//   cb.frequencies_hz[6];   // first elastic mode
#include <span>
#include <vector>

#include <Eigen/Core>

#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_mesh.h"

namespace orrery::flex {

struct CraigBamptonOptions {
  int num_modes = 20;         // fixed-interface normal modes kept (upper bound when cutoff_hz > 0); >= 0
  double cutoff_hz = 0;       // > 0: keep only fixed-interface modes at or below this frequency
  int reference_interface = 0;
  double tolerance = 1e-10;   // Lanczos relative tolerance (FeModesOptions::tolerance)
  // Augment the fixed-interface modes with the static response of the interior (interfaces held)
  // to the 12 unit inertial loads of a moving body: translational and angular acceleration and
  // the six centrifugal products (mbd/flexible_body.h), about the reference master. Normal modes
  // converge slowly to such quasi-static deformations (the centrifugal growth of a disk lies in
  // in-plane modes far above the bending modes); with these columns they are exact. Columns
  // already spanned by the modes are dropped.
  bool inertial_load_modes = false;
};

// Filled by ReduceCraigBampton. nr = 6 + num_elastic coordinates.
struct CraigBamptonModel {
  int num_rigid = 6;
  int num_elastic = 0;               // 6 (num interfaces - 1) + number of normal modes kept
  Eigen::MatrixXd K;                 // (nr x nr) N/m, diag(0 x 6, w^2)
  Eigen::MatrixXd M;                 // (nr x nr) kg; identity on the elastic block
  Eigen::VectorXd eigenvalues;       // (nr) w^2 (rad/s)^2: 0 for the rigid coordinates
  std::vector<double> frequencies_hz;                 // (nr)
  Eigen::MatrixXd shapes;            // (3 num_nodes x nr) nodal displacement per unit coordinate
  Eigen::MatrixXd master_shapes;     // (6 num_interfaces x nr) master DOFs per unit coordinate
  std::vector<Eigen::Vector3d> master_positions_m;    // (num_interfaces)
  int reference_interface = 0;
  Eigen::VectorXd fixed_interface_eigenvalues;        // (normal modes kept) (rad/s)^2
  int num_load_modes = 0;            // inertial-load columns added (options.inertial_load_modes)
  // (3 num_nodes x 6) static displacements under InertialLoadCases(mesh, system, reference master
  // position) (geometric_stiffness.h) with the reference master held, the other masters free: what
  // SolveStaticsHeldAtInterface returns, from K_ii's factorization.
  Eigen::MatrixXd inertial_load_statics;
  bool cutoff_reached = false;       // cutoff_hz > 0 and a computed mode lay above it
  int lanczos_operations = 0;        // operator applications of the normal modes' Lanczos (FeModes)
  // Rigid-body mass properties from the rigid 6 x 6 block of M:
  double mass_kg = 0;
  Eigen::Vector3d p_RoCm_m = Eigen::Vector3d::Zero();  // centre of mass from the reference master
  Eigen::Matrix3d I_Ro_kgm2 = Eigen::Matrix3d::Zero(); // inertia about the reference master
};

// Throws std::invalid_argument for no interfaces, a bad reference index, num_modes < 0 or not
// fewer than the interior DOFs; std::runtime_error if K_ii is singular (the interfaces do not
// hold the body) or the eigen solve fails.
CraigBamptonModel ReduceCraigBampton(const FeMesh& mesh, const FeSystem& system,
                                     std::span<const FeInterface> interfaces, const CraigBamptonOptions& options);

}  // namespace orrery::flex

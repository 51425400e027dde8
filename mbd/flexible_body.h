#pragma once
// A flexible body as the multibody engine sees it: a rigid body frame B on the joint tree plus
// nf modal coordinates q_f (the floating frame of reference, seed 003 eqs. 5-11). A material
// point at x (undeformed, in B) sits at
//   r_P = r_B + R_WB (x + Phi(x) q_f).
// The reduction (flex/: Craig-Bampton, invariants, stress modes) fills `FlexibleBodyModes`; the
// engine needs nothing else. Every volume integral below is over the undeformed body with the
// density rho; with a consistent FE mass matrix they are exact for the interpolated fields.
//
// Equations (B axes, about the origin of B; u = x + Phi q_f, w = Phi q_f-dot, omega and alpha
// the angular velocity and acceleration, a_B the acceleration of B's origin):
//   force:   m a_B + alpha x S + omega x (omega x S) + 2 omega x (I2 q_f-dot) + I2 q_f-ddot
//   moment:  S x a_B + J alpha + omega x J omega + 2 (tr C 1 - C^T) omega + L q_f-ddot
//   modes:   I2^T a_B + L^T alpha + h_w + M_ff q_f-ddot + D q_f-dot + (K + K_g(omega)) q_f
// with S = I1 + I2 q_f (first moment), U = int rho u u^T = I3 + sum_k q_k (I4_k + I4_k^T)
// + sum_kl q_k q_l I5_kl, J = tr(U) 1 - U, L_l = int rho u x Phi_l, C = int rho u w^T,
// h_w,l = omega^T D_l omega - |omega|^2 tr D_l + 2 omega . sum_m q-dot_m int rho Phi_m x Phi_l,
// D_l = int rho u Phi_l^T. The engine evaluates these from the invariants (Shabana, "Dynamics of
// Multibody Systems", 4th ed., ch. 5) in CalcInverseDynamics and CalcMassMatrix.
//
// Geometric (centrifugal) stiffening: K_g(omega) = sum_c p_c(omega) G_c over the six products
// p = (w_x^2, w_y^2, w_z^2, w_x w_y, w_y w_z, w_z w_x) of omega in B, G_c the modal geometric
// stiffness of the stress state of a unit load case c, the body force density
//   c = (i, i): rho (x - e_i x_i)       c = (i, j), i != j: -rho (e_i x_j + e_j x_i)
// with B's interface held (the centrifugal body force is sum_c p_c b_c).
#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mbd/spatial.h"

namespace orrery {

struct FlexibleBodyModes {
  int nf = 0;  // modal coordinates

  // Inertia invariants (kg, kg m, kg m^2), in B.
  double mass = 0;
  Vec3 I1 = Vec3::Zero();                   // int rho x dV
  Mat3 I3 = Mat3::Zero();                   // int rho x x^T dV
  Eigen::Matrix<double, 3, Eigen::Dynamic> I2;  // 3 x nf: int rho Phi dV
  std::vector<Mat3> I4;                     // nf: int rho x Phi_k^T dV
  std::vector<Mat3> I5;                     // nf * nf, index k * nf + l: int rho Phi_k Phi_l^T dV

  // Modal stiffness and damping (nf x nf; the reduction makes K diagonal and M_ff = identity for
  // mass-normalized modes; the engine takes M_ff(k, l) = tr I5_kl as given).
  Eigen::MatrixXd stiffness;
  Eigen::MatrixXd damping;  // may be empty: then FlexibleBodyOptions' damping applies
  std::vector<Eigen::MatrixXd> geometric_stiffness;  // empty, or 6 (nf x nf) G_c, see above

  // Nodes the engine may attach frames to, write out, or draw: undeformed position in B,
  // translation shapes Phi_P (3 x nf) and rotation shapes Psi_P (3 x nf, small rotations; zero
  // for plain solid nodes, the master rotations for interface nodes).
  struct Node {
    int id = 0;  // the FE node id (or the interface's master id)
    Vec3 position = Vec3::Zero();
    Eigen::Matrix<double, 3, Eigen::Dynamic> translation_shapes;
    Eigen::Matrix<double, 3, Eigen::Dynamic> rotation_shapes;
  };
  std::vector<Node> nodes;
  std::map<std::string, std::vector<int>> node_sets;  // name -> indices into `nodes`
  std::vector<std::array<int, 3>> surface_triangles;  // indices into `nodes`, outward normals

  // Modal stress shapes at stress points (indices into `nodes`): stress_modes is 6 n x nf,
  // rows (xx, yy, zz, xy, yz, zx) of point i at 6 i (Pa per unit modal coordinate).
  std::vector<int> stress_nodes;
  Eigen::MatrixXd stress_modes;

  // For output and checks: the eigenfrequencies of the reduced model (Hz), one per mode.
  std::vector<double> frequencies_hz;
};

// Throws std::invalid_argument naming the body and the inconsistent field (sizes, symmetric
// positive semi-definite K, positive mass).
void ValidateFlexibleBodyModes(const std::string& body, const FlexibleBodyModes& modes);

struct FlexibleBodyOptions {
  // Modal damping used when modes.damping is empty: per-mode ratios (one value for all, or nf
  // values; D = diag(2 zeta_k sqrt(k_k m_k))) or Rayleigh D = alpha M_ff + beta K.
  std::vector<double> damping_ratios;
  double rayleigh_alpha = 0, rayleigh_beta = 0;
  bool geometric_stiffening = false;  // needs modes.geometric_stiffness
  bool frozen = false;                // modal coordinates held at zero (the rigid body)
  // Output: deformed surface positions every output step (for the XDMF animation; 3 doubles per
  // surface node per row, so large surfaces make large files).
  bool record_surface = false;
  // Output: elastic displacements (body frame B, m) of the nodes of these node sets every output
  // step, /flexible_bodies/<name>/node_sets/<set>/displacement (3 columns per node).
  std::vector<std::string> record_node_sets;
};

}  // namespace orrery

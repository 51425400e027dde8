#pragma once
// Isoparametric linear elastic solid elements: shape functions, quadrature rules, element
// stiffness and consistent mass matrices, element quality.
//
// Math (Zienkiewicz & Taylor, "The Finite Element Method", vol. 1, 6th ed., ch. 6 and 9;
// Hughes, "The Finite Element Method", 2000, ch. 3):
//   x(xi) = sum_a N_a(xi) x_a,  J_ij = dx_j / dxi_i,  dN/dx = J^-1 dN/dxi,
//   K_e = int B^T D B dV,  M_e = rho int N^T N dV  (3x3 identity blocks),
//   strain in Voigt order [xx, yy, zz, xy, yz, zx] with engineering shears (gamma = 2 eps),
//   D = isotropic: lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
// Element DOFs are node-major: [u_x, u_y, u_z] of node 1, then node 2, ...
//
// Quadrature (stiffness; the CalculiX rules of C3D4, C3D10, C3D8, C3D20):
//   tet4 1 point, tet10 4 points (degree 2), hex8 2x2x2 and hex20 3x3x3 Gauss-Legendre.
// Consistent mass, MassQuadrature::kExact: N^T N integrated exactly on undistorted (affine)
// elements: hex8 2x2x2 (degree 3 per direction), hex20 3x3x3 (degree 5), tets by a collapsed
// (Duffy) Gauss product rule: xi = u, eta = v (1 - u), zeta = w (1 - u)(1 - v) with Jacobian
// (1 - u)^2 (1 - v) and n Gauss points per direction on [0, 1]; a polynomial of degree p in
// (xi, eta, zeta) becomes degree p + 2 in u, so n = 3 (tet4, p = 2) and n = 4 (tet10, p = 4) are
// exact. MassQuadrature::kStiffnessRule uses the stiffness rule for the mass as well, which is
// what CalculiX 2.20 does (e_c3d.f: one loop over the stiffness points fills both matrices); for
// tets it under-integrates N^T N (tet4 1 point: rank 1 per element; tet10 4 points: rank 4).
//
// Usage:
//   Eigen::MatrixX3d X = mesh.ElementPositions(e);            // n x 3
//   Eigen::MatrixXd K = CalcElementStiffness(type, X, IsotropicElasticity(E, nu));
//   Eigen::MatrixXd M = CalcElementMass(type, X, rho);
#include <string>
#include <vector>

#include <Eigen/Core>

#include "flex/fe_mesh.h"

namespace orrery::flex {

enum class MassQuadrature { kExact, kStiffnessRule };

struct QuadratureRule {
  std::vector<Eigen::Vector3d> points;  // natural coordinates
  std::vector<double> weights;          // sum: 1/6 (tets), 8 (hexes)
};

// Gauss-Legendre rule with n points on [-1, 1] (n >= 1; Newton on the Legendre polynomial).
void GaussLegendre(int n, std::vector<double>& points, std::vector<double>& weights);

const QuadratureRule& StiffnessRule(ElementType t);
const QuadratureRule& MassRule(ElementType t, MassQuadrature q = MassQuadrature::kExact);

// Natural coordinates of the nodes of type t (NodeCount x 3).
Eigen::MatrixX3d NaturalNodeCoordinates(ElementType t);

// Shape functions at natural point xi: N (NodeCount) and dN/dxi (NodeCount x 3).
void EvalShapeFunctions(ElementType t, const Eigen::Vector3d& xi, Eigen::VectorXd& N, Eigen::MatrixX3d& dN_dxi);

// The 8-node serendipity face of a hex20 element (a BoundaryFace's corners 0-3, then its midside
// nodes 0-3 on the edges 0-1, 1-2, 2-3, 3-0; flexible_body_modes.h): shape functions N and their
// derivatives in the face coordinates (xi, eta) in [-1, 1]^2, corners at (-1,-1), (1,-1), (1,1),
// (-1,1) (Zienkiewicz & Taylor, The Finite Element Method vol. 1, sec. 8.6).
void QuadFaceShape8(double xi, double eta, double N[8], double dN_dxi[8], double dN_deta[8]);

// Isotropic elasticity matrix (6 x 6, Voigt order above). Throws std::invalid_argument for
// E <= 0 or nu outside (-1, 0.5).
Eigen::Matrix<double, 6, 6> IsotropicElasticity(double youngs_modulus_pa, double poissons_ratio);

// Strain-displacement matrix B (6 x 3n) at xi, with det J; X: node positions (n x 3).
Eigen::MatrixXd CalcStrainDisplacement(ElementType t, const Eigen::MatrixX3d& X, const Eigen::Vector3d& xi,
                                       double* det_J = nullptr);

// Element stiffness (3n x 3n, symmetric) by the stiffness rule. X: n x 3 node positions (m).
Eigen::MatrixXd CalcElementStiffness(ElementType t, const Eigen::MatrixX3d& X, const Eigen::Matrix<double, 6, 6>& D);
// Consistent element mass (3n x 3n, symmetric).
Eigen::MatrixXd CalcElementMass(ElementType t, const Eigen::MatrixX3d& X, double density_kg_m3,
                                MassQuadrature q = MassQuadrature::kExact);

// Volume (m^3) by the exact mass rule.
double CalcElementVolume(ElementType t, const Eigen::MatrixX3d& X);

// Element quality measures. Jacobian determinants are sampled at the points of the stiffness
// and the mass rules.
struct ElementQuality {
  double volume_m3 = 0;
  double min_det_J = 0, max_det_J = 0;
  int min_det_J_point = 0;          // index into the sampled points (stiffness rule first)
  double relative_volume = 0;       // volume / (mean corner-edge length)^3
  double aspect_ratio = 0;          // longest / shortest corner edge
  double jacobian_ratio = 0;        // max det J / min det J (inf if min <= 0)
};
ElementQuality CalcElementQuality(ElementType t, const Eigen::MatrixX3d& X);

// Limits of CheckElementQuality. An undistorted tet has relative volume 0.118 (regular) and a
// cube 1; Jacobian ratio 1 for affine elements.
struct QualityLimits {
  double min_relative_volume = 1e-6;
  double max_aspect_ratio = 1e3;
  double max_jacobian_ratio = 1e2;
};

// Throws std::runtime_error "element <id> (<C3Dx>): inverted ..." (a det J <= 0), "... degenerate
// ..." (relative volume below the limit), "... aspect ratio ..." or "... Jacobian ratio ...",
// each with the value and the limit.
void CheckElementQuality(int element_id, ElementType t, const ElementQuality& q, const QualityLimits& limits = {});

}  // namespace orrery::flex

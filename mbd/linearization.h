#pragma once
// Linear analysis about an operating point: M dv/dt + D v + K dq = f for small motions, reduced to
// independent coordinates where constraints hold, and the natural modes of the undamped system.
//
// Usage:
//   LinearModel lin = Linearize(*model, state);          // state: the operating point
//   ModalResult modes = CalcModes(lin);                   // frequencies_hz ascending
#include <vector>

#include <Eigen/Core>

#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {

struct LinearModel {
  // In the velocity-space coordinates of the model (nv); position perturbations are
  // q (+) dq (exponential map for quaternions).
  Eigen::MatrixXd M;  // nv x nv: mass matrix at the operating point
  Eigen::MatrixXd K;  // nv x nv: d(M vdot + C - Q + G^T lambda)/d(dq), central differences
  Eigen::MatrixXd D;  // nv x nv: d(M vdot + C - Q)/dv (damping and gyroscopic terms)
  Eigen::MatrixXd T;  // nv x nf: orthonormal basis of the null space of G (the free motions)
  Eigen::MatrixXd M_r, K_r, D_r;  // nf x nf: T^T (M, K, D) T
};

// Linearizes at `op` with accelerations `vdot` and multipliers `lambda` (zero-sized: solved for
// by the constrained dynamics at op). Perturbation step: `step` times max(1, |q|) per coordinate.
LinearModel Linearize(const Model& model, const State& op, const Eigen::VectorXd& vdot = {},
                      const Eigen::VectorXd& lambda = {}, double step = 1e-6);

struct ModalResult {
  std::vector<double> frequencies_hz;  // ascending; a negative value marks an unstable mode
  Eigen::MatrixXd shapes;              // nv x nf: mass-normalized mode shapes in model coordinates
};

// Undamped natural modes of the reduced system: K_s x = w^2 M x, K_s the symmetric part of K_r.
ModalResult CalcModes(const LinearModel& lin);

// Relative accuracy of what Linearize measures with relative step `step`: a central difference
// carries a rounding error of eps / step and a truncation error of order step^2 relative to the
// stiffness it measures (Nocedal & Wright, "Numerical Optimization", 2006, sec. 8.1), and each
// eigenvalue w^2 of CalcModes as much relative to itself. Two eigenvalues closer than 10 times
// this are one repeated eigenvalue as far as the linearization can tell (a planet-mode pair that
// symmetry makes equal splits by ~1e-11 relative at step 1e-6).
double LinearizationRelativeError(double step = 1e-6);

// Whether eigenvalues a and b (w^2, (rad/s)^2, of one CalcModes) are one repeated eigenvalue:
// |a - b| within absolute_tolerance (the eigen solver's backward error, e.g. safety n eps
// lambda_max) or within 10 LinearizationRelativeError(step) of max(|a|, |b|).
bool SameEigenvalue(double a, double b, double absolute_tolerance, double step = 1e-6);

}  // namespace orrery

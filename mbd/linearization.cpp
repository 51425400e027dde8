#include "mbd/linearization.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "mbd/dae.h"
#include "mbd/dynamics.h"
#include "mbd/evaluate.h"
#include "mbd/kinematics.h"

namespace orrery {

LinearModel Linearize(const Model& model, const State& op, const Eigen::VectorXd& vdot_in,
                      const Eigen::VectorXd& lambda_in, double step) {
  const int nv = model.nv, nc = model.n_constraints;
  DaeSystem dae(model);
  Eigen::VectorXd vdot = vdot_in, lambda = lambda_in;
  if (vdot.size() != nv || lambda.size() != nc) {
    vdot.setZero(nv);
    lambda.setZero(nc);
    dae.SolveAccelerations(op.t, op.q, op.v, vdot, lambda);
  }
  Data& d = dae.data();
  // r_v = tau_id + G^T lambda at a perturbed point.
  auto rv = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    EvaluateDynamics(model, op.t, q, v, vdot, d);
    Eigen::VectorXd r = d.tau_id;
    if (nc > 0) r += d.G.transpose() * lambda;
    return r;
  };
  LinearModel lin;
  lin.K.setZero(nv, nv);
  lin.D.setZero(nv, nv);
  const double scale = std::max(1.0, op.q.lpNorm<Eigen::Infinity>());
  for (int k = 0; k < nv; ++k) {
    const double h = step * scale;
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(nv);
    dq(k) = h;
    Eigen::VectorXd qp = op.q, qm = op.q;
    IntegratePositions(model, dq, qp);
    IntegratePositions(model, -dq, qm);
    lin.K.col(k) = (rv(qp, op.v) - rv(qm, op.v)) / (2 * h);
    const double hv = step * std::max(1.0, std::abs(op.v(k)));
    Eigen::VectorXd vp = op.v, vm = op.v;
    vp(k) += hv;
    vm(k) -= hv;
    lin.D.col(k) = (rv(op.q, vp) - rv(op.q, vm)) / (2 * hv);
  }
  // Mass matrix and constraint Jacobian at the operating point.
  EvaluateDynamics(model, op.t, op.q, op.v, vdot, d);
  CalcMassMatrix(model, d);
  lin.M = d.M;
  if (nc > 0) {
    // Null space of G: the last nv - rank columns of Q in G^T = Q R.
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(d.G.transpose());
    qr.setThreshold(1e-10);
    const int rank = static_cast<int>(qr.rank());
    const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(nv, nv);
    lin.T = Q.rightCols(nv - rank);
  } else {
    lin.T = Eigen::MatrixXd::Identity(nv, nv);
  }
  lin.M_r = lin.T.transpose() * lin.M * lin.T;
  lin.K_r = lin.T.transpose() * lin.K * lin.T;
  lin.D_r = lin.T.transpose() * lin.D * lin.T;
  return lin;
}

ModalResult CalcModes(const LinearModel& lin) {
  // No free motion (every coordinate constrained): no modes
  if (lin.M_r.rows() == 0) return {{}, Eigen::MatrixXd::Zero(lin.T.rows(), 0)};
  const Eigen::MatrixXd K = 0.5 * (lin.K_r + lin.K_r.transpose());
  const Eigen::MatrixXd M = 0.5 * (lin.M_r + lin.M_r.transpose());
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  if (eig.info() != Eigen::Success)
    throw std::runtime_error("modal analysis: the mass matrix is not positive definite");
  ModalResult r;
  const Eigen::VectorXd& w2 = eig.eigenvalues();  // ascending
  constexpr double kTwoPi = 6.283185307179586476925;
  for (int i = 0; i < w2.size(); ++i)
    r.frequencies_hz.push_back((w2(i) < 0 ? -1.0 : 1.0) * std::sqrt(std::abs(w2(i))) / kTwoPi);
  r.shapes = lin.T * eig.eigenvectors();
  return r;
}

double LinearizationRelativeError(double step) {
  return std::numeric_limits<double>::epsilon() / step + step * step;
}

bool SameEigenvalue(double a, double b, double absolute_tolerance, double step) {
  const double d = std::abs(a - b);
  return d <= absolute_tolerance || d <= 10 * LinearizationRelativeError(step) * std::max(std::abs(a), std::abs(b));
}

}  // namespace orrery

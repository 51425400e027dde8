#include "mbd/stress_hot_spot.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Eigenvalues>

#include "mbd/flexible_dynamics.h"

namespace orrery {

namespace {

// Room for the rounding of the stresses against their bound (header).
constexpr double kBoundRoom = 1e-9;

}  // namespace

StressHotSpot::StressHotSpot(const Eigen::MatrixXd& stress_modes, int nf) : nf_(nf) {
  const int n = static_cast<int>(stress_modes.rows() / 6);
  // P^1/2: sqrt(3/2) (I - 1 1^T / 3) on the normal components (P's deviatoric block has the
  // eigenvalues 0, 3/2, 3/2 on that projector), sqrt(3) I on the shear components.
  Eigen::Matrix<double, 6, 6> root = Eigen::Matrix<double, 6, 6>::Zero();
  root.topLeftCorner<3, 3>() =
      std::sqrt(1.5) * (Eigen::Matrix3d::Identity() - Eigen::Matrix3d::Constant(1.0 / 3));
  root.bottomRightCorner<3, 3>() = std::sqrt(3.0) * Eigen::Matrix3d::Identity();
  std::vector<double> coefficient(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::MatrixXd S = stress_modes.block(6 * i, 0, 6, nf);
    const Eigen::MatrixXd B = root * S;
    // |B|_2^2, the largest eigenvalue of B B^T (6 x 6).
    const Eigen::Matrix<double, 6, 6> G = B * B.transpose();
    const double largest =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(G, Eigen::EigenvaluesOnly)
            .eigenvalues()
            .maxCoeff();
    coefficient[i] = std::sqrt(std::max(0.0, largest)) * (1 + kBoundRoom) + kBoundRoom * S.norm();
  }
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(),
                   [&](int a, int b) { return coefficient[a] > coefficient[b]; });
  bound_.resize(n);
  blocks_.resize(static_cast<size_t>(n) * 6 * nf);
  for (int k = 0; k < n; ++k) {
    bound_[k] = coefficient[order_[k]];
    Eigen::Map<Eigen::MatrixXd>(blocks_.data() + static_cast<size_t>(k) * 6 * nf, 6, nf) =
        stress_modes.block(6 * order_[k], 0, 6, nf);
  }
}

StressHotSpot::Result StressHotSpot::Find(const double* q) const {
  Result r;
  const double q_norm = Eigen::Map<const Eigen::VectorXd>(q, nf_).norm();
  double sigma[6];
  for (size_t k = 0; k < order_.size(); ++k) {
    // No point from here on can reach the largest stress found (a NaN goes on to the end).
    if (bound_[k] * q_norm < r.von_mises) break;
    const int i = order_[k];
    AddColumnCombination(6, nf_, blocks_.data() + k * 6 * static_cast<size_t>(nf_), 6, q, nullptr,
                         sigma);
    const double vm = VonMises(sigma);
    ++r.points_computed;
    if (vm > r.von_mises || (vm == r.von_mises && i < r.point)) {
      r.von_mises = vm;
      r.point = i;
    }
  }
  return r;
}

}  // namespace orrery

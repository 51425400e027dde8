// The von Mises hot spot of a flexible body: the stress point with the largest von Mises stress
// of the modal stresses sigma_i = S_i q (FlexibleBodyModes::stress_modes, the rows of point i),
// as the result recorder writes it at every output row (von_mises_max).
//
// Every point's stress is a 6 x nf product, and a planet has thousands of points, while the
// maximum is reached at a few. The von Mises stress is a norm, vm(sigma) = |P^1/2 sigma| with
//   P = 3/2 (I - 1 1^T / 3) on the normal components and 3 I on the shear components
// (vm^2 = ((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 (t_xy^2 + t_yz^2 + t_zx^2)),
// so vm_i <= |P^1/2 S_i|_2 |q|. The points are taken in decreasing order of that bound's
// coefficient, and the search stops at the first whose bound is below the largest stress found:
// no point after it can reach it. The bound's coefficient carries room for the rounding of the
// products (a relative 1e-9, and 1e-9 |S_i|_F for a point whose stress P^1/2 nearly annuls),
// which is far above it (about nf times the unit roundoff of |S_i| |q|).
//
// The stresses computed are those of the full product to the bit (AddColumnCombination gives
// each row the same sums in the same order, whatever rows it is called with), and ties go to the
// lower point index as in a scan of all points: Find() returns the scan's value and point.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace orrery {

class StressHotSpot {
 public:
  // stress_modes: 6 n x (at least nf) (FlexibleBodyModes::stress_modes); nf: the modes the body
  // uses (its first nf columns).
  StressHotSpot(const Eigen::MatrixXd& stress_modes, int nf);

  struct Result {
    double von_mises = -1;  // Pa; -1 when there are no points
    int point = 0;          // index into the stress points (FlexibleBodyModes::stress_nodes)
    int points_computed = 0;
  };
  // The hot spot at modal coordinates q (nf values). Allocation-free.
  Result Find(const double* q) const;

  int points() const { return static_cast<int>(order_.size()); }

 private:
  int nf_;
  std::vector<int> order_;     // points by decreasing bound coefficient
  std::vector<double> bound_;  // the coefficients, in that order
  // Each point's 6 x nf block in that order, column-major and contiguous (a point's stress reads
  // one run of memory instead of nf columns of the 6 n rows: the stresses of a row are mostly
  // memory traffic).
  std::vector<double> blocks_;
};

// The von Mises stress of sigma = (xx, yy, zz, xy, yz, zx).
inline double VonMises(const double* x) {
  return std::sqrt(0.5 * ((x[0] - x[1]) * (x[0] - x[1]) + (x[1] - x[2]) * (x[1] - x[2]) +
                          (x[2] - x[0]) * (x[2] - x[0])) +
                   3 * (x[3] * x[3] + x[4] * x[4] + x[5] * x[5]));
}

}  // namespace orrery

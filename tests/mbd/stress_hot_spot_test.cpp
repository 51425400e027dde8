// StressHotSpot (mbd/stress_hot_spot.h): the von Mises hot spot found by bounds against two
// oracles, the scan of every point's stress that the recorder made before (the same products
// with AddColumnCombination: equal to the bit, value and point) and Eigen's product with the
// von Mises formula written out (within the rounding).
#include "mbd/stress_hot_spot.h"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "mbd/flexible_dynamics.h"

namespace orrery {
namespace {

struct Scan {
  double von_mises = -1;
  int point = 0;
};

// Every point's stress in one product, then the first largest (the recorder's former loop).
Scan ScanEveryPoint(const Eigen::MatrixXd& modes, int nf, const Eigen::VectorXd& q) {
  const int n = static_cast<int>(modes.rows() / 6);
  Eigen::VectorXd sigma(6 * n);
  AddColumnCombination(6 * n, nf, modes.data(), modes.rows(), q.data(), nullptr, sigma.data());
  Scan s;
  for (int k = 0; k < n; ++k) {
    const double vm = VonMises(sigma.data() + 6 * k);
    if (vm > s.von_mises) s = {vm, k};
  }
  return s;
}

// Find() at `trials` random modal states (the last coordinate zero when asked) against the scan:
// the same value and point to the bit.
void ExpectTheScan(const Eigen::MatrixXd& S, int nf, int trials, bool last_zero,
                   std::mt19937& rng) {
  const StressHotSpot hot(S, nf);
  std::normal_distribution<double> normal;
  for (int t = 0; t < trials; ++t) {
    Eigen::VectorXd q(nf);
    for (int c = 0; c < nf; ++c) q(c) = normal(rng);
    if (last_zero) q(nf - 1) = 0;
    const StressHotSpot::Result r = hot.Find(q.data());
    const Scan s = ScanEveryPoint(S, nf, q);
    ASSERT_EQ(r.von_mises, s.von_mises) << "trial " << t;
    ASSERT_EQ(r.point, s.point) << "trial " << t;
  }
}

// A planet-like field: 3 000 points whose stress modes fall off away from a few hot regions (a
// tooth root's stresses are tens of times the rim's), 24 modes of which the body uses 20.
Eigen::MatrixXd HotRegionModes(std::mt19937& rng) {
  const int n = 3000, modes = 24;
  std::normal_distribution<double> normal;
  Eigen::MatrixXd S(6 * n, modes);
  for (int i = 0; i < n; ++i) {
    const double from_hot = std::min({std::abs(i - 400), std::abs(i - 1500), std::abs(i - 2600)});
    const double amplitude = 2e8 * std::exp(-from_hot / 60.0) + 5e6;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < modes; ++c) S(6 * i + r, c) = amplitude * normal(rng) / (1 + 0.2 * c);
  }
  return S;
}

TEST(StressHotSpot, EqualsTheScanOfEveryPointToTheBit) {
  std::mt19937 rng(3);
  const Eigen::MatrixXd S = HotRegionModes(rng);
  const int nf = 20;
  const StressHotSpot hot(S, nf);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> exponent(-9, -3);
  long computed = 0;
  const int trials = 300;
  for (int t = 0; t < trials; ++t) {
    Eigen::VectorXd q(nf);
    for (int c = 0; c < nf; ++c) q(c) = normal(rng);
    q *= std::pow(10.0, exponent(rng));
    const StressHotSpot::Result r = hot.Find(q.data());
    const Scan s = ScanEveryPoint(S, nf, q);
    ASSERT_EQ(r.von_mises, s.von_mises) << "trial " << t;
    ASSERT_EQ(r.point, s.point) << "trial " << t;
    // Eigen's product, the formula written out: the same point, the value within the rounding.
    const Eigen::VectorXd sigma = S.leftCols(nf) * q;
    double best = -1;
    int where = 0;
    for (int k = 0; k < hot.points(); ++k) {
      const Eigen::Matrix<double, 6, 1> x = sigma.segment<6>(6 * k);
      const double vm = std::sqrt(
          0.5 * ((x(0) - x(1)) * (x(0) - x(1)) + (x(1) - x(2)) * (x(1) - x(2)) +
                 (x(2) - x(0)) * (x(2) - x(0))) +
          3 * x.tail<3>().squaredNorm());
      if (vm > best) best = vm, where = k;
    }
    EXPECT_EQ(r.point, where) << "trial " << t;
    EXPECT_NEAR(r.von_mises, best, 1e-12 * best) << "trial " << t;
    computed += r.points_computed;
  }
  // The bounds leave a small share of the points to compute.
  const double share = double(computed) / (double(trials) * hot.points());
  std::printf("points computed: %.2f %% of %d\n", 100 * share, hot.points());
  EXPECT_LT(share, 0.1);
}

// Equal stresses at several points: the lowest index, as the scan gives it, also where a higher
// one has the larger bound and is computed first (its rows differ only in a mode whose
// coordinate is zero); a point whose modes are hydrostatic (the von Mises norm annuls them,
// leaving the rounding of the product) next to zero points; coordinates that are not finite.
TEST(StressHotSpot, TiesHydrostaticPointsAndNaNsAsTheScan) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  const int n = 40, nf = 6;
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * n, nf);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < nf; ++c) S(6 * 7 + r, c) = 1e8 * normal(rng);
  for (int i : {3, 19, 31}) S.middleRows(6 * i, 6) = S.middleRows(6 * 7, 6);  // ties with 7
  S.middleRows(6 * 25, 6) = S.middleRows(6 * 7, 6);
  S.block(6 * 25, nf - 1, 6, 1) *= 100;  // the larger bound; the same stress where q(nf - 1) = 0
  for (int c = 0; c < nf; ++c) {
    const double p = 1e9 * normal(rng);
    for (int r = 0; r < 3; ++r) S(6 * 12 + r, c) = p * (1 + 1e-13 * r);  // nearly hydrostatic
  }
  const StressHotSpot hot(S, nf);
  Eigen::VectorXd tie = Eigen::VectorXd::Ones(nf);
  tie(nf - 1) = 0;
  const StressHotSpot::Result first = hot.Find(tie.data());
  EXPECT_EQ(first.point, 3);
  EXPECT_EQ(first.von_mises, ScanEveryPoint(S, nf, tie).von_mises);
  ExpectTheScan(S, nf, 50, /*last_zero=*/true, rng);
  // Only the hydrostatic point and zeros: the rounding of its stress decides, as in the scan.
  Eigen::MatrixXd H = S;
  for (int i : {3, 7, 19, 25, 31}) H.middleRows(6 * i, 6).setZero();
  ExpectTheScan(H, nf, 50, /*last_zero=*/false, rng);
  Eigen::VectorXd q = Eigen::VectorXd::Ones(nf);
  q(2) = std::numeric_limits<double>::quiet_NaN();
  const StressHotSpot::Result r = hot.Find(q.data());
  const Scan s = ScanEveryPoint(S, nf, q);
  EXPECT_EQ(r.von_mises, s.von_mises);
  EXPECT_EQ(r.point, s.point);
  EXPECT_EQ(r.points_computed, n);
}

}  // namespace
}  // namespace orrery

// Tests for mbd/linearization.cpp's grouping rule (SameEigenvalue): Linearize measures its
// stiffness by central differences with relative step h, whose rounding error eps / h and
// truncation error h^2 (Nocedal & Wright 2006, sec. 8.1) bound how far apart it can put two
// eigenvalues that symmetry makes equal. Issue 17: `orrery modes` listed a repeated planet-mode
// pair 8e-12 apart as two modes, because the grouping tolerance was absolute (1e3 n eps lambda_max)
// and the pair sat at the top of a 16-coordinate spectrum.
#include "mbd/linearization.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace orrery {
namespace {

TEST(Linearization, RelativeErrorIsTheCentralDifferencesRoundingAndTruncation) {
  const double eps = std::numeric_limits<double>::epsilon();
  EXPECT_DOUBLE_EQ(LinearizationRelativeError(1e-6), eps / 1e-6 + 1e-12);
  EXPECT_DOUBLE_EQ(LinearizationRelativeError(1e-4), eps / 1e-4 + 1e-8);
}

TEST(Linearization, APairSplitByTheLinearizationIsOneEigenvalue) {
  const double eps = std::numeric_limits<double>::epsilon();
  const double lambda_max = std::pow(2 * 3.14159265358979 * 1e4, 2);  // 10 kHz, (rad/s)^2
  const double absolute = 1e3 * 16 * eps * lambda_max;                 // 16 coordinates: 3.6e-12 lambda_max
  // The pair at the top of the spectrum, 8e-12 apart: beyond the absolute tolerance,
  // within the linearization's accuracy (2.2e-9 relative at h = 1e-6)
  const double a = lambda_max, b = lambda_max * (1 + 8e-12);
  EXPECT_GT(b - a, absolute);
  EXPECT_TRUE(SameEigenvalue(a, b, absolute));
  EXPECT_TRUE(SameEigenvalue(b, a, absolute));
  // Modes 1e-6 apart are two modes; near zero only the absolute tolerance counts
  EXPECT_FALSE(SameEigenvalue(a, a * (1 + 1e-6), absolute));
  EXPECT_TRUE(SameEigenvalue(0.0, 0.5 * absolute, absolute));
  EXPECT_FALSE(SameEigenvalue(0.0, 2 * absolute, absolute));
  // A coarser step measures less accurately and groups wider
  EXPECT_TRUE(SameEigenvalue(a, a * (1 + 1e-7), absolute, 1e-4));
}

}  // namespace
}  // namespace orrery

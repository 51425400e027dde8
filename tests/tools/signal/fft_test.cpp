// RealFft (tools/signal/fft.h) against the DFT summed term by term, the inverse against the
// input, and FastFftLength against its definition.
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/fft.h"

namespace orrery::signal {
namespace {

std::vector<double> RandomRecord(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x(n);
  for (double& v : x) v = u(rng);
  return x;
}

// X_k = sum_n x_n exp(-2 pi i k n / N), summed directly (O(N^2), the definition)
std::complex<double> DirectDft(const std::vector<double>& x, int k) {
  const int n = static_cast<int>(x.size());
  std::complex<double> sum = 0;
  for (int i = 0; i < n; ++i)
    sum += x[i] * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>((static_cast<long>(k) * i) % n) / n);
  return sum;
}

TEST(RealFft, MatchesTheDefinitionForEvenOddAndPrimeLengths) {
  for (int n : {1, 2, 3, 4, 5, 7, 8, 12, 15, 16, 17, 30, 31, 64, 97, 100, 243, 1000}) {
    const std::vector<double> x = RandomRecord(n, 7 + n);
    RealFft fft(n);
    ASSERT_EQ(fft.bins(), n / 2 + 1);
    std::vector<std::complex<double>> X(fft.bins());
    fft.Forward(x.data(), X.data());
    // Rounding of an O(N log N) transform against an O(N) sum per bin: a few ulps of sum |x|
    for (int k = 0; k < fft.bins(); ++k)
      EXPECT_LT(std::abs(X[k] - DirectDft(x, k)), 1e-12 * n) << "n = " << n << ", k = " << k;
  }
}

TEST(RealFft, InverseRecoversTheRecord) {
  for (int n : {2, 9, 16, 25, 1024, 1001}) {
    const std::vector<double> x = RandomRecord(n, 3 + n);
    RealFft fft(n);
    std::vector<std::complex<double>> X(fft.bins());
    std::vector<double> back(n);
    fft.Forward(x.data(), X.data());
    fft.Inverse(X.data(), back.data());
    for (int i = 0; i < n; ++i) EXPECT_NEAR(back[i], x[i], 1e-13 * std::sqrt(n)) << "n = " << n;
  }
}

TEST(RealFft, RejectsEmptyLength) { EXPECT_THROW(RealFft(0), std::invalid_argument); }

TEST(FastFftLength, LargestEvenFiveSmoothAtOrBelow) {
  EXPECT_EQ(FastFftLength(20000), 20000);    // 2^5 5^4
  EXPECT_EQ(FastFftLength(20001), 20000);
  EXPECT_EQ(FastFftLength(1031), 1024);       // 1031 is prime; 1030 = 2 5 103
  EXPECT_EQ(FastFftLength(17), 16);
  EXPECT_EQ(FastFftLength(2), 2);
  EXPECT_EQ(FastFftLength(3), 2);
  // Every value returned is even, 5-smooth and the largest such
  for (int n = 2; n < 3000; ++n) {
    const int m = FastFftLength(n);
    int r = m;
    for (int p : {2, 3, 5})
      while (r % p == 0) r /= p;
    ASSERT_TRUE(m % 2 == 0 && r == 1 && m <= n) << n;
    for (int k = m + 2; k <= n; k += 2) {
      int q = k;
      for (int p : {2, 3, 5})
        while (q % p == 0) q /= p;
      ASSERT_NE(q, 1) << n << ": " << k << " is larger and fast";
    }
  }
  EXPECT_THROW(FastFftLength(1), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

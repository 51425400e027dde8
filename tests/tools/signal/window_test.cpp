// Windows (tools/signal/window.h) against the figures of merit of F. J. Harris, "On the use of
// windows for harmonic analysis with the discrete Fourier transform", Proc. IEEE 66(1), 1978,
// Table 1 (rectangle and Hann: coherent gain, ENBW, scalloping loss), and the closed forms of a
// cosine sum for the flat-top window.
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/window.h"

namespace orrery::signal {
namespace {

TEST(Window, CoherentGainAndEnbwOfHarrisTable1) {
  // Harris 1978 Table 1: rectangle CG 1.00, ENBW 1.00 bins; Hanning (alpha = 2) CG 0.50, ENBW 1.50.
  // Periodic sampling makes them exact for any N
  for (int n : {16, 1000, 4097}) {
    const Window rect = MakeWindow(WindowKind::kRectangular, n);
    EXPECT_NEAR(rect.coherent_gain, 1.0, 1e-14);
    EXPECT_NEAR(rect.enbw_bins, 1.0, 1e-14);
    const Window hann = MakeWindow(WindowKind::kHann, n);
    EXPECT_NEAR(hann.coherent_gain, 0.5, 1e-14);
    EXPECT_NEAR(hann.enbw_bins, 1.5, 1e-12);
  }
}

TEST(Window, FlatTopSumsFollowItsCosineCoefficients) {
  // For w_n = sum_j (-1)^j a_j cos(2 pi j n / N), periodic: sum w = N a_0 and
  // sum w^2 = N (a_0^2 + sum_{j>0} a_j^2 / 2) (orthogonality of the cosines over a period), so
  // CG = a_0 = 0.21557895, ENBW = (a_0^2 + sum a_j^2/2) / a_0^2 = 3.7702 bins
  const double a[] = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368};
  double s2 = a[0] * a[0];
  for (int j = 1; j < 5; ++j) s2 += a[j] * a[j] / 2;
  const Window w = MakeWindow(WindowKind::kFlatTop, 2048);
  EXPECT_NEAR(w.coherent_gain, a[0], 1e-14);
  EXPECT_NEAR(w.enbw_bins, s2 / (a[0] * a[0]), 1e-12);
  EXPECT_NEAR(w.enbw_bins, 3.7702, 5e-5);
}

TEST(Window, ScallopingLossOfHarrisTable1) {
  // Harris 1978 Table 1: rectangle 3.92 dB, Hanning 1.42 dB (two decimals)
  EXPECT_NEAR(MaxScallopingLossDb(WindowKind::kRectangular), 3.92, 0.005);
  EXPECT_NEAR(MaxScallopingLossDb(WindowKind::kHann), 1.42, 0.005);
  // The flat-top window's purpose: below 0.02 dB
  EXPECT_LT(std::abs(MaxScallopingLossDb(WindowKind::kFlatTop)), 0.02);
}

TEST(Window, ResponseIsTheLargeRecordLimitOfTheWindowedDft) {
  // |sum_n w_n exp(2 pi i ν n / N)| / sum w_n, evaluated directly for N = 4096, against K(ν):
  // they differ by O(ν/N) (the Dirichlet kernel's sin(pi u / N) against pi u / N)
  const int n = 4096;
  for (WindowKind kind : {WindowKind::kRectangular, WindowKind::kHann, WindowKind::kFlatTop}) {
    const Window w = MakeWindow(kind, n);
    for (double nu : {0.0, 0.25, 0.5, 1.0, 1.5, 2.7, 4.5}) {
      std::complex<double> sum = 0;
      for (int i = 0; i < n; ++i) sum += w.w[i] * std::polar(1.0, 2.0 * std::numbers::pi * nu * i / n);
      EXPECT_NEAR(std::abs(sum) / w.sum, std::abs(WindowResponse(kind, nu)), 1e-5)
          << WindowName(kind) << " at " << nu << " bins";
    }
  }
}

TEST(Window, NamesParse) {
  EXPECT_EQ(ParseWindowKind("hann"), WindowKind::kHann);
  EXPECT_EQ(ParseWindowKind("flattop"), WindowKind::kFlatTop);
  EXPECT_EQ(ParseWindowKind("rect"), WindowKind::kRectangular);
  EXPECT_EQ(WindowName(WindowKind::kFlatTop), "flattop");
  try {
    ParseWindowKind("hamming");
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("hamming"), std::string::npos);
  }
  EXPECT_EQ(MainLobeHalfWidthBins(WindowKind::kHann), 2);
  EXPECT_THROW(MakeWindow(WindowKind::kHann, 0), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::signal

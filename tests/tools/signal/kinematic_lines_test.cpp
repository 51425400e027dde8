// Kinematic labels (tools/signal/kinematic_lines.h) on the lines of seed 003's case 1: ring
// 80.6 rad/s, sun -10 rad/s, Z_s = 22, Z_p = 14, Z_r = 50, 3 planets. From the Willis equation
// ω_c = (Z_s ω_s + Z_r ω_r)/(Z_s + Z_r) = (22·(-10) + 50·80.6)/72 = 52.917 rad/s:
//   f_c = 8.4220 Hz, f_m = Z_r |ω_r - ω_c| / 2π = 220.30 Hz, f_p^H = f_m / Z_p = 15.736 Hz,
//   f_pp = 3 |ω_r - ω_c| / 2π = 13.218 Hz (planets passing a point of the turning ring).
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "tools/signal/kinematic_lines.h"

namespace orrery::signal {
namespace {

std::vector<KinematicLine> Seed003Lines() {
  const double w_r = 80.6, w_s = -10.0;
  const double w_c = (22 * w_s + 50 * w_r) / 72.0;
  const double two_pi = 2 * std::numbers::pi;
  const double f_m = 50 * std::abs(w_r - w_c) / two_pi;
  return {
      {"f_m", f_m, LineKind::kMesh},
      {"f_c", std::abs(w_c) / two_pi, LineKind::kShaft},
      {"f_r", std::abs(w_r) / two_pi, LineKind::kShaft},
      {"f_p^H", f_m / 14, LineKind::kShaft},
      {"f_pp", 3 * std::abs(w_r - w_c) / two_pi, LineKind::kPlanetPass},
      {"f_fault S.planet", f_m / 14, LineKind::kFault},
  };
}

TEST(KinematicLines, Seed003FrequenciesAsPublished) {
  // Seed 003 case 1 reports a mesh frequency of 220.3 Hz
  const std::vector<KinematicLine> lines = Seed003Lines();
  EXPECT_NEAR(lines[0].frequency_hz, 220.3, 0.05);
  EXPECT_NEAR(lines[3].frequency_hz, 15.73, 0.01);
}

TEST(KinematicLines, LabelsLinesHarmonicsAndSidebands) {
  const std::vector<KinematicLine> lines = Seed003Lines();
  const double f_m = lines[0].frequency_hz, f_c = lines[1].frequency_hz, f_ph = lines[3].frequency_hz;
  const double f_pp = lines[4].frequency_hz;
  const double tol = 0.25;  // a 4 s record's resolution
  const auto label = [&](double f) {
    const auto m = MatchKinematicLine(f, lines, tol);
    return m ? m->label : std::string("(none)");
  };
  EXPECT_EQ(label(f_m + 0.1), "f_m");
  EXPECT_EQ(label(2 * f_m), "2 f_m");
  EXPECT_EQ(label(3 * f_c - 0.2), "3 f_c");
  // 13 f_p^H = f_m - f_p^H: the sideband (complexity 1) is simpler than the 13th harmonic
  EXPECT_EQ(label(f_m - f_ph), "1 f_m - 1 f_p^H");
  EXPECT_EQ(label(2 * f_m - f_ph), "2 f_m - 1 f_p^H");
  EXPECT_EQ(label(3 * f_m + 2 * f_pp), "3 f_m + 2 f_pp");
  // Nothing within the tolerance
  EXPECT_EQ(label(f_m + 5.0), "(none)");
  const auto m = MatchKinematicLine(2 * f_m - f_ph, lines, tol);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->harmonic, 2);
  EXPECT_EQ(m->sideband, -1);
  EXPECT_EQ(lines[m->modulator].name, "f_p^H");  // first of the equal-frequency lines
  EXPECT_NEAR(m->frequency_hz, 2 * f_m - f_ph, 1e-12);
}

TEST(KinematicLines, EqualComplexityGoesToTheClosest) {
  const std::vector<KinematicLine> lines = {{"f_a", 100, LineKind::kShaft}, {"f_b", 100.3, LineKind::kShaft}};
  EXPECT_EQ(MatchKinematicLine(100.2, lines, 0.5)->label, "f_b");
  EXPECT_EQ(MatchKinematicLine(100.1, lines, 0.5)->label, "f_a");
  // Lines without a usable frequency are skipped
  const std::vector<KinematicLine> bad = {{"f_0", 0, LineKind::kShaft}};
  EXPECT_FALSE(MatchKinematicLine(0.0, bad, 1.0));
}

TEST(KinematicLines, LabelPeaksSetsEveryLabel) {
  const std::vector<KinematicLine> lines = Seed003Lines();
  std::vector<Peak> peaks(2);
  peaks[0].frequency = lines[0].frequency_hz;
  peaks[1].frequency = 1234.0;
  peaks[1].label = "stale";
  LabelPeaks(peaks, lines, 0.25);
  EXPECT_EQ(peaks[0].label, "f_m");
  EXPECT_EQ(peaks[1].label, "");
}

TEST(KinematicLines, KindsParse) {
  EXPECT_EQ(ParseLineKind("planet_pass"), LineKind::kPlanetPass);
  EXPECT_EQ(LineKindName(LineKind::kFault), "fault");
  EXPECT_THROW(ParseLineKind("bearing"), std::invalid_argument);
  const std::vector<KinematicLine> lines = Seed003Lines();
  EXPECT_EQ(FindLine(lines, LineKind::kFault)->name, "f_fault S.planet");
  EXPECT_EQ(FindLine(lines, LineKind::kShaft, "f_r")->name, "f_r");
  EXPECT_FALSE(FindLine(lines, LineKind::kMesh, "f_m S2"));
}

}  // namespace
}  // namespace orrery::signal

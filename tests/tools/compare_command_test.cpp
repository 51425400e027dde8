// `orrery compare` (tools/cli/compare_command.h) of two synthetic planet runs
// (signal_run_files.h) that differ in their modulation index: healthy m_h = 0.05, faulty
// m_f = 0.3. Closed forms:
//   SER of a carrier amplitude-modulated with index m, each harmonic alike: m^2/2, so
//   sideband_energy_ratio = (m_f / m_h)^2 = 36;
//   RMS of (1 + m cos θ) g(θ), g = cos 14θ + 0.3 cos 28θ: sqrt(0.545 (1 + m^2/2)) (mean g^2 =
//   (1 + 0.09)/2 = 0.545, and (1 + m cos θ)^2 has no orders in common with g^2 but 0);
//   residual r = m cos θ g(θ) (the mesh orders 14, 28 removed): its kurtosis is that of cos θ
//   (3/2) times that of g, whose square has cosine coefficients b_0 = 0.545, b_14 = 0.3,
//   b_28 = 0.5, b_42 = 0.3, b_56 = 0.045, so mean g^4 = b_0^2 + (1/2) sum b_p^2 = 0.5130375 and
//   kurt g = 0.5130375 / 0.545^2; NA4 of the healthy run is 3/2 kurt g, independent of m, and the
//   faulty run's, normalized by the mean of the two residual variances (∝ m^2), is
//   NA4_h (2 m_f^2 / (m_h^2 + m_f^2))^2;
//   FM4 is undefined (null): amplitude modulation once per revolution puts nothing beyond the
//   first-order sidebands.
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/common/cli_support.h"
#include "tests/tools/signal_run_files.h"
#include "tools/cli/compare_command.h"

namespace orrery::cli {
namespace {

using test_support::GearRun;
using test_support::IsOneErrorLine;
using test_support::JsonNumber;

class CompareCommandTest : public test_support::SignalCommandTest {
 protected:
  int Compare(const CompareArgs& args) {
    std::ostringstream out, err;
    const int code = CompareCommand(args, out, err);
    out_ = out.str();
    err_ = err.str();
    return code;
  }
  CompareArgs Args() {
    CompareArgs args;
    args.healthy = Run({.modulation = 0.05}, "healthy.h5");
    args.faulty = Run({.modulation = 0.3}, "faulty.h5");
    args.signal = "/bodies/S.planet1/angular_acceleration";
    args.column = std::string("z");  // (a string, not a literal: GCC 12 -Wrestrict false positive)
    args.json = true;
    return args;
  }
  // {"healthy": a, "faulty": b} of an indicator
  std::pair<double, double> Indicator(const std::string& name) {
    const std::size_t at = out_.find("\"" + name + "\": {");
    if (at == std::string::npos) return {NAN, NAN};
    const std::string object = out_.substr(at, out_.find('}', at) - at);
    const auto value = [&](const std::string& key) {  // JSON null as NaN
      const std::size_t k = object.find("\"" + key + "\": ");
      return object.compare(k + key.size() + 4, 4, "null") == 0 ? NAN : JsonNumber(object, key);
    };
    return {value("healthy"), value("faulty")};
  }
  std::string out_, err_;
};

constexpr double kMh = 0.05, kMf = 0.3;

TEST_F(CompareCommandTest, SidebandEnergyRatioAndRecordIndicators) {
  ASSERT_EQ(Compare(Args()), 0) << err_;
  EXPECT_NEAR(JsonNumber(out_, "sideband_energy_ratio"), std::pow(kMf / kMh, 2), 1e-9 * 36);
  const std::size_t ser = out_.find("\"ser\": {");
  ASSERT_NE(ser, std::string::npos);
  EXPECT_NEAR(JsonNumber(out_.substr(ser), "healthy"), kMh * kMh / 2, 1e-12);
  EXPECT_NEAR(JsonNumber(out_.substr(ser), "faulty"), kMf * kMf / 2, 1e-12);
  EXPECT_NE(out_.find("\"name\": \"f_fault S.planet\""), std::string::npos);
  EXPECT_NE(out_.find("\"indicator_signal\": \"record\""), std::string::npos);
  EXPECT_NE(out_.find("\"tsa\": null"), std::string::npos);
  // RMS of the records (102401 samples: 32 revolutions and one sample, 1e-5 off the mean)
  const auto [rms_h, rms_f] = Indicator("rms");
  EXPECT_NEAR(rms_h, std::sqrt(0.545 * (1 + kMh * kMh / 2)), 1e-4);
  EXPECT_NEAR(rms_f, std::sqrt(0.545 * (1 + kMf * kMf / 2)), 1e-4);
  for (const char* name : {"peak", "crest_factor", "kurtosis"}) EXPECT_TRUE(std::isfinite(Indicator(name).first)) << name;
  // Without a TSA, FM0, FM4 and NA4 are null
  EXPECT_NE(out_.find("\"fm4\": {\n      \"healthy\": null,\n      \"faulty\": null"), std::string::npos) << out_;
}

TEST_F(CompareCommandTest, TsaIndicatorsOverThePlanet) {
  CompareArgs args = Args();
  args.tsa_member = "S.planet1";
  ASSERT_EQ(Compare(args), 0) << err_;
  EXPECT_NE(out_.find("\"mesh_order\": 14"), std::string::npos);
  EXPECT_NE(out_.find("\"samples_per_revolution\": 3200"), std::string::npos);
  EXPECT_NE(out_.find("\"revolutions_faulty\": 32"), std::string::npos);
  const double kurt_g = 0.5130375 / (0.545 * 0.545);
  const double na4_h = 1.5 * kurt_g;
  const auto [h, f] = Indicator("na4");
  EXPECT_NEAR(h, na4_h, 1e-6);
  EXPECT_NEAR(f, na4_h * std::pow(2 * kMf * kMf / (kMh * kMh + kMf * kMf), 2), 1e-6);
  // RMS of the TSA: the closed form exactly (whole revolutions)
  EXPECT_NEAR(Indicator("rms").second, std::sqrt(0.545 * (1 + kMf * kMf / 2)), 1e-9);
  // FM0: peak-to-peak on the TSA's grid over the mesh harmonics' amplitudes 1 + 0.3
  double lo = 1e9, hi = -1e9;
  for (int j = 0; j < 3200; ++j) {
    const double x = test_support::GearRunValue(2 * std::numbers::pi * j / 3200, kMf);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  EXPECT_NEAR(Indicator("fm0").second, (hi - lo) / 1.3, 1e-9);
  EXPECT_TRUE(std::isnan(Indicator("fm4").first));  // null
  // Text form
  args.json = false;
  ASSERT_EQ(Compare(args), 0) << err_;
  EXPECT_NE(out_.find("faulty/healthy   36 (+15.6 dB)"), std::string::npos) << out_;
  EXPECT_NE(out_.find("mesh order 14"), std::string::npos) << out_;
}

TEST_F(CompareCommandTest, ErrorsAreOneLine) {
  CompareArgs args = Args();
  // No fault line in the faulty file: named, and --modulation chooses another line
  args.faulty = Run({.modulation = 0.3, .fault_line = false}, "faulty_no_fault.h5");
  EXPECT_EQ(Compare(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {args.faulty, "/kinematics/lines", "no fault line"}));
  args.modulation = "f_p^H";
  EXPECT_EQ(Compare(args), 0) << err_;
  // No kinematic lines at all
  args = Args();
  args.faulty = Run({.lines = false}, "bare.h5");
  EXPECT_EQ(Compare(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {args.faulty, "/kinematics/lines: no kinematic lines"}));
  // A missing healthy file
  args = Args();
  args.healthy = Path("none.h5");
  EXPECT_EQ(Compare(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {Path("none.h5"), "no such file"}));
  // A TSA member that is no angle
  args = Args();
  args.tsa_member = "/bodies/S.planet1/angular_acceleration";
  EXPECT_EQ(Compare(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {Path("healthy.h5"), "/bodies/S.planet1/angular_acceleration", "not strictly monotonic"}));
  // Sidebands closer than the record resolves (t0 leaves 0.1 s: 10 Hz bins)
  args = Args();
  args.t0 = 1.9;
  EXPECT_EQ(Compare(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {Path("healthy.h5"), "not resolved"}));
}

TEST_F(CompareCommandTest, OverlayPng) {
  CompareArgs args = Args();
  args.png = Path("overlay.png");
  ASSERT_EQ(Compare(args), 0) << err_;
  EXPECT_TRUE(test_support::IsPng(args.png));
}

}  // namespace
}  // namespace orrery::cli

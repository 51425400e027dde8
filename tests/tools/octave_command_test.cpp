// `orrery octave` (tools/cli/octave_command.h): a housing acceleration of a pure sine lands in
// its one-third-octave band at 20 log10((a/√2) / 1e-6) dB (seed 000 eq. 27).
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "mbd/result_file.h"
#include "tests/common/cli_support.h"
#include "tests/tools/signal_run_files.h"
#include "tools/cli/octave_command.h"

namespace orrery::cli {
namespace {

using test_support::IsOneErrorLine;

class OctaveCommandTest : public test_support::SignalCommandTest {
 protected:
  // 1 s at 20 kHz of 0.5 sin(2π 1000 t) m/s^2
  std::string Housing() {
    const std::string path = Path("housing.h5");
    ResultFile out = ResultFile::Create(path);
    const auto t = out.AddSeries("/time", 1, "s");
    const auto a = out.AddSeries("/bodies/housing/linear_acceleration", 3, "m/s^2", {"x", "y", "z"});
    for (int i = 0; i <= 20000; ++i) {
      const double time = i / 20000.0;
      const double row[3] = {0.5 * std::sin(2 * std::numbers::pi * 1000 * time), 0, 0};
      out.Append(t, &time);
      out.Append(a, row);
    }
    return path;
  }
  int Octave(const OctaveArgs& args) {
    std::ostringstream out, err;
    const int code = OctaveCommand(args, out, err);
    out_ = out.str();
    err_ = err.str();
    return code;
  }
  std::string out_, err_;
};

TEST_F(OctaveCommandTest, SineInItsBandAtItsLevel) {
  OctaveArgs args;
  args.path = Housing();
  args.signal = "/bodies/housing/linear_acceleration";
  args.json = true;
  ASSERT_EQ(Octave(args), 0) << err_;
  EXPECT_EQ(err_, "");
  // The 1 kHz band object, then its level
  const std::size_t at = out_.find("\"nominal_hz\": 1000,");
  ASSERT_NE(at, std::string::npos) << out_.substr(0, 500);
  const double level = test_support::JsonNumber(out_.substr(at), "level_db");
  EXPECT_NEAR(level, 20 * std::log10(0.5 / std::sqrt(2.0) / 1e-6), 1e-3);
  EXPECT_NE(out_.find("\"reference\": 1e-06"), std::string::npos);
  // Text and PNG
  args.json = false;
  args.png = Path("octave.png");
  ASSERT_EQ(Octave(args), 0) << err_;
  EXPECT_NE(out_.find("        1000      891.25     1122.02"), std::string::npos) << out_;
  EXPECT_TRUE(test_support::IsPng(args.png));
}

TEST_F(OctaveCommandTest, WarnsWhenTheUnitIsNoAcceleration) {
  OctaveArgs args;
  args.path = Run({}, "run.h5");
  args.signal = "/bodies/S.planet1/angular_acceleration";
  ASSERT_EQ(Octave(args), 0) << err_;
  EXPECT_NE(err_.find("orrery: warning: " + args.path + ": /bodies/S.planet1/angular_acceleration: unit 'rad/s^2'"),
            std::string::npos) << err_;
  args.reference_given = true;
  args.reference = 1e-3;
  ASSERT_EQ(Octave(args), 0) << err_;
  EXPECT_EQ(err_, "");
  args.signal = "/nothing";
  EXPECT_EQ(Octave(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {args.path, "/nothing", "no such dataset"}));
}

}  // namespace
}  // namespace orrery::cli

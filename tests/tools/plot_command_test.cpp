// `orrery plot` (tools/cli/plot_command.h): a recorded signal and a hot-spot stress series drawn
// as PNG files by tools/plot's scripts; errors are one line naming the file and dataset.
#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "mbd/result_file.h"
#include "tests/tools/signal_run_files.h"
#include "tools/cli/plot_command.h"

namespace orrery::cli {
namespace {

using test_support::IsOneErrorLine;

class PlotCommandTest : public test_support::SignalCommandTest {
 protected:
  int Plot(const PlotArgs& args) {
    std::ostringstream out, err;
    const int code = PlotCommand(args, out, err);
    out_ = out.str();
    err_ = err.str();
    return code;
  }
  std::string out_, err_;
};

TEST_F(PlotCommandTest, SignalOverTime) {
  PlotArgs args;
  args.path = Run({}, "run.h5");
  args.signal = "/bodies/S.planet1/angular_acceleration";
  args.column = std::string("z");  // (a string, not a literal: GCC 12 -Wrestrict false positive)
  args.t0 = 1.9;
  args.png = Path("signal.png");
  ASSERT_EQ(Plot(args), 0) << err_;
  EXPECT_TRUE(test_support::IsPng(args.png));
}

TEST_F(PlotCommandTest, HotSpotStressOverTime) {
  // Stress, node, x, y, z per row, as the recorder writes /flexible_bodies/<name>/von_mises_max
  const std::string path = Path("flex.h5");
  {
    ResultFile out = ResultFile::Create(path);
    const auto t = out.AddSeries("/time", 1, "s");
    const auto s = out.AddSeries("/flexible_bodies/S.planet1/von_mises_max", 5, "Pa, 1, m, m, m", {"von_mises", "node", "x", "y", "z"});
    for (int i = 0; i <= 1000; ++i) {
      const double time = i * 1e-3;
      const double row[5] = {2e8 + 5e7 * std::sin(40 * time), 1234, 0.03, 0.001, 0.02};
      out.Append(t, &time);
      out.Append(s, row);
    }
  }
  PlotArgs args;
  args.path = path;
  args.stress = "/flexible_bodies/S.planet1/von_mises_max";
  args.png = Path("stress.png");
  ASSERT_EQ(Plot(args), 0) << err_;
  EXPECT_TRUE(test_support::IsPng(args.png));
  args.stress = "/flexible_bodies/S.planet2/von_mises_max";
  EXPECT_EQ(Plot(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {path, "/flexible_bodies/S.planet2/von_mises_max", "no such dataset"}));
  args.signal = "/time";
  EXPECT_EQ(Plot(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {"exactly one of --signal and --stress"}));
}

}  // namespace
}  // namespace orrery::cli

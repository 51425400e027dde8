// `orrery spectrum` (tools/cli/spectrum_command.h) on synthetic planet runs
// (signal_run_files.h): JSON keys, amplitudes and labels against the signal's closed form, order
// spectra, one-line errors naming the file and dataset, the PNG.
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/common/cli_support.h"
#include "tests/tools/signal_run_files.h"
#include "tools/cli/spectrum_command.h"

namespace orrery::cli {
namespace {

using test_support::GearRun;
using test_support::IsOneErrorLine;
using test_support::JsonArray;

class SpectrumCommandTest : public test_support::SignalCommandTest {
 protected:
  int Spectrum(SpectrumArgs args) {
    std::ostringstream out, err;
    const int code = SpectrumCommand(args, out, err);
    out_ = out.str();
    err_ = err.str();
    return code;
  }
  SpectrumArgs Args(const std::string& file) {
    SpectrumArgs args;
    args.path = file;
    args.signal = "/bodies/S.planet1/angular_acceleration";
    args.column = "z";
    args.json = true;
    return args;
  }
  std::string out_, err_;
};

TEST_F(SpectrumCommandTest, JsonHoldsTheSpectrumAndLabelledPeaks) {
  // m = 0.3: f_m = 224 Hz at amplitude 1, 2 f_m at 0.3, sidebands f_m -+ 16 Hz at m/2 = 0.15,
  // all on bins of 0.5 Hz (102400 samples at 51.2 kHz), read exactly through the Hann window
  ASSERT_EQ(Spectrum(Args(Run({.modulation = 0.3}, "run.h5"))), 0) << err_;
  EXPECT_EQ(err_, "");
  const std::vector<double> f = JsonArray(out_, "frequency_hz"), a = JsonArray(out_, "amplitude");
  ASSERT_EQ(f.size(), 51201u);
  ASSERT_EQ(a.size(), 51201u);
  EXPECT_DOUBLE_EQ(f[448], 224.0);
  EXPECT_NEAR(a[448], 1.0, 1e-9);
  EXPECT_NEAR(a[896], 0.3, 1e-9);
  EXPECT_NEAR(a[416], 0.15, 1e-9);
  // Peaks as objects, largest first, labelled from the file's lines
  const std::size_t peaks = out_.find("\"peaks\": [");
  ASSERT_NE(peaks, std::string::npos) << out_.substr(0, 400);
  const std::string tail = out_.substr(peaks);
  EXPECT_NEAR(test_support::JsonNumber(tail, "frequency_hz"), 224.0, 1e-6) << tail.substr(0, 300);
  EXPECT_NEAR(test_support::JsonNumber(tail, "amplitude"), 1.0, 1e-9);
  EXPECT_NE(tail.find("\"label\": \"f_m\""), std::string::npos);
  EXPECT_NE(tail.find("\"label\": \"2 f_m\""), std::string::npos);
  EXPECT_NE(tail.find("\"label\": \"1 f_m - 1 f_p^H\""), std::string::npos);
  EXPECT_NE(tail.find("\"label\": \"2 f_m + 1 f_p^H\""), std::string::npos);
  EXPECT_NE(out_.find("\"resolution_hz\": 0.5"), std::string::npos);
}

TEST_F(SpectrumCommandTest, OrderSpectrumOverThePlanetsAngle) {
  SpectrumArgs args = Args(Run({.modulation = 0.3}, "run.h5"));
  args.order_member = "S.planet1";
  args.window = "flattop";
  ASSERT_EQ(Spectrum(args), 0) << err_;
  // 32 revolutions, 3200 samples each: orders on bins of 1/32; the mesh is order 14
  const std::vector<double> order = JsonArray(out_, "order"), a = JsonArray(out_, "amplitude");
  ASSERT_EQ(order.size(), 32u * 3200 / 2 + 1);
  EXPECT_DOUBLE_EQ(order[14 * 32], 14.0);
  EXPECT_NEAR(a[14 * 32], 1.0, 1e-6);
  EXPECT_NE(out_.find("\"revolutions\": 32"), std::string::npos);
  EXPECT_NE(out_.find("\"samples_per_revolution\": 3200"), std::string::npos);
  EXPECT_NE(out_.find("\"order\": 14,"), std::string::npos);
  EXPECT_NE(out_.find("\"label\": \"f_m\""), std::string::npos);
  EXPECT_EQ(out_.find("\"frequency_hz\""), std::string::npos);
}

TEST_F(SpectrumCommandTest, WithoutKinematicLinesPeaksAreUnlabelledWithAWarning) {
  ASSERT_EQ(Spectrum(Args(Run({.lines = false}, "run.h5"))), 0) << err_;
  EXPECT_EQ(err_, "orrery: warning: " + Path("run.h5") + ": /kinematics/lines: no kinematic lines, peaks are not labelled\n");
  EXPECT_NE(out_.find("\"label\": \"\""), std::string::npos);
}

TEST_F(SpectrumCommandTest, TextTableListsThePeaks) {
  SpectrumArgs args = Args(Run({}, "run.h5"));
  args.json = false;
  args.max_peaks = 2;
  ASSERT_EQ(Spectrum(args), 0) << err_;
  // Rows "frequency  amplitude  label"
  EXPECT_NE(out_.find("      224.0000              1  f_m\n"), std::string::npos) << out_;
  EXPECT_NE(out_.find("      448.0000            0.3  2 f_m\n"), std::string::npos) << out_;
}

TEST_F(SpectrumCommandTest, ErrorsAreOneLineNamingFileAndDataset) {
  const std::string file = Run({}, "run.h5");
  SpectrumArgs args = Args(Path("missing.h5"));
  EXPECT_EQ(Spectrum(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {Path("missing.h5"), "no such file"}));
  args = Args(file);
  args.signal = "/bodies/S.ring/angular_acceleration";
  EXPECT_EQ(Spectrum(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {file, "/bodies/S.ring/angular_acceleration", "no such dataset"}));
  args = Args(file);
  args.column = "w";
  EXPECT_EQ(Spectrum(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {file, "no column 'w' (columns x, y, z)"}));
  args = Args(file);
  args.t0 = 1.9999;
  EXPECT_EQ(Spectrum(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {file, "/bodies/S.planet1/angular_acceleration", "record too short"}));
  args = Args(file);
  args.order_member = "S.sun";
  EXPECT_EQ(Spectrum(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {file, "/joints/S.sun/q", "no such dataset"}));
  args = Args(file);
  args.png = Path("no/such/dir/x.png");
  EXPECT_EQ(Spectrum(args), 1);
  EXPECT_TRUE(IsOneErrorLine(err_, {"no/such/dir/x.png", "does not exist"}));
  EXPECT_EQ(out_, "");
}

TEST_F(SpectrumCommandTest, PngThroughTheBinaryAndAMissingPython) {
  const std::string file = Run({.modulation = 0.3}, "run.h5");
  const std::string png = Path("spectrum.png");
  const auto [out, code] = test_support::RunCommand(Binary() + "spectrum \"" + file +
                                                    "\" --signal /bodies/S.planet1/angular_acceleration --column z --png \"" + png + "\"");
  ASSERT_EQ(code, 0) << out;
  EXPECT_TRUE(test_support::IsPng(png));
  // No interpreter: one line naming the Debian packages
  const auto [err, failed] = test_support::RunCommand("ORRERY_PYTHON=/nonexistent/python3 " + Binary() + "spectrum \"" + file +
                                                      "\" --signal /bodies/S.planet1/angular_acceleration --png \"" +
                                                      Path("x.png") + "\"");
  EXPECT_EQ(failed, 1);
  EXPECT_TRUE(IsOneErrorLine(err, {"/nonexistent/python3", "python3-matplotlib", "python3-numpy", "python3-h5py"}));
  // A bad window is a usage error
  EXPECT_EQ(test_support::RunCommand(Binary() + "spectrum \"" + file + "\" --signal /time --window hamming").second, 2);
}

}  // namespace
}  // namespace orrery::cli

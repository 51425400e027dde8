// Outputs of a study from result files whose contents are known in closed form: statistics of a
// ramp, the amplitude of an off-bin sine, sidebands and SER of an amplitude-modulated carrier,
// indicators of a pure sine and of its time-synchronous average, the stress hot spot.
#include "tools/study/output_extraction.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "mbd/result_file.h"

namespace orrery::study {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

class OutputExtractionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("orrery_output_extraction_" + std::to_string(getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Rows i = 0 .. 100 at t = i / 100: /ramp (x = i - 40; y = 2i; z = NaN at i = 70) in "m, m, rad"
  std::string RampFile() {
    const std::string path = Path("ramp.h5");
    ResultFile out = ResultFile::Create(path);
    const auto t = out.AddSeries("/time", 1, "s");
    const auto r = out.AddSeries("/ramp", 3, "m, m, rad", {"x", "y", "z"});
    const auto v = out.AddSeries("/flexible_bodies/B/von_mises_max", 5, "Pa, 1, m, m, m",
                                 {"value", "node", "x", "y", "z"});
    for (int i = 0; i <= 100; ++i) {
      const double time = i / 100.0;
      const double row[3] = {i - 40.0, 2.0 * i,
                             i == 70 ? std::numeric_limits<double>::quiet_NaN() : 0.0};
      const double stress[5] = {1e6 * (1 + std::sin(0.1 * i)), double(i), 0, 0, 0};
      out.Append(t, &time);
      out.Append(r, row);
      out.Append(v, stress);
    }
    out.Close();
    return path;
  }

  // 2 s at 2 kHz (4001 rows): /x = (1 + m cos 2π f_x t) cos 2π f_m t + a cos(2π f_a t + 0.3),
  // /p = cos 14θ with the member angle θ = 2π 4 t in /joints/P/q; lines f_m, f_x in the file
  static constexpr double kFs = 2000, kMesh = 100, kMod = 10, kM = 0.4, kA = 3.7, kFa = 123.4;
  std::string SignalFile() {
    const std::string path = Path("signal.h5");
    ResultFile out = ResultFile::Create(path);
    const auto t = out.AddSeries("/time", 1, "s");
    const auto x = out.AddSeries("/x", 1, "m/s^2");
    const auto am = out.AddSeries("/am", 1, "N");
    const auto p = out.AddSeries("/p", 1, "rad/s^2");
    const auto q = out.AddSeries("/joints/P/q", 1, "rad");
    for (int i = 0; i <= 4000; ++i) {
      const double time = i / kFs;
      const double carrier =
          (1 + kM * std::cos(2 * kPi * kMod * time)) * std::cos(2 * kPi * kMesh * time);
      const double value = kA * std::cos(2 * kPi * kFa * time + 0.3);
      const double theta = 2 * kPi * 4 * time, mesh = std::cos(14 * theta);
      out.Append(t, &time);
      out.Append(x, &value);
      out.Append(am, &carrier);
      out.Append(p, &mesh);
      out.Append(q, &theta);
    }
    out.WriteStrings("/kinematics/lines/name", {"f_m", "f_x"});
    out.WriteVector("/kinematics/lines/frequency_hz", {kMesh, kMod}, "Hz");
    out.WriteStrings("/kinematics/lines/kind", {"mesh", "shaft"});
    out.Close();
    return path;
  }

  static StudyOutput Output(StudyOutputKind kind, const std::string& dataset) {
    StudyOutput o;
    o.name = "o";
    o.kind = kind;
    o.dataset = dataset;
    return o;
  }
  static double Extract(const std::string& path, const StudyOutput& o,
                        std::string* unit = nullptr) {
    std::string u;
    const double v = ExtractOutput(Hdf5Reader(path), o, &u);
    if (unit != nullptr) *unit = u;
    return v;
  }

  fs::path dir_;
};

TEST_F(OutputExtractionTest, AWindowFromAFractionOfTheRun) {
  // The ramp runs t = 0 .. 1 (x = i - 40 at t = i / 100): the second half is rows 50 .. 100,
  // x = 10 .. 60, mean 35; and a fraction of 0 is the whole record (mean of -40 .. 60: 10)
  const std::string path = RampFile();
  StudyOutput o = Output(StudyOutputKind::kMean, "/ramp");
  o.from_fraction = 0.5;
  EXPECT_NEAR(Extract(path, o), 35, 1e-12);
  o.from_fraction = 0;
  EXPECT_NEAR(Extract(path, o), 10, 1e-12);
}

TEST_F(OutputExtractionTest, StatisticsOverATimeWindow) {
  const std::string path = RampFile();
  // Rows 20 .. 50 (t in [0.195, 0.505]): x = j for j = -20 .. 10
  auto window = [](StudyOutputKind kind, const std::string& column) {
    StudyOutput o = Output(kind, "/ramp");
    o.column = column;
    o.from_s = 0.195;
    o.to_s = 0.505;
    return o;
  };
  std::string unit;
  EXPECT_EQ(Extract(path, window(StudyOutputKind::kPeak, "x"), &unit), 20);
  EXPECT_EQ(unit, "m");
  EXPECT_EQ(Extract(path, window(StudyOutputKind::kMin, "x")), -20);
  EXPECT_EQ(Extract(path, window(StudyOutputKind::kMax, "0")), 10);
  EXPECT_EQ(Extract(path, window(StudyOutputKind::kFinal, "x")), 10);
  EXPECT_NEAR(Extract(path, window(StudyOutputKind::kMean, "x")), -155.0 / 31, 1e-14);
  // sum j^2 over -20 .. 10 = 2870 + 385 = 3255 over 31 rows
  EXPECT_NEAR(Extract(path, window(StudyOutputKind::kRms, "x")), std::sqrt(3255.0 / 31), 1e-13);
  EXPECT_EQ(Extract(path, window(StudyOutputKind::kMax, "y")), 100);
  // The whole record by default; a NaN in the window makes the statistic NaN
  EXPECT_EQ(Extract(path, Output(StudyOutputKind::kPeak, "/ramp")), 60);
  EXPECT_EQ(Extract(path, window(StudyOutputKind::kMax, "z"), &unit), 0);
  EXPECT_EQ(unit, "rad");
  StudyOutput nan = window(StudyOutputKind::kRms, "z");
  nan.to_s = 0.8;
  EXPECT_TRUE(std::isnan(Extract(path, nan)));
  // The stress hot spot: column 0 of von_mises_max
  StudyOutput stress = Output(StudyOutputKind::kMaxStress, "/flexible_bodies/B/von_mises_max");
  double expected = 0;
  for (int i = 0; i <= 100; ++i) expected = std::max(expected, 1e6 * (1 + std::sin(0.1 * i)));
  EXPECT_EQ(Extract(path, stress, &unit), expected);
  EXPECT_EQ(unit, "Pa");
}

TEST_F(OutputExtractionTest, AmplitudeOfAnOffBinSine) {
  const std::string path = SignalFile();
  // 123.4 Hz lies 0.8 of a bin (0.5 Hz) beyond bin 246: the Hann window reads it 1.42 dB low at
  // worst; the interpolation restores it to within the leakage of its mirror at -123.4 Hz (the
  // Hann side lobes, ~1/(2 * 246.8)^3 of the amplitude)
  StudyOutput o = Output(StudyOutputKind::kAmplitude, "/x");
  o.frequency_hz = kFa;
  std::string unit;
  const double mirror_leakage = 1 / std::pow(2 * kFa / 0.5, 3);  // 8.3e-9
  EXPECT_NEAR(Extract(path, o, &unit), kA, mirror_leakage * kA);
  EXPECT_EQ(unit, "m/s^2");
  o.window = "flattop";
  EXPECT_NEAR(Extract(path, o), kA, 1e-3 * kA);  // the flat-top's ripple, 0.01 dB at most
  // Where no line is, the leakage floor: far below
  o.window = "hann";
  o.frequency_hz = 400;
  EXPECT_LT(Extract(path, o), 1e-4 * kA);
}

TEST_F(OutputExtractionTest, LinesSidebandsAndSidebandEnergyRatio) {
  const std::string path = SignalFile();
  // (1 + m cos 2π f_x t) cos 2π f_m t = cos 2π f_m t + (m/2) [cos 2π (f_m - f_x) t + cos 2π (f_m +
  // f_x) t]
  StudyOutput o = Output(StudyOutputKind::kAmplitude, "/am");
  o.line = "f_m";
  EXPECT_NEAR(Extract(path, o), 1.0, 1e-9);
  o.sideband = -1;
  o.modulation = "f_x";
  EXPECT_NEAR(Extract(path, o), kM / 2, 1e-9);
  o.sideband = 1;
  o.modulation.clear();
  o.modulation_hz = kMod;
  EXPECT_NEAR(Extract(path, o), kM / 2, 1e-9);
  o.sideband = 2;  // nothing at f_m + 2 f_x
  EXPECT_LT(Extract(path, o), 1e-6);
  // SER of an AM carrier: m^2 / 2
  StudyOutput ser = Output(StudyOutputKind::kSidebandEnergyRatio, "/am");
  ser.mesh = "f_m";
  ser.modulation = "f_x";
  ser.sidebands = 3;
  std::string unit;
  EXPECT_NEAR(Extract(path, ser, &unit), kM * kM / 2, 1e-9);
  EXPECT_EQ(unit, "1");
  // A line the file does not have
  ser.modulation = "f_y";
  try {
    Extract(path, ser);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": /kinematics/lines: no line named 'f_y'");
  }
}

TEST_F(OutputExtractionTest, IndicatorsOfARecordAndOfItsSynchronousAverage) {
  const std::string path = SignalFile();
  // A pure sine over whole periods (200 of 100 Hz in the first 4000 samples): kurtosis 3/2,
  // crest factor sqrt(2) (a sample sits on every crest)
  StudyOutput o = Output(StudyOutputKind::kIndicator, "/am");
  o.to_s = 1.9996;
  o.dataset = "/p";  // cos 14 θ, θ = 2π 4 t: 56 Hz, 112 whole periods
  o.indicator = "kurtosis";
  EXPECT_NEAR(Extract(path, o), 1.5, 1e-9);
  o.indicator = "crest_factor";
  EXPECT_NEAR(Extract(path, o), std::sqrt(2.0), 1e-9);
  // The TSA over the member (8 revolutions) holds the mesh tone alone: RMS 1/sqrt 2, crest factor
  // sqrt 2, FM0 = peak-to-peak over the mesh amplitude = 2; up to the resampling's cubic
  // interpolation, (k h)^4 9/384 = 2.3e-5 of the amplitude for k h = 2π 56 / 2000 rad per sample
  // (tools/signal/order_resample.h)
  const double bound = std::pow(2 * kPi * 56 / kFs, 4) * 9 / 384;
  o.tsa = "P";
  o.mesh_order = 14;
  o.indicator = "rms";
  EXPECT_NEAR(Extract(path, o), 1 / std::sqrt(2.0), bound);
  o.indicator = "crest_factor";
  EXPECT_NEAR(Extract(path, o), std::sqrt(2.0), 2 * std::sqrt(2.0) * bound);
  o.indicator = "fm0";
  std::string unit;
  EXPECT_NEAR(Extract(path, o, &unit), 2.0, 4 * bound);
  EXPECT_EQ(unit, "1");
  // The mesh order from the mesh frequency over the member's speed: 56 / 4 = 14
  o.mesh_order = 0;
  o.mesh_hz = 56;
  EXPECT_NEAR(Extract(path, o), 2.0, 4 * bound);
  o.mesh_hz = 58;  // 14.5 orders: not a gear on this member
  EXPECT_THROW(Extract(path, o), std::runtime_error);
}

TEST_F(OutputExtractionTest, FailuresNameTheOutputAndTheOthersStillCount) {
  const std::string path = RampFile();
  std::vector<StudyOutput> outputs{Output(StudyOutputKind::kPeak, "/ramp"),
                                   Output(StudyOutputKind::kPeak, "/nothing"),
                                   Output(StudyOutputKind::kMean, "/ramp")};
  outputs[1].name = "missing";
  outputs[2].column = "w";
  const ExtractedOutputs x = ExtractOutputs(path, outputs);
  EXPECT_EQ(x.values[0], 60);
  EXPECT_TRUE(std::isnan(x.values[1]));
  EXPECT_TRUE(std::isnan(x.values[2]));
  EXPECT_EQ(x.error, "output 'missing': " + path + ": /nothing: no such dataset");
  // An empty window, a file that is not there
  StudyOutput late = Output(StudyOutputKind::kPeak, "/ramp");
  late.from_s = 2;
  EXPECT_EQ(ExtractOutputs(path, {late}).error,
            "output 'o': " + path +
                ": /ramp: no rows in the window [2, inf] s (the run recorded 0 to 1 s)");
  EXPECT_NE(ExtractOutputs(Path("none.h5"), {late}).error.find("none.h5"), std::string::npos);
}

}  // namespace
}  // namespace orrery::study

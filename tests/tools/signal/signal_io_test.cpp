// Signals and kinematic lines read from result files (tools/signal/signal_io.h), written here with
// mbd's ResultFile in the layout of mbd/result_recorder.h and kinematic_lines.h.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mbd/result_file.h"
#include "tools/signal/signal_io.h"

namespace orrery::signal {
namespace {

namespace fs = std::filesystem;

class SignalIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("orrery_signal_io_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // 100 rows at 1 kHz: /time, a 3-column acceleration (x = t, y = 2t, z = 3t), a joint angle
  std::string WriteRun(const std::string& name, bool lines) {
    const std::string path = (dir_ / name).string();
    ResultFile out = ResultFile::Create(path);
    const auto t = out.AddSeries("/time", 1, "s");
    const auto a = out.AddSeries("/bodies/planet/linear_acceleration", 3, "m/s^2", {"x", "y", "z"});
    const auto q = out.AddSeries("/joints/S.carrier/q", 1, "rad");
    for (int i = 0; i < 100; ++i) {
      const double time = i * 1e-3;
      const double row[3] = {time, 2 * time, 3 * time};
      const double angle = 50 * time;
      out.Append(t, &time);
      out.Append(a, row);
      out.Append(q, &angle);
    }
    if (lines) {
      out.WriteStrings("/kinematics/lines/name", {"f_m", "f_c", "f_fault S.planet"});
      out.WriteVector("/kinematics/lines/frequency_hz", {220.3, 8.42, 15.73}, "Hz");
      out.WriteStrings("/kinematics/lines/kind", {"mesh", "shaft", "fault"});
    }
    out.Close();
    return path;
  }

  // The message of what `f` throws
  template <typename F>
  std::string Error(F f) {
    try {
      f();
    } catch (const std::exception& e) {
      return e.what();
    }
    return "(no error)";
  }

  fs::path dir_;
};

TEST_F(SignalIoTest, ReadsAColumnByNameOrIndexFromT0) {
  Hdf5Reader file(WriteRun("run.h5", true));
  const RecordedSignal s = ReadSignal(file, "/bodies/planet/linear_acceleration", "z", 0.0495);
  EXPECT_EQ(s.values.size(), 50u);
  EXPECT_NEAR(s.time_s.front(), 0.050, 1e-15);
  EXPECT_NEAR(s.values.front(), 0.150, 1e-15);
  EXPECT_NEAR(s.sample_rate_hz, 1000.0, 1e-9);
  EXPECT_EQ(s.unit, "m/s^2");
  EXPECT_EQ(s.column, 2);
  EXPECT_EQ(s.column_name, "z");
  EXPECT_EQ(ReadSignal(file, "/bodies/planet/linear_acceleration", "1").column_name, "y");
  EXPECT_EQ(ReadSignal(file, "/bodies/planet/linear_acceleration").column, 0);
  // The reference angle at the same rows
  const std::vector<double> angle = ReadReferenceAngle(file, "S.carrier", s);
  ASSERT_EQ(angle.size(), 50u);
  EXPECT_NEAR(angle.front(), 2.5, 1e-12);
  EXPECT_EQ(ReferenceAnglePath("/joints/x/q"), "/joints/x/q");
}

TEST_F(SignalIoTest, ErrorsNameTheFileAndDataset) {
  const std::string path = WriteRun("run.h5", false);
  Hdf5Reader file(path);
  const std::string missing = Error([&] { ReadSignal(file, "/bodies/ring/linear_acceleration"); });
  EXPECT_NE(missing.find(path + ": /bodies/ring/linear_acceleration: no such dataset"), std::string::npos) << missing;
  const std::string column = Error([&] { ReadSignal(file, "/bodies/planet/linear_acceleration", "w"); });
  EXPECT_NE(column.find("no column 'w' (columns x, y, z)"), std::string::npos) << column;
  const std::string index = Error([&] { ReadSignal(file, "/bodies/planet/linear_acceleration", "3"); });
  EXPECT_NE(index.find("no column 3"), std::string::npos) << index;
  const std::string short_record = Error([&] { ReadSignal(file, "/bodies/planet/linear_acceleration", "", 0.09); });
  EXPECT_NE(short_record.find("record too short: 10 samples from t0 = 0.09 s"), std::string::npos) << short_record;
  const std::string lines = Error([&] { ReadKinematicLines(file); });
  EXPECT_NE(lines.find(path + ": /kinematics/lines: no kinematic lines"), std::string::npos) << lines;
  EXPECT_FALSE(HasKinematicLines(file));
  const std::string member = Error([&] { ReadReferenceAngle(file, "S.sun", ReadSignal(file, "/time")); });
  EXPECT_NE(member.find("/joints/S.sun/q: no such dataset"), std::string::npos) << member;
  EXPECT_THROW(Hdf5Reader((dir_ / "none.h5").string()), std::runtime_error);
}

TEST_F(SignalIoTest, ReadsKinematicLines) {
  Hdf5Reader file(WriteRun("run.h5", true));
  ASSERT_TRUE(HasKinematicLines(file));
  const std::vector<KinematicLine> lines = ReadKinematicLines(file);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[2].name, "f_fault S.planet");
  EXPECT_EQ(lines[2].kind, LineKind::kFault);
  EXPECT_DOUBLE_EQ(lines[0].frequency_hz, 220.3);
}

TEST_F(SignalIoTest, RejectsMalformedLines) {
  const std::string path = (dir_ / "bad.h5").string();
  {
    ResultFile out = ResultFile::Create(path);
    out.WriteStrings("/kinematics/lines/name", {"f_m", "f_c"});
    out.WriteVector("/kinematics/lines/frequency_hz", {220.3, 8.42}, "Hz");
    out.WriteStrings("/kinematics/lines/kind", {"mesh", "bearing"});
  }
  Hdf5Reader file(path);
  const std::string kind = Error([&] { ReadKinematicLines(file); });
  EXPECT_NE(kind.find("/kinematics/lines/kind: unknown kinematic line kind 'bearing'"), std::string::npos) << kind;
}

}  // namespace
}  // namespace orrery::signal

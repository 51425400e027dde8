// Study folders: FNV-1a against its published vectors, preparing, reopening and refusing folders,
// completion markers written atomically, and the index tables.
#include "tools/study/study_folder.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "mbd/hdf5_reader.h"
#include "tools/study/study_index.h"

namespace orrery::study {
namespace {

namespace fs = std::filesystem;

// Test vectors of FNV-1a 64 (L. C. Noll, the FNV reference page and draft-eastlake-fnv, test
// suite "FNV-1a 64-bit": "" -> cbf29ce484222325, "a" -> af63dc4c8601ec8c, "foobar" ->
// 85944171f73967e8)
TEST(StudyFolderTest, HashIsFnv1a64) {
  EXPECT_EQ(HashText(""), "cbf29ce484222325");
  EXPECT_EQ(HashText("a"), "af63dc4c8601ec8c");
  EXPECT_EQ(HashText("foobar"), "85944171f73967e8");
}

class StudyFolderFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("orrery_study_folder_test_" + std::to_string(getpid()) + "_" + info->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Read(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

TEST_F(StudyFolderFileTest, PreparesReopensAndRefuses) {
  std::ostringstream warn;
  const std::string folder = (dir_ / "study").string();
  StudyFolder f = StudyFolder::Prepare(folder, "s.yaml", "scene: a\n", "scene text", 7, warn);
  EXPECT_TRUE(fs::is_directory(dir_ / "study" / "runs"));
  EXPECT_EQ(Read(dir_ / "study" / "study.yaml"), "scene: a\n");
  EXPECT_EQ(Read(dir_ / "study" / "study.id"),
            "study " + HashText("scene: a\n") + "\nscene " + HashText("scene text") + "\n");
  EXPECT_EQ(f.ResultPath(3), folder + "/runs/run_00003.h5");
  EXPECT_EQ(StudyFolder::Open(folder, 123457).MarkerPath(9), folder + "/runs/run_000009.done");
  // The same study again: fine, nothing said
  StudyFolder::Prepare(folder, "s.yaml", "scene: a\n", "scene text", 7, warn);
  EXPECT_EQ(warn.str(), "");
  // A changed scene: a warning
  StudyFolder::Prepare(folder, "s.yaml", "scene: a\n", "other scene text", 7, warn);
  EXPECT_NE(warn.str().find(folder + ": the base scene changed since the study started"),
            std::string::npos)
      << warn.str();
  // Another study: refused, naming both hashes
  try {
    StudyFolder::Prepare(folder, "t.yaml", "scene: b\n", "scene text", 7, warn);
    FAIL() << "not refused";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              folder + ": holds another study (study file hash " + HashText("scene: a\n") +
                  ", t.yaml has " + HashText("scene: b\n") + "); choose another folder (-o DIR)");
  }
  EXPECT_EQ(Read(dir_ / "study" / "study.yaml"), "scene: a\n");  // untouched
  // A folder with other things in it: refused
  fs::create_directories(dir_ / "other");
  std::ofstream(dir_ / "other" / "notes.txt") << "mine";
  EXPECT_THROW(StudyFolder::Prepare((dir_ / "other").string(), "s.yaml", "x", "y", 1, warn),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(dir_ / "other" / "study.id"));
}

TEST_F(StudyFolderFileTest, MarkersAreCompleteOrAbsent) {
  std::ostringstream warn;
  const StudyFolder f = StudyFolder::Prepare((dir_ / "s").string(), "s.yaml", "x", "y", 4, warn);
  EXPECT_FALSE(f.ReadMarker(2));
  RunRecord r;
  r.run = 2;
  r.status = RunStatus::kOk;
  r.outputs = {4.25};
  r.units = {"N"};
  f.WriteMarker(r, {"a=1"});
  ASSERT_TRUE(f.ReadMarker(2));
  EXPECT_EQ(f.ReadMarker(2)->outputs, std::vector<double>{4.25});
  EXPECT_FALSE(fs::exists(f.MarkerPath(2) + ".tmp"));
  // A marker cut short (a crash while writing by some other means), a leftover temporary file,
  // or another run's record: not finished
  std::ofstream(f.MarkerPath(1)) << EncodeRunRecord(r).substr(0, 40);
  EXPECT_FALSE(f.ReadMarker(1));
  std::ofstream(f.MarkerPath(3) + ".tmp") << EncodeRunRecord(r);
  EXPECT_FALSE(f.ReadMarker(3));
  fs::copy_file(f.MarkerPath(2), f.MarkerPath(0));
  EXPECT_FALSE(f.ReadMarker(0));
}

TEST_F(StudyFolderFileTest, IndexTablesHoldParametersOutputsAndFailures) {
  std::ostringstream warn;
  const StudyPlan plan = MakeStudyPlan(ParseStudyFile(
      "scene: a.yaml\naxes:\n  - {key: m, values: [1, 0.1]}\n  - {key: k, values: [ida, \"x,y\"]}\n"
      "outputs:\n  - {name: f, type: peak, dataset: /a}\n",
      "s.yaml"));
  const StudyFolder folder =
      StudyFolder::Prepare((dir_ / "s").string(), "s.yaml", "x", "y", 4, warn);
  std::vector<std::optional<RunRecord>> records(4);
  records[0] = RunRecord{.run = 0,
                         .status = RunStatus::kOk,
                         .exit_status = 0,
                         .wall_time_s = 1.5,
                         .cpu_time_s = 1.25,
                         .peak_memory_mib = 30,
                         .rank = 0,
                         .host = "n1",
                         .reason = "",
                         .outputs = {0.1 + 0.2},
                         .units = {"N"}};
  records[2] = RunRecord{.run = 2,
                         .status = RunStatus::kFailed,
                         .exit_status = 1,
                         .wall_time_s = 0.5,
                         .cpu_time_s = 0.5,
                         .peak_memory_mib = 20,
                         .rank = 3,
                         .host = "n2",
                         .reason = "mass \"m\" must be positive, got -1",
                         .outputs = {std::numeric_limits<double>::quiet_NaN()},
                         .units = {""}};
  const std::string csv = StudyIndexCsv(plan, folder, records);
  EXPECT_EQ(csv,
            "run,status,m,k,f,wall_time_s,cpu_time_s,peak_memory_mib,exit_status,reason,rank,host,"
            "result_file\n"
            "0,ok,1,ida,0.30000000000000004,1.5,1.25,30,0,,0,n1,runs/run_00000.h5\n"
            "1,pending,1,\"\"\"x,y\"\"\",,,,,,,,,runs/run_00001.h5\n"
            "2,failed,0.1,ida,nan,0.5,0.5,20,1,\"mass \"\"m\"\" must be positive, got "
            "-1\",3,n2,runs/run_00002.h5\n"
            "3,pending,0.1,\"\"\"x,y\"\"\",,,,,,,,,runs/run_00003.h5\n");
  // HDF5: the same, with units and counts
  WriteStudyIndex(plan, folder, records, "0123");
  const Hdf5Reader h5(folder.IndexHdf5Path());
  EXPECT_EQ(h5.ReadVector("/outputs/f")[0], 0.1 + 0.2);
  EXPECT_EQ(h5.ReadStringAttribute("/outputs/f", "unit"), "N");
  EXPECT_EQ(h5.ReadVector("/parameters/m"), (std::vector<double>{1, 1, 0.1, 0.1}));
  // Parameters are the YAML text handed to --set (a quoted string stays quoted)
  EXPECT_EQ(h5.ReadStrings("/parameters/k"),
            (std::vector<std::string>{"ida", "\"x,y\"", "ida", "\"x,y\""}));
  EXPECT_EQ(h5.ReadStrings("/runs/status"),
            (std::vector<std::string>{"ok", "pending", "failed", "pending"}));
  EXPECT_EQ(h5.ReadIntAttribute("/", "pending"), 2);
  EXPECT_EQ(h5.ReadStringAttribute("/", "study_hash"), "0123");
  EXPECT_FALSE(fs::exists(folder.IndexHdf5Path() + ".tmp"));
}

}  // namespace
}  // namespace orrery::study

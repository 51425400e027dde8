// Tests for mbd/result_file.cpp: round trips through Hdf5Reader, List(), error messages, and
// crash safety (a writer killed with SIGKILL after Flush() leaves every flushed row readable).
#include "mbd/result_file.h"

#include "mbd/hdf5_reader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

namespace orrery {
namespace {

// A file in the test temp directory, removed when the test ends.
class TempFile {
 public:
  explicit TempFile(const std::string& name)
      : path_(::testing::TempDir() + "orrery_result_file_" + std::to_string(::getpid()) + "_" + name + ".h5") {
    std::filesystem::remove(path_);
  }
  ~TempFile() { std::filesystem::remove(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Value of row r, column c of series s: distinct per cell and exact in double.
double Value(int s, std::int64_t r, int c) { return s * 1.0e6 + static_cast<double>(r) + c / 8.0; }

// Appends rows [first, first + count) of series number `s` (ncols columns) to `id`.
void AppendRows(ResultFile& out, ResultFile::SeriesId id, int s, int ncols, std::int64_t first, std::int64_t count) {
  std::vector<double> row(static_cast<std::size_t>(ncols));
  for (std::int64_t r = first; r < first + count; ++r) {
    for (int c = 0; c < ncols; ++c) row[static_cast<std::size_t>(c)] = Value(s, r, c);
    out.Append(id, row.data());
  }
}

// Checks that `m` is rows x ncols and holds Value(s, r, c).
void ExpectSeries(const Eigen::MatrixXd& m, int s, int ncols, std::int64_t rows) {
  ASSERT_EQ(m.rows(), rows);
  ASSERT_EQ(m.cols(), ncols);
  for (std::int64_t r = 0; r < rows; ++r)
    for (int c = 0; c < ncols; ++c)
      ASSERT_EQ(m(r, c), Value(s, r, c)) << "series " << s << " row " << r << " col " << c;
}

// Runs `child` in a forked process that must end by SIGKILL; returns false (with a failure) if it
// ended otherwise.
template <class Child>
bool RunKilledChild(Child child) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    try {
      child();
    } catch (...) {
      ::_exit(2);
    }
    ::_exit(3);  // the child is expected to kill itself
  }
  int status = 0;
  EXPECT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "child exited with status " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  return WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
}

TEST(ResultFileTest, SeriesRoundTripWithPartialBlocksAndFlushes) {
  TempFile file("round_trip");
  // ncols 1 (1024-row blocks), 3 (341), 7 (146) and 1500 (one row per block, chunk > 8 KiB)
  const std::vector<int> ncols = {1, 3, 7, 1500};
  const std::vector<std::string> paths = {"/time", "/bodies/link1/position", "/joints/crank/state", "/wide"};
  const std::int64_t rows = 2500;
  {
    ResultFile out = ResultFile::Create(file.path());
    std::vector<ResultFile::SeriesId> ids;
    for (std::size_t s = 0; s < ncols.size(); ++s) ids.push_back(out.AddSeries(paths[s], ncols[s], "1"));
    // Flush at uneven row counts so partially written blocks get completed later
    std::int64_t done = 0;
    for (std::int64_t until : {std::int64_t{700}, std::int64_t{701}, std::int64_t{1100}, rows}) {
      for (std::size_t s = 0; s < ncols.size(); ++s)
        AppendRows(out, ids[s], static_cast<int>(s), ncols[s], done, until - done);
      done = until;
      if (until != rows) out.Flush();
    }
    for (auto id : ids) EXPECT_EQ(out.rows(id), rows);
    out.Close();
  }
  Hdf5Reader in(file.path());
  for (std::size_t s = 0; s < ncols.size(); ++s) {
    SCOPED_TRACE(paths[s]);
    ExpectSeries(in.ReadMatrix(paths[s]), static_cast<int>(s), ncols[s], rows);
  }
}

// AppendRow over a range of series (not the file's first, nor its last) writes what Append on
// each does: the same cells through full blocks, partial blocks and flushes, and the series
// outside the range untouched.
TEST(ResultFileTest, AppendRowOfConsecutiveSeriesIsAppendOnEach) {
  TempFile file("append_row");
  const std::vector<int> ncols = {2, 1, 3, 6, 7, 1500, 4};
  const std::int64_t rows = 2100;
  {
    ResultFile out = ResultFile::Create(file.path());
    std::vector<ResultFile::SeriesId> ids;
    for (std::size_t s = 0; s < ncols.size(); ++s)
      ids.push_back(out.AddSeries("/s" + std::to_string(s), ncols[s], "1"));
    for (std::size_t s = 0; s < ncols.size(); ++s) EXPECT_EQ(out.cols(ids[s]), ncols[s]);
    // Series 1 to 5 by rows; series 0 and 6 by Append, fewer rows.
    std::vector<double> row;
    for (std::int64_t r = 0; r < rows; ++r) {
      row.clear();
      for (std::size_t s = 1; s <= 5; ++s)
        for (int c = 0; c < ncols[s]; ++c) row.push_back(Value(static_cast<int>(s), r, c));
      out.AppendRow(ids[1], 5, row.data());
      if (r == 700 || r == 1023 || r == 1500) out.Flush();
    }
    AppendRows(out, ids[0], 0, ncols[0], 0, 10);
    AppendRows(out, ids[6], 6, ncols[6], 0, 3);
    EXPECT_EQ(out.rows(ids[1]), rows);
    EXPECT_EQ(out.rows(ids[0]), 10);
    EXPECT_THROW(out.AppendRow(ids[5], 3, row.data()), std::invalid_argument);
    out.Close();
    EXPECT_THROW(out.AppendRow(ids[1], 1, row.data()), std::logic_error);
  }
  Hdf5Reader in(file.path());
  for (std::size_t s = 0; s < ncols.size(); ++s) {
    SCOPED_TRACE(s);
    ExpectSeries(in.ReadMatrix("/s" + std::to_string(s)), static_cast<int>(s), ncols[s],
                 s == 0   ? 10
                 : s == 6 ? 3
                          : rows);
  }
}

TEST(ResultFileTest, DestructorWritesBufferedRows) {
  TempFile file("destructor");
  {
    ResultFile out = ResultFile::Create(file.path());
    const auto q = out.AddSeries("/q", 2, "rad");
    AppendRows(out, q, 0, 2, 0, 5);  // fewer rows than a block, never flushed
  }
  Hdf5Reader in(file.path());
  ExpectSeries(in.ReadMatrix("/q"), 0, 2, 5);
}

TEST(ResultFileTest, EmptySeriesHasZeroRows) {
  TempFile file("empty_series");
  {
    ResultFile out = ResultFile::Create(file.path());
    out.AddSeries("/nothing", 4, "m");
  }
  Hdf5Reader in(file.path());
  const Eigen::MatrixXd m = in.ReadMatrix("/nothing");
  EXPECT_EQ(m.rows(), 0);
  EXPECT_EQ(m.cols(), 4);
}

TEST(ResultFileTest, MoveKeepsTheOpenFile) {
  TempFile file("move");
  {
    ResultFile first = ResultFile::Create(file.path());
    const auto t = first.AddSeries("/t", 1, "s");
    AppendRows(first, t, 0, 1, 0, 10);
    ResultFile second(std::move(first));
    AppendRows(second, t, 0, 1, 10, 10);
    TempFile other_file("move_other");
    ResultFile third = ResultFile::Create(other_file.path());
    third = std::move(second);  // closes the other file, takes this one
    EXPECT_EQ(third.path(), file.path());
    AppendRows(third, t, 0, 1, 20, 10);
    EXPECT_EQ(third.rows(t), 30);
    EXPECT_THROW(first.Append(t, nullptr), std::logic_error);
  }
  Hdf5Reader in(file.path());
  ExpectSeries(in.ReadMatrix("/t"), 0, 1, 30);
}

TEST(ResultFileTest, AttributesOfEveryKindAnywhereAndAnytime) {
  TempFile file("attributes");
  {
    ResultFile out = ResultFile::Create(file.path());
    const auto w = out.AddSeries("/joints/crank/w", 3, "rad/s", {"wx", "wy", "wz"});
    AppendRows(out, w, 0, 3, 0, 400);
    out.Flush();
    // After rows and a flush: on the series, on the root, on a group created on the way
    out.SetAttribute("/joints/crank/w", "description", std::string("ω of the crank, Kurbel"));
    out.SetAttribute("/", "orrery_version", std::string("0.1.0"));
    out.SetAttribute("/", "step_s", 0.1);
    out.SetAttribute("/solver/settings", "max_iterations", std::int64_t{-42});
    out.SetAttribute("/solver/settings", "tolerance", 1e-300);
    // Replacing an attribute may change its type
    out.SetAttribute("/", "seed", std::string("none"));
    out.SetAttribute("/", "seed", std::int64_t{9007199254740993});
    AppendRows(out, w, 0, 3, 400, 100);
  }
  Hdf5Reader in(file.path());
  EXPECT_EQ(in.ReadAttributeText("/joints/crank/w", "unit"), "rad/s");
  EXPECT_EQ(in.ReadAttributeText("/joints/crank/w", "columns"), "wx,wy,wz");
  EXPECT_EQ(in.ReadAttributeText("/joints/crank/w", "description"), "ω of the crank, Kurbel");
  EXPECT_EQ(in.ReadAttributeText("/", "orrery_version"), "0.1.0");
  EXPECT_EQ(in.ReadAttributeText("/", "step_s"), "0.1");
  EXPECT_EQ(std::stod(in.ReadAttributeText("/", "step_s")), 0.1);
  EXPECT_EQ(in.ReadAttributeText("/solver/settings", "max_iterations"), "-42");
  EXPECT_EQ(std::stod(in.ReadAttributeText("/solver/settings", "tolerance")), 1e-300);
  EXPECT_EQ(in.ReadAttributeText("/", "seed"), "9007199254740993");
  EXPECT_TRUE(in.Exists("/solver/settings"));
  ExpectSeries(in.ReadMatrix("/joints/crank/w"), 0, 3, 500);
}

TEST(ResultFileTest, FixedMatricesAndVectors) {
  TempFile file("fixed");
  Eigen::MatrixXd m(3, 4);  // not symmetric, not square: a transposed or mis-strided copy shows
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) m(i, j) = 10.0 * i + j + 0.5;
  const std::vector<double> v = {1.5, -2.25, 3.0e-9, 4.0e9};
  {
    ResultFile out = ResultFile::Create(file.path());
    const auto t = out.AddSeries("/time", 1, "s");
    AppendRows(out, t, 0, 1, 0, 3000);
    // Written after rows were appended, one under an existing group
    out.WriteMatrix("/model/mass_matrix", m, "kg");
    out.WriteVector("/model/masses", v, "kg");
    out.WriteVector("/model/empty", {}, "1");
    out.WriteMatrix("/time_table", m.transpose(), "s");
  }
  Hdf5Reader in(file.path());
  EXPECT_EQ(in.ReadMatrix("/model/mass_matrix"), m);
  EXPECT_EQ(in.ReadMatrix("/time_table"), m.transpose());
  const Eigen::MatrixXd masses = in.ReadMatrix("/model/masses");
  ASSERT_EQ(masses.rows(), 4);
  ASSERT_EQ(masses.cols(), 1);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(masses(i, 0), v[static_cast<std::size_t>(i)]);
  EXPECT_EQ(in.ReadMatrix("/model/empty").size(), 0);
  EXPECT_EQ(in.ReadAttributeText("/model/mass_matrix", "unit"), "kg");
  ExpectSeries(in.ReadMatrix("/time"), 0, 1, 3000);
}

TEST(ResultFileTest, ListWalksDepthFirstSortedByName) {
  TempFile file("list");
  {
    ResultFile out = ResultFile::Create(file.path());
    // Created out of order; "/a-b" sorts after the children of "/a" (a plain string sort would
    // put it before "/a/x", since '-' < '/')
    out.WriteVector("/a-b", {1.0, 2.0}, "m");
    const auto x = out.AddSeries("/a/x", 2, "N", {"fx", "fy"});
    AppendRows(out, x, 0, 2, 0, 1500);
    out.WriteMatrix("/a/b/c", Eigen::MatrixXd::Zero(2, 5), "1");
    out.SetAttribute("/", "seed", std::int64_t{7});
    out.SetAttribute("/a", "kind", std::string("joint"));
  }
  Hdf5Reader in(file.path());
  const std::vector<Hdf5Reader::Entry> entries = in.List();
  std::vector<std::string> paths;
  for (const auto& e : entries) paths.push_back(e.path);
  EXPECT_EQ(paths, (std::vector<std::string>{"/", "/a", "/a/b", "/a/b/c", "/a/x", "/a-b"}));
  ASSERT_EQ(entries.size(), 6u);
  // Groups, shapes, attributes
  EXPECT_TRUE(entries[0].is_group);
  EXPECT_EQ(entries[0].attributes, (std::vector<std::pair<std::string, std::string>>{{"seed", "7"}}));
  EXPECT_TRUE(entries[1].is_group);
  EXPECT_EQ(entries[1].attributes, (std::vector<std::pair<std::string, std::string>>{{"kind", "joint"}}));
  EXPECT_TRUE(entries[2].is_group);
  EXPECT_TRUE(entries[2].shape.empty());
  EXPECT_FALSE(entries[3].is_group);
  EXPECT_EQ(entries[3].shape, (std::vector<std::int64_t>{2, 5}));
  EXPECT_FALSE(entries[4].is_group);
  EXPECT_EQ(entries[4].shape, (std::vector<std::int64_t>{1500, 2}));
  EXPECT_EQ(entries[4].attributes,
            (std::vector<std::pair<std::string, std::string>>{{"columns", "fx,fy"}, {"unit", "N"}}));
  EXPECT_EQ(entries[5].shape, (std::vector<std::int64_t>{2}));
}

TEST(ResultFileErrorsTest, MissingAndForeignFilesNameThePath) {
  TempFile missing("missing");
  try {
    Hdf5Reader in(missing.path());
    FAIL() << "opened a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.path()), std::string::npos) << e.what();
  }
  TempFile text("not_hdf5");
  std::ofstream(text.path()) << "time,q\n0,1\n";
  try {
    Hdf5Reader in(text.path());
    FAIL() << "opened a text file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(text.path()), std::string::npos) << e.what();
  }
  const std::string no_dir = ::testing::TempDir() + "orrery_no_such_dir/run.h5";
  try {
    ResultFile::Create(no_dir);
    FAIL() << "created a file in a missing directory";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(no_dir), std::string::npos) << e.what();
  }
}

TEST(ResultFileErrorsTest, BadSeriesAndObjectsNameThePaths) {
  TempFile file("errors");
  ResultFile out = ResultFile::Create(file.path());
  out.AddSeries("/bodies/a/position", 3, "m");
  out.WriteVector("/fixed", {1.0}, "1");
  // Duplicate series, a series over a fixed dataset or a group: invalid_argument naming both
  // paths
  for (const std::string path : {"/bodies/a/position", "/fixed", "/bodies/a"}) {
    try {
      out.AddSeries(path, 3, "m");
      FAIL() << "added a duplicate " << path;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file.path()), std::string::npos) << what;
      EXPECT_NE(what.find(path), std::string::npos) << what;
    }
  }
  EXPECT_THROW(out.AddSeries("/zero", 0, "m"), std::invalid_argument);
  EXPECT_THROW(out.AddSeries("/names", 2, "m", {"x"}), std::invalid_argument);
  EXPECT_THROW(out.AddSeries("relative/path", 1, "m"), std::invalid_argument);
  // Failing HDF5 calls: runtime_error naming the file and the object
  try {
    out.AddSeries("/fixed/below", 1, "m");  // the parent is a dataset
    FAIL() << "created a series below a dataset";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("result file " + file.path() + ": cannot create dataset /fixed/below"), std::string::npos)
        << what;
  }
  try {
    out.WriteMatrix("/fixed", Eigen::MatrixXd::Ones(2, 2), "1");
    FAIL() << "overwrote a dataset";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create dataset /fixed"), std::string::npos) << e.what();
  }
  out.Close();
  EXPECT_THROW(out.Flush(), std::logic_error);
  // Reading what is not there
  Hdf5Reader in(file.path());
  for (const std::string path : {"/nothing", "/bodies"}) {
    try {
      in.ReadMatrix(path);
      FAIL() << "read " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(in.ReadAttributeText("/fixed", "no_such_key"), std::runtime_error);
  EXPECT_FALSE(in.Exists("/fixed/below"));
  EXPECT_FALSE(in.Exists("/no/such/group"));
}

// The child creates a file, appends and flushes twice (series, attributes and a fixed dataset
// added between the flushes), then appends many more rows, adds objects and is killed without
// flushing. Every flushed row must be readable, and nothing after the last flush visible.
TEST(ResultFileCrashTest, SigkillAfterFlushKeepsEveryFlushedRow) {
  TempFile file("crash");
  const std::int64_t first = 1500, second = 800, late = 333, unflushed = 20000;
  Eigen::MatrixXd m(2, 3);
  m << 1, 2, 3, 4, 5, 6;
  const bool killed = RunKilledChild([&] {
    ResultFile out = ResultFile::Create(file.path());
    const auto a = out.AddSeries("/time", 1, "s");
    const auto b = out.AddSeries("/bodies/link1/position", 3, "m", {"x", "y", "z"});
    out.SetAttribute("/", "model", std::string("crank"));
    AppendRows(out, a, 0, 1, 0, first);
    AppendRows(out, b, 1, 3, 0, first);
    out.Flush();
    // Objects added after the first flush, rows up to the second
    const auto c = out.AddSeries("/late/c", 5, "N");
    out.WriteMatrix("/fixed/m", m, "kg");
    out.SetAttribute("/bodies/link1/position", "frame", std::string("W"));
    AppendRows(out, a, 0, 1, first, second);
    AppendRows(out, b, 1, 3, first, second);
    AppendRows(out, c, 2, 5, 0, late);
    out.Flush();
    // Unflushed: full blocks reach the file, extents and new objects stay in memory
    AppendRows(out, a, 0, 1, first + second, unflushed);
    AppendRows(out, b, 1, 3, first + second, unflushed);
    AppendRows(out, c, 2, 5, late, unflushed);
    const auto d = out.AddSeries("/unflushed/d", 2, "1");
    AppendRows(out, d, 3, 2, 0, 5000);
    out.WriteMatrix("/unflushed/m", m, "1");
    out.SetAttribute("/", "model", std::string("changed"));
    std::raise(SIGKILL);
  });
  ASSERT_TRUE(killed);
  Hdf5Reader in(file.path());
  ExpectSeries(in.ReadMatrix("/time"), 0, 1, first + second);
  ExpectSeries(in.ReadMatrix("/bodies/link1/position"), 1, 3, first + second);
  ExpectSeries(in.ReadMatrix("/late/c"), 2, 5, late);
  EXPECT_EQ(in.ReadMatrix("/fixed/m"), m);
  EXPECT_EQ(in.ReadAttributeText("/", "model"), "crank");
  EXPECT_EQ(in.ReadAttributeText("/bodies/link1/position", "frame"), "W");
  EXPECT_EQ(in.ReadAttributeText("/bodies/link1/position", "columns"), "x,y,z");
  EXPECT_FALSE(in.Exists("/unflushed"));
  // The whole file walks (no damaged object anywhere)
  EXPECT_EQ(in.List().size(), 9u);  // / /bodies /bodies/link1 .../position /fixed /fixed/m /late /late/c /time
}

// Many series each writing new chunks after the flush: the metadata dirtied between the flushes
// (a chunk index node per series, ~2.6 KB each) outgrows HDF5's default 2 MB metadata cache. With
// the default cache configuration HDF5 then writes index nodes that point past the flushed
// end-of-file address, and every series fails to read ("addr overflow"); the fixed-size cache
// of result_file.cpp keeps them in memory.
TEST(ResultFileCrashTest, SigkillAfterManySeriesWroteUnflushedBlocks) {
  TempFile file("crash_many_series");
  const int nseries = 1000;
  const std::int64_t flushed = 100, unflushed = 1000;  // 3 columns: ~3 new chunks per series
  const auto path = [](int s) { return "/g" + std::to_string(s % 17) + "/s" + std::to_string(s); };
  const bool killed = RunKilledChild([&] {
    ResultFile out = ResultFile::Create(file.path());
    std::vector<ResultFile::SeriesId> ids;
    for (int s = 0; s < nseries; ++s) ids.push_back(out.AddSeries(path(s), 3, "m"));
    for (int s = 0; s < nseries; ++s) AppendRows(out, ids[static_cast<std::size_t>(s)], s, 3, 0, flushed);
    out.Flush();
    for (int s = 0; s < nseries; ++s) AppendRows(out, ids[static_cast<std::size_t>(s)], s, 3, flushed, unflushed);
    std::raise(SIGKILL);
  });
  ASSERT_TRUE(killed);
  Hdf5Reader in(file.path());
  for (int s = 0; s < nseries; ++s) {
    SCOPED_TRACE(path(s));
    ExpectSeries(in.ReadMatrix(path(s)), s, 3, flushed);
    if (::testing::Test::HasFailure()) break;
  }
}

// Kills writers at random moments while they append after their last flush (the writer reports
// the flushed row count through a pipe, then appends until killed).
TEST(ResultFileCrashTest, SigkillAtRandomMomentsWhileAppending) {
  std::mt19937 rng(20240611);
  for (int trial = 0; trial < 8; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    TempFile file("crash_random_" + std::to_string(trial));
    const std::int64_t flushed = 1000 + static_cast<std::int64_t>(rng() % 5000);
    const int delay_us = static_cast<int>(rng() % 30000);
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::close(fds[0]);
      try {
        ResultFile out = ResultFile::Create(file.path());
        const auto a = out.AddSeries("/a", 1, "s");
        const auto b = out.AddSeries("/group/b", 6, "m");
        AppendRows(out, a, 0, 1, 0, flushed / 2);
        AppendRows(out, b, 1, 6, 0, flushed / 2);
        out.Flush();
        AppendRows(out, a, 0, 1, flushed / 2, flushed - flushed / 2);
        AppendRows(out, b, 1, 6, flushed / 2, flushed - flushed / 2);
        out.Flush();
        const char ready = 'r';
        if (::write(fds[1], &ready, 1) != 1) ::_exit(4);
        // Append until killed (bounded, then wait)
        for (std::int64_t r = flushed; r < flushed + 2000000; r += 1000) {
          AppendRows(out, a, 0, 1, r, 1000);
          AppendRows(out, b, 1, 6, r, 1000);
        }
        ::pause();
      } catch (...) {
        ::_exit(2);
      }
      ::_exit(3);
    }
    ::close(fds[1]);
    char ready = 0;
    ASSERT_EQ(::read(fds[0], &ready, 1), 1) << "writer failed before its flush";
    ::close(fds[0]);
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us));
    ::kill(pid, SIGKILL);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "writer exited with " << WEXITSTATUS(status);
    Hdf5Reader in(file.path());
    ExpectSeries(in.ReadMatrix("/a"), 0, 1, flushed);
    ExpectSeries(in.ReadMatrix("/group/b"), 1, 6, flushed);
    EXPECT_EQ(in.List().size(), 4u);
  }
}

}  // namespace
}  // namespace orrery

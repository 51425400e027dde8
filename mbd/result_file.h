#pragma once
// Result files: HDF5 written while a run goes, readable after a crash.
//
// A `ResultFile` holds time series (2-D datasets of doubles, rows appended as the run goes,
// chunked and extendible along the first dimension) and fixed datasets and attributes. Rows are
// buffered in memory and written in blocks; `Flush()` pushes buffered rows and the file's metadata
// to disk so that a run killed after it leaves a readable file holding every flushed row.
// HDF5 headers stay inside mbd/result_file.cpp (this header is HDF5-free). Files are read back
// with Hdf5Reader (mbd/hdf5_reader.h).
//
// Usage:
//   ResultFile out = ResultFile::Create("run.h5");
//   auto t = out.AddSeries("/time", 1, "s");
//   auto q = out.AddSeries("/joints/crank/q", 1, "rad");
//   out.Append(t, &time); out.Append(q, q_row);   // no allocation once a block is sized
//   out.Flush();                                    // every so often
//
// Paths are absolute ("/bodies/link1/position"); missing groups are created.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace orrery {

struct ResultFileOptions {
  // Largest size the file may reach (bytes; 0: no quota). Like a file-size limit (RLIMIT_FSIZE)
  // or a full disk, reaching it stops the rows (CheckRoom) while the file can still be closed.
  std::uint64_t max_bytes = 0;
};

// Thrown by CheckRoom when the file has no room for more rows: what() names the file and the
// limit (quota, file-size limit, free disk space). Every row appended before still fits:
// Flush() and Close() write them.
class ResultFileFullError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ResultFile {
 public:
  using SeriesId = int;

  // Creates (truncates) `path`. Throws std::runtime_error naming the path when it cannot, or
  // when the path exists and is not a regular file (a device such as /dev/null, a FIFO, a
  // directory).
  static ResultFile Create(const std::string& path, const ResultFileOptions& options = {});
  // A file held in memory only (HDF5's core driver, no backing store), e.g. to lay out a run's
  // series and count their columns before deciding to write anything; `name` stands for it in
  // messages.
  static ResultFile CreateInMemory(const std::string& name);

  ResultFile(ResultFile&&) noexcept;
  ResultFile& operator=(ResultFile&&) noexcept;
  ~ResultFile();  // flushes and closes

  // Declares a time series of `ncols` doubles per row at `path`, with attribute "unit" (SI unit
  // string, "1" for dimensionless) and, if given, attribute "columns" (comma-separated names,
  // size must equal ncols). Throws std::invalid_argument on a duplicate path or ncols < 1.
  SeriesId AddSeries(const std::string& path, int ncols, const std::string& unit,
                     const std::vector<std::string>& column_names = {});

  // Appends one row (`ncols` doubles read from `row`). Allocation-free while the series' block
  // buffer has room; writes the block to the file when it fills.
  void Append(SeriesId id, const double* row);

  // Appends one row to each of the `count` series first, first + 1, ..., first + count - 1 (ids
  // as AddSeries gave them), their columns read one series after the other from `row` (the sum
  // of their ncols doubles): the same as Append on each in turn, with the object's checks made
  // once for the row (a recorder's row of a few hundred short series: ResultRecorder::Record).
  void AppendRow(SeriesId first, int count, const double* row);

  // Columns of a series (its ncols).
  int cols(SeriesId id) const;

  // Number of rows appended so far to a series (written or buffered).
  std::int64_t rows(SeriesId id) const;

  // Fixed datasets (written at once, not extendible): a matrix (rows x cols) or a vector.
  void WriteMatrix(const std::string& path, const Eigen::MatrixXd& m, const std::string& unit);
  void WriteVector(const std::string& path, const std::vector<double>& v, const std::string& unit);
  // Fixed datasets of 32-bit signed integers (indices, ids; "unit" "1"): a matrix (rows x cols)
  // or a vector. Throws std::invalid_argument when a value does not fit in 32 bits.
  void WriteIntMatrix(const std::string& path, const Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic>& m);
  void WriteIntVector(const std::string& path, const std::vector<std::int64_t>& v);
  // A fixed 1-D dataset of variable-length UTF-8 strings (h5py reads them as str).
  void WriteStrings(const std::string& path, const std::vector<std::string>& values);

  // Attributes on a group or dataset at `path` ("/" for the file); the object must exist (groups
  // on the way are created for "/"-rooted group paths).
  void SetAttribute(const std::string& path, const std::string& key, const std::string& value);
  void SetAttribute(const std::string& path, const std::string& key, double value);
  void SetAttribute(const std::string& path, const std::string& key, std::int64_t value);

  // Writes buffered rows of every series and flushes the file to disk.
  void Flush();

  // Throws ResultFileFullError when one more row of every series, and what a run writes at its
  // end, might not fit in the room left (quota, file-size limit, free disk space; see
  // result_file.cpp), before anything is written; once it threw, it throws again. Allocation-
  // free; a statvfs now and then.
  void CheckRoom();

  // Bytes of one row of every series (doubles), for estimates of a file's size.
  std::int64_t bytes_per_row() const;

  // Flushes and closes; later calls are errors. Called by the destructor if not called before.
  // A write, flush or close that fails (a full disk) throws and leaves the file as the last
  // successful Flush() wrote it: nothing more reaches the disk, and later writes throw.
  void Close();

  const std::string& path() const;

 private:
  struct Impl;
  explicit ResultFile(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace orrery

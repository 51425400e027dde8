#pragma once
// Result files: HDF5 written while a run goes, readable after a crash.
//
// A `ResultFile` holds time series (2-D datasets of doubles, rows appended as the run goes,
// chunked and extendible along the first dimension) and fixed datasets and attributes. Rows are
// buffered in memory and written in blocks; `Flush()` pushes buffered rows and the file's metadata
// to disk so that a run killed after it leaves a readable file holding every flushed row.
// HDF5 headers stay inside mbd/result_file.cpp (this header is HDF5-free).
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
#include <string>
#include <vector>

#include <Eigen/Core>

namespace orrery {

class ResultFile {
 public:
  using SeriesId = int;

  // Creates (truncates) `path`. Throws std::runtime_error naming the path when it cannot.
  static ResultFile Create(const std::string& path);

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

  // Flushes and closes; later calls are errors. Called by the destructor if not called before.
  void Close();

  const std::string& path() const;

 private:
  struct Impl;
  explicit ResultFile(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Read-only access to a result file (for `orrery inspect`, tests and post-processing).
class ResultReader {
 public:
  // Opens `path` read-only. Throws std::runtime_error naming the path when it cannot.
  explicit ResultReader(const std::string& path);
  ~ResultReader();
  ResultReader(ResultReader&&) noexcept;
  ResultReader& operator=(ResultReader&&) noexcept;

  struct Entry {
    std::string path;                  // "/bodies/link1/position"
    bool is_group = false;
    std::vector<std::int64_t> shape;   // datasets only
    std::vector<std::pair<std::string, std::string>> attributes;  // key -> value as text
  };
  // Every group and dataset in the file, depth first, sorted by name within a group.
  std::vector<Entry> List() const;

  bool Exists(const std::string& path) const;
  // A dataset of doubles as a matrix (a 1-D dataset becomes one column). Throws naming the path.
  Eigen::MatrixXd ReadMatrix(const std::string& path) const;
  // An attribute as text (strings as they are, numbers printed with full precision). Throws.
  std::string ReadAttribute(const std::string& path, const std::string& key) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace orrery

#pragma once
// The one read-only view of an HDF5 file: typed reads of datasets and attributes by absolute path,
// a listing of everything a file holds, with errors that name the file and the object. For every
// file the engine reads back: result files (`orrery inspect`, the run summary, tests, examples)
// and reduced bodies (flex/reduced_body_file.h). HDF5 headers stay in mbd/hdf5_reader.cpp.
//
// Every failure throws std::runtime_error "<file>: <object>: <reason>" (the object is the
// dataset or group path, "attribute <key> of <path>" for attributes), e.g.
//   "body.h5: /modes/stiffness: no such dataset"
//   "body.h5: /modes/nodes/ids: expected integers, found floating-point numbers"
//
// Usage:
//   Hdf5Reader r("body.h5");
//   Eigen::MatrixXd K = r.ReadMatrix("/craig_bampton/K");
//   std::vector<std::int64_t> ids = r.ReadInts("/modes/nodes/ids");
//   std::string source = r.ReadStringAttribute("/provenance", "source");
//   for (const std::string& name : r.ListGroup("/")) ...
//   for (const Hdf5Reader::Entry& e : r.List()) ...      // every group and dataset, depth first
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace orrery {

class Hdf5Reader {
 public:
  using IntMatrix = Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic>;

  // Opens `path` read-only. Throws when the file is missing or is not an HDF5 file.
  explicit Hdf5Reader(const std::string& path);
  ~Hdf5Reader();
  Hdf5Reader(Hdf5Reader&&) noexcept;
  Hdf5Reader& operator=(Hdf5Reader&&) noexcept;

  const std::string& path() const;

  struct Entry {
    std::string path;                  // "/bodies/link1/position"
    bool is_group = false;
    std::vector<std::int64_t> shape;   // datasets only
    std::vector<std::pair<std::string, std::string>> attributes;  // key -> value as text
                                                                  // (ReadAttributeText), by name
  };
  // Every group and dataset in the file, "/" first, depth first, sorted by name within a group.
  // An attribute of a type other than strings and numbers reads as "<unsupported type>".
  std::vector<Entry> List() const;

  // Whether an object (group or dataset) exists at the absolute path `object`; false for paths
  // that are not absolute and for missing parents.
  bool Exists(const std::string& object) const;
  bool IsGroup(const std::string& object) const;
  bool IsDataset(const std::string& object) const;
  // Names of the members (groups and datasets) of a group, sorted. Throws if it is no group.
  std::vector<std::string> ListGroup(const std::string& group) const;
  // Dimensions of a dataset (empty for a scalar).
  std::vector<std::int64_t> Shape(const std::string& dataset) const;

  // A numeric dataset (integers are converted) of rank 0, 1 (one column) or 2 as a matrix.
  Eigen::MatrixXd ReadMatrix(const std::string& dataset) const;
  // A numeric dataset of rank 0 or 1, or a single row or column of rank 2.
  std::vector<double> ReadVector(const std::string& dataset) const;
  // An integer dataset (floating-point data is an error) of rank 0 to 2 as a matrix.
  IntMatrix ReadIntMatrix(const std::string& dataset) const;
  // An integer dataset of rank 0 or 1, or a single row or column of rank 2.
  std::vector<std::int64_t> ReadInts(const std::string& dataset) const;
  // String datasets (variable or fixed length) of rank 0 or 1.
  std::vector<std::string> ReadStrings(const std::string& dataset) const;
  // A string dataset holding exactly one string.
  std::string ReadString(const std::string& dataset) const;

  bool HasAttribute(const std::string& object, const std::string& key) const;
  // Scalar attributes (or single-element arrays). A string attribute is not a number and an
  // integer attribute is not a string; ReadNumberAttribute accepts integers, ReadIntAttribute
  // accepts only integers.
  std::string ReadStringAttribute(const std::string& object, const std::string& key) const;
  double ReadNumberAttribute(const std::string& object, const std::string& key) const;
  std::int64_t ReadIntAttribute(const std::string& object, const std::string& key) const;
  // Any string or numeric attribute (scalar or array) as text: strings as they are, numbers at
  // full precision (shortest round trip), arrays as "[a, b, c]".
  std::string ReadAttributeText(const std::string& object, const std::string& key) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace orrery

// Hdf5Reader on the HDF5 C API. Every call silences HDF5's automatic error printing and turns
// failures into one std::runtime_error "<file>: <object>: <reason> (<HDF5 detail>)".

#include "mbd/hdf5_reader.h"

#include <hdf5.h>

#include "mbd/hdf5_handle.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace orrery {
namespace {

using hdf5::Handle;
using hdf5::Hdf5Detail;
using hdf5::QuietHdf5;

// Throws "<file>: <object>: <reason>" with HDF5's detail when there is one.
[[noreturn]] void Fail(const std::string& file, const std::string& object, const std::string& reason) {
  std::string message = file + ": ";
  if (!object.empty()) message += object + ": ";
  message += reason;
  const std::string detail = Hdf5Detail();
  if (!detail.empty()) message += " (" + detail + ")";
  throw std::runtime_error(message);
}

// Owns `id`, or fails with the reason when it is invalid.
Handle Own(hid_t id, Handle::Closer close, const std::string& file, const std::string& object,
           const std::string& reason) {
  if (id < 0) Fail(file, object, reason);
  return Handle(id, close);
}

void Check(herr_t status, const std::string& file, const std::string& object, const std::string& reason) {
  if (status < 0) Fail(file, object, reason);
}

// Whether every link on the way to `path` exists and the last one resolves to an object.
bool ObjectExists(hid_t file, const std::string& path) {
  if (path == "/") return true;
  if (path.empty() || path.front() != '/' || path.back() == '/' || path.find("//") != std::string::npos) return false;
  for (std::size_t slash = path.find('/', 1);; slash = path.find('/', slash + 1)) {
    if (H5Lexists(file, path.substr(0, slash).c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
    if (slash == std::string::npos) break;
  }
  const htri_t resolves = H5Oexists_by_name(file, path.c_str(), H5P_DEFAULT);
  if (resolves < 0) H5Eclear2(H5E_DEFAULT);
  return resolves > 0;
}

// The kind of object at an existing path (H5O_TYPE_UNKNOWN when it cannot be told).
H5O_type_t ObjectType(hid_t file, const std::string& path) {
  H5O_info_t info{};
#if H5_VERSION_GE(1, 12, 0)
  if (H5Oget_info_by_name3(file, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
#else
  if (H5Oget_info_by_name2(file, path.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
#endif
    H5Eclear2(H5E_DEFAULT);
    return H5O_TYPE_UNKNOWN;
  }
  return info.type;
}

// "floating-point numbers", "integers", "strings", ... for messages.
std::string ClassName(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER: return "integers";
    case H5T_FLOAT: return "floating-point numbers";
    case H5T_STRING: return "strings";
    case H5T_COMPOUND: return "compound values";
    case H5T_ENUM: return "enumerated values";
    case H5T_ARRAY: return "array values";
    default: return "values of an unsupported type";
  }
}

// Dimensions of a dataspace.
std::vector<hsize_t> Dims(hid_t space, const std::string& file, const std::string& object) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) Fail(file, object, "cannot get the rank");
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space, dims.data(), nullptr) < 0) Fail(file, object, "cannot get the shape");
  return dims;
}

std::string ShapeText(const std::vector<hsize_t>& dims) {
  if (dims.empty()) return "a scalar";
  std::string s;
  for (std::size_t i = 0; i < dims.size(); ++i) s += (i ? " x " : "") + std::to_string(dims[i]);
  return "shape " + s;
}

// Strings of type `type` read by `read(mem_type, buffer)` (n of them): variable length through
// char pointers freed with H5free_memory, fixed length cut at the first NUL and trailing padding.
template <class Read>
std::vector<std::string> ReadStringValues(hid_t type, std::size_t n, Read read, const std::string& file,
                                          const std::string& object) {
  std::vector<std::string> values;
  values.reserve(n);
  const htri_t variable = H5Tis_variable_str(type);
  if (variable < 0) Fail(file, object, "cannot inspect the string type");
  if (variable > 0) {
    Handle mem = Own(H5Tcopy(H5T_C_S1), H5Tclose, file, object, "cannot create a string type");
    Check(H5Tset_size(mem.get(), H5T_VARIABLE), file, object, "cannot size a string type");
    Check(H5Tset_cset(mem.get(), H5Tget_cset(type)), file, object, "cannot set a string character set");
    std::vector<char*> ptrs(n, nullptr);
    if (n > 0) Check(read(mem.get(), static_cast<void*>(ptrs.data())), file, object, "cannot read");
    for (char* p : ptrs) {
      values.emplace_back(p != nullptr ? p : "");
      H5free_memory(p);
    }
    return values;
  }
  const std::size_t size = H5Tget_size(type);
  if (size == 0) Fail(file, object, "cannot get the string size");
  std::vector<char> buf(n * size);
  if (n > 0) Check(read(type, static_cast<void*>(buf.data())), file, object, "cannot read");
  const bool space_pad = H5Tget_strpad(type) == H5T_STR_SPACEPAD;
  for (std::size_t i = 0; i < n; ++i) {
    std::string_view s(buf.data() + i * size, size);
    s = s.substr(0, s.find('\0'));
    if (space_pad) s = s.substr(0, s.find_last_not_of(' ') + 1);
    values.emplace_back(s);
  }
  return values;
}

// Shortest text that reads back to the same double.
std::string DoubleText(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

// Values as "a" (one value) or "[a, b, c]".
std::string JoinValues(const std::vector<std::string>& values) {
  if (values.size() == 1) return values.front();
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + values[i];
  return out + "]";
}

// An open attribute's values as text: strings as they are, integers in full, floating-point
// numbers at their shortest round trip, several values as "[a, b]". Fails for other types.
std::string AttributeText(hid_t attr, const std::string& file, const std::string& where) {
  Handle type = Own(H5Aget_type(attr), H5Tclose, file, where, "cannot get the type");
  Handle space = Own(H5Aget_space(attr), H5Sclose, file, where, "cannot get the dataspace");
  const hssize_t npoints = H5Sget_simple_extent_npoints(space.get());
  if (npoints < 0) Fail(file, where, "cannot count the values");
  const auto n = static_cast<std::size_t>(npoints);
  const auto read = [&](hid_t mem, void* buf) { return H5Aread(attr, mem, buf); };
  std::vector<std::string> values;
  switch (const H5T_class_t c = H5Tget_class(type.get())) {
    case H5T_STRING:
      values = ReadStringValues(type.get(), n, read, file, where);
      break;
    case H5T_INTEGER:
      // Through int64 or uint64, by sign
      if (H5Tget_sign(type.get()) == H5T_SGN_NONE) {
        std::vector<unsigned long long> v(n);
        if (n > 0) Check(read(H5T_NATIVE_ULLONG, v.data()), file, where, "cannot read");
        for (auto x : v) values.push_back(std::to_string(x));
      } else {
        std::vector<long long> v(n);
        if (n > 0) Check(read(H5T_NATIVE_LLONG, v.data()), file, where, "cannot read");
        for (auto x : v) values.push_back(std::to_string(x));
      }
      break;
    case H5T_FLOAT: {
      std::vector<double> v(n);
      if (n > 0) Check(read(H5T_NATIVE_DOUBLE, v.data()), file, where, "cannot read");
      for (double x : v) values.push_back(DoubleText(x));
      break;
    }
    default:
      Fail(file, where, "expected strings or numbers, found " + ClassName(c));
  }
  return JoinValues(values);
}

// Components of an absolute path ("/a/b" -> {a, b}; "/" -> {}), for depth-first ordering.
std::vector<std::string_view> PathComponents(const std::string& path) {
  std::vector<std::string_view> parts;
  std::string_view rest(path);
  while (rest.size() > 1) {
    rest.remove_prefix(1);
    const std::size_t slash = rest.find('/');
    parts.push_back(rest.substr(0, slash));
    rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash);
  }
  return parts;
}

}  // namespace

struct Hdf5Reader::Impl {
  std::string path;
  Handle file;

  // Opens a dataset, failing with "no such dataset" or "is a group, not a dataset".
  Handle OpenDataset(const std::string& object) const {
    if (!ObjectExists(file.get(), object)) Fail(path, object, "no such dataset");
    if (ObjectType(file.get(), object) != H5O_TYPE_DATASET) Fail(path, object, "is a group, not a dataset");
    return Own(H5Dopen2(file.get(), object.c_str(), H5P_DEFAULT), H5Dclose, path, object, "cannot open the dataset");
  }

  // A numeric dataset as row-major values of memory type `mem_type` with its dimensions.
  template <class T>
  std::vector<T> ReadNumbers(const std::string& object, hid_t mem_type, bool integers_only,
                             std::vector<hsize_t>* dims) const {
    Handle dataset = OpenDataset(object);
    Handle type = Own(H5Dget_type(dataset.get()), H5Tclose, path, object, "cannot get the type");
    const H5T_class_t c = H5Tget_class(type.get());
    if (integers_only ? c != H5T_INTEGER : (c != H5T_INTEGER && c != H5T_FLOAT))
      Fail(path, object, std::string("expected ") + (integers_only ? "integers" : "numbers") + ", found " + ClassName(c));
    Handle space = Own(H5Dget_space(dataset.get()), H5Sclose, path, object, "cannot get the dataspace");
    *dims = Dims(space.get(), path, object);
    if (dims->size() > 2) Fail(path, object, "expected rank 0, 1 or 2, found " + ShapeText(*dims));
    std::size_t n = 1;
    for (hsize_t d : *dims) n *= static_cast<std::size_t>(d);
    std::vector<T> values(n);
    if (n > 0)
      Check(H5Dread(dataset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), path, object,
            "cannot read");
    return values;
  }

  // An attribute opened by object path and key, failing with what is missing.
  Handle OpenAttribute(const std::string& object, const std::string& key) const {
    if (!ObjectExists(file.get(), object)) Fail(path, object, "no such object (looking for attribute " + key + ")");
    if (H5Aexists_by_name(file.get(), object.c_str(), key.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      Fail(path, object, "no attribute " + key);
    }
    return Own(H5Aopen_by_name(file.get(), object.c_str(), key.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, path,
               "attribute " + key + " of " + object, "cannot open");
  }

  // A single-element attribute's type class, checked to have one value.
  H5T_class_t AttributeClass(hid_t attr, Handle* type, const std::string& where) const {
    *type = Own(H5Aget_type(attr), H5Tclose, path, where, "cannot get the type");
    Handle space = Own(H5Aget_space(attr), H5Sclose, path, where, "cannot get the dataspace");
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (n != 1) Fail(path, where, "expected a single value, found " + std::to_string(n));
    return H5Tget_class(type->get());
  }
  // Fills `entry` (kind, shape, attributes) from the object at entry.path; false, leaving it
  // unfilled, for objects other than groups and datasets (named datatypes).
  bool Describe(Hdf5Reader::Entry& entry) const {
    const std::string& object = entry.path;
    Handle obj = Own(H5Oopen(file.get(), object.c_str(), H5P_DEFAULT), H5Oclose, path, object, "cannot open");
    const H5I_type_t kind = H5Iget_type(obj.get());
    if (kind != H5I_GROUP && kind != H5I_DATASET) return false;
    entry.is_group = kind == H5I_GROUP;
    if (kind == H5I_DATASET) {
      Handle space = Own(H5Dget_space(obj.get()), H5Sclose, path, object, "cannot get the dataspace");
      const std::vector<hsize_t> dims = Dims(space.get(), path, object);
      entry.shape.assign(dims.begin(), dims.end());
    }
    // Attribute names in name order, then their values as text
    std::vector<std::string> names;
    Check(H5Aiterate2(
              obj.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
              [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
                static_cast<std::vector<std::string>*>(data)->emplace_back(name);
                return 0;
              },
              &names),
          path, object, "cannot list the attributes");
    for (const std::string& name : names) {
      const std::string where = "attribute " + name + " of " + object;
      Handle attr = Own(H5Aopen(obj.get(), name.c_str(), H5P_DEFAULT), H5Aclose, path, where, "cannot open");
      std::string text;
      try {
        text = AttributeText(attr.get(), path, where);
      } catch (const std::runtime_error&) {
        text = "<unsupported type>";
      }
      entry.attributes.emplace_back(name, std::move(text));
    }
    return true;
  }
};

Hdf5Reader::Hdf5Reader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  QuietHdf5 quiet;
  impl_->path = path;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw std::runtime_error(path + ": no such file");
  if (std::filesystem::is_directory(path, ec)) throw std::runtime_error(path + ": is a directory, not an HDF5 file");
  if (!std::filesystem::is_regular_file(path, ec)) throw std::runtime_error(path + ": not a regular file, not an HDF5 file");
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    throw std::runtime_error(path + ": not an HDF5 file");
  }
  impl_->file = Own(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, path, "", "cannot open read-only");
}

Hdf5Reader::~Hdf5Reader() {
  if (impl_) {
    QuietHdf5 quiet;
    impl_->file.Reset();
  }
}

Hdf5Reader::Hdf5Reader(Hdf5Reader&&) noexcept = default;
Hdf5Reader& Hdf5Reader::operator=(Hdf5Reader&&) noexcept = default;

const std::string& Hdf5Reader::path() const { return impl_->path; }

bool Hdf5Reader::Exists(const std::string& object) const {
  QuietHdf5 quiet;
  return ObjectExists(impl_->file.get(), object);
}

bool Hdf5Reader::IsGroup(const std::string& object) const {
  QuietHdf5 quiet;
  return ObjectExists(impl_->file.get(), object) && ObjectType(impl_->file.get(), object) == H5O_TYPE_GROUP;
}

bool Hdf5Reader::IsDataset(const std::string& object) const {
  QuietHdf5 quiet;
  return ObjectExists(impl_->file.get(), object) && ObjectType(impl_->file.get(), object) == H5O_TYPE_DATASET;
}

std::vector<std::string> Hdf5Reader::ListGroup(const std::string& group) const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  if (!ObjectExists(impl.file.get(), group)) Fail(impl.path, group, "no such group");
  if (ObjectType(impl.file.get(), group) != H5O_TYPE_GROUP) Fail(impl.path, group, "is a dataset, not a group");
  // Names of the links in the group, in name order
  std::vector<std::string> names;
  Check(H5Literate_by_name(
            impl.file.get(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
            [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
              static_cast<std::vector<std::string>*>(data)->emplace_back(name);
              return 0;
            },
            &names, H5P_DEFAULT),
        impl.path, group, "cannot list the group");
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::int64_t> Hdf5Reader::Shape(const std::string& dataset) const {
  QuietHdf5 quiet;
  Handle d = impl_->OpenDataset(dataset);
  Handle space = Own(H5Dget_space(d.get()), H5Sclose, impl_->path, dataset, "cannot get the dataspace");
  const std::vector<hsize_t> dims = Dims(space.get(), impl_->path, dataset);
  return {dims.begin(), dims.end()};
}

Eigen::MatrixXd Hdf5Reader::ReadMatrix(const std::string& dataset) const {
  QuietHdf5 quiet;
  std::vector<hsize_t> dims;
  const std::vector<double> v = impl_->ReadNumbers<double>(dataset, H5T_NATIVE_DOUBLE, false, &dims);
  // Row-major values into a column-major matrix
  const auto rows = static_cast<Eigen::Index>(dims.empty() ? 1 : dims[0]);
  const auto cols = static_cast<Eigen::Index>(dims.size() == 2 ? dims[1] : 1);
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(v.data(), rows, cols);
}

std::vector<double> Hdf5Reader::ReadVector(const std::string& dataset) const {
  QuietHdf5 quiet;
  std::vector<hsize_t> dims;
  std::vector<double> v = impl_->ReadNumbers<double>(dataset, H5T_NATIVE_DOUBLE, false, &dims);
  if (dims.size() == 2 && dims[0] != 1 && dims[1] != 1)
    Fail(impl_->path, dataset, "expected a vector, found " + ShapeText(dims));
  return v;
}

Hdf5Reader::IntMatrix Hdf5Reader::ReadIntMatrix(const std::string& dataset) const {
  QuietHdf5 quiet;
  std::vector<hsize_t> dims;
  const std::vector<std::int64_t> v = impl_->ReadNumbers<std::int64_t>(dataset, H5T_NATIVE_INT64, true, &dims);
  const auto rows = static_cast<Eigen::Index>(dims.empty() ? 1 : dims[0]);
  const auto cols = static_cast<Eigen::Index>(dims.size() == 2 ? dims[1] : 1);
  return Eigen::Map<const Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(v.data(), rows,
                                                                                                         cols);
}

std::vector<std::int64_t> Hdf5Reader::ReadInts(const std::string& dataset) const {
  QuietHdf5 quiet;
  std::vector<hsize_t> dims;
  std::vector<std::int64_t> v = impl_->ReadNumbers<std::int64_t>(dataset, H5T_NATIVE_INT64, true, &dims);
  if (dims.size() == 2 && dims[0] != 1 && dims[1] != 1)
    Fail(impl_->path, dataset, "expected a vector, found " + ShapeText(dims));
  return v;
}

std::vector<std::string> Hdf5Reader::ReadStrings(const std::string& dataset) const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  Handle d = impl.OpenDataset(dataset);
  Handle type = Own(H5Dget_type(d.get()), H5Tclose, impl.path, dataset, "cannot get the type");
  const H5T_class_t c = H5Tget_class(type.get());
  if (c != H5T_STRING) Fail(impl.path, dataset, "expected strings, found " + ClassName(c));
  Handle space = Own(H5Dget_space(d.get()), H5Sclose, impl.path, dataset, "cannot get the dataspace");
  const std::vector<hsize_t> dims = Dims(space.get(), impl.path, dataset);
  if (dims.size() > 1) Fail(impl.path, dataset, "expected a scalar or a list of strings, found " + ShapeText(dims));
  const std::size_t n = dims.empty() ? 1 : static_cast<std::size_t>(dims[0]);
  return ReadStringValues(
      type.get(), n,
      [&](hid_t mem, void* buf) { return H5Dread(d.get(), mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf); }, impl.path,
      dataset);
}

std::string Hdf5Reader::ReadString(const std::string& dataset) const {
  const std::vector<std::string> values = ReadStrings(dataset);
  if (values.size() != 1)
    throw std::runtime_error(impl_->path + ": " + dataset + ": expected one string, found " +
                             std::to_string(values.size()));
  return values.front();
}

bool Hdf5Reader::HasAttribute(const std::string& object, const std::string& key) const {
  QuietHdf5 quiet;
  if (!ObjectExists(impl_->file.get(), object)) return false;
  const htri_t exists = H5Aexists_by_name(impl_->file.get(), object.c_str(), key.c_str(), H5P_DEFAULT);
  if (exists < 0) H5Eclear2(H5E_DEFAULT);
  return exists > 0;
}

std::string Hdf5Reader::ReadStringAttribute(const std::string& object, const std::string& key) const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  const std::string where = "attribute " + key + " of " + object;
  Handle attr = impl.OpenAttribute(object, key);
  Handle type;
  const H5T_class_t c = impl.AttributeClass(attr.get(), &type, where);
  if (c != H5T_STRING) Fail(impl.path, where, "expected a string, found " + ClassName(c));
  return ReadStringValues(
             type.get(), 1, [&](hid_t mem, void* buf) { return H5Aread(attr.get(), mem, buf); }, impl.path, where)
      .front();
}

double Hdf5Reader::ReadNumberAttribute(const std::string& object, const std::string& key) const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  const std::string where = "attribute " + key + " of " + object;
  Handle attr = impl.OpenAttribute(object, key);
  Handle type;
  const H5T_class_t c = impl.AttributeClass(attr.get(), &type, where);
  if (c != H5T_FLOAT && c != H5T_INTEGER) Fail(impl.path, where, "expected a number, found " + ClassName(c));
  double value = 0;
  Check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &value), impl.path, where, "cannot read");
  return value;
}

std::int64_t Hdf5Reader::ReadIntAttribute(const std::string& object, const std::string& key) const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  const std::string where = "attribute " + key + " of " + object;
  Handle attr = impl.OpenAttribute(object, key);
  Handle type;
  const H5T_class_t c = impl.AttributeClass(attr.get(), &type, where);
  if (c != H5T_INTEGER) Fail(impl.path, where, "expected an integer, found " + ClassName(c));
  std::int64_t value = 0;
  Check(H5Aread(attr.get(), H5T_NATIVE_INT64, &value), impl.path, where, "cannot read");
  return value;
}

std::string Hdf5Reader::ReadAttributeText(const std::string& object, const std::string& key) const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  Handle attr = impl.OpenAttribute(object, key);
  return AttributeText(attr.get(), impl.path, "attribute " + key + " of " + object);
}

std::vector<Hdf5Reader::Entry> Hdf5Reader::List() const {
  QuietHdf5 quiet;
  const Impl& impl = *impl_;
  // The paths of every hard link below the root
  std::vector<std::string> paths{"/"};
  Check(H5Lvisit(
            impl.file.get(), H5_INDEX_NAME, H5_ITER_INC,
            [](hid_t, const char* name, const auto* info, void* data) -> herr_t {
              if (info->type == H5L_TYPE_HARD) static_cast<std::vector<std::string>*>(data)->push_back("/" + std::string(name));
              return 0;
            },
            &paths),
        impl.path, "/", "cannot walk the file");
  // Depth first, by name within a group
  std::sort(paths.begin(), paths.end(),
            [](const std::string& a, const std::string& b) { return PathComponents(a) < PathComponents(b); });
  std::vector<Entry> entries;
  for (const std::string& p : paths) {
    Entry entry;
    entry.path = p;
    if (impl.Describe(entry)) entries.push_back(std::move(entry));
  }
  return entries;
}

}  // namespace orrery

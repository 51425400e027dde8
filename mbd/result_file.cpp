// Result files on the HDF5 C API.
//
// Crash safety: version 1.8 format, normal (not SWMR) mode, H5Fflush, and caches set so that
// nothing reaches the disk between two Flush() calls but raw rows nothing points to yet.
// - Not the latest file format. With H5F_LIBVER_LATEST the superblock is version 3, which carries
//   "open for write" status flags; a writer killed by SIGKILL leaves them set and every later
//   H5Fopen (HDF5 tools, h5py) fails with "file is already open for write (may use <h5clear file>
//   ...)". Files are written with bounds (V18, V18) instead: superblock and object headers of
//   version 2 (checksummed), no status flags, readable by HDF5 1.8 and later.
// - Not SWMR. SWMR needs the version 3 superblock, so a crashed file opens only in SWMR-read mode
//   (plain h5py.File(path) fails), and a SWMR writer may not add datasets, groups or attributes,
//   which this class does at any time (series added late, attributes after the run).
// - H5Fflush leaves a consistent file; what must not happen is HDF5 writing metadata on its own
//   before the next flush. Its default metadata cache does (entries aged out or evicted when the
//   cache is full): chunk index nodes pointing past the flushed end-of-address reach the disk and
//   every read of the series fails with "addr overflow" (ResultFileCrashTest.
//   SigkillAfterManySeriesWroteUnflushedBlocks fails that way with the default cache). So:
//   * the metadata cache has a fixed size of kMetadataCacheBytes, automatic resizing off; dirty
//     entries stay in memory unless the metadata touched between two flushes exceeds that size;
//   * series datasets have no chunk cache and no fill value, so a full block goes straight to its
//     chunk (new space past the flushed end, or the tail of the chunk the last Flush wrote part
//     of) and HDF5 holds no rows of its own; chunks are unfiltered, so they never move.
// Running out of room (a full disk, a file-size limit such as `ulimit -f`, the caller's quota) must
// leave a readable file too, and a file half-written by a flush that failed half way is not one.
// So the room is checked before it runs out, and a write that fails anyway leaves the file alone:
// - CheckRoom() (called before each row by the simulation loop) stops the run with
//   ResultFileFullError while what the file may still need fits: at most one chunk per series
//   (every series' current block; a full block's chunk is allocated when written), the metadata
//   the cache holds (written at the next flush) and kFinalBytes for what a run writes at its end.
//   Limits: the smallest of the quota, RLIMIT_FSIZE and the file's size plus the free space of
//   its file system (statvfs, looked at again once half of what was free may have been used).
//   Then Flush() and Close() write every row appended, within that room.
// - A write or flush that fails all the same (another process filled the disk) detaches the file:
//   HDF5's descriptor is pointed at an anonymous memory file (memfd), so that nothing more reaches
//   the disk and the handles close cleanly; the file keeps what the last successful Flush() wrote.
//   The error says so. HDF5's library shutdown is not run at exit (H5dont_atexit, hdf5_handle.h),
//   so an identifier a failed close left open cannot crash the process as it ends.
// - Not covered: a kill inside Flush() itself. HDF5 writes the metadata of a flush in several
//   pieces, in no crash-safe order outside SWMR; in stress runs such kills left files that opened
//   but had a series unreadable ("addr overflow", "incorrect metadata checksum").

#include "mbd/result_file.h"

#include <hdf5.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "mbd/file_checks.h"
#include "mbd/hdf5_handle.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace orrery {
namespace {

// Target bytes per chunk of a series (rows x ncols doubles); one block buffer holds one chunk.
constexpr std::size_t kChunkBytes = 8192;
// Fixed metadata cache size of a writer (see the top comment).
constexpr std::size_t kMetadataCacheBytes = 32u << 20;
// Room kept for what a run writes after its last row (statistics, health, attributes) and for the
// metadata of the last flush beyond what the cache holds now (chunk index nodes, object headers).
constexpr std::uint64_t kFinalBytes = 64u << 10;

using hdf5::Handle;
using hdf5::Hdf5Detail;
using hdf5::QuietHdf5;

// "result file <file>: <what> <object> (<HDF5 detail>)".
std::string FailMessage(const std::string& file, const std::string& what, const std::string& object) {
  std::string message = "result file " + file + ": " + what;
  if (!object.empty()) message += " " + object;
  const std::string detail = Hdf5Detail();
  if (!detail.empty()) message += " (" + detail + ")";
  return message;
}

// Throws std::runtime_error with FailMessage.
[[noreturn]] void Fail(const std::string& file, const std::string& what, const std::string& object) {
  throw std::runtime_error(FailMessage(file, what, object));
}

// The Impl of a live object: throws std::logic_error after a move or after Close.
template <class ImplPtr>
auto& Live(const ImplPtr& impl, const char* operation) {
  if (!impl) throw std::logic_error(std::string("result file: ") + operation + " on a moved-from object");
  if constexpr (requires { impl->closed; }) {
    if (impl->closed) throw std::logic_error("result file " + impl->path + ": " + operation + " after Close");
  }
  return *impl;
}

// Returns `id` when valid, else fails with the message parts.
hid_t CheckId(hid_t id, const std::string& file, const std::string& what, const std::string& object) {
  if (id < 0) Fail(file, what, object);
  return id;
}

// Fails with the message parts when `status` is negative.
void Check(herr_t status, const std::string& file, const char* what, const std::string& object) {
  if (status < 0) Fail(file, what, object);
}

// Owns `id`, or fails with the message parts when it is invalid.
Handle MakeHandle(hid_t id, Handle::Closer close, const std::string& file, const std::string& what,
                  const std::string& object) {
  return Handle(CheckId(id, file, what, object), close);
}

// Rejects paths that are not absolute object paths ("/a/b", no empty component).
void ValidatePath(const std::string& file, const std::string& path, bool allow_root) {
  const bool root = path == "/";
  bool ok = !path.empty() && path.front() == '/' && (allow_root || !root);
  if (ok && !root) ok = path.back() != '/' && path.find("//") == std::string::npos;
  if (!ok) throw std::invalid_argument("result file " + file + ": invalid object path '" + path + "'");
}

// Whether a link chain resolves to an object at `path` (every prefix checked, so a missing parent
// is "no" rather than an error).
bool ObjectExists(hid_t file, const std::string& path) {
  if (path == "/") return true;
  for (std::size_t slash = path.find('/', 1);; slash = path.find('/', slash + 1)) {
    const std::string prefix = path.substr(0, slash);
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
    if (slash == std::string::npos) break;
  }
  const htri_t resolves = H5Oexists_by_name(file, path.c_str(), H5P_DEFAULT);
  if (resolves < 0) H5Eclear2(H5E_DEFAULT);
  return resolves > 0;
}

// A link creation property list that creates missing groups on the way.
Handle IntermediateGroupsLcpl(const std::string& file, const std::string& object) {
  Handle lcpl = MakeHandle(H5Pcreate(H5P_LINK_CREATE), H5Pclose, file, "cannot create property list for", object);
  Check(H5Pset_create_intermediate_group(lcpl.get(), 1), file, "cannot set intermediate groups for", object);
  return lcpl;
}

// Variable-length UTF-8 string type (h5py reads it as str).
Handle Utf8StringType(const std::string& file, const std::string& object) {
  Handle type = MakeHandle(H5Tcopy(H5T_C_S1), H5Tclose, file, "cannot create string type for", object);
  Check(H5Tset_size(type.get(), H5T_VARIABLE), file, "cannot size string type for", object);
  Check(H5Tset_cset(type.get(), H5T_CSET_UTF8), file, "cannot set UTF-8 for", object);
  return type;
}

// Creates (or replaces) scalar attribute `key` on `obj` of type `type` from `value`.
void WriteScalarAttribute(hid_t obj, const std::string& key, hid_t type, const void* value,
                          const std::string& file, const std::string& object) {
  const std::string where = object + " attribute " + key;
  // Replace an existing attribute (its type may differ)
  const htri_t exists = H5Aexists(obj, key.c_str());
  Check(static_cast<herr_t>(exists), file, "cannot look up", where);
  if (exists > 0) Check(H5Adelete(obj, key.c_str()), file, "cannot replace", where);
  // Create and write it
  Handle space = MakeHandle(H5Screate(H5S_SCALAR), H5Sclose, file, "cannot create dataspace for", where);
  Handle attr = MakeHandle(H5Acreate2(obj, key.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                           H5Aclose, file, "cannot create", where);
  Check(H5Awrite(attr.get(), type, value), file, "cannot write", where);
}

// Creates (or replaces) a scalar variable-length UTF-8 string attribute.
void WriteStringAttribute(hid_t obj, const std::string& key, const std::string& value,
                          const std::string& file, const std::string& object) {
  Handle type = Utf8StringType(file, object);
  const char* text = value.c_str();
  WriteScalarAttribute(obj, key, type.get(), &text, file, object);
}

// One time series: its dataset and the block buffer rows are collected in.
struct Series {
  std::string path;
  hsize_t ncols = 0;
  hsize_t block_capacity = 0;   // rows per block == rows per chunk
  Handle dataset;
  std::vector<double> block;    // block_capacity x ncols, row-major, allocated by AddSeries
  hsize_t block_start = 0;      // file row of block row 0
  hsize_t block_rows = 0;       // rows held in the block
  hsize_t block_written = 0;    // leading block rows already in the file (by Flush)
  hsize_t extent = 0;           // rows of the dataset in the file
};

}  // namespace

struct ResultFile::Impl {
  std::string path;
  Handle file;
  std::vector<Series> series;                      // indexed by SeriesId
  std::unordered_map<std::string, SeriesId> ids;   // series path -> id
  bool closed = false;
  bool detached = false;              // a write failed: nothing more reaches the disk (Detach)
  bool in_memory = false;             // CreateInMemory: no disk, no room to check
  std::string full_reason;            // CheckRoom found no room for another row ("" before)
  std::uint64_t limit_bytes = UINT64_MAX;  // quota and RLIMIT_FSIZE, whichever is smaller
  std::string limit_name;                   // what limit_bytes is, for messages
  std::uint64_t disk_checked_until = 0;     // file size up to which the free space last seen suffices
  std::uint64_t chunk_bytes = 0;            // sum over series of one chunk (AddSeries)

  // Size of the file as HDF5 has allocated it (end of allocated space), 0 if unknown.
  std::uint64_t FileSize() const {
    hsize_t size = 0;
    if (H5Fget_filesize(file.get(), &size) < 0) H5Eclear2(H5E_DEFAULT);
    return size;
  }

  // What the file may still need beyond its size: one chunk per series, the metadata the cache
  // holds, and kFinalBytes.
  std::uint64_t Pending() const {
    std::size_t cache = 0;
    if (H5Fget_mdc_size(file.get(), nullptr, nullptr, &cache, nullptr) < 0) {
      H5Eclear2(H5E_DEFAULT);
      cache = kMetadataCacheBytes;
    }
    return chunk_bytes + cache + kFinalBytes;
  }

  // "" when a file of `needed` bytes fits every limit, else the reason it does not.
  std::string NoRoom(std::uint64_t size, std::uint64_t needed) {
    if (needed > limit_bytes)
      return "the " + limit_name + " of " + std::to_string(limit_bytes) + " bytes would be exceeded (the file has " +
             std::to_string(size) + " bytes)";
    if (needed <= disk_checked_until) return "";
    // Free space of the file system, looked at again
    struct statvfs fs {};
    if (::statvfs(path.c_str(), &fs) != 0) return "";  // cannot tell: go on
    const std::uint64_t free_bytes = static_cast<std::uint64_t>(fs.f_bavail) * fs.f_frsize;
    if (needed > size + free_bytes)
      return "the disk is full (" + std::to_string(free_bytes) + " bytes free, " + std::to_string(needed - size) +
             " needed to go on and close the file)";
    disk_checked_until = size + free_bytes / 2;
    return "";
  }

  // Points HDF5's descriptor at an anonymous memory file and closes every handle, so that the
  // file on disk keeps what the last successful flush wrote (top comment). Errors are ignored.
  void Detach() {
    if (detached) return;
    detached = true;
    if (file.get() >= 0) {
      const hid_t fapl = H5Fget_access_plist(file.get());
      void* handle = nullptr;
      if (fapl >= 0 && H5Fget_vfd_handle(file.get(), fapl, &handle) >= 0 && handle != nullptr) {
        const int memory = ::memfd_create("orrery-detached-result", MFD_CLOEXEC);
        if (memory >= 0) {
          ::dup2(memory, *static_cast<int*>(handle));
          ::close(memory);
        }
      }
      if (fapl >= 0) H5Pclose(fapl);
    }
    for (Series& s : series) s.dataset.Reset();
    file.Reset();
    H5Eclear2(H5E_DEFAULT);
  }

  // Throws after a failed write has detached the file.
  void CheckNotDetached(const char* operation) const {
    if (detached)
      throw std::runtime_error("result file " + path + ": " + operation +
                               " after a failed write (the file keeps what the last flush wrote)");
  }

  // Runs `write`; a failure detaches the file and rethrows with what the file keeps.
  template <class Write>
  void Guarded(Write write) {
    CheckNotDetached("write");
    try {
      write();
    } catch (const std::runtime_error& e) {
      Detach();
      throw std::runtime_error(std::string(e.what()) + "; nothing more was written: the file keeps what the last flush wrote");
    }
  }

  // Writes block rows [block_written, block_rows) of `s` to the file, extending the dataset.
  void WriteBlockRows(Series& s) {
    const hsize_t count = s.block_rows - s.block_written;
    if (count == 0) return;
    const hsize_t first = s.block_start + s.block_written;
    // Grow the dataset to hold the rows
    if (first + count > s.extent) {
      const hsize_t dims[2] = {first + count, s.ncols};
      Check(H5Dset_extent(s.dataset.get(), dims), path, "cannot extend dataset", s.path);
      s.extent = first + count;
    }
    // Select the rows in the file and write them from the block
    Handle file_space = MakeHandle(H5Dget_space(s.dataset.get()), H5Sclose, path, "cannot get dataspace of", s.path);
    const hsize_t start[2] = {first, 0};
    const hsize_t size[2] = {count, s.ncols};
    Check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, size, nullptr), path,
          "cannot select rows of", s.path);
    Handle mem_space =
        MakeHandle(H5Screate_simple(2, size, nullptr), H5Sclose, path, "cannot create dataspace for", s.path);
    Check(H5Dwrite(s.dataset.get(), H5T_NATIVE_DOUBLE, mem_space.get(), file_space.get(), H5P_DEFAULT,
                   s.block.data() + s.block_written * s.ncols),
          path, "cannot write rows of", s.path);
    s.block_written = s.block_rows;
  }

  // Writes a full block and starts the next one.
  void WriteFullBlock(Series& s) {
    WriteBlockRows(s);
    s.block_start += s.block_capacity;
    s.block_rows = 0;
    s.block_written = 0;
  }

  // Opens the object at `path`, creating it as a group (with parents) when missing.
  Handle OpenOrCreateObject(const std::string& object) {
    if (ObjectExists(file.get(), object))
      return MakeHandle(H5Oopen(file.get(), object.c_str(), H5P_DEFAULT), H5Oclose, path, "cannot open object", object);
    Handle lcpl = IntermediateGroupsLcpl(path, object);
    return MakeHandle(H5Gcreate2(file.get(), object.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose, path,
                      "cannot create group", object);
  }

  // Creates a fixed (contiguous) double dataset of `rank` dims from row-major `data`, with "unit".
  void WriteFixed(const std::string& object, int rank, const hsize_t* dims, const double* data,
                  const std::string& unit) {
    WriteFixedTyped(object, rank, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data, &unit);
  }

  // Creates a fixed dataset of file type `file_type` from row-major `data` of memory type
  // `mem_type`, with "unit" when `unit` is given.
  void WriteFixedTyped(const std::string& object, int rank, const hsize_t* dims, hid_t file_type, hid_t mem_type,
                       const void* data, const std::string* unit) {
    ValidatePath(path, object, false);
    Handle space =
        MakeHandle(H5Screate_simple(rank, dims, nullptr), H5Sclose, path, "cannot create dataspace for", object);
    Handle lcpl = IntermediateGroupsLcpl(path, object);
    Handle dataset = MakeHandle(
        H5Dcreate2(file.get(), object.c_str(), file_type, space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Dclose, path, "cannot create dataset", object);
    // Write the values (nothing to write for an empty dataset)
    hssize_t npoints = H5Sget_simple_extent_npoints(space.get());
    if (npoints > 0)
      Check(H5Dwrite(dataset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), path, "cannot write dataset",
            object);
    if (unit != nullptr) WriteStringAttribute(dataset.get(), "unit", *unit, path, object);
  }

  // Narrows 64-bit integers to 32 bits, or throws naming the dataset.
  std::vector<std::int32_t> Narrow(const std::string& object, const std::int64_t* values, std::size_t n) const {
    std::vector<std::int32_t> out(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (values[i] < INT32_MIN || values[i] > INT32_MAX)
        throw std::invalid_argument("result file " + path + ": dataset " + object + ": value " +
                                    std::to_string(values[i]) + " does not fit in 32 bits");
      out[i] = static_cast<std::int32_t>(values[i]);
    }
    return out;
  }
};

// ---------------------------------------------------------------------------------------------
// ResultFile

ResultFile::ResultFile(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ResultFile::ResultFile(ResultFile&&) noexcept = default;

ResultFile& ResultFile::operator=(ResultFile&& other) noexcept {
  if (this != &other) {
    // Close what this object held before taking the other file
    try {
      if (impl_ && !impl_->closed) Close();
    } catch (...) {
    }
    impl_ = std::move(other.impl_);
  }
  return *this;
}

ResultFile::~ResultFile() {
  try {
    if (impl_ && !impl_->closed) Close();
  } catch (...) {
  }
}

namespace {

// File access list of a writer: version 1.8 objects (no superblock status flags), fixed metadata
// cache (the top comment).
Handle WriterAccessList(const std::string& path) {
  Handle fapl = MakeHandle(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, path, "cannot create file access list", "");
  Check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18), path, "cannot set format version", "");
  H5AC_cache_config_t mdc{};
  mdc.version = H5AC__CURR_CACHE_CONFIG_VERSION;
  Check(H5Pget_mdc_config(fapl.get(), &mdc), path, "cannot get metadata cache configuration", "");
  mdc.set_initial_size = true;
  mdc.initial_size = kMetadataCacheBytes;
  mdc.max_size = kMetadataCacheBytes;
  mdc.min_size = std::min(mdc.min_size, kMetadataCacheBytes);
  mdc.incr_mode = H5C_incr__off;
  mdc.flash_incr_mode = H5C_flash_incr__off;
  mdc.decr_mode = H5C_decr__off;
  Check(H5Pset_mdc_config(fapl.get(), &mdc), path, "cannot set metadata cache configuration", "");
  return fapl;
}

}  // namespace

ResultFile ResultFile::Create(const std::string& path, const ResultFileOptions& options) {
  QuietHdf5 quiet;
  // A device, FIFO or directory is no place for a result file (HDF5 reads back what it writes)
  CheckOutputPath(path, "result file");
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  // Limits on the file's size: the caller's quota, the process's file-size limit
  if (options.max_bytes > 0) {
    impl->limit_bytes = options.max_bytes;
    impl->limit_name = "result file size limit";
  }
  struct rlimit fsize {};
  if (::getrlimit(RLIMIT_FSIZE, &fsize) == 0 && fsize.rlim_cur != RLIM_INFINITY &&
      static_cast<std::uint64_t>(fsize.rlim_cur) < impl->limit_bytes) {
    impl->limit_bytes = static_cast<std::uint64_t>(fsize.rlim_cur);
    impl->limit_name = "file-size limit (ulimit -f)";
  }
  // Create (truncate) the file
  Handle fapl = WriterAccessList(path);
  impl->file = MakeHandle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose, path,
                          "cannot create file", "");
  return ResultFile(std::move(impl));
}

ResultFile ResultFile::CreateInMemory(const std::string& name) {
  QuietHdf5 quiet;
  auto impl = std::make_unique<Impl>();
  impl->path = name;
  impl->in_memory = true;
  // The core driver without a backing store: nothing reaches the disk
  Handle fapl = WriterAccessList(name);
  Check(H5Pset_fapl_core(fapl.get(), 1 << 20, 0), name, "cannot set the memory driver", "");
  impl->file = MakeHandle(H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose, name,
                          "cannot create file in memory", "");
  return ResultFile(std::move(impl));
}

ResultFile::SeriesId ResultFile::AddSeries(const std::string& path, int ncols, const std::string& unit,
                                           const std::vector<std::string>& column_names) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "AddSeries");
  // Check the arguments
  ValidatePath(impl.path, path, false);
  if (ncols < 1)
    throw std::invalid_argument("result file " + impl.path + ": series " + path + " needs ncols >= 1, got " +
                                std::to_string(ncols));
  if (!column_names.empty() && column_names.size() != static_cast<std::size_t>(ncols))
    throw std::invalid_argument("result file " + impl.path + ": series " + path + " has " + std::to_string(ncols) +
                                " columns but " + std::to_string(column_names.size()) + " column names");
  if (impl.ids.count(path) != 0 || ObjectExists(impl.file.get(), path))
    throw std::invalid_argument("result file " + impl.path + ": series " + path + " already exists");
  // Size the chunk (and block) to about kChunkBytes
  Series s;
  s.path = path;
  s.ncols = static_cast<hsize_t>(ncols);
  s.block_capacity = std::max<hsize_t>(1, kChunkBytes / (sizeof(double) * s.ncols));
  // Dataset [0 x ncols], unlimited rows, chunked, never filled, no chunk cache
  const hsize_t dims[2] = {0, s.ncols};
  const hsize_t max_dims[2] = {H5S_UNLIMITED, s.ncols};
  const hsize_t chunk[2] = {s.block_capacity, s.ncols};
  Handle space =
      MakeHandle(H5Screate_simple(2, dims, max_dims), H5Sclose, impl.path, "cannot create dataspace for", path);
  Handle dcpl = MakeHandle(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, impl.path, "cannot create property list for", path);
  Check(H5Pset_chunk(dcpl.get(), 2, chunk), impl.path, "cannot set chunking of", path);
  Check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), impl.path, "cannot set fill time of", path);
  Handle dapl = MakeHandle(H5Pcreate(H5P_DATASET_ACCESS), H5Pclose, impl.path, "cannot create property list for", path);
  Check(H5Pset_chunk_cache(dapl.get(), 1, 0, 1.0), impl.path, "cannot set chunk cache of", path);
  Handle lcpl = IntermediateGroupsLcpl(impl.path, path);
  s.dataset = MakeHandle(
      H5Dcreate2(impl.file.get(), path.c_str(), H5T_IEEE_F64LE, space.get(), lcpl.get(), dcpl.get(), dapl.get()),
      H5Dclose, impl.path, "cannot create dataset", path);
  // Attributes "unit" and "columns"
  WriteStringAttribute(s.dataset.get(), "unit", unit, impl.path, path);
  if (!column_names.empty()) {
    std::string columns;
    for (std::size_t i = 0; i < column_names.size(); ++i) columns += (i ? "," : "") + column_names[i];
    WriteStringAttribute(s.dataset.get(), "columns", columns, impl.path, path);
  }
  // The block buffer: the only allocation a series makes
  s.block.assign(s.block_capacity * s.ncols, 0.0);
  impl.chunk_bytes += s.block_capacity * s.ncols * sizeof(double);
  const auto id = static_cast<SeriesId>(impl.series.size());
  impl.series.push_back(std::move(s));
  impl.ids.emplace(path, id);
  return id;
}

void ResultFile::Append(SeriesId id, const double* row) {
  Impl& impl = Live(impl_, "Append");
  if (id < 0 || static_cast<std::size_t>(id) >= impl.series.size())
    throw std::invalid_argument("result file " + impl.path + ": no series with id " + std::to_string(id));
  Series& s = impl.series[static_cast<std::size_t>(id)];
  impl.CheckNotDetached("Append");
  // Copy the row; write the block when it fills
  std::copy_n(row, s.ncols, s.block.data() + s.block_rows * s.ncols);
  if (++s.block_rows == s.block_capacity) {
    QuietHdf5 quiet;
    impl.Guarded([&] { impl.WriteFullBlock(s); });
  }
}

void ResultFile::AppendRow(SeriesId first, int count, const double* row) {
  Impl& impl = Live(impl_, "AppendRow");
  if (first < 0 || count < 0 ||
      static_cast<std::size_t>(first) + static_cast<std::size_t>(count) > impl.series.size())
    throw std::invalid_argument("result file " + impl.path + ": no series " +
                                std::to_string(first) + " to " + std::to_string(first + count - 1));
  impl.CheckNotDetached("AppendRow");
  // Series by series as Append: copy the row (a short loop, not memcpy: most rows are 1 to 6
  // doubles); write the block when it fills
  for (Series *s = impl.series.data() + first, *end = s + count; s != end; ++s) {
    double* to = s->block.data() + s->block_rows * s->ncols;
    for (hsize_t c = 0; c < s->ncols; ++c) to[c] = row[c];
    row += s->ncols;
    if (++s->block_rows == s->block_capacity) {
      QuietHdf5 quiet;
      impl.Guarded([&] { impl.WriteFullBlock(*s); });
    }
  }
}

int ResultFile::cols(SeriesId id) const {
  if (!impl_) throw std::logic_error("result file: cols on a moved-from object");
  const Impl& impl = *impl_;
  if (id < 0 || static_cast<std::size_t>(id) >= impl.series.size())
    throw std::invalid_argument("result file " + impl.path + ": no series with id " +
                                std::to_string(id));
  return static_cast<int>(impl.series[static_cast<std::size_t>(id)].ncols);
}

std::int64_t ResultFile::rows(SeriesId id) const {
  if (!impl_) throw std::logic_error("result file: rows on a moved-from object");
  const Impl& impl = *impl_;
  if (id < 0 || static_cast<std::size_t>(id) >= impl.series.size())
    throw std::invalid_argument("result file " + impl.path + ": no series with id " + std::to_string(id));
  const Series& s = impl.series[static_cast<std::size_t>(id)];
  return static_cast<std::int64_t>(s.block_start + s.block_rows);
}

void ResultFile::WriteMatrix(const std::string& path, const Eigen::MatrixXd& m, const std::string& unit) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "WriteMatrix");
  // Row-major copy for the file's C order
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = m;
  const hsize_t dims[2] = {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())};
  impl.WriteFixed(path, 2, dims, row_major.data(), unit);
}

void ResultFile::WriteVector(const std::string& path, const std::vector<double>& v, const std::string& unit) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "WriteVector");
  const hsize_t dims[1] = {v.size()};
  impl.WriteFixed(path, 1, dims, v.data(), unit);
}

void ResultFile::WriteIntMatrix(const std::string& path,
                                const Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic>& m) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "WriteIntMatrix");
  // Row-major 32-bit copy for the file's C order
  const Eigen::Matrix<std::int64_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = m;
  const std::vector<std::int32_t> values = impl.Narrow(path, row_major.data(), static_cast<std::size_t>(m.size()));
  const hsize_t dims[2] = {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())};
  const std::string unit = "1";
  impl.WriteFixedTyped(path, 2, dims, H5T_STD_I32LE, H5T_NATIVE_INT32, values.data(), &unit);
}

void ResultFile::WriteIntVector(const std::string& path, const std::vector<std::int64_t>& v) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "WriteIntVector");
  const std::vector<std::int32_t> values = impl.Narrow(path, v.data(), v.size());
  const hsize_t dims[1] = {v.size()};
  const std::string unit = "1";
  impl.WriteFixedTyped(path, 1, dims, H5T_STD_I32LE, H5T_NATIVE_INT32, values.data(), &unit);
}

void ResultFile::WriteStrings(const std::string& path, const std::vector<std::string>& values) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "WriteStrings");
  // Variable-length strings are written as an array of char pointers
  Handle type = Utf8StringType(impl.path, path);
  std::vector<const char*> pointers;
  pointers.reserve(values.size());
  for (const std::string& v : values) pointers.push_back(v.c_str());
  const hsize_t dims[1] = {values.size()};
  impl.WriteFixedTyped(path, 1, dims, type.get(), type.get(), pointers.data(), nullptr);
}

void ResultFile::SetAttribute(const std::string& path, const std::string& key, const std::string& value) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "SetAttribute");
  ValidatePath(impl.path, path, true);
  Handle obj = impl.OpenOrCreateObject(path);
  WriteStringAttribute(obj.get(), key, value, impl.path, path);
}

void ResultFile::SetAttribute(const std::string& path, const std::string& key, double value) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "SetAttribute");
  ValidatePath(impl.path, path, true);
  Handle obj = impl.OpenOrCreateObject(path);
  WriteScalarAttribute(obj.get(), key, H5T_NATIVE_DOUBLE, &value, impl.path, path);
}

void ResultFile::SetAttribute(const std::string& path, const std::string& key, std::int64_t value) {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "SetAttribute");
  ValidatePath(impl.path, path, true);
  Handle obj = impl.OpenOrCreateObject(path);
  WriteScalarAttribute(obj.get(), key, H5T_NATIVE_INT64, &value, impl.path, path);
}

void ResultFile::Flush() {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "Flush");
  // Buffered rows of every series, then all metadata
  impl.Guarded([&] {
    for (Series& s : impl.series) impl.WriteBlockRows(s);
    Check(H5Fflush(impl.file.get(), H5F_SCOPE_GLOBAL), impl.path, "cannot flush file", "");
  });
}

void ResultFile::CheckRoom() {
  Impl& impl = Live(impl_, "CheckRoom");
  impl.CheckNotDetached("CheckRoom");
  if (impl.in_memory) return;
  if (!impl.full_reason.empty()) throw ResultFileFullError(impl.full_reason);
  QuietHdf5 quiet;
  const std::uint64_t size = impl.FileSize();
  const std::string reason = impl.NoRoom(size, size + impl.Pending());
  if (reason.empty()) return;
  impl.full_reason = "result file " + impl.path + ": " + reason + "; writing stopped";
  throw ResultFileFullError(impl.full_reason);
}

std::int64_t ResultFile::bytes_per_row() const {
  if (!impl_) throw std::logic_error("result file: bytes_per_row on a moved-from object");
  std::int64_t bytes = 0;
  for (const Series& s : impl_->series) bytes += static_cast<std::int64_t>(s.ncols * sizeof(double));
  return bytes;
}

void ResultFile::Close() {
  QuietHdf5 quiet;
  Impl& impl = Live(impl_, "Close");
  impl.closed = true;
  if (impl.detached) return;  // closed by Detach, after the error that said why
  // Write buffered rows and the metadata (a failure detaches: the file keeps the last flush)
  impl.Guarded([&] {
    for (Series& s : impl.series) impl.WriteBlockRows(s);
    Check(H5Fflush(impl.file.get(), H5F_SCOPE_GLOBAL), impl.path, "cannot flush file", "");
  });
  // Close every handle; keep the first error
  std::string error;
  for (Series& s : impl.series) {
    if (!s.dataset.Reset() && error.empty()) error = FailMessage(impl.path, "cannot close dataset", s.path);
  }
  if (!impl.file.Reset() && error.empty()) error = FailMessage(impl.path, "cannot close file", "");
  if (!error.empty()) throw std::runtime_error(error);
}

const std::string& ResultFile::path() const {
  static const std::string kNone;
  return impl_ ? impl_->path : kNone;
}

}  // namespace orrery

#pragma once
// Small HDF5 helpers shared by the result-file writer and the reader (mbd/ .cpp files only: this
// header includes HDF5, which no other folder sees).
#include <string>
#include <utility>

#include <hdf5.h>

namespace orrery::hdf5 {

// Turns HDF5's automatic error printing off for the life of the guard (the setting is per thread
// in thread-safe builds, so it is set and restored around each call into HDF5).
//
// Every entry point into HDF5 starts with this guard, so its first construction also comes before
// the library initializes: it asks HDF5 not to run its shutdown at exit (H5dont_atexit). That
// shutdown closes whatever identifiers are still open, and one left open by a close that failed
// (a full disk, /dev/null) crashed it (SIGSEGV after main returned). Every object of ours is
// closed by its Handle; files are flushed by their owners, never by the shutdown.
class QuietHdf5 {
 public:
  QuietHdf5() {
    static const bool no_shutdown_at_exit = (H5dont_atexit(), true);
    (void)no_shutdown_at_exit;
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietHdf5(const QuietHdf5&) = delete;
  QuietHdf5& operator=(const QuietHdf5&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      Reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  ~Handle() { Reset(); }

  hid_t get() const { return id_; }
  // Closes now; returns false when HDF5 reports a failure.
  bool Reset() {
    bool ok = true;
    if (id_ >= 0 && close_ != nullptr) ok = close_(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return ok;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

// The most specific message on HDF5's error stack (then clears the stack).
inline std::string Hdf5Detail() {
  std::string detail;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* err, void* data) -> herr_t {
        if (n == 0 && err != nullptr && err->desc != nullptr) *static_cast<std::string*>(data) = err->desc;
        return 0;
      },
      &detail);
  H5Eclear2(H5E_DEFAULT);
  return detail;
}

}  // namespace orrery::hdf5

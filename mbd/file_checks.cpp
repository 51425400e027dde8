#include "mbd/file_checks.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace orrery {
namespace {

[[noreturn]] void Fail(const std::string& what, const std::string& path, const std::string& reason) {
  throw std::runtime_error(what + " " + path + ": " + reason);
}

// "a directory", "a FIFO", ... for messages.
std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

// "64 MiB" for messages.
std::string Mib(std::size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

// Closes a descriptor when it goes out of scope.
struct FdCloser {
  int fd;
  ~FdCloser() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string ReadInputFile(const std::string& path, const std::string& what, std::size_t max_bytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) Fail(what, path, std::string("cannot open: ") + std::strerror(errno));
  const FdCloser closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) Fail(what, path, std::string("cannot stat: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) Fail(what, path, "is a directory");
  const bool regular = S_ISREG(st.st_mode);
  if (regular && static_cast<std::size_t>(st.st_size) > max_bytes)
    Fail(what, path, "is " + std::to_string(st.st_size) + " bytes, more than the " + Mib(max_bytes) + " an input may hold");
  // Read up to one byte past the bound (a device or FIFO may never end)
  std::string text;
  text.reserve(regular ? static_cast<std::size_t>(st.st_size) : 4096);
  char buffer[1 << 16];
  while (text.size() <= max_bytes) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) Fail(what, path, std::string("cannot read: ") + std::strerror(errno));
    if (n == 0) return text;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  Fail(what, path, (regular ? std::string("grew beyond ") : KindOf(st.st_mode) + " giving more than ") + Mib(max_bytes) +
                       " (an input may hold at most that)");
}

void CheckRegularInput(const std::string& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) Fail(what, path, errno == ENOENT ? "no such file" : std::strerror(errno));
  if (!S_ISREG(st.st_mode)) Fail(what, path, KindOf(st.st_mode) + ", not a regular file");
}

void CheckOutputPath(const std::string& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // does not exist yet (or cannot be seen: the create says why)
  if (!S_ISREG(st.st_mode)) Fail(what, path, KindOf(st.st_mode) + ", not a regular file; name a file to write");
}

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

}  // namespace orrery

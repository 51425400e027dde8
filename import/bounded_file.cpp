#include "import/bounded_file.h"

#include <fstream>
#include <stdexcept>

namespace orrery {

std::uintmax_t CheckedFileSize(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw std::runtime_error(path.string() + ": no such file");
  if (!fs::is_regular_file(status)) {
    const char* kind = fs::is_directory(status)       ? "a directory"
                       : fs::is_character_file(status) ? "a character device"
                       : fs::is_block_file(status)     ? "a block device"
                       : fs::is_fifo(status)           ? "a pipe"
                       : fs::is_socket(status)         ? "a socket"
                                                       : "a special file";
    throw std::runtime_error(path.string() + ": not a regular file (" + kind + ")");
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw std::runtime_error(path.string() + ": cannot read its size (" + ec.message() + ")");
  if (size > max_bytes)
    throw std::runtime_error(path.string() + ": " + std::to_string(size) + " bytes, more than the limit of " +
                             std::to_string(max_bytes) + " bytes");
  return size;
}

std::string ReadFileBounded(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  const std::uintmax_t size = CheckedFileSize(path, max_bytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size)
    throw std::runtime_error(path.string() + ": read " + std::to_string(in.gcount()) + " of " + std::to_string(size) +
                             " bytes (the file changed or cannot be read)");
  // One more byte means the file grew while it was read: refuse rather than read on.
  if (in.peek() != std::ifstream::traits_type::eof())
    throw std::runtime_error(path.string() + ": the file grew while it was read");
  return bytes;
}

}  // namespace orrery

#pragma once
// Reading input files with a bound: every importer (surface meshes, gmsh .msh, FE matrices)
// reads its file through these, so that nothing is read without a limit. A path that is not a
// regular file (a directory, /dev/zero, a FIFO) is refused before a byte is read, and a file is
// read only up to its size as the file system states it, which must not exceed the caller's
// limit. A reader that takes counts from the file (triangles, nodes, matrix entries) checks them
// against the bytes that are left before it reserves memory for them.
//
// Usage:
//   std::string bytes = ReadFileBounded("part.stl", kDefaultMaxInputBytes);
#include <cstdint>
#include <filesystem>
#include <string>

namespace orrery {

// 4 GiB: larger than a 50M-triangle binary STL, small enough to refuse a runaway file.
inline constexpr std::uintmax_t kDefaultMaxInputBytes = std::uintmax_t{4} << 30;

// The size of a regular file. Throws std::runtime_error "FILE: no such file", "FILE: not a
// regular file (...)" or "FILE: N bytes, more than the limit of M bytes".
std::uintmax_t CheckedFileSize(const std::filesystem::path& path, std::uintmax_t max_bytes = kDefaultMaxInputBytes);

// The whole content of a regular file (binary), CheckedFileSize first. Throws std::runtime_error
// "FILE: ..." as above, or when reading fails or the file changes size while it is read.
std::string ReadFileBounded(const std::filesystem::path& path, std::uintmax_t max_bytes = kDefaultMaxInputBytes);

}  // namespace orrery

#pragma once
// Checks on the files a command reads and writes, so that nothing reads without bound, blocks on
// a device, or overwrites an input.
//
// - ReadInputFile: the whole of a text input (scene, reduce input) with a size bound. A regular
//   file larger than the bound is refused from its size; anything else (a FIFO, /dev/stdin, a
//   character device such as /dev/zero) is read up to the bound and refused beyond it, so an
//   endless source ends in a message instead of exhausting memory. Directories are refused.
// - CheckRegularInput: for inputs that are streamed or opened by a library (FE meshes, HDF5
//   files): the path must be a regular file.
// - CheckOutputPath: an output must be a regular file or not exist yet (a device, FIFO or
//   directory is refused: HDF5 reads back what it writes, and opening a FIFO blocks).
// - SameFile: whether two paths name the same file (same device and inode), so an output that
//   would overwrite an input is refused however the path is spelt (links, "./", "..").
//
// Every failure throws std::runtime_error "<what> <path>: <reason>".
//
// Usage:
//   const std::string text = ReadInputFile(path, "scene file", kMaxSceneBytes);
//   if (SameFile(output, scene)) throw ...;
#include <cstddef>
#include <string>

namespace orrery {

// Bound of text inputs read whole (scenes, reduce inputs): far above any real scene (the largest
// shipped scene is a few kB), far below what would exhaust memory.
inline constexpr std::size_t kMaxTextInputBytes = std::size_t{64} << 20;

// Reads `path` whole. Throws when it cannot be opened, is a directory, or holds more than
// `max_bytes`.
std::string ReadInputFile(const std::string& path, const std::string& what, std::size_t max_bytes);

// Throws unless `path` exists and is a regular file (symbolic links followed).
void CheckRegularInput(const std::string& path, const std::string& what);

// Throws when `path` exists and is not a regular file.
void CheckOutputPath(const std::string& path, const std::string& what);

// True when both paths exist and are the same file (device and inode); false otherwise.
bool SameFile(const std::string& a, const std::string& b);

}  // namespace orrery

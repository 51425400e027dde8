#pragma once
// XDMF (eXtensible Data Model and Format, version 3; https://www.xdmf.org/index.php/XDMF_Model_and_Format)
// files beside a result file, so that ParaView (File > Open, "Xdmf3ReaderS" or "XDMF Reader")
// animates the deformed surfaces of flexible bodies. The XML holds no numbers of its own: every
// array is a reference "<result>.h5:/path" into the result file, which stays the only data.
//
// Layout of the result file it refers to (written by the recorder):
//   /time                                            (rows x 1) s
//   /flexible_bodies/<body>/surface/triangles        (ntri x 3) int, 0-based node indices
//   /flexible_bodies/<body>/surface/reference_positions (n x 3) m, undeformed, body frame B
//   /flexible_bodies/<body>/surface/positions        (rows x 3 n) m, deformed, world frame,
//                                                    node i in columns 3 i .. 3 i + 2
// Per body: a temporal collection of `rows` grids; grid k has the body's triangles as topology
// and row k of `positions` (a HyperSlab: start (k, 0), stride (1, 1), count (1, 3 n)) as its
// XYZ geometry, at time /time[k]. The times are written into the XML (ParaView needs them as
// values); the reference configuration is one more grid outside the collection.
//
// Usage:
//   WriteSurfaceXdmf("run.h5", {{.body = "planet1", .num_nodes = 812, .num_triangles = 1620}}, times);
//   // -> run.xdmf
//   WriteSurfaceXdmf("run.h5");   // after the run: bodies, sizes and times read from run.h5
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace orrery {

struct XdmfSurface {
  std::string body;               // name under /flexible_bodies
  std::int64_t num_nodes = 0;     // n
  std::int64_t num_triangles = 0; // ntri
};

// The XDMF path of a result file: the same path with extension ".xdmf".
std::filesystem::path XdmfPathFor(const std::filesystem::path& h5_path);

// Writes XdmfPathFor(h5_path) for the given surfaces and output times (one grid per time). The
// data paths are relative to the XDMF file (the result file's name), so the pair can be moved
// together. Throws std::invalid_argument for an empty body name, a name that XML or HDF5 paths
// cannot carry ('/', '<', '&', '"'), or non-positive sizes; std::runtime_error naming the file
// when it cannot be written. Returns the XDMF path.
std::filesystem::path WriteSurfaceXdmf(const std::filesystem::path& h5_path, std::span<const XdmfSurface> surfaces,
                                       std::span<const double> times);

// The same for a finished result file: every body under /flexible_bodies with a surface, its
// sizes from the datasets and the times from /time (checked: positions has one row per time and
// 3 n columns). Throws std::runtime_error naming the file and the dataset that is missing or
// inconsistent.
std::filesystem::path WriteSurfaceXdmf(const std::filesystem::path& h5_path);

}  // namespace orrery

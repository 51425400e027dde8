#include "mbd/xdmf_writer.h"

#include <charconv>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mbd/hdf5_reader.h"

namespace orrery {
namespace {

// Shortest text that reads back to the same double.
std::string Number(double x) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, result.ptr);
}

void CheckSurface(const XdmfSurface& s) {
  if (s.body.empty()) throw std::invalid_argument("XDMF: empty body name");
  if (s.body.find_first_of("/<>&\"'") != std::string::npos)
    throw std::invalid_argument("XDMF: body name '" + s.body + "' contains one of / < > & \" '");
  if (s.num_nodes < 1 || s.num_triangles < 1)
    throw std::invalid_argument("XDMF: body " + s.body + " needs nodes and triangles, got " +
                                std::to_string(s.num_nodes) + " and " + std::to_string(s.num_triangles));
}

// A DataItem reading `dims` values of `h5:path`.
std::string HdfItem(const std::string& h5, const std::string& path, const std::string& dims, bool integers,
                    const std::string& indent) {
  return indent + "<DataItem Format=\"HDF\" Dimensions=\"" + dims + "\" NumberType=\"" +
         (integers ? "Int\" Precision=\"4\"" : "Float\" Precision=\"8\"") + ">" + h5 + ":" + path + "</DataItem>\n";
}

}  // namespace

std::filesystem::path XdmfPathFor(const std::filesystem::path& h5_path) {
  std::filesystem::path p = h5_path;
  return p.replace_extension(".xdmf");
}

std::filesystem::path WriteSurfaceXdmf(const std::filesystem::path& h5_path, std::span<const XdmfSurface> surfaces,
                                       std::span<const double> times) {
  for (const XdmfSurface& s : surfaces) CheckSurface(s);
  const std::string h5 = h5_path.filename().string();
  if (h5.find_first_of("<>&\"") != std::string::npos)
    throw std::invalid_argument("XDMF: result file name " + h5 + " contains one of < > & \"");
  const auto rows = static_cast<std::int64_t>(times.size());
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
    << "<Xdmf xmlns:xi=\"http://www.w3.org/2001/XInclude\" Version=\"3.0\">\n"
    << "  <Domain>\n";
  for (const XdmfSurface& s : surfaces) {
    const std::string base = "/flexible_bodies/" + s.body + "/surface";
    const std::string n = std::to_string(s.num_nodes), ntri = std::to_string(s.num_triangles);
    const auto topology = [&](const std::string& indent) {
      return indent + "<Topology TopologyType=\"Triangle\" NumberOfElements=\"" + ntri + "\">\n" +
             HdfItem(h5, base + "/triangles", ntri + " 3", true, indent + "  ") + indent + "</Topology>\n";
    };
    // The undeformed surface in the body frame
    x << "    <Grid Name=\"" << s.body << " reference (body frame)\" GridType=\"Uniform\">\n"
      << topology("      ") << "      <Geometry GeometryType=\"XYZ\">\n"
      << HdfItem(h5, base + "/reference_positions", n + " 3", false, "        ") << "      </Geometry>\n"
      << "    </Grid>\n";
    // One grid per output time: row k of the deformed positions
    x << "    <Grid Name=\"" << s.body << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    const std::string cols = std::to_string(3 * s.num_nodes);
    for (std::int64_t k = 0; k < rows; ++k) {
      x << "      <Grid Name=\"" << s.body << " " << k << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << Number(times[static_cast<std::size_t>(k)]) << "\"/>\n"
        << topology("        ") << "        <Geometry GeometryType=\"XYZ\">\n"
        << "          <DataItem ItemType=\"HyperSlab\" Dimensions=\"1 " << cols << "\">\n"
        << "            <DataItem Dimensions=\"3 2\" Format=\"XML\">" << k << " 0 1 1 1 " << cols << "</DataItem>\n"
        << HdfItem(h5, base + "/positions", std::to_string(rows) + " " + cols, false, "            ")
        << "          </DataItem>\n"
        << "        </Geometry>\n"
        << "      </Grid>\n";
    }
    x << "    </Grid>\n";
  }
  x << "  </Domain>\n</Xdmf>\n";
  // Write the whole text at once
  const std::filesystem::path path = XdmfPathFor(h5_path);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << x.str();
  out.close();
  if (!out) throw std::runtime_error("XDMF file " + path.string() + ": cannot write");
  return path;
}

std::filesystem::path WriteSurfaceXdmf(const std::filesystem::path& h5_path) {
  const Hdf5Reader r(h5_path.string());
  const std::vector<double> times = r.ReadVector("/time");
  const auto fail = [&](const std::string& object, const std::string& reason) {
    throw std::runtime_error(h5_path.string() + ": " + object + ": " + reason);
  };
  // Bodies with a surface, their sizes checked against the positions series
  std::vector<XdmfSurface> surfaces;
  if (r.IsGroup("/flexible_bodies")) {
    for (const std::string& body : r.ListGroup("/flexible_bodies")) {
      const std::string base = "/flexible_bodies/" + body + "/surface";
      if (!r.IsGroup(base)) continue;
      const std::vector<std::int64_t> tri = r.Shape(base + "/triangles");
      const std::vector<std::int64_t> ref = r.Shape(base + "/reference_positions");
      const std::vector<std::int64_t> pos = r.Shape(base + "/positions");
      if (tri.size() != 2 || tri[1] != 3) fail(base + "/triangles", "expected ntri x 3");
      if (ref.size() != 2 || ref[1] != 3) fail(base + "/reference_positions", "expected n x 3");
      if (pos.size() != 2 || pos[1] != 3 * ref[0] || pos[0] != static_cast<std::int64_t>(times.size()))
        fail(base + "/positions", "expected " + std::to_string(times.size()) + " x " + std::to_string(3 * ref[0]) +
                                      " (one row per /time, 3 columns per surface node)");
      surfaces.push_back({.body = body, .num_nodes = ref[0], .num_triangles = tri[0]});
    }
  }
  return WriteSurfaceXdmf(h5_path, surfaces, times);
}

}  // namespace orrery

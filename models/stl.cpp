#include "models/stl.h"

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace orrery::gears {
namespace {

static_assert(std::endian::native == std::endian::little, "binary STL writer assumes little-endian");

Vec3 FacetNormal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

void PutFloat(std::string& buf, double v) {
  const float f = static_cast<float>(v);
  char bytes[4];
  std::memcpy(bytes, &f, 4);
  buf.append(bytes, 4);
}

void Check(const std::ofstream& out, const std::string& path) {
  if (!out) throw std::runtime_error("STL: cannot write '" + path + "'");
}

}  // namespace

void WriteStlBinary(const TriangleMesh& mesh, const std::string& path, const StlOptions& options) {
  // Header: the solid name, padded with zeros (must not start with "solid").
  std::string buf(80, '\0');
  const std::string header = "binary STL " + options.solid_name;
  std::memcpy(buf.data(), header.data(), std::min<size_t>(80, header.size()));
  const auto count = static_cast<std::uint32_t>(mesh.triangles.size());
  char count_bytes[4];
  std::memcpy(count_bytes, &count, 4);
  buf.append(count_bytes, 4);
  buf.reserve(84 + 50 * static_cast<size_t>(count));
  // Facets.
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] * options.scale, b = mesh.vertices[t[1]] * options.scale,
               c = mesh.vertices[t[2]] * options.scale;
    const Vec3 n = FacetNormal(a, b, c);
    for (const Vec3* v : {&n, &a, &b, &c})
      for (int k = 0; k < 3; ++k) PutFloat(buf, (*v)[k]);
    buf.append(2, '\0');
  }
  std::ofstream out(path, std::ios::binary);
  Check(out, path);
  out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  Check(out, path);
}

void WriteStlAscii(const TriangleMesh& mesh, const std::string& path, const StlOptions& options) {
  std::ofstream out(path);
  Check(out, path);
  char line[160];
  out << "solid " << options.solid_name << "\n";
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] * options.scale, b = mesh.vertices[t[1]] * options.scale,
               c = mesh.vertices[t[2]] * options.scale;
    const Vec3 n = FacetNormal(a, b, c);
    std::snprintf(line, sizeof line, "  facet normal %.9e %.9e %.9e\n", n.x(), n.y(), n.z());
    out << line << "    outer loop\n";
    for (const Vec3* v : {&a, &b, &c}) {
      std::snprintf(line, sizeof line, "      vertex %.9e %.9e %.9e\n", v->x(), v->y(), v->z());
      out << line;
    }
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid " << options.solid_name << "\n";
  Check(out, path);
}

}  // namespace orrery::gears

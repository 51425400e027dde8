#pragma once
// Closed primitive surfaces for the import tests (box, regular prism, UV sphere, torus), and
// writers of the file formats the readers take (binary / ASCII STL, OBJ), so that every test
// makes its own input files. Orientation: outward, counter-clockwise seen from outside.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <unistd.h>

#include "mbd/triangle_mesh.h"

namespace orrery::test_meshes {

inline void Quad(TriangleMesh& m, int a, int b, int c, int d) {
  m.triangles.push_back({a, b, c});
  m.triangles.push_back({a, c, d});
}

// Axis-aligned box [0, a] x [0, b] x [0, c].
inline TriangleMesh Box(double a, double b, double c) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k) m.vertices.emplace_back(k & 1 ? a : 0, k & 2 ? b : 0, k & 4 ? c : 0);
  Quad(m, 0, 2, 3, 1);  // z = 0, normal -z
  Quad(m, 4, 5, 7, 6);  // z = c
  Quad(m, 0, 1, 5, 4);  // y = 0
  Quad(m, 2, 6, 7, 3);  // y = b
  Quad(m, 0, 4, 6, 2);  // x = 0
  Quad(m, 1, 3, 7, 5);  // x = a
  return m;
}

// Regular n-gon prism inscribed in the cylinder of radius r about z, z in [0, h].
inline TriangleMesh Prism(double r, double h, int n) {
  TriangleMesh m;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * std::numbers::pi * k / n;
    m.vertices.emplace_back(r * std::cos(t), r * std::sin(t), 0);
    m.vertices.emplace_back(r * std::cos(t), r * std::sin(t), h);
  }
  const int bottom = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(0, 0, 0);
  m.vertices.emplace_back(0, 0, h);
  for (int k = 0; k < n; ++k) {
    const int i = 2 * k, j = 2 * ((k + 1) % n);
    Quad(m, i, j, j + 1, i + 1);
    m.triangles.push_back({bottom, j, i});
    m.triangles.push_back({bottom + 1, i + 1, j + 1});
  }
  return m;
}

// Tube about z: n-gon prisms of radii r_in < r_out (vertices on the circles), z in [0, h].
inline TriangleMesh Tube(double r_in, double r_out, double h, int n) {
  TriangleMesh m;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * std::numbers::pi * k / n;
    for (double r : {r_in, r_out})
      for (double z : {0.0, h}) m.vertices.emplace_back(r * std::cos(t), r * std::sin(t), z);
  }
  // Vertex 4 k + {0: in bottom, 1: in top, 2: out bottom, 3: out top}
  for (int k = 0; k < n; ++k) {
    const int a = 4 * k, b = 4 * ((k + 1) % n);
    Quad(m, a + 2, b + 2, b + 3, a + 3);  // outer wall, outward
    Quad(m, a + 0, a + 1, b + 1, b + 0);  // bore wall, towards the axis
    Quad(m, a + 0, b + 0, b + 2, a + 2);  // bottom, -z
    Quad(m, a + 1, a + 3, b + 3, b + 1);  // top, +z
  }
  return m;
}

// UV sphere of radius r about the origin: n_lat bands, n_lon meridians.
inline TriangleMesh Sphere(double r, int n_lat, int n_lon) {
  TriangleMesh m;
  m.vertices.emplace_back(0, 0, -r);
  for (int i = 1; i < n_lat; ++i) {
    const double phi = -std::numbers::pi / 2 + std::numbers::pi * i / n_lat;
    for (int j = 0; j < n_lon; ++j) {
      const double t = 2 * std::numbers::pi * j / n_lon;
      m.vertices.emplace_back(r * std::cos(phi) * std::cos(t), r * std::cos(phi) * std::sin(t), r * std::sin(phi));
    }
  }
  const int top = static_cast<int>(m.vertices.size());
  m.vertices.emplace_back(0, 0, r);
  const auto ring = [&](int i, int j) { return 1 + (i - 1) * n_lon + (j % n_lon); };
  for (int j = 0; j < n_lon; ++j) {
    m.triangles.push_back({0, ring(1, j + 1), ring(1, j)});
    m.triangles.push_back({top, ring(n_lat - 1, j), ring(n_lat - 1, j + 1)});
    for (int i = 1; i + 1 < n_lat; ++i) Quad(m, ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j));
  }
  return m;
}

// Torus about z: major radius R, minor radius r, n_u around the axis, n_v around the tube.
inline TriangleMesh Torus(double R, double r, int n_u, int n_v) {
  TriangleMesh m;
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) {
      const double u = 2 * std::numbers::pi * i / n_u, v = 2 * std::numbers::pi * j / n_v;
      m.vertices.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  const auto at = [&](int i, int j) { return (i % n_u) * n_v + (j % n_v); };
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) Quad(m, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  return m;
}

// A scratch directory for one test, removed by the caller.
inline std::filesystem::path ScratchDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("orrery_import_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Coordinates as written = value * scale.
inline void WriteBinaryStl(const TriangleMesh& m, const std::filesystem::path& path, double scale = 1.0,
                           std::uint32_t count_override = 0) {
  std::ofstream out(path, std::ios::binary);
  char header[80] = {};
  std::strncpy(header, "orrery test", sizeof header);
  out.write(header, 80);
  const std::uint32_t n = count_override ? count_override : static_cast<std::uint32_t>(m.triangles.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : m.triangles) {
    float rec[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) rec[3 + 3 * k + j] = static_cast<float>(m.vertices[t[k]][j] * scale);
    out.write(reinterpret_cast<const char*>(rec), sizeof rec);
    const std::uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
}

inline std::string AsciiStl(const TriangleMesh& m, const std::string& name = "part", double scale = 1.0) {
  std::string s = "solid " + name + "\n";
  char buf[160];
  for (const auto& t : m.triangles) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = m.vertices[t[k]] * scale;
      std::snprintf(buf, sizeof buf, "      vertex %.17g %.17g %.17g\n", p.x(), p.y(), p.z());
      s += buf;
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid " + name + "\n";
}

inline std::string Obj(const TriangleMesh& m, double scale = 1.0) {
  std::string s = "# orrery test\no part\n";
  char buf[160];
  for (const Vec3& v : m.vertices) {
    std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", v.x() * scale, v.y() * scale, v.z() * scale);
    s += buf;
  }
  for (const auto& t : m.triangles) s += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  return s;
}

inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace orrery::test_meshes

// Surface-mesh reading (import/surface_mesh.h and its readers): every format gives the same welded
// mesh in metres; STL binary/ASCII and OBJ by the project's readers, PLY, glTF and 3MF through
// assimp (files written by hand where the format is text, by assimp's exporter otherwise). The
// project's STL and OBJ readers are checked against assimp's own reading of the same files (an
// independent implementation). Bad input: each case one error naming the file and the problem.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "import/assimp_surface.h"
#include "import/obj_reader.h"
#include "import/stl_reader.h"
#include "import/surface_mesh.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using namespace test_meshes;

class SurfaceMeshTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = ScratchDir("surface"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  // The error message of reading `path`, "" when it reads.
  std::string ErrorOf(const std::string& path, SurfaceReadOptions options = {}) const {
    try {
      ReadSurfaceMesh(path, options);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

// Same vertex count and the same triangles (each matched, up to a cyclic turn of its vertices, to
// one of the other mesh within `tol` per coordinate; brute force, the meshes are small).
void ExpectSameMesh(const TriangleMesh& a, const TriangleMesh& b, double tol) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  std::vector<char> used(b.triangles.size(), 0);
  for (std::size_t s = 0; s < a.triangles.size(); ++s) {
    bool found = false;
    for (std::size_t t = 0; t < b.triangles.size() && !found; ++t) {
      if (used[t]) continue;
      for (int turn = 0; turn < 3 && !found; ++turn) {
        double d = 0;
        for (int k = 0; k < 3; ++k)
          d = std::max(d, (a.vertices[a.triangles[s][k]] - b.vertices[b.triangles[t][(k + turn) % 3]]).cwiseAbs().maxCoeff());
        if (d <= tol) {
          found = true;
          used[t] = 1;
        }
      }
    }
    ASSERT_TRUE(found) << "triangle " << s << " has no match";
  }
}

TEST_F(SurfaceMeshTest, StlBinaryAsciiAndObjGiveTheWeldedMeshInMetres) {
  const TriangleMesh torus = Torus(0.04, 0.01, 24, 12);  // 288 vertices, 576 triangles
  WriteBinaryStl(torus, Path("t.stl"), 1000);            // millimetres, float32
  WriteText(Path("ta.stl"), AsciiStl(torus, "ring", 1000));
  WriteText(Path("t.obj"), Obj(torus, 1000));
  const SurfaceReadOptions mm{.unit = LengthUnit::kMillimetre};
  const SurfaceMesh binary = ReadSurfaceMesh(Path("t.stl"), mm);
  const SurfaceMesh ascii = ReadSurfaceMesh(Path("ta.stl"), mm);
  const SurfaceMesh obj = ReadSurfaceMesh(Path("t.obj"), mm);
  EXPECT_EQ(binary.format, "STL (binary)");
  EXPECT_EQ(ascii.format, "STL (ASCII)");
  EXPECT_EQ(obj.format, "OBJ");
  // Welded: the torus's own vertex count, 3 per triangle in the STL files
  EXPECT_EQ(binary.file_vertices, 3 * 576);
  EXPECT_EQ(binary.mesh.vertices.size(), 288u);
  EXPECT_EQ(ascii.mesh.vertices.size(), 288u);
  EXPECT_EQ(obj.mesh.vertices.size(), 288u);
  EXPECT_EQ(binary.unit, "mm");
  EXPECT_TRUE(binary.unit_stated);
  ASSERT_EQ(ascii.region_names.size(), 1u);
  EXPECT_EQ(ascii.region_names[0], "ring");
  // float32 of millimetres: 0.5 ulp of 50 mm is 2e-6 mm
  ExpectSameMesh(binary.mesh, torus, 5e-9);
  ExpectSameMesh(ascii.mesh, torus, 1e-15);
  ExpectSameMesh(obj.mesh, torus, 1e-15);
  // Normals from the faces: unit and outward (the torus is oriented outward)
  for (std::size_t t = 0; t < obj.face_normals.size(); ++t) EXPECT_NEAR(obj.face_normals[t].norm(), 1.0, 1e-12);
}

TEST_F(SurfaceMeshTest, OwnReadersAgreeWithAssimp) {
  const TriangleMesh sphere = Sphere(0.02, 10, 16);
  WriteBinaryStl(sphere, Path("s.stl"));
  WriteText(Path("sa.stl"), AsciiStl(sphere));
  WriteText(Path("s.obj"), Obj(sphere));
  for (const char* name : {"s.stl", "sa.stl", "s.obj"}) {
    const SurfaceMesh ours = ReadSurfaceMesh(Path(name));
    const SurfaceMesh theirs = WeldRawSurface(ReadAssimpSurface(Path(name)), 1.0, name);
    ExpectSameMesh(ours.mesh, theirs.mesh, 1e-7);  // assimp keeps single precision
  }
}

TEST_F(SurfaceMeshTest, AssimpFormatsPlyGltfAnd3mf) {
  const TriangleMesh box = Box(0.1, 0.05, 0.02);
  // PLY, written by hand (ASCII)
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& v : box.vertices) ply += std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z()) + "\n";
  for (const auto& t : box.triangles) ply += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  WriteText(Path("box.ply"), ply);
  // glTF 2.0 with an embedded base64 buffer: 8 float32 positions, 36 uint16 indices
  std::string buffer;
  for (const Vec3& v : box.vertices)
    for (int k = 0; k < 3; ++k) {
      const float f = static_cast<float>(v[k]);
      buffer.append(reinterpret_cast<const char*>(&f), 4);
    }
  for (const auto& t : box.triangles)
    for (int i : t) {
      const std::uint16_t u = static_cast<std::uint16_t>(i);
      buffer.append(reinterpret_cast<const char*>(&u), 2);
    }
  static const char* kB64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < buffer.size(); i += 3) {
    std::uint32_t n = static_cast<unsigned char>(buffer[i]) << 16;
    if (i + 1 < buffer.size()) n |= static_cast<unsigned char>(buffer[i + 1]) << 8;
    if (i + 2 < buffer.size()) n |= static_cast<unsigned char>(buffer[i + 2]);
    b64 += kB64[n >> 18 & 63];
    b64 += kB64[n >> 12 & 63];
    b64 += i + 1 < buffer.size() ? kB64[n >> 6 & 63] : '=';
    b64 += i + 2 < buffer.size() ? kB64[n & 63] : '=';
  }
  const std::string gltf =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
      "\"meshes\":[{\"name\":\"block\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
      "\"buffers\":[{\"byteLength\":168,\"uri\":\"data:application/octet-stream;base64," + b64 + "\"}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":96},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":72}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":8,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[0.1,0.05,0.02]},"
      "{\"bufferView\":1,\"componentType\":5123,\"count\":36,\"type\":\"SCALAR\"}]}";
  WriteText(Path("box.gltf"), gltf);
  // 3MF and binary glTF by assimp's exporter
  WriteAssimpSurface(box, Path("box.3mf"), "3mf");
  WriteAssimpSurface(box, Path("box.glb"), "glb2");
  for (const char* name : {"box.ply", "box.gltf", "box.3mf", "box.glb"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh s = ReadSurfaceMesh(Path(name));
    EXPECT_EQ(s.format.rfind("assimp", 0), 0u) << s.format;
    ExpectSameMesh(s.mesh, box, 1e-7);
  }
  EXPECT_EQ(ReadSurfaceMesh(Path("box.gltf")).region_names.at(0), "block");
}

TEST_F(SurfaceMeshTest, UnitsAndTheMillimetreWarning) {
  const TriangleMesh box = Box(0.1, 0.05, 0.02);
  WriteBinaryStl(box, Path("mm.stl"), 1000);
  const SurfaceMesh plain = ReadSurfaceMesh(Path("mm.stl"));
  ASSERT_EQ(plain.warnings.size(), 1u);
  EXPECT_NE(plain.warnings[0].find("100 m across"), std::string::npos) << plain.warnings[0];
  EXPECT_NE(plain.warnings[0].find("--unit mm"), std::string::npos);
  EXPECT_FALSE(plain.unit_stated);
  const SurfaceMesh mm = ReadSurfaceMesh(Path("mm.stl"), {.unit = LengthUnit::kMillimetre});
  EXPECT_TRUE(mm.warnings.empty());
  WriteBinaryStl(box, Path("in.stl"), 1 / 0.0254);
  const SurfaceMesh in = ReadSurfaceMesh(Path("in.stl"), {.unit = LengthUnit::kInch});
  ExpectSameMesh(in.mesh, box, 1e-8);
  EXPECT_EQ(ParseLengthUnit("in"), LengthUnit::kInch);
  EXPECT_FALSE(ParseLengthUnit("inch").has_value());
}

TEST_F(SurfaceMeshTest, StlParserDetails) {
  // Binary header beginning with "solid": still binary by its size
  const TriangleMesh box = Box(1, 1, 1);
  WriteBinaryStl(box, Path("solid.stl"));
  {
    std::fstream f(Path("solid.stl"), std::ios::in | std::ios::out | std::ios::binary);
    f.write("solid binary", 12);
  }
  EXPECT_EQ(ReadSurfaceMesh(Path("solid.stl")).format, "STL (binary)");
  // ASCII: case-insensitive keywords, several solids (regions), a quad facet split in two
  const std::string text =
      "SOLID a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
      "endfacet\nendsolid a\nsolid b\nfacet normal 0 0 0\n outer loop\n vertex 0 0 1\n vertex 1 0 1\n vertex 0 1 1\n"
      " endloop\nendfacet\nendsolid\n";
  const RawSurface raw = ParseStl(text, "x.stl");
  EXPECT_EQ(raw.triangles.size(), 3u);
  EXPECT_EQ(raw.region_names, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(raw.triangle_region, (std::vector<int>{0, 0, 1}));
}

TEST_F(SurfaceMeshTest, ObjParserDetails) {
  const std::string text =
      "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
      "g top\nf 1/1/1 2/1/1 3/1/1 4/1/1\ng side\nf -4//1 -3//1 -1//1\ns off\n";
  const RawSurface raw = ParseObj(text, "x.obj");
  ASSERT_EQ(raw.triangles.size(), 3u);
  EXPECT_EQ(raw.triangles[2], (std::array<int, 3>{0, 1, 3}));
  EXPECT_EQ(raw.region_names, (std::vector<std::string>{"top", "side"}));
  EXPECT_EQ(raw.notes.size(), 4u);  // mtllib, vt, vn, s: one note each
}

TEST_F(SurfaceMeshTest, BadInputIsOneErrorNamingTheFile) {
  const std::string missing = Path("missing.stl");
  EXPECT_EQ(ErrorOf(missing), missing + ": no such file");
  EXPECT_EQ(ErrorOf("/dev/zero"), "/dev/zero: not a regular file (a character device)");
  EXPECT_EQ(ErrorOf(dir_.string()), dir_.string() + ": not a regular file (a directory)");
  WriteText(Path("x.xyz"), "1 2 3\n");
  EXPECT_EQ(ErrorOf(Path("x.xyz")).rfind(Path("x.xyz") + ": unknown mesh format '.xyz' (supported: .stl .obj .step", 0), 0u)
      << ErrorOf(Path("x.xyz"));
  // Binary STL whose count promises more (or fewer) triangles than the file holds
  WriteBinaryStl(Box(1, 1, 1), Path("count.stl"), 1.0, 1000);
  EXPECT_EQ(ErrorOf(Path("count.stl")),
            Path("count.stl") + ": binary STL header says 1000 triangles (50084 bytes) but the file has 684 bytes");
  WriteBinaryStl(Box(1, 1, 1), Path("huge_count.stl"), 1.0, 0xffffffffu);
  EXPECT_NE(ErrorOf(Path("huge_count.stl")).find("header says 4294967295 triangles"), std::string::npos);
  WriteText(Path("short.stl"), "abc");
  EXPECT_NE(ErrorOf(Path("short.stl")).find("not an STL file (3 bytes"), std::string::npos);
  WriteText(Path("empty.stl"), "solid e\nendsolid e\n");
  EXPECT_EQ(ErrorOf(Path("empty.stl")), Path("empty.stl") + ": the STL file holds no triangles");
  WriteBinaryStl(TriangleMesh{}, Path("empty_binary.stl"));
  EXPECT_EQ(ErrorOf(Path("empty_binary.stl")), Path("empty_binary.stl") + ": the binary STL file holds no triangles");
  WriteText(Path("bad.stl"), "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\nendloop\n");
  EXPECT_EQ(ErrorOf(Path("bad.stl")), Path("bad.stl") + ":6: expected a coordinate, got 'endloop'");
  // NaN and huge coordinates
  WriteText(Path("nan.stl"), "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\nvertex 0 1 0\n"
                             "endloop\nendfacet\nendsolid x\n");
  EXPECT_EQ(ErrorOf(Path("nan.stl")), Path("nan.stl") + ": vertex 2 has a non-finite coordinate (1, 0, nan)");
  WriteText(Path("huge.obj"), "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(ErrorOf(Path("huge.obj")).find(Path("huge.obj") + ": vertex 2 lies 1e+30 m from the origin"), std::string::npos)
      << ErrorOf(Path("huge.obj"));
  // OBJ: bad index, no faces, short face
  WriteText(Path("index.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  EXPECT_EQ(ErrorOf(Path("index.obj")), Path("index.obj") + ":4: face refers to vertex 4, but 3 are defined so far");
  WriteText(Path("noface.obj"), "v 0 0 0\n");
  EXPECT_EQ(ErrorOf(Path("noface.obj")), Path("noface.obj") + ": the OBJ file holds no faces");
  WriteText(Path("short.obj"), "v 0 0 0\nv 1 0 0\nf 1 2\n");
  EXPECT_EQ(ErrorOf(Path("short.obj")), Path("short.obj") + ":3: a face needs at least 3 vertices, got 2");
  // assimp's own message for a broken file
  WriteText(Path("bad.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n");
  EXPECT_EQ(ErrorOf(Path("bad.ply")).rfind(Path("bad.ply") + ": ", 0), 0u) << ErrorOf(Path("bad.ply"));
  // A zip container (3MF) that would expand beyond the limit is not expanded
  WriteAssimpSurface(Sphere(1, 8, 8), Path("zip.3mf"), "3mf");
  const auto zip_size = fs::file_size(Path("zip.3mf"));
  EXPECT_NE(ErrorOf(Path("zip.3mf"), {.max_bytes = zip_size}).find(": zip container expands to "), std::string::npos)
      << ErrorOf(Path("zip.3mf"), {.max_bytes = zip_size});
  // A size limit
  WriteBinaryStl(Box(1, 1, 1), Path("limit.stl"));
  EXPECT_EQ(ErrorOf(Path("limit.stl"), {.max_bytes = 100}), Path("limit.stl") + ": 684 bytes, more than the limit of 100 bytes");
}

}  // namespace
}  // namespace orrery

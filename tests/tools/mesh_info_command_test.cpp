// `orrery mesh-info` (tools/cli/mesh_info_command.cpp), in process and through the built program:
// the JSON keys the issue fixes (triangles, watertight, volume_m3, mass_kg, center_of_mass_m,
// inertia_kg_m2) with a box's closed-form values, nulls where a value does not exist, and bad
// input as one error line with exit code 1.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "import/gmsh_mesher.h"
#include "tests/common/cli_support.h"
#include "tests/import/mesh_fixtures.h"
#include "tools/cli/error_message.h"
#include "tools/cli/mesh_info_command.h"

namespace orrery::cli {
namespace {

namespace fs = std::filesystem;
using namespace test_meshes;
using test_support::JsonArray;
using test_support::JsonNumber;

// 'text' for a shell command (appends: GCC 12 warns wrongly about "'" + std::string).
std::string Quote(const std::string& text) {
  std::string q(1, '\'');
  q += text;
  q += '\'';
  return q;
}

class MeshInfoTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = ScratchDir("mesh_info"); }
  void TearDown() override { fs::remove_all(dir_); }
  int Run(MeshInfoArgs args) {
    out_.str("");
    err_.str("");
    return MeshInfoCommand(args, out_, err_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
  std::ostringstream out_, err_;
};

TEST_F(MeshInfoTest, JsonOfABoxInMillimetres) {
  // 100 x 50 x 20 mm, steel, shifted: closed forms of a box
  TriangleMesh box = Box(0.1, 0.05, 0.02);
  for (Vec3& v : box.vertices) v += Vec3(0.01, 0.02, 0.03);
  WriteBinaryStl(box, Path("box.stl"), 1000);
  ASSERT_EQ(Run({.path = Path("box.stl"), .unit = "mm", .density_kg_m3 = 7850, .json = true}), kExitSuccess) << err_.str();
  const std::string json = out_.str();
  const double m = 7850 * 1e-4;
  EXPECT_EQ(JsonNumber(json, "triangles"), 12);
  EXPECT_NE(json.find("\"watertight\": true"), std::string::npos) << json;
  EXPECT_NEAR(JsonNumber(json, "volume_m3"), 1e-4, 1e-4 * 1e-6);  // float32 millimetres
  EXPECT_NEAR(JsonNumber(json, "mass_kg"), m, m * 1e-6);
  const std::vector<double> c = JsonArray(json, "center_of_mass_m");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_NEAR(c[0], 0.06, 1e-8);
  EXPECT_NEAR(c[1], 0.045, 1e-8);
  EXPECT_NEAR(c[2], 0.04, 1e-8);
  // inertia_kg_m2: 3 rows of 3, read in order
  const std::size_t at = json.find("\"inertia_kg_m2\"");
  ASSERT_NE(at, std::string::npos);
  std::vector<double> rows;
  for (const char* q = json.c_str() + json.find('[', at); rows.size() < 9 && *q != '\0';) {
    if (*q == '[' || *q == ']' || *q == ',' || *q == ' ' || *q == '\n') {
      ++q;
      continue;
    }
    char* end = nullptr;
    rows.push_back(std::strtod(q, &end));
    q = end;
  }
  ASSERT_EQ(rows.size(), 9u);
  EXPECT_NEAR(rows[0], m * (0.05 * 0.05 + 0.02 * 0.02) / 12, 1e-6 * rows[0]);
  EXPECT_NEAR(rows[4], m * (0.1 * 0.1 + 0.02 * 0.02) / 12, 1e-6 * rows[4]);
  EXPECT_NEAR(rows[8], m * (0.1 * 0.1 + 0.05 * 0.05) / 12, 1e-6 * rows[8]);
  EXPECT_NEAR(rows[1], 0, 1e-6 * rows[0]);
  EXPECT_EQ(err_.str(), "");
}

TEST_F(MeshInfoTest, NullsWhereThereIsNoValue) {
  WriteText(Path("box.obj"), Obj(Box(1, 1, 1)));
  ASSERT_EQ(Run({.path = Path("box.obj"), .json = true}), kExitSuccess);
  EXPECT_NE(out_.str().find("\"mass_kg\": null"), std::string::npos) << out_.str();
  EXPECT_NE(out_.str().find("\"inertia_kg_m2\": null"), std::string::npos);
  EXPECT_NEAR(JsonNumber(out_.str(), "volume_m3"), 1.0, 1e-15);
  // Open: no volume, not an error without a density
  TriangleMesh open = Box(1, 1, 1);
  open.triangles.pop_back();
  WriteText(Path("open.obj"), Obj(open));
  ASSERT_EQ(Run({.path = Path("open.obj"), .json = true}), kExitSuccess);
  EXPECT_NE(out_.str().find("\"watertight\": false"), std::string::npos);
  EXPECT_NE(out_.str().find("\"volume_m3\": null"), std::string::npos);
  EXPECT_EQ(JsonNumber(out_.str(), "boundary_edges"), 3);
  // Text
  ASSERT_EQ(Run({.path = Path("open.obj")}), kExitSuccess);
  EXPECT_NE(out_.str().find("watertight: no"), std::string::npos) << out_.str();
  EXPECT_NE(out_.str().find("3 boundary edges: the mesh is open"), std::string::npos);
}

TEST_F(MeshInfoTest, BadInputIsOneErrorLine) {
  TriangleMesh open = Box(1, 1, 1);
  open.triangles.pop_back();
  WriteText(Path("open.obj"), Obj(open));
  const struct {
    MeshInfoArgs args;
    std::string error;
  } cases[] = {
      {{.path = Path("open.obj"), .density_kg_m3 = 1000},
       Path("open.obj") + ": mass properties need a closed surface, but the mesh is not watertight (3 boundary edges, 0 "
                          "non-manifold edges)"},
      {{.path = "/dev/zero"}, "/dev/zero: not a regular file (a character device)"},
      {{.path = Path("none.stl")}, Path("none.stl") + ": no such file"},
      {{.path = Path("open.obj"), .unit = "furlong"}, "--unit furlong: expected m, cm, mm or in"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(Run(c.args), kExitFailure);
    EXPECT_EQ(err_.str(), "orrery: error: " + c.error + "\n");
    EXPECT_EQ(out_.str(), "");
  }
}

TEST_F(MeshInfoTest, TheProgramAnswersForEveryFormat) {
  const fs::path orrery = fs::path(ORRERY_BINARY_DIR) / "bin" / "orrery";
  if (!fs::exists(orrery)) GTEST_SKIP() << "orrery program not built";
  WriteBinaryStl(Prism(0.02, 0.01, 32), Path("p.stl"));
  WriteText(Path("p.obj"), Obj(Prism(0.02, 0.01, 32)));
  for (const char* name : {"p.stl", "p.obj"}) {
    const auto [out, code] = test_support::RunCommand(Quote(orrery.string()) + " mesh-info " + Quote(Path(name)) + " --density 7850 --json");
    EXPECT_EQ(code, 0) << out;
    EXPECT_NEAR(JsonNumber(out, "volume_m3"), 0.01 * 16 * 0.02 * 0.02 * std::sin(2 * 3.14159265358979 / 32), 1e-12);
  }
  // STEP through gmsh
  if (const auto gmsh = FindGmsh()) {
    WriteText(Path("c.geo"), "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 30, 20, 10};\n");
    const std::string make_step =
        "cd " + Quote(dir_.string()) + " && " + Quote(gmsh->string()) + " c.geo -0 -o c.step -format step > /dev/null 2>&1";
    ASSERT_EQ(std::system(make_step.c_str()), 0);
    const auto [out, code] = test_support::RunCommand(Quote(orrery.string()) + " mesh-info " + Quote(Path("c.step")) + " --density 1000 --json");
    EXPECT_EQ(code, 0) << out;
    EXPECT_NEAR(JsonNumber(out, "volume_m3"), 6e-6, 1e-18);
    EXPECT_NEAR(JsonNumber(out, "mass_kg"), 6e-3, 1e-15);
    EXPECT_NE(out.find("\"unit\": \"mm\""), std::string::npos) << out;
  }
  const auto [out, code] = test_support::RunCommand(Quote(orrery.string()) + " mesh-info " + Quote(Path("p.xyz")));
  EXPECT_EQ(code, 1);
  EXPECT_EQ(out, "orrery: error: " + Path("p.xyz") + ": no such file\n");
}

}  // namespace
}  // namespace orrery::cli

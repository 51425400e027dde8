// gmsh .msh files (import/msh_reader.h). Hand-written 2.2 and 4.1 ASCII files with physical
// groups; the same tet10 and hex20 meshes saved by gmsh in all four variants (2.2 / 4.1, ASCII /
// binary) must read to the same FE mesh, whose midside nodes (in CalculiX order after the
// conversion) sit at the midpoints of their edges on these straight-sided meshes and whose
// elements fill the box exactly (the FE assembly's volume). Bad input: one error each.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "flex/fe_assembly.h"
#include "import/gmsh_mesher.h"
#include "import/msh_reader.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using namespace test_meshes;

// A unit cube as one hex8 (physical volume 7 "BODY") and its bottom face as two triangles
// (physical surface 3 "BOTTOM"), in 2.2 and 4.1 ASCII.
constexpr const char* kCube22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
2 3 "BOTTOM"
3 7 "BODY"
$EndPhysicalNames
$Nodes
8
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0 0 1
6 1 0 1
7 1 1 1
8 0 1 1
$EndNodes
$Elements
3
1 2 2 3 1 1 3 2
2 2 2 3 1 1 4 3
3 5 2 7 1 1 2 3 4 5 6 7 8
$EndElements
)";

constexpr const char* kCube41 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
2 3 "BOTTOM"
3 7 "BODY"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 1 0 1 3 0
1 0 0 0 1 1 1 1 7 0
$EndEntities
$Nodes
1 8 1 8
3 1 0 8
1
2
3
4
5
6
7
8
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
$EndNodes
$Elements
2 3 1 3
2 1 2 2
1 1 3 2
2 1 4 3
3 1 5 1
3 1 2 3 4 5 6 7 8
$EndElements
)";

std::string ErrorOf(const std::string& text) {
  try {
    ParseGmshMsh(text, "x.msh");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(MshReaderTest, HandWrittenFilesWithPhysicalGroups) {
  for (const char* text : {kCube22, kCube41}) {
    const GmshMesh m = ParseGmshMsh(text, "cube.msh", {.scale = 0.01});
    ASSERT_EQ(m.mesh.num_nodes(), 8);
    ASSERT_EQ(m.mesh.num_elements(), 1);
    EXPECT_EQ(m.mesh.elements()[0].type, flex::ElementType::kHex8);
    EXPECT_EQ(m.mesh.positions()[6], Eigen::Vector3d(0.01, 0.01, 0.01));
    EXPECT_EQ(m.mesh.NodeSet("BOTTOM"), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(m.mesh.NodeSet("body").size(), 8u);
    EXPECT_EQ(m.mesh.ElementSet("BODY"), (std::vector<int>{0}));
    EXPECT_EQ(m.surface.triangles.size(), 2u);
    EXPECT_EQ(m.surface.region_names, (std::vector<std::string>{"BOTTOM"}));
    flex::FeMesh mesh = m.mesh;
    mesh.AssignMaterialToAll({.name = "S", .youngs_modulus_pa = 2e11, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
    EXPECT_NEAR(flex::AssembleFeSystem(mesh).volume_m3, 1e-6, 1e-18);
  }
  EXPECT_EQ(ParseGmshMsh(kCube41, "c").volume_entities, 1);
}

TEST(MshReaderTest, BadInputIsOneErrorNamingTheFile) {
  std::string text = kCube22;
  // An element on a node that is not in $Nodes
  std::string missing = text;
  missing.replace(missing.find("3 5 2 7 1 1 2 3 4 5 6 7 8"), 25, "3 5 2 7 1 1 2 3 4 5 6 7 9");
  EXPECT_EQ(ErrorOf(missing), "x.msh: element 3 refers to node 9, which is not in $Nodes");
  // A prism: no such FE element
  std::string prism = text;
  prism.replace(prism.find("3 5 2 7 1 1 2 3 4 5 6 7 8"), 25, "3 6 2 7 1 1 2 3 4 5 6");
  EXPECT_EQ(ErrorOf(prism), "x.msh: element 3 is a 6-node prism (gmsh type 6), which Orrery's FE solids do not have "
                            "(tet4, tet10, hex8, hex20)");
  // Unknown type, old version, duplicate node, truncated, not a mesh
  std::string unknown = text;
  unknown.replace(unknown.find("3 5 2 7 1 1"), 11, "3 99 2 7 1 1");
  EXPECT_EQ(ErrorOf(unknown), "x.msh:24: $Elements: element 3: unknown element type 99");
  std::string v40 = text;
  v40.replace(v40.find("2.2 0 8"), 7, "4 0 8");
  EXPECT_EQ(ErrorOf(v40), "x.msh:2: $MeshFormat: MSH version 4 is not supported: save the mesh as version 4.1 or 2.2");
  std::string duplicate = text;
  duplicate.replace(duplicate.find("2 1 0 0\n"), 8, "1 1 0 0\n");
  EXPECT_EQ(ErrorOf(duplicate), "x.msh:12: $Nodes: node tag 1 appears twice");
  EXPECT_EQ(ErrorOf(text.substr(0, text.find("5 0 0 1"))), "x.msh:14: $Nodes: expected a node tag, got the end of the file");
  EXPECT_EQ(ErrorOf("hello\n"), "x.msh:1: expected a section ($Name), got 'hello'");
  std::string nan = text;
  nan.replace(nan.find("7 1 1 1"), 7, "7 1 nan 1");
  EXPECT_EQ(ErrorOf(nan), "x.msh:17: $Nodes: node 7 has a non-finite coordinate");
  std::string huge = text;
  huge.replace(huge.find("7 1 1 1"), 7, "7 1 1e300 1");
  EXPECT_EQ(ErrorOf(huge), "x.msh:17: $Nodes: node 7 lies beyond 100000 m from the origin (wrong unit or a corrupt file?)");
  // A count in a header is not trusted: a billion nodes announced in a short file
  std::string many = kCube41;
  many.replace(many.find("1 8 1 8\n3 1 0 8"), 15, "1 8 1 8\n3 1 0 1000000000");
  EXPECT_NE(ErrorOf(many).find("header says 1000000000 items"), std::string::npos) << ErrorOf(many);
}

// gmsh's own files: a box as tet10 and as hex20, each saved four ways.
class MshFromGmshTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gmsh_ = FindGmsh();
    if (!gmsh_) GTEST_SKIP() << "gmsh not found on PATH (Debian package gmsh): .msh cross-check skipped";
    dir_ = ScratchDir("msh");
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // Runs gmsh on `geo` and saves the mesh as `name` in each of the four variants.
  void Save(const std::string& geo, const std::string& name) {
    WriteText(dir_ / (name + ".geo"), geo);
    for (const auto& [suffix, options] : std::vector<std::pair<std::string, std::string>>{
             {"41a", "-format msh41"}, {"41b", "-format msh41 -bin"}, {"22a", "-format msh22"}, {"22b", "-format msh22 -bin"}}) {
      const std::string command = "cd '" + dir_.string() + "' && '" + gmsh_->string() + "' " + name + ".geo -3 " + options +
                                  " -o " + name + "_" + suffix + ".msh > /dev/null 2>&1";
      ASSERT_EQ(std::system(command.c_str()), 0) << command;
    }
  }
  std::optional<fs::path> gmsh_;
  fs::path dir_;
};

void ExpectMidsideNodesAtMidpoints(const flex::FeMesh& mesh) {
  for (const flex::FeElement& e : mesh.elements()) {
    const auto& x = mesh.positions();
    const auto mid = [&](int a, int b) -> Eigen::Vector3d { return 0.5 * (x[e.nodes[a]] + x[e.nodes[b]]); };
    if (e.type == flex::ElementType::kTet10) {
      const int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
      for (int k = 0; k < 6; ++k) ASSERT_LT((x[e.nodes[4 + k]] - mid(edges[k][0], edges[k][1])).norm(), 1e-12);
    } else if (e.type == flex::ElementType::kHex20) {
      const int edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
      for (int k = 0; k < 12; ++k) ASSERT_LT((x[e.nodes[8 + k]] - mid(edges[k][0], edges[k][1])).norm(), 1e-12);
    }
  }
}

TEST_F(MshFromGmshTest, AllFourVariantsGiveTheSameTet10AndHex20Meshes) {
  const std::string box = "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 0.3, 0.2, 0.1};\n"
                          "Physical Volume(\"SOLID\") = {1};\nPhysical Surface(\"XMIN\") = {1};\n";
  Save(box + "Mesh.MeshSizeMax = 0.08;\nMesh.ElementOrder = 2;\n", "tet");
  Save(box + "Transfinite Curve{:} = 3;\nTransfinite Surface{:};\nRecombine Surface{:};\nTransfinite Volume{1};\n"
             "Mesh.ElementOrder = 2;\nMesh.SecondOrderIncomplete = 1;\n",
       "hex");
  for (const std::string name : {"tet", "hex"}) {
    const flex::ElementType type = name == "tet" ? flex::ElementType::kTet10 : flex::ElementType::kHex20;
    std::optional<flex::FeMesh> first;
    for (const char* suffix : {"41a", "41b", "22a", "22b"}) {
      SCOPED_TRACE(name + "_" + suffix);
      GmshMesh m = ReadGmshMsh(dir_ / (name + "_" + suffix + ".msh"));
      EXPECT_EQ(m.binary, suffix[2] == 'b');
      ASSERT_GT(m.mesh.num_elements(), 0);
      for (const flex::FeElement& e : m.mesh.elements()) ASSERT_EQ(e.type, type);
      ExpectMidsideNodesAtMidpoints(m.mesh);
      EXPECT_GT(m.mesh.NodeSet("XMIN").size(), 3u);
      for (int n : m.mesh.NodeSet("XMIN")) EXPECT_NEAR(m.mesh.positions()[n].x(), 0.0, 1e-15);
      m.mesh.AssignMaterialToAll({.name = "S", .youngs_modulus_pa = 2e11, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
      EXPECT_NEAR(flex::AssembleFeSystem(m.mesh).volume_m3, 0.3 * 0.2 * 0.1, 1e-15);
      if (!first) {
        first = m.mesh;
        continue;
      }
      ASSERT_EQ(m.mesh.num_nodes(), first->num_nodes());
      ASSERT_EQ(m.mesh.num_elements(), first->num_elements());
      EXPECT_EQ(m.mesh.node_ids(), first->node_ids());
      // ASCII files hold 16 significant digits: equal to 1e-15 m on a 0.3 m box
      for (int i = 0; i < first->num_nodes(); ++i) ASSERT_LT((m.mesh.positions()[i] - first->positions()[i]).norm(), 1e-15);
      for (int e = 0; e < first->num_elements(); ++e) ASSERT_EQ(m.mesh.elements()[e].nodes, first->elements()[e].nodes);
      EXPECT_EQ(m.mesh.NodeSet("XMIN"), first->NodeSet("XMIN"));
    }
  }
}

TEST_F(MshFromGmshTest, TruncatedBinaryFileIsAnError) {
  Save("SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 1, 1, 1};\nMesh.MeshSizeMax = 0.5;\n", "cut");
  for (const char* suffix : {"41b", "22b"}) {
    const std::string bytes = ReadFileBounded(dir_ / (std::string("cut_") + suffix + ".msh"));
    try {
      ParseGmshMsh(bytes.substr(0, bytes.size() * 2 / 3), "cut.msh");
      FAIL() << "no error for " << suffix;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cut.msh: $", 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace orrery

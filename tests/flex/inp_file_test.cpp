// Abaqus / CalculiX .inp reading and writing (flex/inp_file.cpp): keywords, continuation lines,
// GENERATE, set references, materials and sections, ignored keywords with notes, errors that
// name file, line and keyword, and a write / read round trip that reproduces the mesh and its
// assembled matrices bit for bit.
#include <gtest/gtest.h>

#include <sstream>

#include "flex/box_mesher.h"
#include "flex/fe_assembly.h"
#include "flex/inp_file.h"

namespace orrery::flex {
namespace {

const char* kTwoElements = R"(** a C3D20 brick and a C3D10 tet sharing nothing
*Heading
 two elements
*NODE, NSET=Nall
1, 0, 0, 0
2, 1, 0, 0
3, 1, 1, 0
4, 0, 1, 0
5, 0, 0, 1
6, 1, 0, 1
7, 1, 1, 1
8, 0, 1, 1
9, 0.5, 0, 0
10, 1, 0.5, 0
11, 0.5, 1, 0
12, 0, 0.5, 0
13, 0.5, 0, 1
14, 1, 0.5, 1
15, 0.5, 1, 1
16, 0, 0.5, 1
17, 0, 0, 0.5
18, 1, 0, 0.5
19, 1, 1, 0.5
20, 0, 1, 0.5
*element, type=C3D20, elset=BRICK
7, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15,
16, 17, 18, 19, 20
*ELEMENT, TYPE=C3D10, ELSET=TET
8, 101, 102, 103, 104, 105, 106, 107, 108, 109, 110
*NODE
101, 3, 0, 0
102, 4, 0, 0
103, 3, 1, 0
104, 3, 0, 1
105, 3.5, 0, 0
106, 3.5, 0.5, 0
107, 3, 0.5, 0
108, 3, 0, 0.5
109, 3.5, 0, 0.5
110, 3, 0.5, 0.5
*NSET, NSET=base, GENERATE
1, 4
9, 12, 1
*NSET, NSET=BASE_AND_TOP
base, 5, 6, 7, 8
*ELSET, ELSET=EALL
BRICK, 8
*MATERIAL, NAME=Steel
*ELASTIC
2.1E11, 0.3
*DENSITY
7850.
*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL
*BOUNDARY
BASE, 1, 3
*STEP
*FREQUENCY
10
*END STEP
)";

TEST(InpFileTest, ReadsNodesElementsSetsAndMaterials) {
  std::istringstream in(kTwoElements);
  const InpReadResult r = ParseInp(in, "two.inp");
  const FeMesh& m = r.mesh;
  EXPECT_EQ(m.num_nodes(), 30);
  ASSERT_EQ(m.num_elements(), 2);
  EXPECT_EQ(m.elements()[0].type, ElementType::kHex20);
  EXPECT_EQ(m.elements()[1].type, ElementType::kTet10);
  EXPECT_EQ(m.elements()[0].id, 7);
  EXPECT_EQ(m.node_ids()[m.elements()[0].nodes[19]], 20);  // continuation line read
  EXPECT_EQ(m.node_ids()[m.elements()[1].nodes[9]], 110);  // nodes defined after the element
  EXPECT_EQ(m.NodeSet("Base").size(), 8u);
  EXPECT_EQ(m.NodeSet("base_and_top").size(), 12u);
  EXPECT_EQ(m.NodeSet("NALL").size(), 20u);
  EXPECT_EQ(m.ElementSet("eall").size(), 2u);
  ASSERT_EQ(m.materials().size(), 1u);
  EXPECT_EQ(m.materials()[0].youngs_modulus_pa, 2.1e11);
  EXPECT_EQ(m.materials()[0].density_kg_m3, 7850);
  EXPECT_EQ(m.element_material()[1], 0);
  // Notes for the keywords it skips
  ASSERT_EQ(r.notes.size(), 5u);
  EXPECT_EQ(r.notes[0], "two.inp:2: *HEADING ignored");
  EXPECT_EQ(r.notes[1].substr(0, 24), "two.inp:54: *BOUNDARY ig");
  // Volumes: unit cube + tet of volume 1/6
  EXPECT_NEAR(AssembleFeSystem(m).volume_m3, 1 + 1.0 / 6, 1e-14);
}

// The error message of parsing `text`, "" if it parses.
std::string ErrorOf(const std::string& text) {
  std::istringstream in(text);
  try {
    ParseInp(in, "bad.inp");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(InpFileTest, ErrorsNameFileLineAndKeyword) {
  EXPECT_EQ(ErrorOf("*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=S4\n1, 1\n"),
            "bad.inp:3: *ELEMENT: element type S4 not supported (C3D4, C3D10, C3D8, C3D20)");
  EXPECT_EQ(ErrorOf("*NODE\n1, 0, x, 0\n"), "bad.inp:2: *NODE: coordinate 'x' is not a number");
  EXPECT_EQ(ErrorOf("*NODE\n1,0,0,0\n2,1,0,0\n3,0,1,0\n4,0,0,1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 9\n"),
            "bad.inp:7: *ELEMENT: element 1: unknown node 9");
  EXPECT_EQ(ErrorOf("*NODE\n1,0,0,0\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4, 5\n"),
            "bad.inp:4: *ELEMENT: 5 node ids for a C3D4 element, expected 4");
  EXPECT_EQ(ErrorOf("*NODE\n1,0,0,0\n*NSET, NSET=A\n1, 2\n"), "bad.inp:4: *NSET: unknown node 2");
  EXPECT_EQ(ErrorOf("*NSET\n1\n"), "bad.inp:1: *NSET: missing parameter NSET=");
  EXPECT_EQ(ErrorOf("*NODE\n1,0,0,0\n1,1,0,0\n"), "bad.inp:3: *NODE: node 1 defined twice");
  EXPECT_EQ(ErrorOf("*INCLUDE, INPUT=mesh.inp\n"),
            "bad.inp:1: *INCLUDE: not supported (merge the included file into this one)");
  EXPECT_EQ(ErrorOf("*NODE\n1,0,0,0,\n"), "bad.inp:2: *NODE: data line continued with a comma but the file ends");
  EXPECT_EQ(ErrorOf("*SOLID SECTION, ELSET=E, MATERIAL=M\n"), "bad.inp:1: *SOLID SECTION: unknown material M");
  EXPECT_NE(ErrorOf("*NODE\n1,0,0,0\n*NSET, NSET=A, GENERATE\n5, 1\n").find("bad.inp:4: *NSET: bad GENERATE range"),
            std::string::npos);
}

TEST(InpFileTest, WriteReadRoundTripIsExact) {
  for (ElementType t : {ElementType::kTet4, ElementType::kTet10, ElementType::kHex8, ElementType::kHex20}) {
    FeMesh mesh = MakeBoxMesh({.origin_m = {0.1, -0.2, 0.3}, .size_m = {0.3, 0.07, 0.11}, .divisions = {3, 2, 1}, .type = t});
    mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 2.07e11, .poissons_ratio = 0.29, .density_kg_m3 = 7833.4});
    std::stringstream ss;
    WriteInp(ss, mesh, {.fixed_node_sets = {"XMIN"}, .num_frequencies = 12});
    EXPECT_NE(ss.str().find("*BOUNDARY\nXMIN, 1, 3\n*STEP\n*FREQUENCY\n12\n*END STEP\n"), std::string::npos);
    const InpReadResult r = ParseInp(ss, "round.inp");
    EXPECT_EQ(r.mesh.positions(), mesh.positions());
    EXPECT_EQ(r.mesh.node_ids(), mesh.node_ids());
    EXPECT_EQ(r.mesh.node_sets(), mesh.node_sets());
    EXPECT_EQ(r.mesh.element_sets(), mesh.element_sets());
    ASSERT_EQ(r.mesh.num_elements(), mesh.num_elements());
    for (int e = 0; e < mesh.num_elements(); ++e) EXPECT_EQ(r.mesh.elements()[e].nodes, mesh.elements()[e].nodes);
    const FeSystem a = AssembleFeSystem(mesh), b = AssembleFeSystem(r.mesh);
    EXPECT_EQ((Eigen::MatrixXd(a.K) - Eigen::MatrixXd(b.K)).cwiseAbs().maxCoeff(), 0.0) << CalculixName(t);
    EXPECT_EQ((Eigen::MatrixXd(a.M) - Eigen::MatrixXd(b.M)).cwiseAbs().maxCoeff(), 0.0) << CalculixName(t);
  }
  FeMesh mesh = MakeBoxMesh({});
  std::stringstream ss;
  EXPECT_THROW(WriteInp(ss, mesh, {.fixed_node_sets = {"NOPE"}}), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::flex

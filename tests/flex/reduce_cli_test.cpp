// `orrery reduce` end to end (tools/cli/reduce_command.cpp; here because the CLI test folder does
// not link flex/): coarse generated gears and a box mesh reduced by the built `orrery` program,
// the JSON checked against the bounds the reduction must satisfy, the file read back and
// validated, bad inputs rejected in one line naming the file and key. Skipped when the program
// has not been built.
//
// Oracles for the frequencies (lambda = (2 pi f)^2, full = the FE model with the reference
// master clamped and every interface constraint applied, the model the reduction approximates):
// - One interface: the Craig-Bampton elastic basis is the lowest fixed-interface modes, which are
//   exact eigenvectors of that model, so reduced = full to the Lanczos tolerance (1e-10 on the
//   eigenvalues; 1e-8 relative on the frequencies leaves room for the re-orthogonalization).
// - Two interfaces (the second an RBE3 whose master is free in the full model): Rayleigh-Ritz
//   gives full_i <= reduced_i; the basis contains the fixed-interface modes of the model with the
//   second master clamped too (6 more constraints), so by the interlacing of constrained
//   eigenvalues reduced_i <= fixed_i <= full_(i+6).
#include <gtest/gtest.h>

#include "tests/common/cli_support.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "flex/box_mesher.h"
#include "flex/calculix.h"
#include "flex/fe_assembly.h"
#include "flex/inp_file.h"
#include "flex/reduced_body_file.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery::flex {
namespace {

using test_support::JsonArray;
using test_support::RunCommand;


// A coarse hex8 gear (23 teeth, m_n 2 mm, bore 20 mm) with the given interfaces and material.
std::string GearInput(const std::string& interfaces, const std::string& material = "{name: steel, E: 210e9, nu: 0.3, rho: 7850}") {
  std::string s =
      "gear: {teeth: 23, module_mm: 2, pressure_angle_deg: 20, face_width_mm: 10, bore_diameter_mm: 20}\n"
      "mesh: {element: hex8, flank_divisions: 3, fillet_divisions: 2, tooth_divisions: 2,\n"
      "       root_layer_divisions: 1, rim_divisions: 2, face_divisions: 2, smoothing_iterations: 50}\n"
      "material: ";
  s += material;
  s += "\ninterfaces:\n";
  s += interfaces;
  s += "reduction: {modes: 8}\n";
  return s;
}

class ReduceCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    orrery_ = std::filesystem::path(ORRERY_BINARY_DIR) / "bin" / "orrery";
    if (!std::filesystem::exists(orrery_)) GTEST_SKIP() << "orrery program not built: " << orrery_;
    dir_ = std::filesystem::temp_directory_path() / ("orrery_reduce_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }

  std::string Write(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // `orrery reduce <args>` (built by appending: GCC 12 warns falsely (-Wrestrict) about chains
  // of string operator+).
  std::pair<std::string, int> Reduce(const std::string& args) const {
    std::string c = "'";
    c += orrery_.string();
    c += "' reduce ";
    c += args;
    return RunCommand(c);
  }

  std::filesystem::path orrery_, dir_;
};

TEST_F(ReduceCliTest, OneInterfaceReducedEqualsFullAndFileReadsBack) {
  const std::string input = Write("gear.yaml", GearInput("  - {name: bore, node_set: BORE, kind: rbe2}\n"));
  const std::string body = (dir_ / "gear.h5").string();
  const auto [json, status] = Reduce("'" + input + "' -o '" + body + "' --json");
  ASSERT_EQ(status, 0) << json;
  for (const char* key : {"\"full_frequencies_hz\"", "\"reduced_frequencies_hz\"", "\"full_model_boundary\"",
                          "\"elastic_modes\": 8", "\"modes_kept\": 8", "\"reference_interface\": \"bore\"",
                          "\"timings_s\"", "\"output\"", "\"element_type\": \"C3D8\""})
    EXPECT_NE(json.find(key), std::string::npos) << key << "\n" << json;
  const std::vector<double> full = JsonArray(json, "full_frequencies_hz");
  const std::vector<double> reduced = JsonArray(json, "reduced_frequencies_hz");
  ASSERT_EQ(full.size(), 8u) << json;
  ASSERT_EQ(reduced.size(), 8u) << json;
  for (std::size_t i = 0; i < full.size(); ++i) EXPECT_NEAR(reduced[i], full[i], 1e-8 * full[i]) << i;

  // The file: the same frequencies, modes that pass the engine's checks, its provenance
  const ReducedBody b = ReadReducedBody(body);
  EXPECT_EQ(b.full_frequencies_hz, full);
  EXPECT_EQ(std::vector<double>(b.reduced_frequencies_hz.begin() + 6, b.reduced_frequencies_hz.end()), reduced);
  EXPECT_EQ(b.modes.frequencies_hz, reduced);
  EXPECT_NO_THROW(ValidateFlexibleBodyModes("gear", b.modes));
  EXPECT_EQ(b.modes.nf, 8);
  EXPECT_FALSE(b.modes.surface_triangles.empty());
  EXPECT_EQ(b.modes.geometric_stiffness.size(), 6u);
  EXPECT_GT(b.modes.stress_modes.rows(), 0);
  EXPECT_EQ(b.provenance.element_type, "C3D8");
  EXPECT_EQ(b.provenance.modes_kept, 8);
  EXPECT_EQ(b.provenance.material.youngs_modulus_pa, 210e9);
  EXPECT_EQ(b.provenance.source.rfind("gear z=23, m_n=0.002 m", 0), 0u) << b.provenance.source;
  // Asking for more modes than the file holds: stale, with the reason
  ReducedBodyProvenance expected = b.provenance;
  expected.modes_kept = 30;
  try {
    ReadReducedBody(body, &expected);
    FAIL() << "stale file accepted";
  } catch (const StaleReducedBodyError& e) {
    EXPECT_NE(std::string(e.what()).find("modes kept 8, the scene asks 30"), std::string::npos) << e.what();
  }
  // Text output: the table of both
  const auto [text, text_status] = Reduce("'" + input + "' -o '" + body + "'");
  EXPECT_EQ(text_status, 0) << text;
  EXPECT_NE(text.find("mode         full (Hz)      reduced (Hz)"), std::string::npos) << text;
}

TEST_F(ReduceCliTest, TwoInterfacesReducedFrequenciesAreBracketed) {
  const std::string input = Write("gear2.yaml", GearInput("  - {name: bore, node_set: BORE, kind: rbe2}\n"
                                                          "  - {name: mesh_point, node_set: TOOTH0_FLANK_PLUS, kind: rbe3}\n"));
  const auto [json, status] = Reduce("'" + input + "' -o '" + (dir_ / "gear2.h5").string() + "' --json");
  ASSERT_EQ(status, 0) << json;
  const std::vector<double> full = JsonArray(json, "full_frequencies_hz");
  const std::vector<double> reduced = JsonArray(json, "reduced_frequencies_hz");
  ASSERT_EQ(full.size(), 14u) << json;  // 6 constraint modes of the second interface + 8
  ASSERT_EQ(reduced.size(), 14u);
  for (std::size_t i = 0; i < full.size(); ++i) {
    EXPECT_GE(reduced[i], full[i] * (1 - 1e-9)) << i;
    if (i + 6 < full.size()) {
      EXPECT_LE(reduced[i], full[i + 6] * (1 + 1e-9)) << i;
    }
  }
  const ReducedBody b = ReadReducedBody((dir_ / "gear2.h5").string());
  ASSERT_EQ(b.interfaces.size(), 2u);
  EXPECT_EQ(b.interfaces[1].kind, InterfaceKind::kRbe3);
  EXPECT_EQ(b.modes.node_sets.count("mesh_point"), 1u);
}

TEST_F(ReduceCliTest, MeshInputWithInterfacesFromTheCommandLine) {
  FeMesh mesh = MakeBoxMesh({.size_m = {0.3, 0.04, 0.04}, .divisions = {6, 1, 1}, .type = ElementType::kHex20});
  WriteInpFile(dir_ / "beam.inp", mesh);
  const std::string beam = (dir_ / "beam.inp").string();
  const std::string body = (dir_ / "beam.h5").string();
  const auto [json, status] =
      Reduce("'" + beam + "' -o '" + body + "' --interface XMIN --interface XMAX:rbe3 --E 7e10 --nu 0.33 --rho 2700 --modes 4 --json");
  ASSERT_EQ(status, 0) << json;
  const std::vector<double> full = JsonArray(json, "full_frequencies_hz");
  const std::vector<double> reduced = JsonArray(json, "reduced_frequencies_hz");
  ASSERT_EQ(full.size(), 10u) << json;
  for (std::size_t i = 0; i < full.size(); ++i) EXPECT_GE(reduced[i], full[i] * (1 - 1e-9)) << i;
  const ReducedBody b = ReadReducedBody(body);
  EXPECT_EQ(b.provenance.source, "mesh file " + beam);
  EXPECT_EQ(b.provenance.element_type, "C3D20");
  EXPECT_EQ(b.interfaces[0].name, "XMIN");
  // A mesh needs interfaces
  const auto [none, s1] = Reduce("'" + beam + "' -o '" + body + "' --E 7e10 --nu 0.33 --rho 2700");
  EXPECT_EQ(s1, 1);
  EXPECT_NE(none.find("a mesh input needs --interface"), std::string::npos) << none;
  const auto [kind, s2] = Reduce("'" + beam + "' -o '" + body + "' --interface XMIN:rbe9 --E 7e10 --nu 0.33 --rho 2700");
  EXPECT_EQ(s2, 1);
  EXPECT_EQ(kind, "orrery: error: --interface XMIN:rbe9: expected NODESET, NODESET:rbe2 or NODESET:rbe3 (NODESET a node set or bore)\n");
}

TEST_F(ReduceCliTest, BadInputsNameTheFileAndKey) {
  const std::string body = (dir_ / "bad.h5").string();
  const auto run = [&](const std::string& name, const std::string& text) {
    const std::string input = Write(name, text);
    return Reduce("'" + input + "' -o '" + body + "'");
  };
  const std::string bore = "  - {name: bore, node_set: BORE, kind: rbe2}\n";
  // Missing key
  auto [missing, s1] = run("missing.yaml", GearInput(bore, "{name: steel, nu: 0.3, rho: 7850}"));
  EXPECT_EQ(s1, 1);
  EXPECT_EQ(missing, "orrery: error: " + (dir_ / "missing.yaml").string() +
                         ":4: material.E: missing required key 'E'\n");
  // Negative Young's modulus
  auto [negative, s2] = run("negative.yaml", GearInput(bore, "{name: steel, E: -210e9, nu: 0.3, rho: 7850}"));
  EXPECT_EQ(s2, 1);
  EXPECT_EQ(negative, "orrery: error: " + (dir_ / "negative.yaml").string() +
                          ":4: material.E: Young's modulus must be > 0 (Pa), got -210e9\n");
  // Unknown node set: the interface's node_set key, and the set
  auto [unknown, s3] = run("unknown.yaml", GearInput("  - {name: bore, node_set: HUB, kind: rbe2}\n"));
  EXPECT_EQ(s3, 1);
  EXPECT_EQ(unknown.rfind("orrery: error: " + (dir_ / "unknown.yaml").string() +
                              ":6: interfaces[bore].node_set: no node set 'HUB'",
                          0),
            0u)
      << unknown;
  EXPECT_EQ(std::count(unknown.begin(), unknown.end(), '\n'), 1);
  // Misspelt key, unknown reference
  auto [typo, s4] = run("typo.yaml", GearInput(bore) + "outputs: {stres_modes: false}\n");
  EXPECT_EQ(s4, 1);
  EXPECT_NE(typo.find("outputs.stres_modes: unknown key 'stres_modes'; did you mean 'stress_modes'?"),
            std::string::npos)
      << typo;
  // Missing file; missing -o is a usage error
  const auto [nofile, s5] = Reduce("'" + (dir_ / "none.yaml").string() + "' -o '" + body + "'");
  EXPECT_EQ(s5, 1);
  EXPECT_EQ(nofile, "orrery: error: input file " + (dir_ / "none.yaml").string() + ": no such file\n");
  const auto [usage, s6] = Reduce("'" + (dir_ / "missing.yaml").string() + "'");
  EXPECT_EQ(s6, 2) << usage;
  EXPECT_FALSE(std::filesystem::exists(body));
}

// Parts other than generated gears (import/part_reduction.h): a tube STL tetrahedralized by gmsh
// and held at its bore, a gmsh .msh, CalculiX's and Matrix Market matrices of a box. One
// interface: reduced = full (the Craig-Bampton basis holds the exact fixed-interface modes). The
// matrices of the box, from ccx or written from Orrery's own assembly, reduce to the frequencies
// of the .inp mesh reduced directly (to 1e-9: 14 and 17 significant digits in the files).

bool HaveProgram(const std::string& name) {
  return std::system(("command -v " + name + " > /dev/null 2>&1").c_str()) == 0;
}

TEST_F(ReduceCliTest, StlPartTetrahedralizedAndHeldAtItsBore) {
  if (!HaveProgram("gmsh")) GTEST_SKIP() << "gmsh not found (Debian package gmsh)";
  test_meshes::WriteBinaryStl(test_meshes::Tube(0.005, 0.02, 0.01, 24), dir_ / "tube.stl", 1000);
  const std::string stl = (dir_ / "tube.stl").string(), body = (dir_ / "tube.h5").string();
  const auto [json, status] = Reduce("'" + stl + "' -o '" + body +
                                     "' --unit mm --E 2.1e11 --nu 0.3 --density 7850 --interface bore --modes 4 "
                                     "--mesh-size 0.005 --json");
  ASSERT_EQ(status, 0) << json;
  EXPECT_NE(json.find("\"element_type\": \"C3D10\""), std::string::npos) << json;
  const std::vector<double> full = JsonArray(json, "full_frequencies_hz");
  const std::vector<double> reduced = JsonArray(json, "reduced_frequencies_hz");
  ASSERT_EQ(full.size(), 4u) << json;
  for (std::size_t i = 0; i < full.size(); ++i) EXPECT_NEAR(reduced[i], full[i], 1e-8 * full[i]) << i;
  const ReducedBody b = ReadReducedBody(body);
  EXPECT_EQ(b.interfaces.at(0).name, "BORE");
  EXPECT_NE(b.provenance.source.find("tet10"), std::string::npos) << b.provenance.source;
  // Reading the part again gives the same mesh: the provenance matches
  const auto [again, s2] = Reduce("'" + stl + "' -o '" + (dir_ / "tube2.h5").string() +
                                  "' --unit mm --E 2.1e11 --nu 0.3 --density 7850 --interface bore --modes 4 "
                                  "--mesh-size 0.005 --json");
  ASSERT_EQ(s2, 0) << again;
  EXPECT_NO_THROW(ReadReducedBody((dir_ / "tube2.h5").string(), &b.provenance));
  // Without a material: one line naming what is missing
  const auto [none, s3] = Reduce("'" + stl + "' -o '" + body + "' --unit mm --interface bore");
  EXPECT_EQ(s3, 1);
  EXPECT_EQ(none, "orrery: error: " + stl + " has no material: give --E, --nu and --density\n");
}

TEST_F(ReduceCliTest, GmshMshPartWithAPhysicalGroup) {
  if (!HaveProgram("gmsh")) GTEST_SKIP() << "gmsh not found (Debian package gmsh)";
  Write("box.geo", "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 0.2, 0.03, 0.03};\nPhysical Volume(\"SOLID\") = {1};\n"
                   "Physical Surface(\"XMIN\") = {1};\nMesh.MeshSizeMax = 0.015;\nMesh.ElementOrder = 2;\n");
  ASSERT_EQ(std::system(("cd '" + dir_.string() + "' && gmsh box.geo -3 -o box.msh > /dev/null 2>&1").c_str()), 0);
  const auto [json, status] = Reduce("'" + (dir_ / "box.msh").string() + "' -o '" + (dir_ / "box.h5").string() +
                                     "' --E 7e10 --nu 0.33 --density 2700 --interface XMIN --modes 3 --json");
  ASSERT_EQ(status, 0) << json;
  const std::vector<double> full = JsonArray(json, "full_frequencies_hz");
  const std::vector<double> reduced = JsonArray(json, "reduced_frequencies_hz");
  ASSERT_EQ(full.size(), 3u) << json;
  for (std::size_t i = 0; i < full.size(); ++i) EXPECT_NEAR(reduced[i], full[i], 1e-8 * full[i]) << i;
}

// Matrix Market text of a symmetric sparse matrix (lower triangle).
std::string MatrixMarket(const Eigen::SparseMatrix<double>& A) {
  std::string s = "%%MatrixMarket matrix coordinate real symmetric\n";
  std::vector<std::string> lines;
  char buf[96];
  for (int c = 0; c < A.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (it.row() >= it.col()) {
        std::snprintf(buf, sizeof buf, "%ld %ld %.17g\n", static_cast<long>(it.row() + 1), static_cast<long>(it.col() + 1),
                      it.value());
        lines.push_back(buf);
      }
  s += std::to_string(A.rows()) + " " + std::to_string(A.cols()) + " " + std::to_string(lines.size()) + "\n";
  for (const std::string& l : lines) s += l;
  return s;
}

TEST_F(ReduceCliTest, ExternalMatricesReduceToTheMeshsFrequencies) {
  FeMesh mesh = MakeBoxMesh({.origin_m = Eigen::Vector3d(1, 1, 1), .size_m = {0.3, 0.04, 0.04}, .divisions = {6, 1, 1},
                             .type = ElementType::kHex8});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
  WriteInpFile(dir_ / "job.inp", mesh);
  const std::string inp = (dir_ / "job.inp").string();
  const auto [direct, s0] = Reduce("'" + inp + "' -o '" + (dir_ / "direct.h5").string() + "' --interface XMIN --modes 5 --json");
  ASSERT_EQ(s0, 0) << direct;
  const std::vector<double> expected = JsonArray(direct, "reduced_frequencies_hz");
  ASSERT_EQ(expected.size(), 5u);
  const auto check = [&](const std::string& args, const char* what) {
    const auto [json, status] = Reduce(args + " --interface XMIN --modes 5 --json");
    ASSERT_EQ(status, 0) << what << ": " << json;
    const std::vector<double> f = JsonArray(json, "reduced_frequencies_hz");
    ASSERT_EQ(f.size(), 5u) << what;
    for (std::size_t i = 0; i < f.size(); ++i) EXPECT_NEAR(f[i], expected[i], 1e-9 * expected[i]) << what << " " << i;
  };
  // Matrix Market, written from Orrery's assembly, DOFs in a shuffled order
  const FeSystem system = AssembleFeSystem(mesh);
  std::string dofs = "# node direction\n";
  for (int n = 0; n < mesh.num_nodes(); ++n)
    for (int d = 1; d <= 3; ++d) dofs += std::to_string(mesh.node_ids()[n]) + " " + std::to_string(d) + "\n";
  Write("K.mtx", MatrixMarket(system.K));
  Write("M.mtx", MatrixMarket(system.M));
  Write("dofs.txt", dofs);
  check("'" + (dir_ / "K.mtx").string() + "' -o '" + (dir_ / "mm.h5").string() + "' --mass '" + (dir_ / "M.mtx").string() +
            "' --dofs '" + (dir_ / "dofs.txt").string() + "' --mesh '" + inp + "'",
        "Matrix Market");
  // CalculiX's own export (hex8: the same integration rules as Orrery)
  if (HaveProgram("ccx")) {
    std::ofstream(dir_ / "job.inp", std::ios::app) << "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n";
    ASSERT_EQ(std::system(("cd '" + dir_.string() + "' && OMP_NUM_THREADS=1 ccx -i job > ccx.log 2>&1").c_str()), 0);
    check("'" + (dir_ / "job.sti").string() + "' -o '" + (dir_ / "ccx.h5").string() + "'", "CalculiX");
  }
  // Mismatched sizes: a mass matrix of another mesh
  Write("M2.mtx", MatrixMarket(Eigen::SparseMatrix<double>(system.M.topLeftCorner(30, 30))));
  const auto [bad, s1] = Reduce("'" + (dir_ / "K.mtx").string() + "' -o '" + (dir_ / "bad.h5").string() + "' --mass '" +
                                (dir_ / "M2.mtx").string() + "' --dofs '" + (dir_ / "dofs.txt").string() + "' --mesh '" +
                                inp + "' --interface XMIN");
  EXPECT_EQ(s1, 1);
  EXPECT_NE(bad.find("K.mtx is " + std::to_string(system.K.rows())), std::string::npos) << bad;
  EXPECT_EQ(std::count(bad.begin(), bad.end(), '\n'), 1);
}

TEST_F(ReduceCliTest, FormatDetectionAndPartOptions) {
  // An STL is not read as YAML any more; a YAML input takes no part options; unknown formats
  Write("x.stl", "solid x\nendsolid x\n");
  const auto [stl, s1] = Reduce("'" + (dir_ / "x.stl").string() + "' -o '" + (dir_ / "x.h5").string() +
                                "' --interface bore --E 2e11 --nu 0.3 --density 7850");
  EXPECT_EQ(s1, 1);
  EXPECT_EQ(stl, "orrery: error: " + (dir_ / "x.stl").string() + ": the STL file holds no triangles\n");
  const std::string yaml = Write("g.yaml", GearInput("  - {name: bore, node_set: BORE, kind: rbe2}\n"));
  const auto [y, s2] = Reduce("'" + yaml + "' -o '" + (dir_ / "g.h5").string() + "' --unit mm");
  EXPECT_EQ(s2, 1);
  EXPECT_NE(y.find("go with a part input"), std::string::npos) << y;
  Write("x.abc", "1\n");
  const auto [abc, s3] = Reduce("'" + (dir_ / "x.abc").string() + "' -o '" + (dir_ / "x.h5").string() +
                                "' --interface bore --E 2e11 --nu 0.3 --density 7850");
  EXPECT_EQ(s3, 1);
  EXPECT_NE(abc.find("x.abc: unknown mesh format '.abc'"), std::string::npos) << abc;
}

}  // namespace
}  // namespace orrery::flex

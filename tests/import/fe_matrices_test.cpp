// External FE matrices (import/fe_matrices.h). Matrix Market and DOF tables parsed by hand-made
// files; CalculiX's own export (*FREQUENCY, SOLVER=MATRIXSTORAGE) of a box mesh compared with
// Orrery's assembly of the same mesh, entry by entry, and through a Craig-Bampton reduction:
// the same frequencies. CalculiX integrates the mass with the stiffness rule (flex/fe_element.h),
// so the like-for-like assembly uses MassQuadrature::kStiffnessRule; ccx writes 14 significant
// digits, so the entries agree to 1e-12 of the largest, and the reduced frequencies (smooth
// functions of the entries) to 1e-9. Skipped without ccx on PATH.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>

#include "flex/box_mesher.h"
#include "flex/calculix.h"
#include "flex/craig_bampton.h"
#include "flex/fe_interface.h"
#include "flex/inp_file.h"
#include "import/fe_matrices.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(FeMatricesTest, MatrixMarketFormats) {
  // Symmetric coordinate: lower triangle, mirrored; duplicates summed
  const Eigen::SparseMatrix<double> s = ParseMatrixMarket(
      "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n3 3 6\n1 1 4\n2 1 -1\n2 2 4\n3 2 -1\n3 3 2\n3 3 2\n",
      "k.mtx");
  EXPECT_EQ(s.coeff(0, 1), -1);
  EXPECT_EQ(s.coeff(1, 0), -1);
  EXPECT_EQ(s.coeff(2, 2), 4);
  // General coordinate, symmetric content; array symmetric (lower triangle by columns)
  const Eigen::SparseMatrix<double> g = ParseMatrixMarket(
      "%%MatrixMarket matrix coordinate real general\n2 2 4\n1 1 2\n1 2 1\n2 1 1\n2 2 3\n", "g.mtx");
  EXPECT_EQ(g.coeff(0, 1), 1);
  const Eigen::SparseMatrix<double> a =
      ParseMatrixMarket("%%MatrixMarket matrix array real symmetric\n2 2\n2\n1\n3\n", "a.mtx");
  EXPECT_EQ(Eigen::MatrixXd(a), Eigen::MatrixXd(g));
  // Errors
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate pattern symmetric\n1 1 1\n1 1\n", "p.mtx"); }),
            "p.mtx:1: field 'pattern' (real or integer are read: stiffness and mass are real)");
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 2 1\n", "n.mtx"); })
                .rfind("n.mtx: the matrix is not symmetric", 0),
            0u);
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n3 1 1\n", "r.mtx"); }),
            "r.mtx:3: row 3 outside 1..2");
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1\n", "c.mtx"); }),
            "c.mtx:3: expected row, got the end of the file");
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 1\n", "c.mtx"); }),
            "c.mtx:2: header says 3 entries, more than the 7 bytes left can hold");
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate real symmetric\n2 3 0\n", "s.mtx"); }),
            "s.mtx:2: a stiffness or mass matrix is square: got 2 x 3");
  EXPECT_EQ(ErrorOf([] { ParseMatrixMarket("hello\n", "h.mtx"); }),
            "h.mtx:1: expected '%%MatrixMarket matrix coordinate|array real|integer general|symmetric'");
  EXPECT_NE(ErrorOf([] { ParseMatrixMarket("%%MatrixMarket matrix coordinate real symmetric\n9 9 2000000000\n1 1 1\n", "b.mtx"); })
                .find("header says 2000000000 entries"),
            std::string::npos);
}

TEST(FeMatricesTest, DofTables) {
  const std::vector<DofEntry> d = ParseDofTable("# node dir\n1 1\n1.2\n1 z\n\n7 x % comment\n", "d.txt");
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[1].node_id, 1);
  EXPECT_EQ(d[1].direction, 2);
  EXPECT_EQ(d[2].direction, 3);
  EXPECT_EQ(d[3].node_id, 7);
  EXPECT_EQ(ErrorOf([] { ParseDofTable("1 4\n", "d.txt"); }),
            "d.txt:1: direction 4 of node 1: only the translations 1-3 of solid elements are supported (no shell or "
            "beam rotations)");
  EXPECT_EQ(ErrorOf([] { ParseDofTable("a b\n", "d.txt"); }), "d.txt:1: expected a node id, got 'a'");
}

TEST(FeMatricesTest, MappingOntoAMesh) {
  const flex::FeMesh mesh = flex::MakeBoxMesh({.divisions = {1, 1, 1}, .type = flex::ElementType::kHex8});
  FeMatrices m;
  m.K.resize(24, 24);
  m.M.resize(24, 24);
  for (int n = 1; n <= 8; ++n)
    for (int d = 1; d <= 3; ++d) m.dofs.push_back({n, d});
  m.source = "m";
  EXPECT_NO_THROW(ToFeModel(m, mesh, "box.inp"));
  FeMatrices wrong = m;
  wrong.dofs[5].node_id = 99;
  EXPECT_EQ(ErrorOf([&] { ToFeModel(wrong, mesh, "box.inp"); }), "m: DOF 6 is on node 99, which box.inp does not have");
  wrong = m;
  wrong.dofs[5].direction = 1;
  EXPECT_EQ(ErrorOf([&] { ToFeModel(wrong, mesh, "box.inp"); }), "m: node 2 direction 1 is listed twice");
  wrong = m;
  wrong.dofs.resize(21);
  wrong.K.resize(21, 21);
  wrong.M.resize(21, 21);
  EXPECT_EQ(ErrorOf([&] { ToFeModel(wrong, mesh, "box.inp"); }),
            "box.inp: element 1 uses node 8, which has no DOFs in m");
}

// Runs ccx's MATRIXSTORAGE step on `mesh` (with its material) in `dir`/job.*.
void ExportWithCalculix(const fs::path& ccx, const flex::FeMesh& mesh, const fs::path& dir) {
  flex::WriteInpFile(dir / "job.inp", mesh, {.heading = "orrery matrices"});
  std::ofstream(dir / "job.inp", std::ios::app) << "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n";
  const std::string command = "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 '" + ccx.string() + "' -i job > job.log 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
}

TEST(FeMatricesTest, CalculixMatricesEqualOrreryAssemblyAndReduceToTheSameFrequencies) {
  const std::optional<fs::path> ccx = flex::FindCalculix();
  if (!ccx) GTEST_SKIP() << "CalculiX (ccx) not found on PATH: matrix import cross-check skipped";
  const fs::path dir = test_meshes::ScratchDir("ccx_matrices");
  for (flex::ElementType type : {flex::ElementType::kHex20, flex::ElementType::kTet10}) {
    SCOPED_TRACE(flex::CalculixName(type));
    flex::FeMesh mesh = flex::MakeBoxMesh({.origin_m = Eigen::Vector3d(1, 1, 1), .size_m = {0.2, 0.04, 0.03},
                                           .divisions = {4, 1, 1}, .type = type});
    mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
    ExportWithCalculix(*ccx, mesh, dir);
    const FeMatrices matrices = ReadCalculixMatrices(dir / "job.sti");
    const flex::FeMesh read_back = flex::ReadInp(dir / "job.inp").mesh;
    const ExternalFeModel model = ToFeModel(matrices, read_back, "job.inp");
    ASSERT_EQ(model.mesh.num_nodes(), mesh.num_nodes());
    // Entry by entry against Orrery's assembly with CalculiX's mass rule
    const flex::FeSystem own = flex::AssembleFeSystem(mesh, {.mass_quadrature = flex::MassQuadrature::kStiffnessRule});
    const double dk = Eigen::MatrixXd(model.system.K - own.K).cwiseAbs().maxCoeff();
    const double dm = Eigen::MatrixXd(model.system.M - own.M).cwiseAbs().maxCoeff();
    EXPECT_LT(dk, 1e-12 * Eigen::MatrixXd(own.K).cwiseAbs().maxCoeff());
    EXPECT_LT(dm, 1e-12 * Eigen::MatrixXd(own.M).cwiseAbs().maxCoeff());
    EXPECT_NEAR(model.system.mass_kg, own.mass_kg, 1e-12 * own.mass_kg);
    // Reduced with the same interface: the same frequencies
    const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(model.mesh, "XMIN", flex::InterfaceKind::kRbe2)};
    const flex::CraigBamptonModel a = flex::ReduceCraigBampton(model.mesh, model.system, ifs, {.num_modes = 8});
    const flex::CraigBamptonModel b = flex::ReduceCraigBampton(mesh, own, ifs, {.num_modes = 8});
    for (int k = 6; k < 14; ++k) EXPECT_NEAR(a.frequencies_hz[k], b.frequencies_hz[k], 1e-9 * b.frequencies_hz[k]) << k;
    std::printf("%s: ccx matrices, first elastic frequency %.6f Hz (own assembly %.6f Hz)\n", flex::CalculixName(type),
                a.frequencies_hz[6], b.frequencies_hz[6]);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace orrery

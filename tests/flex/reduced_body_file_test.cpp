// Reduced-body files (flex/reduced_body_file.cpp): a written body reads back bit for bit (a
// synthetic body with every field filled, and a real reduction of a box), stale files are
// rejected with their reason, and damaged files fail with the file and the dataset named.
#include "flex/reduced_body_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <unistd.h>

#include "flex/box_mesher.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/flexible_body_modes.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"

namespace orrery::flex {
namespace {

class ReducedBodyFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("orrery_reduced_body_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;
};

// A body with every field filled with distinct random values (not physical; the file does not
// care), nf = 3, 5 nodes, 2 interfaces.
ReducedBody SyntheticBody() {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto random = [&](Eigen::Index r, Eigen::Index c) {
    return Eigen::MatrixXd(Eigen::MatrixXd::NullaryExpr(r, c, [&]() { return u(gen); }));
  };
  const int nf = 3, n = 5;
  ReducedBody b;
  FlexibleBodyModes& m = b.modes;
  m.nf = nf;
  m.mass = 1.0 / 3.0;
  m.I1 = random(3, 1);
  m.I3 = random(3, 3);
  m.I2 = random(3, nf);
  for (int k = 0; k < nf; ++k) m.I4.push_back(random(3, 3));
  for (int k = 0; k < nf * nf; ++k) m.I5.push_back(random(3, 3));
  m.stiffness = random(nf, nf);
  m.damping = random(nf, nf);
  for (int c = 0; c < 6; ++c) m.geometric_stiffness.push_back(random(nf, nf));
  for (int i = 0; i < n; ++i)
    m.nodes.push_back({.id = 100 + 7 * i, .position = random(3, 1), .translation_shapes = random(3, nf),
                       .rotation_shapes = random(3, nf)});
  m.node_sets["BORE"] = {0, 2};
  m.node_sets["TOOTH0_FLANK_PLUS"] = {4, 3, 1};
  m.node_sets["EMPTY"] = {};
  m.surface_triangles = {{0, 1, 2}, {2, 3, 4}, {4, 1, 0}};
  m.stress_nodes = {1, 4};
  m.stress_modes = random(12, nf);
  m.frequencies_hz = {101.5, 202.25, 1e4 / 3};
  b.K = random(9, 9);
  b.M = random(9, 9);
  b.reduced_frequencies_hz = {0, 0, 0, 0, 0, 0, 101.5, 202.25, 1e4 / 3};
  b.full_frequencies_hz = {101.25, 202.0, 3333.0};
  b.full_model_boundary = "reference interface master clamped";
  b.interfaces = {{.name = "bore", .kind = InterfaceKind::kRbe2, .master_position_m = {0, 0, 0.01},
                   .slave_node_ids = {1, 2, 3}, .weights = {1, 1, 1}},
                  {.name = "pin", .kind = InterfaceKind::kRbe3, .master_position_m = {0.05, 0, 0.01},
                   .slave_node_ids = {9, 8}, .weights = {0.5, 2}}};
  b.reference_interface = 1;
  ReducedBodyProvenance& p = b.provenance;
  p.source = "synthetic";
  p.mesh_hash = Fnv1a64Hex("mesh");
  p.options_hash = Fnv1a64Hex("options");
  p.element_type = "C3D20";
  p.material.name = "STEEL";
  p.material.youngs_modulus_pa = 2.1e11;
  p.material.poissons_ratio = 0.3;
  p.material.density_kg_m3 = 7850;
  p.modes_kept = 20;
  p.engine_version = ORRERY_VERSION;
  return b;
}

// Exact (bitwise for doubles) comparison of two bodies, field by field.
void ExpectIdentical(const ReducedBody& a, const ReducedBody& b) {
  const auto same = [](const auto& x, const auto& y) { return x.rows() == y.rows() && x.cols() == y.cols() && x == y; };
  const FlexibleBodyModes& m = a.modes;
  const FlexibleBodyModes& n = b.modes;
  EXPECT_EQ(m.nf, n.nf);
  EXPECT_EQ(m.mass, n.mass);
  EXPECT_TRUE(same(m.I1, n.I1));
  EXPECT_TRUE(same(m.I2, n.I2));
  EXPECT_TRUE(same(m.I3, n.I3));
  ASSERT_EQ(m.I4.size(), n.I4.size());
  for (std::size_t k = 0; k < m.I4.size(); ++k) EXPECT_TRUE(same(m.I4[k], n.I4[k])) << k;
  ASSERT_EQ(m.I5.size(), n.I5.size());
  for (std::size_t k = 0; k < m.I5.size(); ++k) EXPECT_TRUE(same(m.I5[k], n.I5[k])) << k;
  EXPECT_TRUE(same(m.stiffness, n.stiffness));
  EXPECT_TRUE(same(m.damping, n.damping));
  ASSERT_EQ(m.geometric_stiffness.size(), n.geometric_stiffness.size());
  for (std::size_t c = 0; c < m.geometric_stiffness.size(); ++c)
    EXPECT_TRUE(same(m.geometric_stiffness[c], n.geometric_stiffness[c])) << c;
  ASSERT_EQ(m.nodes.size(), n.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    EXPECT_EQ(m.nodes[i].id, n.nodes[i].id);
    EXPECT_TRUE(same(m.nodes[i].position, n.nodes[i].position)) << i;
    EXPECT_TRUE(same(m.nodes[i].translation_shapes, n.nodes[i].translation_shapes)) << i;
    EXPECT_TRUE(same(m.nodes[i].rotation_shapes, n.nodes[i].rotation_shapes)) << i;
  }
  EXPECT_EQ(m.node_sets, n.node_sets);
  EXPECT_EQ(m.surface_triangles, n.surface_triangles);
  EXPECT_EQ(m.stress_nodes, n.stress_nodes);
  EXPECT_TRUE(same(m.stress_modes, n.stress_modes));
  EXPECT_EQ(m.frequencies_hz, n.frequencies_hz);
  EXPECT_TRUE(same(a.K, b.K));
  EXPECT_TRUE(same(a.M, b.M));
  EXPECT_EQ(a.reduced_frequencies_hz, b.reduced_frequencies_hz);
  EXPECT_EQ(a.full_frequencies_hz, b.full_frequencies_hz);
  EXPECT_EQ(a.full_model_boundary, b.full_model_boundary);
  ASSERT_EQ(a.interfaces.size(), b.interfaces.size());
  for (std::size_t i = 0; i < a.interfaces.size(); ++i) {
    EXPECT_EQ(a.interfaces[i].name, b.interfaces[i].name);
    EXPECT_EQ(a.interfaces[i].kind, b.interfaces[i].kind);
    EXPECT_TRUE(same(a.interfaces[i].master_position_m, b.interfaces[i].master_position_m));
    EXPECT_EQ(a.interfaces[i].slave_node_ids, b.interfaces[i].slave_node_ids);
    EXPECT_EQ(a.interfaces[i].weights, b.interfaces[i].weights);
  }
  EXPECT_EQ(a.reference_interface, b.reference_interface);
  const ReducedBodyProvenance& p = a.provenance;
  const ReducedBodyProvenance& q = b.provenance;
  EXPECT_EQ(p.source, q.source);
  EXPECT_EQ(p.mesh_hash, q.mesh_hash);
  EXPECT_EQ(p.options_hash, q.options_hash);
  EXPECT_EQ(p.element_type, q.element_type);
  EXPECT_EQ(p.material.name, q.material.name);
  EXPECT_EQ(p.material.youngs_modulus_pa, q.material.youngs_modulus_pa);
  EXPECT_EQ(p.material.poissons_ratio, q.material.poissons_ratio);
  EXPECT_EQ(p.material.density_kg_m3, q.material.density_kg_m3);
  EXPECT_EQ(p.modes_kept, q.modes_kept);
  EXPECT_EQ(p.engine_version, q.engine_version);
}

// Copies a reduced-body file dataset by dataset through the reader and ResultFile, letting
// `edit` skip (return false) or change a dataset on the way; attributes keep their types.
void CopyFile(const std::string& from, const std::string& to,
              const std::function<bool(const std::string&, Eigen::MatrixXd&)>& edit) {
  const Hdf5Reader r(from);
  ResultFile out = ResultFile::Create(to);
  for (const Hdf5Reader::Entry& e : r.List()) {
    if (!e.is_group) {
      bool is_string = false, is_int = false;
      try {
        r.ReadStrings(e.path);
        is_string = true;
      } catch (const std::runtime_error&) {
      }
      if (!is_string) {
        try {
          r.ReadIntMatrix(e.path);
          is_int = true;
        } catch (const std::runtime_error&) {
        }
      }
      Eigen::MatrixXd m = is_string ? Eigen::MatrixXd() : r.ReadMatrix(e.path);
      if (!edit(e.path, m)) continue;
      if (is_string) {
        out.WriteStrings(e.path, r.ReadStrings(e.path));
      } else if (is_int) {
        const Hdf5Reader::IntMatrix ints = m.cast<std::int64_t>();
        if (e.shape.size() == 1) {
          out.WriteIntVector(e.path, std::vector<std::int64_t>(ints.data(), ints.data() + ints.size()));
        } else {
          out.WriteIntMatrix(e.path, ints);
        }
      } else if (e.shape.size() == 1) {
        out.WriteVector(e.path, std::vector<double>(m.data(), m.data() + m.size()), "1");
      } else {
        out.WriteMatrix(e.path, m, "1");
      }
    }
    for (const auto& [key, text] : e.attributes) {
      if (key == "unit" && !e.is_group) continue;
      try {
        out.SetAttribute(e.path, key, r.ReadIntAttribute(e.path, key));
      } catch (const std::runtime_error&) {
        try {
          out.SetAttribute(e.path, key, r.ReadNumberAttribute(e.path, key));
        } catch (const std::runtime_error&) {
          out.SetAttribute(e.path, key, r.ReadStringAttribute(e.path, key));
        }
      }
    }
  }
  out.Close();
}

// The message of the std::exception `f` throws ("" if none).
std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST_F(ReducedBodyFileTest, SyntheticBodyRoundTripsExactly) {
  const ReducedBody body = SyntheticBody();
  WriteReducedBody(Path("body.h5"), body);
  ExpectIdentical(body, ReadReducedBody(Path("body.h5")));
  // With the expected provenance equal to the file's, the read succeeds too
  ExpectIdentical(body, ReadReducedBody(Path("body.h5"), &body.provenance));
}

TEST_F(ReducedBodyFileTest, EmptyOptionalFieldsRoundTrip) {
  // No damping, no geometric stiffness, no stress modes, no triangles: each stays empty
  ReducedBody body = SyntheticBody();
  body.modes.damping.resize(0, 0);
  body.modes.geometric_stiffness.clear();
  body.modes.stress_nodes.clear();
  body.modes.stress_modes.resize(0, 0);
  body.modes.surface_triangles.clear();
  body.modes.node_sets.clear();
  WriteReducedBody(Path("body.h5"), body);
  ExpectIdentical(body, ReadReducedBody(Path("body.h5")));
}

TEST_F(ReducedBodyFileTest, InconsistentBodyIsNotWritten) {
  ReducedBody body = SyntheticBody();
  body.modes.stiffness.resize(2, 2);
  EXPECT_NE(ErrorOf([&] { WriteReducedBody(Path("bad.h5"), body); }).find("modes.stiffness"), std::string::npos);
  body = SyntheticBody();
  body.modes.surface_triangles.push_back({0, 1, 5});
  EXPECT_NE(ErrorOf([&] { WriteReducedBody(Path("bad.h5"), body); }).find("surface_triangles"), std::string::npos);
  body = SyntheticBody();
  body.reference_interface = 2;
  EXPECT_NE(ErrorOf([&] { WriteReducedBody(Path("bad.h5"), body); }).find("reference_interface"), std::string::npos);
}

// A real reduction of a hex8 box clamped at XMIN with an RBE3 at XMAX: it round-trips, the read
// modes pass the engine's validation, and the provenance tracks the mesh and the options.
TEST_F(ReducedBodyFileTest, ReductionOfABoxRoundTripsAndTracksProvenance) {
  FeMesh mesh = MakeBoxMesh({.size_m = {0.2, 0.04, 0.03}, .divisions = {6, 2, 2}, .type = ElementType::kHex8});
  const IsotropicMaterial steel{.name = "STEEL", .youngs_modulus_pa = 2.1e11, .poissons_ratio = 0.3,
                                .density_kg_m3 = 7850};
  mesh.AssignMaterialToAll(steel);
  const std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2),
                                        MakeInterface(mesh, "XMAX", InterfaceKind::kRbe3)};
  const CraigBamptonOptions cb_options{.num_modes = 4};
  const FlexibleBodyModesOptions outputs{.stress_modes = true, .geometric_stiffness = true};
  const FeSystem system = AssembleFeSystem(mesh);
  const CraigBamptonModel cb = ReduceCraigBampton(mesh, system, ifs, cb_options);
  ReducedBody body{.modes = MakeFlexibleBodyModes(mesh, system, cb, ifs, outputs),
                   .K = cb.K,
                   .M = cb.M,
                   .reduced_frequencies_hz = cb.frequencies_hz,
                   .full_frequencies_hz = {},
                   .full_model_boundary = "not computed"};
  for (const FeInterface& i : ifs) body.interfaces.push_back(DescribeInterface(mesh, i));
  body.provenance = MakeReducedBodyProvenance(mesh, cb_options, ifs, outputs, "box 0.2 x 0.04 x 0.03");
  EXPECT_EQ(body.provenance.element_type, "C3D8");
  EXPECT_EQ(body.provenance.material.youngs_modulus_pa, 2.1e11);
  EXPECT_EQ(body.provenance.modes_kept, 4);
  WriteReducedBody(Path("box.h5"), body);
  const ReducedBody read = ReadReducedBody(Path("box.h5"), &body.provenance);
  ExpectIdentical(body, read);
  EXPECT_NO_THROW(ValidateFlexibleBodyModes("box", read.modes));
  EXPECT_EQ(read.interfaces[1].slave_node_ids.size(), mesh.NodeSet("XMAX").size());

  // The same mesh built again hashes the same; a longer one does not: the file is stale, and
  // says why
  FeMesh same = MakeBoxMesh({.size_m = {0.2, 0.04, 0.03}, .divisions = {6, 2, 2}, .type = ElementType::kHex8});
  same.AssignMaterialToAll(steel);
  EXPECT_EQ(HashFeMesh(same), HashFeMesh(mesh));
  FeMesh longer = MakeBoxMesh({.size_m = {0.2 + 1e-12, 0.04, 0.03}, .divisions = {6, 2, 2}, .type = ElementType::kHex8});
  longer.AssignMaterialToAll(steel);
  ReducedBodyProvenance expected =
      MakeReducedBodyProvenance(longer, cb_options, ifs, outputs, "box 0.2 x 0.04 x 0.03 (moved)");
  const std::string stale = ErrorOf([&] { ReadReducedBody(Path("box.h5"), &expected); });
  EXPECT_NE(stale.find(Path("box.h5")), std::string::npos) << stale;
  EXPECT_NE(stale.find("mesh hash differs: file was reduced from box 0.2 x 0.04 x 0.03 (fnv1a64:"), std::string::npos)
      << stale;
  EXPECT_NE(stale.find("the scene's mesh is box 0.2 x 0.04 x 0.03 (moved)"), std::string::npos) << stale;
  EXPECT_THROW(ReadReducedBody(Path("box.h5"), &expected), StaleReducedBodyError);

  // More modes asked: both the options hash and the count differ
  expected = MakeReducedBodyProvenance(mesh, {.num_modes = 6}, ifs, outputs, "box");
  const std::string modes = ErrorOf([&] { CheckReducedBodyMatches(read.provenance, expected); });
  EXPECT_NE(modes.find("modes kept 4, the scene asks 6"), std::string::npos) << modes;
  EXPECT_NE(modes.find("reduction options differ"), std::string::npos) << modes;
  EXPECT_EQ(modes.find("mesh hash"), std::string::npos) << modes;

  // Another material, another interface kind, other outputs
  FeMesh aluminium = mesh;
  aluminium.AssignMaterialToAll({.name = "AL", .youngs_modulus_pa = 7e10, .poissons_ratio = 0.33, .density_kg_m3 = 2700});
  expected = MakeReducedBodyProvenance(aluminium, cb_options, ifs, outputs, "box");
  const std::string material = ErrorOf([&] { CheckReducedBodyMatches(read.provenance, expected); });
  EXPECT_NE(material.find("material E 2.1e+11 Pa"), std::string::npos) << material;
  std::vector<FeInterface> rbe2 = ifs;
  rbe2[1].kind = InterfaceKind::kRbe2;
  EXPECT_NE(HashReductionOptions(cb_options, rbe2, outputs), body.provenance.options_hash);
  EXPECT_NE(HashReductionOptions(cb_options, ifs, {.stress_modes = false, .geometric_stiffness = true}),
            body.provenance.options_hash);
  // Unknown fields of the expectation are not compared
  EXPECT_NO_THROW(CheckReducedBodyMatches(read.provenance, {.mesh_hash = body.provenance.mesh_hash}));
}

TEST_F(ReducedBodyFileTest, Fnv1aMatchesPublishedVectors) {
  // Test vectors of the FNV reference page (http://www.isthe.com/chongo/tech/comp/fnv/)
  EXPECT_EQ(Fnv1a64Hex(""), "fnv1a64:cbf29ce484222325");
  EXPECT_EQ(Fnv1a64Hex("a"), "fnv1a64:af63dc4c8601ec8c");
  EXPECT_EQ(Fnv1a64Hex("foobar"), "fnv1a64:85944171f73967e8");
}

TEST_F(ReducedBodyFileTest, BadFilesNameTheFileAndTheDataset) {
  // Missing file, a text file, an HDF5 file of another kind
  std::string e = ErrorOf([&] { ReadReducedBody(Path("missing.h5")); });
  EXPECT_EQ(e, Path("missing.h5") + ": no such file");
  std::ofstream(Path("text.h5")) << "not hdf5\n";
  e = ErrorOf([&] { ReadReducedBody(Path("text.h5")); });
  EXPECT_EQ(e, Path("text.h5") + ": not an HDF5 file");
  {
    ResultFile other = ResultFile::Create(Path("result.h5"));
    other.WriteVector("/time", {0, 1}, "s");
  }
  e = ErrorOf([&] { ReadReducedBody(Path("result.h5")); });
  EXPECT_EQ(e.rfind(Path("result.h5") + ": not an orrery reduced body file", 0), 0u) << e;

  // Damaged copies of a good file: a dataset missing, a wrong shape, an index out of range, a
  // newer format version
  WriteReducedBody(Path("good.h5"), SyntheticBody());
  CopyFile(Path("good.h5"), Path("copy.h5"), [](const std::string&, Eigen::MatrixXd&) { return true; });
  ExpectIdentical(SyntheticBody(), ReadReducedBody(Path("copy.h5")));

  CopyFile(Path("good.h5"), Path("no_k.h5"), [](const std::string& p, Eigen::MatrixXd&) { return p != "/modes/stiffness"; });
  e = ErrorOf([&] { ReadReducedBody(Path("no_k.h5")); });
  EXPECT_EQ(e, Path("no_k.h5") + ": /modes/stiffness: no such dataset");

  CopyFile(Path("good.h5"), Path("shape.h5"), [](const std::string& p, Eigen::MatrixXd& m) {
    if (p == "/modes/nodes/translation_shapes") m.conservativeResizeLike(Eigen::MatrixXd::Zero(m.rows(), m.cols() + 1));
    return true;
  });
  e = ErrorOf([&] { ReadReducedBody(Path("shape.h5")); });
  EXPECT_EQ(e, Path("shape.h5") + ": /modes/nodes/translation_shapes: expected 15 x 3, found 15 x 4");

  CopyFile(Path("good.h5"), Path("index.h5"), [](const std::string& p, Eigen::MatrixXd& m) {
    if (p == "/modes/surface_triangles") m(1, 2) = 5;
    return true;
  });
  e = ErrorOf([&] { ReadReducedBody(Path("index.h5")); });
  EXPECT_EQ(e, Path("index.h5") + ": /modes/surface_triangles: node index 5 in row 1 is outside [0, 5)");

  CopyFile(Path("good.h5"), Path("ints.h5"), [](const std::string& p, Eigen::MatrixXd& m) {
    if (p == "/modes/nodes/ids") m.resize(0, 0);
    return true;
  });
  e = ErrorOf([&] { ReadReducedBody(Path("ints.h5")); });
  EXPECT_EQ(e.rfind(Path("ints.h5") + ": /modes/nodes/positions: expected 0 x 3", 0), 0u) << e;

  {
    // Same layout, format version 2
    CopyFile(Path("good.h5"), Path("v2.h5"), [](const std::string&, Eigen::MatrixXd&) { return true; });
    // (ResultFile cannot reopen a file; rewrite it with the attribute changed)
    ResultFile f = ResultFile::Create(Path("v2.h5"));
    f.SetAttribute("/", "format", std::string("orrery reduced body"));
    f.SetAttribute("/", "format_version", std::int64_t{2});
  }
  e = ErrorOf([&] { ReadReducedBody(Path("v2.h5")); });
  EXPECT_EQ(e, Path("v2.h5") + ": reduced body format version 2, this engine reads version 1");
}

// Issue 17, class 5: a NaN or inf anywhere in the numbers of a reduced body (a node position, a
// mode shape, a stress mode, a matrix) is refused naming the file, the dataset and the entry,
// instead of flowing silently into every result.
TEST_F(ReducedBodyFileTest, NonFiniteNumbersAreRefusedWithFileAndDataset) {
  WriteReducedBody(Path("good.h5"), SyntheticBody());
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::string dataset;
    Eigen::Index row, col;
    double value;
    std::string shown;
  };
  for (const Case& c : {Case{"/modes/nodes/positions", 3, 0, nan, "nan"},
                        Case{"/modes/nodes/translation_shapes", 7, 2, inf, "inf"},
                        Case{"/modes/nodes/rotation_shapes", 0, 1, -inf, "-inf"},
                        Case{"/modes/stress_modes", 11, 0, nan, "nan"},
                        Case{"/modes/stiffness", 1, 1, inf, "inf"},
                        Case{"/modes/damping", 0, 0, nan, "nan"},
                        Case{"/modes/geometric_stiffness", 17, 2, nan, "nan"},
                        Case{"/modes/inertia/I5", 4, 1, nan, "nan"},
                        Case{"/craig_bampton/M", 8, 8, inf, "inf"}}) {
    CopyFile(Path("good.h5"), Path("bad.h5"), [&](const std::string& p, Eigen::MatrixXd& m) {
      if (p == c.dataset) m(c.row, c.col) = c.value;
      return true;
    });
    EXPECT_EQ(ErrorOf([&] { ReadReducedBody(Path("bad.h5")); }),
              Path("bad.h5") + ": " + c.dataset + ": value " + c.shown + " at row " + std::to_string(c.row) +
                  ", column " + std::to_string(c.col) + " is not finite");
  }
  // Vectors too (the modal frequencies)
  CopyFile(Path("good.h5"), Path("bad.h5"), [&](const std::string& p, Eigen::MatrixXd& m) {
    if (p == "/modes/frequencies_hz") m(1, 0) = nan;
    return true;
  });
  EXPECT_EQ(ErrorOf([&] { ReadReducedBody(Path("bad.h5")); }),
            Path("bad.h5") + ": /modes/frequencies_hz: value nan at 1 is not finite");
}

}  // namespace
}  // namespace orrery::flex

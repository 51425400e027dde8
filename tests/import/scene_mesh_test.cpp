// Scene bodies whose mass properties and contact surface come from a mesh file (import/scene.cpp,
// `bodies: - mesh: {file, unit, density, contact_region}`), and the `contact` force element
// between two such bodies. Oracles: a box's closed-form mass properties (the body frame is the
// file's frame); a small box settling on a larger fixed one under gravity: at rest, pressed in by
// the order of its weight over the penalty stiffness times its footprint (the node-based contact
// integrates the pressure with node area weights; with only the small box's face nodes on the
// large face, a pass carries half its weight, so the depth lies in [1, 2] W / (k_A A)).
#include <gtest/gtest.h>

#include <filesystem>

#include "import/scene.h"
#include "mbd/simulation.h"
#include "tests/import/mesh_fixtures.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using namespace test_meshes;

class SceneMeshTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ScratchDir("scene_mesh");
    TriangleMesh small = Box(0.1, 0.1, 0.02);
    for (Vec3& v : small.vertices) v -= Vec3(0.05, 0.05, 0);  // footprint centred on the axis
    WriteBinaryStl(small, dir_ / "small.stl", 1000);
    TriangleMesh big = Box(0.3, 0.3, 0.02);
    for (Vec3& v : big.vertices) v -= Vec3(0.15, 0.15, 0.02);  // top face at z = 0
    WriteText(dir_ / "big.obj", "g base\n" + Obj(big).substr(std::string("# orrery test\no part\n").size()));
    TriangleMesh open = Box(1, 1, 1);
    open.triangles.pop_back();
    WriteBinaryStl(open, dir_ / "open.stl");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A scene file in the scratch directory (mesh files relative to it).
  Scene Load(const std::string& text) {
    WriteText(dir_ / "scene.yaml", text);
    return LoadScene((dir_ / "scene.yaml").string());
  }
  std::string ErrorOf(const std::string& text) {
    try {
      Load(text);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

constexpr const char* kDrop = R"(name: drop
gravity: [0, 0, -9.81]
bodies:
  - name: block
    mesh: {file: small.stl, unit: mm, density: 1000}
  - name: base
    mesh: {file: big.obj, unit: m, density: 7850, contact_region: base}
joints:
  - {name: slide, type: prismatic, parent: world, child: block, axis: [0, 0, 1], initial_position: 0.0005}
  - {name: weld, type: fixed, parent: world, child: base}
force_elements:
  - {type: contact, name: touch, body_a: block, body_b: base, stiffness_per_area: 1e9, hunt_crossley: 20, margin: 0.001}
solver: {integrator: ida, end_time: 1.0, rtol: 1e-9, atol: 1e-11}
output: {interval: 0.01}
)";

TEST_F(SceneMeshTest, MassPropertiesFromTheMeshAndContactOnItsSurface) {
  const Scene scene = Load(kDrop);
  const Body& block = scene.model->bodies[1];
  const double m = 1000 * 0.1 * 0.1 * 0.02;
  EXPECT_NEAR(block.mass, m, 1e-6 * m);  // float32 millimetres in the file
  EXPECT_LT((block.com_B - Vec3(0, 0, 0.01)).norm(), 1e-9);
  EXPECT_NEAR(block.inertia_cm_B(0, 0), m * (0.01 + 0.0004) / 12, 1e-6 * block.inertia_cm_B(0, 0));
  EXPECT_NEAR(block.inertia_cm_B(2, 2), m * 0.02 / 12, 1e-6 * block.inertia_cm_B(2, 2));
  const Body& base = scene.model->bodies[2];
  EXPECT_NEAR(base.mass, 7850 * 0.3 * 0.3 * 0.02, 1e-9);
  ASSERT_EQ(scene.model->external_forces.size(), 1u);
  EXPECT_EQ(scene.model->external_forces[0]->name(), "touch");

  // Dropped from 0.5 mm, it comes to rest on the base
  const SimulationReport report = Simulate(*scene.model, scene.simulation, nullptr);
  const double depth = -report.final_state.q[0];
  const double reference = m * 9.81 / (1e9 * 0.01);
  std::printf("block at rest %.3g m deep, W / (k_A A) = %.3g m\n", depth, reference);
  EXPECT_GE(depth, 0.99 * reference);
  EXPECT_LE(depth, 2.01 * reference);
  EXPECT_LT(std::abs(report.final_state.v[0]), 1e-6);
}

TEST_F(SceneMeshTest, ErrorsNameTheFileLineAndKey) {
  const std::string file = (dir_ / "scene.yaml").string();
  const auto scene = [](const std::string& body) {
    return "bodies:\n  - name: b\n    " + body +
           "\njoints:\n  - {name: j, type: revolute, parent: world, child: b}\nsolver: {end_time: 1}\noutput: {interval: 0.1}\n";
  };
  EXPECT_EQ(ErrorOf(scene("mesh: {file: small.stl, density: 1000}")),
            file + ":3: bodies[b].mesh.unit: missing required key 'unit': a mesh file has no unit of its own (m, cm, mm or in)");
  EXPECT_EQ(ErrorOf(scene("mesh: {file: small.stl, unit: yard, density: 1000}")),
            file + ":3: bodies[b].mesh.unit: unknown length unit 'yard' (expected m, cm, mm or in)");
  EXPECT_EQ(ErrorOf(scene("mesh: {file: small.stl, unit: mm, density: -1}")),
            file + ":3: bodies[b].mesh.density: density must be > 0 (kg/m^3), got -1");
  EXPECT_EQ(ErrorOf(scene("mesh: {file: open.stl, unit: m, density: 1000}")),
            file + ":3: bodies[b].mesh.file: " + (dir_ / "open.stl").string() +
                ": not a valid solid for mass properties: 3 boundary edges: the mesh is open (not watertight)");
  EXPECT_EQ(ErrorOf(scene("mesh: {file: none.stl, unit: m, density: 1000}")),
            file + ":3: bodies[b].mesh.file: " + (dir_ / "none.stl").string() + ": no such file");
  EXPECT_EQ(ErrorOf(scene("mesh: {file: big.obj, unit: m, density: 1000, contact_region: bass}")),
            file + ":3: bodies[b].mesh.contact_region: no region 'bass' in " + (dir_ / "big.obj").string() +
                "; did you mean 'base'?");
  EXPECT_EQ(ErrorOf("bodies:\n  - name: b\n    mass: 1\n    mesh: {file: small.stl, unit: mm, density: 1000}\n"
                    "joints:\n  - {name: j, type: revolute, parent: world, child: b}\nsolver: {end_time: 1}\n"
                    "output: {interval: 0.1}\n"),
            file + ":3: bodies[b].mass: body 'b' takes its mass properties from its mesh: remove 'mass'");
  // A contact needs meshes on both sides
  std::string no_mesh = kDrop;
  const std::string base_mesh = "    mesh: {file: big.obj, unit: m, density: 7850, contact_region: base}";
  no_mesh.replace(no_mesh.find(base_mesh), base_mesh.size(), "    mass: 1\n    inertia: [1, 1, 1]");
  EXPECT_EQ(ErrorOf(no_mesh), file + ":13: force_elements[touch].body_b: body 'base' has no mesh: a contact needs bodies "
                                     "with a 'mesh:'");
}

}  // namespace
}  // namespace orrery

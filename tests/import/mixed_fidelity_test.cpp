// Fidelity per mesh branch and per body from YAML and from C++ (models/scenes/
// seed003_mixed_fidelity.yaml, models/train_description.h): the scene read from the file and the
// same GearTrainDescription filled by hand (as models/examples/mixed_fidelity_stage.cpp does)
// assemble the same model, element by element and force by force at the initial state; the
// branches carry the models asked for; the mixed model runs; and the YAML description is plain
// data a program can change and assemble again (the healthy twin of a study, a fidelity swap).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "import/scene.h"
#include "mbd/hdf5_reader.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "mbd/state.h"
#include "models/planetary_scenes.h"
#include "models/train_description.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using namespace orrery::gears;

std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The scene, loaded from a scratch copy of models/scenes and models/bodies (its reduced body is
// made on the first load, `make_reduced_bodies`, and must not land in the source tree).
Scene LoadMixedScene() {
  const fs::path copy = fs::path(::testing::TempDir()) / "mixed_fidelity";
  for (const char* folder : {"scenes", "bodies"}) {
    fs::create_directories(copy / folder);
    for (const auto& entry : fs::directory_iterator(fs::path(ORRERY_SOURCE_DIR) / "models" / folder)) {
      if (entry.path().extension() != ".yaml") continue;
      // A changed reduce input: its reduced bodies from an earlier run would be refused as stale
      const fs::path to = copy / folder / entry.path().filename();
      if (folder == std::string("bodies") && (!fs::exists(to) || ReadText(to) != ReadText(entry.path())))
        for (const auto& made : fs::directory_iterator(copy / folder))
          if (made.path().extension() == ".h5" && made.path().stem().string().rfind(to.stem().string(), 0) == 0)
            fs::remove(made.path());
      fs::copy_file(entry.path(), to, fs::copy_options::overwrite_existing);
    }
  }
  return LoadScene((copy / "scenes" / "seed003_mixed_fidelity.yaml").string(), {}, {.make_reduced_bodies = true});
}

// The description of models/examples/mixed_fidelity_stage.cpp, with the planet's modes given.
GearTrainDescription CxxDescription(std::shared_ptr<const FlexibleBodyModes> planet_modes) {
  GearTrainDescription d = MakeSeed003StageDescription(-10);
  TrainModelOptions& o = d.options;
  o.mesh_model = MeshModel::kLumped;
  o.mesh_stiffness_source = MeshStiffnessSource::kTvms;
  o.mesh_models["S.sun-planet#1"] = MeshModel::kContact;
  o.mesh_models["S.ring-planet#1"] = MeshModel::kContact;
  TrainFlexibleBody& planet = o.flexible_bodies["S.planet1"];
  planet.modes = std::move(planet_modes);
  planet.options.damping_ratios = {0.02};
  o.contact.normal_backlash_m = 20e-6;
  o.backlash_m = 20e-6;
  o.contact.gear.involute_intervals = 40;
  o.contact.gear.calibration_load_n = 15000;
  o.contact.gear.hunt_crossley_s_per_m = 0.5;
  o.contact.gear.margin_m = 100e-6;
  return d;
}

// Generalized forces (inverse dynamics at zero acceleration) at the model's initial state.
Eigen::VectorXd InitialForces(const Model& m) {
  Data d(m);
  const State x = State::Initial(m);
  EvaluateDynamics(m, x.t, x.q, x.v, Eigen::VectorXd::Zero(m.nv), d);
  return d.tau_id;
}

TEST(MixedFidelity, YamlAndCxxAssembleTheSameModel) {
  const Scene scene = LoadMixedScene();
  ASSERT_EQ(scene.kind, SceneKind::kGearTrain);
  const GearTrainScene& g = *scene.gear_train;
  // The branches carry the models asked for: planet 1 in contact, planets 2 and 3 lumped.
  ASSERT_EQ(g.model->branches.size(), 6u);
  for (const TrainMeshBranch& b : g.model->branches)
    EXPECT_EQ(b.model, b.branch == 0 ? MeshModel::kContact : MeshModel::kLumped)
        << g.train->meshes[b.train_mesh].name << "#" << b.branch + 1;
  ASSERT_EQ(g.model->contacts.size(), 2u);
  EXPECT_EQ(g.model->contacts[0].flexible_side, 2);  // sun-planet: the planet is gear 2
  EXPECT_EQ(g.model->contacts[1].flexible_side, 1);  // ring-planet: the planet is gear 1
  const Model& yaml = *scene.model;
  ASSERT_EQ(yaml.flexible_bodies.size(), 1u);
  // Lumped TVMS branches: a table over the mesh cycle, so the stiffness varies.
  for (const GearMesh& m : yaml.gear_meshes) {
    ASSERT_FALSE(m.spec.stiffness_table.empty()) << m.spec.name;
    const auto [lo, hi] = std::minmax_element(m.spec.stiffness_table.begin(), m.spec.stiffness_table.end());
    EXPECT_GT(*hi - *lo, 0.1 * m.k_mean) << m.spec.name;
  }

  // The same description by hand, with the planet's modes the scene loaded.
  const GearTrainAssembly cxx = AssembleGearTrain(CxxDescription(g.options.flexible_bodies.at("S.planet1").modes));
  const Model& m = *cxx.model.model;
  ASSERT_EQ(m.nq, yaml.nq);
  ASSERT_EQ(m.nv, yaml.nv);
  ASSERT_EQ(m.gear_meshes.size(), yaml.gear_meshes.size());
  ASSERT_EQ(m.external_forces.size(), yaml.external_forces.size());
  ASSERT_EQ(m.drivers.size(), yaml.drivers.size());
  EXPECT_EQ((m.q_initial - yaml.q_initial).norm(), 0);
  EXPECT_EQ((m.v_initial - yaml.v_initial).norm(), 0);
  for (size_t k = 0; k < m.gear_meshes.size(); ++k) {
    EXPECT_EQ(m.gear_meshes[k].spec.phase, yaml.gear_meshes[k].spec.phase);
    EXPECT_EQ(m.gear_meshes[k].spec.stiffness_table, yaml.gear_meshes[k].spec.stiffness_table);
  }
  const Eigen::VectorXd f_yaml = InitialForces(yaml), f_cxx = InitialForces(m);
  EXPECT_LE((f_yaml - f_cxx).lpNorm<Eigen::Infinity>(), 1e-12 * f_yaml.lpNorm<Eigen::Infinity>());
  EXPECT_EQ(cxx.model.input_torque_n_m, g.input_torque_n_m);
}

// The description read from YAML is plain data: swapped to all-lumped (the planet rigid) it
// assembles a model with no contact element and the same drive.
TEST(MixedFidelity, TheReadDescriptionAssemblesAgainChanged) {
  const Scene scene = LoadMixedScene();
  GearTrainDescription d = scene.gear_train->description;
  d.options.mesh_models.clear();
  d.options.flexible_bodies.clear();
  const GearTrainAssembly lumped = AssembleGearTrain(d);
  EXPECT_TRUE(lumped.model.contacts.empty());
  EXPECT_EQ(lumped.model.meshes.size(), 6u);
  EXPECT_TRUE(lumped.model.model->flexible_bodies.empty());
  EXPECT_EQ(lumped.model.input_torque_n_m, scene.gear_train->input_torque_n_m);
}

// The mixed model runs (2 ms, the scene's integrator), and every branch carries load by its end.
TEST(MixedFidelity, Runs) {
  Scene scene = LoadMixedScene();
  scene.simulation.end_time = 2e-3;
  const fs::path file = fs::path(::testing::TempDir()) / "mixed_fidelity.h5";
  {
    ResultFile out = ResultFile::Create(file.string());
    ASSERT_NO_THROW(Simulate(*scene.model, scene.simulation, &out));
  }
  const Hdf5Reader in(file.string());
  for (const char* name : {"S.sun-planet#1", "S.ring-planet#1"})
    EXPECT_GT(in.ReadMatrix(std::string("/external/") + name + "/normal_force").bottomRows(1)(0, 0), 1000) << name;
  for (const char* name : {"S.sun-planet#2", "S.ring-planet#3"})
    EXPECT_GT(std::abs(in.ReadMatrix(std::string("/gear_meshes/") + name + "/force").bottomRows(1)(0, 0)), 1000) << name;
}

}  // namespace
}  // namespace orrery

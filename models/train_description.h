#pragma once
// A planetary train as plain data: what a scene says about a gear train, with no physics in it.
// The YAML reader (import/gear_scene.h) fills a GearTrainDescription; a C++ user can fill one by
// hand; AssembleGearTrain turns it into the train (PlanetaryTrainBuilder) and its model
// (BuildTrainModel, train_dynamics.h). Read, then assemble, then finalize (MuJoCo's mjSpec ->
// mjModel).
//
// Usage (seed 003's stage, planet 1 flexible in tooth contact, the others lumped):
//   GearTrainDescription d;
//   d.train.stages.push_back(SinglePlanetStageSpec{.name = "S", .sun = {.teeth = 22},
//       .planet = {.teeth = 14}, .ring = {.teeth = 50}, .num_planets = 3,
//       .tooth_form = ToothForm{.normal_module_m = 4e-3, .normal_pressure_angle_rad = 0.3927}});
//   d.train.stage_face_widths_m["S"] = 0.040;
//   d.train.ranges = {{.name = "steer"}};
//   d.train.inputs = {"S.ring", "S.sun"};
//   d.train.output = "S.carrier";
//   d.options.input = TrainModelOptions::Input::kSpeed;
//   d.options.input_speed_functions = {TimeFunction::Constant(80.6), TimeFunction::Constant(-10)};
//   d.options.output_port_torque_n_m = -6000;
//   d.options.mesh_stiffness_source = MeshStiffnessSource::kTvms;
//   d.options.mesh_models["S.sun-planet#1"] = d.options.mesh_models["S.ring-planet#1"] = MeshModel::kContact;
//   d.options.flexible_bodies["S.planet1"] = {.modes = planet_modes};
//   GearTrainAssembly a = AssembleGearTrain(d);   // a.model.model: the Model to simulate
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "models/planetary_train.h"
#include "models/train_dynamics.h"

namespace orrery::gears {

using StageSpec = std::variant<SinglePlanetStageSpec, DoublePlanetStageSpec, RavigneauxStageSpec>;

// A connection or clutch between two members, by member name ("S1.carrier").
struct CouplingSpec {
  std::string name, member_a, member_b;
};

struct BrakeSpec {
  std::string name, member;
};

// A gear range: the clutches and brakes it engages, by name.
struct RangeSpec {
  std::string name;
  std::vector<std::string> engaged;
};

// The train's topology and gears (PlanetaryTrainBuilder's input, planetary_train.h).
struct PlanetaryTrainDescription {
  std::vector<StageSpec> stages;
  std::vector<CouplingSpec> connections, clutches;
  std::vector<BrakeSpec> brakes;
  std::vector<RangeSpec> ranges;
  std::vector<std::string> inputs;  // member names, in the order of the input speeds
  std::string output;
  // Face width of a stage's gears by stage name: the default for its members and planet sets
  // that have no face width of their own (TrainMemberOverride), and TrainModelOptions::face_width_m
  // when that is 0 (the first stage's).
  std::map<std::string, double> stage_face_widths_m;
};

// Names a stage's members and planet sets get (PlanetaryTrainBuilder's naming): for stage "S"
// of each type, single_planet: S.sun, S.ring, S.carrier and S.planet; double_planet: S.sun,
// S.ring, S.carrier, S.inner, S.outer; ravigneaux: S.sun1, S.sun2, S.ring, S.carrier, S.short,
// S.long. Gears are named as their member or planet set; meshes "S.sun-planet", ... (below).
std::vector<std::string> StageMemberNames(const StageSpec& stage);
std::vector<std::string> StagePlanetSetNames(const StageSpec& stage);
std::vector<std::string> StageMeshNames(const StageSpec& stage);
const std::string& StageName(const StageSpec& stage);
int StagePlanetCount(const StageSpec& stage);

// Builds the train. Throws std::invalid_argument from PlanetaryTrainBuilder (naming the stage,
// gear, coupling, range or port).
std::shared_ptr<const PlanetaryTrain> BuildPlanetaryTrain(const PlanetaryTrainDescription& description);

// A train model to assemble: the train, its range and the options of BuildTrainModel.
struct GearTrainDescription {
  PlanetaryTrainDescription train;
  std::string range;         // "" : the first
  TrainModelOptions options;
};

struct GearTrainAssembly {
  std::shared_ptr<const PlanetaryTrain> train;
  int range = 0;
  TrainModelOptions options;  // as assembled (stage face widths applied)
  TrainModel model;
};

// BuildPlanetaryTrain, the stage face widths, BuildTrainModel. Throws std::invalid_argument for
// an unknown range or what the two throw (std::runtime_error from the kinematics).
GearTrainAssembly AssembleGearTrain(const GearTrainDescription& description);

// The options with the train's stage face widths applied (as AssembleGearTrain does).
TrainModelOptions WithStageFaceWidths(const PlanetaryTrain& train, const PlanetaryTrainDescription& description,
                                      TrainModelOptions options);

}  // namespace orrery::gears

#pragma once
// The `gear_train:` section read into a plain description (models/train_description.h), with
// where each part came from, so that errors the assembly raises later are reported at their key.
// Internal to import/: gear_train_reader.cpp reads the train, its ports and drive;
// train_dynamics_reader.cpp the `dynamics:` map; gear_scene.cpp loads the flexible bodies'
// reduced-body files and assembles.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "import/scene_reader.h"
#include "models/train_description.h"

namespace orrery::scene_reader {

// Where the parts of a gear_train description were read.
struct GearTrainSources {
  Item section;
  std::vector<std::pair<std::string, MapReader>> stages;  // by stage name
  std::vector<std::pair<std::string, Item>> couplings;    // connections, clutches, brakes by name
  std::vector<std::pair<std::string, Item>> ranges;       // by range name
  std::optional<Item> inputs, output, range, dynamics, mesh_stiffness;
  std::vector<std::pair<std::string, Item>> dynamics_entries;  // overrides, mesh models and
                                                               // flexible bodies, by name
  std::vector<std::pair<std::string, Item>> sensors;           // the scene's sensors, by name
};

// A flexible body's reduced-body file as the scene names it (paths resolved against the scene's
// folder).
struct FlexibleBodyFile {
  std::string body;              // "S.planet1", "S.sun"
  Item item;
  std::string reduced_body;      // path
  std::optional<Item> reduced_body_item;
  std::string reduce_input;      // path, "" if none
  std::optional<Item> reduce_input_item, mesh_interface_item, geometric_stiffening_item, record_node_sets_item;
};

// What the names of a train description are (for references and suggestions).
struct TrainNames {
  std::vector<std::string> members, planet_sets, gears, meshes, planets, branches;
  std::map<std::string, int> gear_teeth;     // by gear (member or planet-set) name
  std::map<std::string, int> set_planets;    // planets of each planet set
};
TrainNames NamesOf(const gears::PlanetaryTrainDescription& train);

struct GearTrainRead {
  gears::GearTrainDescription description;
  GearTrainSources sources;
  std::vector<TimeFunction> input_speed_functions;  // (inputs) rad/s; empty without `drive: speed`
  std::vector<double> input_speeds_rad_s;           // (inputs) the analyses' operating point: the
                                                    // value of largest magnitude over [0, end_time]
  std::string mesh_stiffness = "c_gamma";           // the dynamics.mesh_stiffness keyword
  std::vector<FlexibleBodyFile> flexible_files;
};

// The train, its ports and drive (gear_train_reader.cpp); then ReadTrainDynamics.
GearTrainRead ReadGearTrainDescription(const Context& ctx, const Item& section, double end_time);

// The dynamics map into r.description.options, r.mesh_stiffness, r.flexible_files
// (train_dynamics_reader.cpp).
void ReadTrainDynamics(const Context& ctx, const std::optional<Item>& item, GearTrainRead& r);

// Places an error the assembly raised at the key it is about and throws the SceneError.
[[noreturn]] void FailAtSource(const Context& ctx, const GearTrainSources& sources, const std::string& what,
                               bool kinematics_error);

}  // namespace orrery::scene_reader

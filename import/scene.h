#pragma once
// Scenes from YAML files (yaml-cpp stays inside import/).
//
// A scene file describes the same things as the C++ API: bodies, frames, joints, loop closures,
// drivers, force elements, solver and output settings. Everything is validated before anything
// runs: unknown keys, missing keys, wrong types and non-physical values are errors naming the
// file, the line and the key ("pendulum.yaml:12: bodies[bob].mass: must be > 0, got -1").
// The schema is documented in docs/scene_format.md.
//
// A scene holds exactly one model section: bodies + joints (a generic multibody model),
// `lumped_stage:` (a planetary stage with explicit lumped parameters, BuildLumpedStage) or
// `gear_train:` (an N-stage planetary train from tooth counts and tooth forms: read into a
// GearTrainDescription, then assembled by AssembleGearTrain, models/train_description.h).
// For the two gear sections the scene also keeps what the analysis commands need (the train, the
// gear range, the operating point, the options); Scene::model is then the model a run simulates.
//
// Usage:
//   Scene scene = LoadScene("models/scenes/pendulum.yaml", {"solver.end_time=2"});
//   ResultFile out = ResultFile::Create(scene.output_path);
//   Simulate(*scene.model, scene.simulation, &out);
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbd/model.h"
#include "mbd/simulation.h"
#include "mbd/time_function.h"
#include "models/lumped_planetary.h"
#include "models/planetary_train.h"
#include "models/train_description.h"
#include "models/train_dynamics.h"

namespace orrery {

// Error in a scene: what() is "FILE:LINE: KEY: reason" (or "FILE: reason" without a line).
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class SceneKind { kMultibody, kLumpedStage, kGearTrain };

// A driver or load of a lumped stage's member (`input:` / `load:` entries), for reports.
struct LumpedStagePort {
  std::string member;         // "sun", "ring", "carrier"
  enum class Kind { kSpeed, kTorque } kind = Kind::kTorque;
  TimeFunction function;      // rad/s or N m
  bool is_load = false;       // from `load:` (else `input:`)
};

// Filled by the loader for `lumped_stage:` scenes. Scene::model is stage.model.
struct LumpedStageScene {
  LumpedStageParams params;          // SI, as read
  LumpedStage stage;                 // the built stage (joints of sun, ring, carrier, planets)
  std::vector<LumpedStagePort> ports;
  int rotation_coordinate = 0;       // spin within a member joint's velocities (0, 2 or 5)
};

// Filled by the loader for `gear_train:` scenes: the description read from the file (plain data,
// models/train_description.h) and what was assembled from it. Scene::model is model->model.
struct GearTrainScene {
  gears::GearTrainDescription description;         // as read (reduced bodies loaded)
  std::shared_ptr<const gears::PlanetaryTrain> train;
  int range = 0;                                   // `range:` (default: the first range)
  std::vector<TimeFunction> input_speed_functions; // one per train input (rad/s); empty: torque in
  std::vector<double> input_speeds_rad_s;          // operating point of the analyses: per input,
                                                   // the function's value of largest magnitude
                                                   // over [0, solver.end_time]
  double input_torque_n_m = 0;                      // on train->inputs[0] (from input_torque, or
                                                   // from output_torque through the power flow)
  std::string mesh_stiffness;                      // "c_gamma" (default), "value", "iso6336",
                                                   // "tvms", "tvms_mean"
  std::vector<std::string> contact_meshes;         // contact elements ("S.sun-planet#1", ...),
                                                   // outputs under /external/<name>/
  gears::TrainModelOptions options;                // as assembled (stage face widths applied)
  std::shared_ptr<const gears::TrainModel> model;  // for `range`
};

struct Scene {
  std::string name;                    // scene "name:" (default: file stem)
  std::string source_path;             // the file it came from ("" for a string)
  std::shared_ptr<const Model> model;
  SimulationOptions simulation;        // end time, output interval, integrator, scene text
  std::string output_path;             // "output: file:" or "<file stem>.h5"
  std::vector<std::string> input_files;  // other files it read (reduced bodies, reduce inputs)
  SceneKind kind = SceneKind::kMultibody;
  std::shared_ptr<const LumpedStageScene> lumped_stage;  // kLumpedStage only
  std::shared_ptr<const GearTrainScene> gear_train;      // kGearTrain only
};

struct SceneLoadOptions {
  // A flexible body whose reduced-body file is missing is reduced from its reduce_input and the
  // file written where the scene names it (what `orrery run` does). Off: the missing file is an
  // error naming the command that makes it, and loading writes nothing (the analysis commands).
  bool make_reduced_bodies = false;
  // The healthy twin of a faulty scene (what `orrery fault-study` runs beside it): a gear train's
  // tooth faults (TrainModelOptions::tooth_faults) are cleared before its bodies are loaded and
  // its model assembled; everything else is as written.
  bool without_faults = false;
};

// Loads and validates a scene file. `overrides` are "key.path=value" settings applied to the
// YAML tree before validation ("solver.end_time=2", "bodies.bob.mass=2"; list items by name);
// a path that does not exist is a SceneError naming it. The file is read with a bound
// (mbd/file_checks.h: /dev/zero or an endless FIFO is refused, not read until memory runs out).
Scene LoadScene(const std::string& path, const std::vector<std::string>& overrides = {},
                const SceneLoadOptions& options = {});

// Same from text; `name` stands for the file in messages.
Scene LoadSceneFromString(const std::string& text, const std::string& name,
                          const std::vector<std::string>& overrides = {},
                          const SceneLoadOptions& options = {});

}  // namespace orrery

#pragma once
// Scenes from YAML files (yaml-cpp stays inside import/).
//
// A scene file describes the same things as the C++ API: bodies, frames, joints, loop closures,
// drivers, force elements, solver and output settings. Everything is validated before anything
// runs: unknown keys, missing keys, wrong types and non-physical values are errors naming the
// file, the line and the key ("pendulum.yaml:12: bodies[bob].mass: must be > 0, got -1").
// The schema is documented in docs/scene_format.md.
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

namespace orrery {

// Error in a scene: what() is "FILE:LINE: KEY: reason" (or "FILE: reason" without a line).
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Scene {
  std::string name;                    // scene "name:" (default: file stem)
  std::string source_path;             // the file it came from ("" for a string)
  std::shared_ptr<const Model> model;
  SimulationOptions simulation;        // end time, output interval, integrator, scene text
  std::string output_path;             // "output: file:" or "<file stem>.h5"
};

// Loads and validates a scene file. `overrides` are "key.path=value" settings applied to the
// YAML tree before validation ("solver.end_time=2", "bodies.bob.mass=2"; list items by name);
// a path that does not exist is a SceneError naming it.
Scene LoadScene(const std::string& path, const std::vector<std::string>& overrides = {});

// Same from text; `name` stands for the file in messages.
Scene LoadSceneFromString(const std::string& text, const std::string& name,
                          const std::vector<std::string>& overrides = {});

}  // namespace orrery

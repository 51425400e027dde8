#pragma once
// `orrery modes SCENE [--json]`: natural frequencies of a scene about its initial configuration,
// ascending, grouped into repeated modes, each with a class:
//   gear_train scenes:    CalcTrainModes (models/modal_analysis.h) on the scene's train model:
//                         rigid_body, rotational, translational, planet, mixed;
//   lumped_stage scenes:  Linearize + CalcModes, classified as Lin & Parker (1999) do from the
//                         central members (sun, ring, carrier): kinetic energy share of their
//                         spins and of their translations (and tilts) below 1e-6 of the mode's
//                         means "does not move"; planet: neither moves; rotational: central
//                         members do not translate (every mode of the torsional DOF set);
//                         translational: they do not rotate; mixed otherwise;
//   bodies/joints scenes: Linearize + CalcModes, class "mode".
// Operating point: initial positions, zero velocities (no gyroscopic terms); drivers stay as
// constraints (a speed-driven input removes the rigid-body mode). Repeated modes: eigenvalues
// w^2 within 1e3 n eps max|w^2| (modal_analysis.h's tolerance), where n is the number of
// velocity coordinates; rigid-body modes (|w^2| within it) are reported as 0 Hz.
//
// Text: one line per group, "frequency  class  multiplicity". JSON (--json): an object with
//   "scene", "kind" ("multibody" | "lumped_stage" | "gear_train"),
//   "frequencies_hz": every mode ascending, a repeated mode as often as it repeats,
//   "modes": [{"frequency_hz", "class", "multiplicity"}] one entry per group.
// Failures print one line "orrery: error: <reason>" and return kExitFailure.
#include <ostream>
#include <string>
#include <vector>

#include "import/scene.h"

namespace orrery::cli {

struct ModesArgs {
  std::string scene_path;
  std::vector<std::string> overrides;  // --set key.path=value
  bool json = false;
};

struct ModeGroupEntry {
  double frequency_hz = 0;
  std::string mode_class;  // rigid_body | rotational | translational | planet | mixed | mode
  int multiplicity = 1;
};

struct SceneModes {
  std::vector<double> frequencies_hz;  // every mode, ascending
  std::vector<ModeGroupEntry> groups;
};

// The modes of a loaded scene (see above). Throws std::runtime_error from the eigen solvers.
SceneModes CalcSceneModes(const Scene& scene);

int ModesCommand(const ModesArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

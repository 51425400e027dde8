#pragma once
// Readers of the two gear model sections of a scene (internal to import/; the schema is in
// docs/scene_format.md, "Gear model sections"):
//   lumped_stage:  explicit lumped parameters of one planetary stage -> BuildLumpedStage
//                  (models/lumped_planetary.h), with optional member drivers and loads;
//   gear_train:    stages, connections, clutches, brakes, ranges, inputs and output, drive and
//                  dynamics read into a GearTrainDescription (gear_train_reader.h: plain data, no
//                  physics), the flexible bodies' reduced-body files loaded, then assembled
//                  (models/train_description.h AssembleGearTrain) for the scene's range.
// Both fill Scene::model, Scene::kind and their part of the scene; errors are SceneErrors at the
// key they are about ("seed.yaml:12: gear_train.stages[S1].planets: ...").
#include "import/scene.h"
#include "import/scene_reader.h"

namespace orrery::scene_reader {

// `section` is the lumped_stage map.
void ReadLumpedStage(const Context& ctx, const Item& section, Scene& scene);

// `section` is the gear_train map, `sensors` the scene's `sensors:` list (sensor_reader.h,
// ReadTrainSensors); scene.simulation.end_time must be read already (the operating point of a
// time-varying input speed is taken over [0, end_time]). With ctx.without_faults() the train's
// tooth faults are cleared before its flexible bodies are loaded and its model assembled.
void ReadGearTrain(const Context& ctx, const Item& section, const std::optional<Item>& sensors, Scene& scene);

}  // namespace orrery::scene_reader

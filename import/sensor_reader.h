#pragma once
// The `sensors:` section of a scene (docs/scene_format.md, "Sensors"; docs/sensors.md): a list of
// sensors added to a ModelBuilder, every name resolved against what the builder holds so far
// (bodies, frames, joints, gear meshes, external elements), so that any reader that assembles a
// model through a ModelBuilder (the generic multibody scene, the gear train) can read the same
// section once its elements are added. Errors are "FILE:LINE: sensors[NAME].KEY: reason".
// Internal to import/ (it includes yaml-cpp through scene_reader.h).
#include <optional>

#include "import/scene_reader.h"
#include "mbd/model.h"
#include "mbd/sensor_sampler.h"
#include "models/train_dynamics.h"

namespace orrery::scene_reader {

// Reads the list (absent or null: no sensors) and adds each sensor to `builder`. Lengths
// (positions on bodies) are in the scene's unit, `length_unit` metres each. A sensor given by
// `body` and `position` sits on the body's own frame at that pose (SensorSpec::X_FS); one on a
// flexible body's `node` gets a node frame of its own named "sensor:<name>".
void ReadSensors(const Context& ctx, const std::optional<Item>& list, double length_unit,
                 ModelBuilder& builder);

// The `sensors:` list of a gear-train scene as plain TrainSensors (models/train_dynamics.h,
// "Sensors"): names of bodies, joints and mesh branches are resolved later by the train
// assembler's sensors stage; `items` receives each sensor's item by name, so that the stage's
// errors ("sensor 'NAME': ...") are placed at it. Positions are in metres (gear-train scenes are
// SI). Keys per type as in ReadSensors, with `body`/`node`/`position`/`rotation` for point
// sensors, `joint` (a member, planet or "housing") for encoders and tachometers, and `mesh` (a
// branch "S.ring-planet#1") with `quantity` for gear_mesh sensors.
std::vector<gears::TrainSensor> ReadTrainSensors(const Context& ctx, const std::optional<Item>& list,
                                                 std::vector<std::pair<std::string, Item>>& items);

// The `output.sensors:` map: how the sensors are sampled (SensorSamplingOptions).
SensorSamplingOptions ReadSensorSampling(const Context& ctx, const Item& item);

}  // namespace orrery::scene_reader

#pragma once
// A tooth fault (models/tooth_fault.h) read from a scene or reduce-input YAML map, with the
// scene rules (strict keys with suggestions, unit suffixes, "FILE:LINE: KEY: reason" errors):
//
//   {kind: broken_tooth, tooth: 3, height_fraction: 0.5, face_fraction: 1, from_face: zmin}
//   {kind: root_crack, tooth: 3, crack_depth_mm: 0.8, crack_angle_deg: 45, crack_face_fraction: 1,
//    crack_end_depth_mm: 0, flank: plus, from_face: zmin}
//   {kind: spall, tooth: 3, flank: plus, roll_start_mm: 5.2, roll_end_mm: 6.0,
//    axial_start_mm: 10, axial_end_mm: 20, depth_um: 20}
//
// Lengths take `_m` implied (no suffix), `_mm` or `_um`; angles `_deg` or radians. Keys that do
// not belong to the kind are rejected ("crack_depth_mm does not apply to a spall"). `extra_keys`
// are allowed and left to the caller (a train's `gear`, `branch`). Validation against the gear
// (ValidateToothFault) is CheckToothFault's, once the gear exists.
#include <string>
#include <vector>

#include "import/scene_reader.h"
#include "models/planetary_train.h"
#include "models/tooth_fault.h"
#include "models/train_dynamics.h"

namespace orrery {

gears::ToothFaultSpec ReadToothFault(const scene_reader::Context& ctx, const scene_reader::Item& item,
                                     const std::vector<std::string>& extra_keys = {});

// One fault map or a list of them (an absent or null item: none).
std::vector<gears::ToothFaultSpec> ReadToothFaults(const scene_reader::Context& ctx,
                                                   const std::optional<scene_reader::Item>& item,
                                                   const std::vector<std::string>& extra_keys = {});

// ValidateToothFault's message as "FILE:LINE: PATH: reason" at `item` (SceneError).
void CheckToothFault(const scene_reader::Context& ctx, const scene_reader::Item& item, const gears::Gear& gear,
                     const gears::ToothFaultSpec& fault);

// A train's tooth fault written on a command line as comma-separated KEY=VALUE pairs, the keys
// of a scene's `dynamics.faults` entry (docs/scene_format.md; `branch` 1-based for planets):
//   "gear=S1.planet,branch=1,kind=broken_tooth,tooth=17,height_fraction=0.25"
// checked against `train` (gear name, branch, tooth index) as the scene reader checks it. Throws
// SceneError "--fault 'TEXT': KEY: reason" (a pair without '=', an unknown key or value).
gears::TrainToothFault ReadTrainToothFaultArgument(const std::string& text, const gears::PlanetaryTrain& train);

}  // namespace orrery

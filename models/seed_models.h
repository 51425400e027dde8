#pragma once
// Dynamic models of the seed scenarios that tests, benchmarks and examples share.
//
// Seed 002 (wind-turbine stage, docs/validation/scenarios.md): helical 19/34/89, module
// 16 mm, 20 deg, helix 7 deg, face width 330 mm, 3 planets, ring held, carrier input, sun output.
// The paper gives no profile shifts, yet 19 + 2 x 34 != 89: the sun, planet and ring are shifted
// by x = 0.3, 0.2, 0.27 so the stage assembles, the pin radius being the shifted sun-planet
// centre distance. Bearings (not given): radial 2e9 N/m, axial 1e9 N/m, tilt 1e9 N m/rad, 5 %
// damping of the planet on its radial bearing. Input shaft 15 kg m^2, sun 0.25 kg m^2 (as
// given), meshes from the time-varying stiffness with 5 % damping.
#include <memory>

#include "mbd/time_function.h"
#include "models/planetary_train.h"
#include "models/train_dynamics.h"

namespace orrery::gears {

// The seed 002 stage with the profile-shifted pin radius (one range "run": ring braked).
std::shared_ptr<const PlanetaryTrain> Seed002ShiftedStage();

// Spatial (6 DOF per member) options with the speed input set to `carrier_speed` (rad/s) and the
// 3e5 N m input torque setting the power flow.
TrainModelOptions Seed002DynamicsOptions(const TimeFunction& carrier_speed);

}  // namespace orrery::gears

#pragma once
// Planetary trains of the seed papers as ready-made descriptions (see
// docs/validation/scenarios.md). Each factory returns a finalized train; member names are
// "<stage>.sun", ".ring", ".carrier". Values a paper does not give are stated per factory.
#include <memory>

#include "models/planetary_train.h"
#include "models/train_description.h"

namespace orrery::gears {

// Seed 000 (two-stage hoist, Table 1): stage "S1" 25/34/95, 3 planets, module 10 mm; stage "S2"
// 21/25/71, 4 planets, module 16 mm. Spur gears; the pressure angle is not given: 20 deg assumed.
// Both rings are held (brakes "B1", "B2", engaged in the only range "hoist"); the input shaft
// drives S1.sun, S1.carrier drives S2.sun (connection "S1.carrier-S2.sun"), S2.carrier is the
// output. Stage ratios 1 + Z_r/Z_s = 4.8 and 4.381, overall 21.03. (Stage 1 is not concentric with
// reference gears, Z_s + 2 Z_p = 93 != 95: the paper's gears are profile-shifted; the pin radius
// here is the sun-planet reference centre distance, 295 mm.)
std::shared_ptr<const PlanetaryTrain> MakeSeed000HoistTrain();

// Seed 001 (three-stage automatic transmission, Table 1): stages "S1", "S2", "S3", each 34/18/70,
// module 1.5 mm, pressure angle 21.3 deg, spur; pin circle diameter 78 mm; planet and sun outside
// diameters 30.5 and 52.74 mm. S1 has 4 equally spaced planets; S2 and S3 have 3 planets, which
// (34 + 70)/3 does not allow to space equally: they sit at AssemblablePlanetAngles(104, 3) =
// 0, 121.15, 238.85 deg.
//
// Connection scheme (the paper's stick diagram is not in the text; this one reproduces the loaded
// stages of Table 2 in every range given and its 2nd and 3rd range mesh forces, see
// planetary_scenes_test.cpp): a series of three reduction stages, ring in, carrier out, sun held.
//   input S1.ring; connections S1.carrier = S3.ring, S3.carrier = S2.ring; output S2.carrier.
//   brakes B1 S1.sun, B2 S2.sun, B3 S3.sun; lock-up clutches K1 S1.ring = S1.carrier,
//   K3 S3.ring = S3.carrier, K2 S2.ring = S2.carrier (a locked stage turns as one body, unloaded).
//   range  engaged       ratio (k = Z_s/Z_r = 34/70)   loaded stages
//   "1st"  B1 B2 B3      (1 + k)^3 = 3.2795            S1 S2 S3
//   "2nd"  K1 B2 B3      (1 + k)^2 = 2.2073            S2 S3
//   "3rd"  K1 K3 B2      (1 + k)   = 1.4857            S2
//   "4th"  K1 K3 K2      1 (direct drive)              none
// The paper's 5th (overdrive) range is not reproduced.
std::shared_ptr<const PlanetaryTrain> MakeSeed001AutomaticTransmission();

// Seed 002 (wind-turbine stage): stage "S" 19/34/89, 3 planets, normal module 16 mm, normal
// pressure angle 20 deg, helix 7 deg. Ring held (brake "B", range "run"), input S.carrier, output
// S.sun: w_s / w_c = 1 + Z_r/Z_s = 108/19.
std::shared_ptr<const PlanetaryTrain> MakeSeed002WindTurbineStage();

// Seed 003 (steering differential): stage "S" 22/14/50 (tooth counts inferred in scenarios.md),
// 3 planets, no tooth form (module not given). Two inputs, S.ring then S.sun (speed vector order),
// output S.carrier, range "steer" with nothing engaged (2 DOF).
std::shared_ptr<const PlanetaryTrain> MakeSeed003SteeringDifferential();

// Seed 003's stage as a scene description (train_description.h), the stage of
// models/scenes/seed003_*.yaml: 22/14/50, 3 planets, and the gear data the paper does not give:
// module 4 mm, pressure angle 22.5 deg (a 14-tooth planet undercuts at 20 deg; at 25 deg the rack
// fillets overlap), face width 40 mm. The ring driven at +80.6 rad/s and the sun at
// `sun_speed_rad_s` (case 1: -10, case 2: -30: the sun turns against the ring), 6000 N m on the
// carrier against its rotation (output_port_torque_n_m = -6000 at these speeds). Torsional,
// lumped meshes with c_gamma b: set the fidelity on the returned options.
GearTrainDescription MakeSeed003StageDescription(double sun_speed_rad_s = -10);

}  // namespace orrery::gears

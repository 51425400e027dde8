#pragma once
// The kinematic frequencies of a planetary train at an operating point: the lines a spectrum of
// the train's vibration is read against (DESIGN.md, "Sensors and diagnostics"). From the
// kinematics (planetary_kinematics.h), per stage:
//   f_m      mesh frequency (all meshes of a stage share it; seed 001 eq. 3)       kind mesh
//   f_s, f_r, f_c   absolute rotation frequency of the sun(s), ring and carrier     kind shaft
//            (Ravigneaux: f_s1, f_s2)
//   f_p      a planet set's absolute rotation frequency                             kind shaft
//   f_p^H    a planet set's rotation relative to the carrier (= f_m / Z_p): the
//            modulation a damaged planet tooth puts on the mesh (sidebands
//            k f_m +- n f_p^H)                                                        kind shaft
//   f_pp     planet pass at a point fixed to the housing: N |f_c|                    kind planet_pass
//   f_pp^R   planet pass at a point fixed to the ring: N |f_c - f_r|                 kind planet_pass
// and per gear its local tooth-fault frequency ("f_fault S.planet": a damaged tooth meets its
// partners once per turn relative to the carrier, times the number of meshes it has or of
// planets that meet it; Feng & Zuo 2012, planetary_kinematics.h)               kind fault.
// Double-planet sets are named after their set suffix (f_p^H inner, ...). A train of several
// stages adds the stage name to every per-stage line ("f_m S1", "f_c S2").
//
// Usage:
//   for (const TrainFrequency& f : CalcTrainFrequencies(*train, kinematics)) ...
#include <string>
#include <vector>

#include "models/planetary_kinematics.h"
#include "models/planetary_train.h"

namespace orrery::gears {

struct TrainFrequency {
  std::string name;       // "f_m", "f_p^H", "f_fault S.planet", ...
  double frequency_hz = 0;
  std::string kind;       // "mesh", "shaft", "planet_pass", "fault"
};

// The lines above, the mesh frequencies first, then per stage its shafts and planet passes, then
// the fault lines; zero frequencies (a held member) are left out.
std::vector<TrainFrequency> CalcTrainFrequencies(const PlanetaryTrain& train, const PlanetaryKinematics& kinematics);

}  // namespace orrery::gears

#include "models/train_frequencies.h"

#include <cmath>
#include <numbers>

namespace orrery::gears {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// "f_c" or "f_c S1" (several stages).
std::string Line(const std::string& symbol, const PlanetaryTrain& train, int stage) {
  return train.stages.size() > 1 ? symbol + " " + train.stages[stage].name : symbol;
}

// The symbol of a central member: f_s, f_s1, f_s2, f_r, f_c.
std::string MemberSymbol(const Member& m) {
  const std::string suffix = m.name.substr(m.name.find('.') + 1);
  if (m.kind == MemberKind::kCarrier) return "f_c";
  if (m.kind == MemberKind::kRing) return "f_r";
  return suffix == "sun" ? "f_s" : "f_s" + suffix.substr(3);
}

// f_p, f_p^H of a planet set; a set other than ".planet" carries its suffix ("f_p^H inner").
std::string PlanetSymbol(const PlanetSet& ps, const std::string& symbol) {
  const std::string suffix = ps.name.substr(ps.name.find('.') + 1);
  return suffix == "planet" ? symbol : symbol + " " + suffix;
}

}  // namespace

std::vector<TrainFrequency> CalcTrainFrequencies(const PlanetaryTrain& train, const PlanetaryKinematics& k) {
  std::vector<TrainFrequency> lines;
  auto add = [&](const std::string& name, double hz, const char* kind) {
    if (std::abs(hz) > 0) lines.push_back({name, std::abs(hz), kind});
  };
  for (int s = 0; s < static_cast<int>(train.stages.size()); ++s)
    add(Line("f_m", train, s), k.stage_mesh_frequencies_hz(s), "mesh");
  for (int s = 0; s < static_cast<int>(train.stages.size()); ++s) {
    const Stage& st = train.stages[s];
    const double w_c = k.speeds_rad_s(st.carrier);
    double w_r = 0;
    for (int mi : st.members) {
      const Member& m = train.members[mi];
      add(Line(MemberSymbol(m), train, s), k.speeds_rad_s(mi) / kTwoPi, "shaft");
      if (m.kind == MemberKind::kRing) w_r = k.speeds_rad_s(mi);
    }
    for (int ps : st.planet_sets) {
      const PlanetSet& set = train.planet_sets[ps];
      add(Line(PlanetSymbol(set, "f_p"), train, s), k.speeds_rad_s(train.num_members() + ps) / kTwoPi, "shaft");
      add(Line(PlanetSymbol(set, "f_p^H"), train, s), k.planet_relative_speeds_rad_s(ps) / kTwoPi, "shaft");
    }
    add(Line("f_pp", train, s), st.num_planets * w_c / kTwoPi, "planet_pass");
    add(Line("f_pp^R", train, s), st.num_planets * (w_c - w_r) / kTwoPi, "planet_pass");
  }
  for (int g = 0; g < static_cast<int>(train.gears.size()); ++g)
    add("f_fault " + train.gears[g].name, k.gear_fault_frequencies_hz(g), "fault");
  return lines;
}

}  // namespace orrery::gears

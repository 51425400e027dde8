#include "import/train_mesh_geometry.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace orrery {
namespace {

using gears::PlanetaryTrain;
using gears::TrainGear;
using gears::TrainModelOptions;

// Override key of a gear: its member ("S1.sun") or planet set ("S1.planet").
const std::string& OverrideName(const PlanetaryTrain& train, const TrainGear& g) {
  return g.planet_set >= 0 ? train.planet_sets[g.planet_set].name : train.members[g.member].name;
}

const gears::TrainMemberOverride* OverrideOf(const PlanetaryTrain& train, const TrainGear& g,
                                             const TrainModelOptions& o) {
  const auto it = o.members.find(OverrideName(train, g));
  return it == o.members.end() ? nullptr : &it->second;
}

double FaceWidth(const PlanetaryTrain& train, const TrainGear& g, const TrainModelOptions& o) {
  const gears::TrainMemberOverride* ov = OverrideOf(train, g, o);
  return ov && ov->face_width_m ? *ov->face_width_m : o.face_width_m;
}

// Gear 1 and gear 2 of a mesh (indices into train.gears).
std::pair<int, int> PairGears(const PlanetaryTrain& train, int mesh) {
  const gears::TrainMesh& m = train.meshes.at(mesh);
  if (m.kind == gears::MeshKind::kInternal) return {m.gear_b, m.gear_a};  // planet, ring
  return {m.gear_a, m.gear_b};
}

gears::Gear MakeGear(const TrainGear& g, gears::HelixHand hand, double face_width_m) {
  if (!g.has_tooth_form)
    throw std::invalid_argument("gear '" + g.name + "' has no tooth form (no module given)");
  gears::GearSpec s;
  s.teeth = g.teeth;
  s.normal_module_m = g.tooth_form.normal_module_m;
  s.normal_pressure_angle_rad = g.tooth_form.normal_pressure_angle_rad;
  s.helix_angle_rad = std::abs(g.tooth_form.helix_angle_rad);
  s.hand = hand;
  s.addendum_coef = g.tooth_form.addendum_coefficient;
  s.face_width_m = face_width_m;
  s.tip_radius_m = g.tip_radius_m;
  s.internal = g.internal;
  return gears::Gear(s);
}

}  // namespace

double TrainMeshFaceWidth(const PlanetaryTrain& train, int mesh, const TrainModelOptions& options) {
  const auto [g1, g2] = PairGears(train, mesh);
  return std::min(FaceWidth(train, train.gears[g1], options), FaceWidth(train, train.gears[g2], options));
}

gears::GearPair MakeTrainMeshPair(const PlanetaryTrain& train, int mesh,
                                  const TrainModelOptions& options) {
  const auto [i1, i2] = PairGears(train, mesh);
  const TrainGear& g1 = train.gears[i1];
  const TrainGear& g2 = train.gears[i2];
  const double b = TrainMeshFaceWidth(train, mesh, options);
  if (!(b > 0))
    throw std::invalid_argument("mesh '" + train.meshes[mesh].name + "': face width must be > 0");
  // Opposite hands for external pairs, the same hand for an internal pair.
  const gears::HelixHand hand2 = g2.internal ? gears::HelixHand::kRight : gears::HelixHand::kLeft;
  return gears::GearPair(MakeGear(g1, gears::HelixHand::kRight, b), MakeGear(g2, hand2, b));
}

gears::TvmsOptions TrainMeshTvmsOptions(const PlanetaryTrain& train, int mesh,
                                        const TrainModelOptions& options) {
  const auto [i1, i2] = PairGears(train, mesh);
  // Blank radius of a gear: bore (external) or rim (internal), as BuildTrainModel derives them.
  auto blank = [&](const TrainGear& g) {
    const gears::TrainMemberOverride* ov = OverrideOf(train, g, options);
    if (g.internal)
      return ov && ov->outer_radius_m
                 ? *ov->outer_radius_m
                 : g.pitch_radius_m + options.ring_rim_modules * g.tooth_form.normal_module_m;
    return ov && ov->bore_radius_m ? *ov->bore_radius_m : options.bore_to_pitch_ratio * g.pitch_radius_m;
  };
  gears::TvmsOptions t;
  t.bore_radius1_m = blank(train.gears[i1]);
  t.rim_radius2_m = blank(train.gears[i2]);
  return t;
}

}  // namespace orrery

// Stage 2 of BuildTrainModel: the lumped parameters of members and planet sets (derived from the
// gear geometry and material, then overridden), and the involute geometry of the train's meshes
// that the stiffness models and the parameters share (MakeTrainGearPair, MakeTrainTvmsOptions).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "models/train_assembly.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

// Annulus r_in..r_out of thickness b: mass, polar and transverse inertia about its centre.
TrainBodyParams Annulus(double rho, double r_in, double r_out, double b) {
  TrainBodyParams p;
  p.face_width_m = b;
  p.mass_kg = rho * kPi * (r_out * r_out - r_in * r_in) * b;
  p.polar_inertia_kg_m2 = 0.5 * p.mass_kg * (r_out * r_out + r_in * r_in);
  p.transverse_inertia_kg_m2 = p.mass_kg * (3.0 * (r_out * r_out + r_in * r_in) + b * b) / 12.0;
  return p;
}

// A carrier's crude default: a steel disc reaching the tip circles of the planets.
TrainBodyParams CarrierParams(const PlanetaryTrain& train, int stage, const TrainMemberOverride& ov,
                              double b, const TrainModelOptions& o) {
  double r_out = 0;
  for (int ps : train.stages[stage].planet_sets) {
    const PlanetSet& set = train.planet_sets[ps];
    const TrainGear& g = train.gears[set.gear];
    r_out = std::max(r_out, set.center_radius_m + (g.has_tooth_form ? g.tip_radius_m : 0.0));
  }
  r_out = ov.outer_radius_m.value_or(r_out);
  return Annulus(o.density_kg_m3, ov.bore_radius_m.value_or(0.0), r_out, b);
}

// A gear's blank: an annulus from the bore to the pitch circle, or a ring's from the pitch
// circle to its rim.
TrainBodyParams GearBlankParams(const TrainGear& g, const TrainMemberOverride& ov, double b,
                                const TrainModelOptions& o) {
  if (!g.has_tooth_form) FailTrain("gear '" + g.name + "' has no tooth form: give mass and inertia");
  const double r = g.pitch_radius_m;
  if (g.internal)
    return Annulus(o.density_kg_m3, r, ov.outer_radius_m.value_or(r + o.ring_rim_modules * g.tooth_form.normal_module_m), b);
  return Annulus(o.density_kg_m3, ov.bore_radius_m.value_or(o.bore_to_pitch_ratio * r), r, b);
}

// Member / planet-set parameters: derived from geometry and material, then overridden.
TrainBodyParams ResolveBody(const TrainAssembly& a, const std::string& name, int gear, bool carrier,
                            int stage) {
  const TrainModelOptions& o = a.o;
  const TrainMemberOverride& ov = a.Override(name);
  const double b = ov.face_width_m.value_or(o.face_width_m);
  TrainBodyParams p;
  const bool all_given = ov.mass_kg && ov.polar_inertia_kg_m2;
  if (!all_given && !(b > 0)) FailTrain("'" + name + "' needs a face width (options.face_width_m or an override)");
  if (carrier) {
    if (!all_given) p = CarrierParams(a.train, stage, ov, b, o);
  } else {
    const TrainGear& g = a.train.gears[gear];
    if (!g.has_tooth_form && !ov.base_radius_m)
      FailTrain("gear '" + g.name + "' has no tooth form: give its base radius as an override");
    if (!all_given) p = GearBlankParams(g, ov, b, o);
    p.base_radius_m = ov.base_radius_m.value_or(g.base_radius_m);
  }
  p.face_width_m = b > 0 ? b : p.face_width_m;
  if (ov.mass_kg) p.mass_kg = *ov.mass_kg;
  if (ov.polar_inertia_kg_m2) p.polar_inertia_kg_m2 = *ov.polar_inertia_kg_m2;
  // Transverse inertia: given, derived, or a thin disc's I_z / 2 + m b^2 / 12.
  if (ov.transverse_inertia_kg_m2) p.transverse_inertia_kg_m2 = *ov.transverse_inertia_kg_m2;
  else if (ov.mass_kg || ov.polar_inertia_kg_m2) p.transverse_inertia_kg_m2 = 0.5 * p.polar_inertia_kg_m2 + p.mass_kg * b * b / 12.0;
  if (!(p.mass_kg > 0) || !(p.polar_inertia_kg_m2 > 0) || !(p.transverse_inertia_kg_m2 > 0))
    FailTrain("'" + name + "': mass and inertias must be > 0");
  return p;
}

const TrainMemberOverride& OverrideOf(const TrainModelOptions& o, const std::string& name) {
  static const TrainMemberOverride kNone;
  const auto it = o.members.find(name);
  return it == o.members.end() ? kNone : it->second;
}

// Involute gear of train gear g (train_dynamics.h, "Mesh stiffness"): the geometry every level
// meshes with.
Gear MakeTrainGear(const PlanetaryTrain& train, int g, bool right_hand, const TrainModelOptions& o,
                   double fallback_face_width_m) {
  const TrainGear& tg = train.gears[g];
  if (!tg.has_tooth_form) FailTrain("gear '" + tg.name + "' has no tooth form: its stiffness cannot come from geometry");
  const TrainMemberOverride& ov = OverrideOf(o, TrainGearOwnerName(train, g));
  GearSpec spec;
  spec.teeth = tg.teeth;
  spec.normal_module_m = tg.tooth_form.normal_module_m;
  spec.normal_pressure_angle_rad = tg.tooth_form.normal_pressure_angle_rad;
  spec.helix_angle_rad = std::abs(tg.tooth_form.helix_angle_rad);
  spec.hand = right_hand ? HelixHand::kRight : HelixHand::kLeft;
  spec.profile_shift = ov.profile_shift.value_or(0.0);
  spec.addendum_coef = ov.addendum_coefficient.value_or(tg.internal ? o.ring_addendum_coefficient
                                                                   : tg.tooth_form.addendum_coefficient);
  if (tg.internal) spec.root_fillet_coef = o.ring_root_fillet_coefficient;
  if (tg.tip_given) spec.tip_radius_m = tg.tip_radius_m;  // a measured outside diameter wins
  spec.face_width_m = ov.face_width_m.value_or(o.face_width_m);
  if (spec.face_width_m == 0) spec.face_width_m = fallback_face_width_m;
  spec.internal = tg.internal;
  try {
    return Gear(spec);
  } catch (const std::invalid_argument& e) {
    FailTrain("gear '" + tg.name + "': " + e.what());
  }
}

// Bore radius of an external gear, outer rim radius of a ring (as for the inertias).
double RimRadius(const PlanetaryTrain& train, int g, const TrainModelOptions& o) {
  const TrainGear& tg = train.gears[g];
  const TrainMemberOverride& ov = OverrideOf(o, TrainGearOwnerName(train, g));
  if (tg.internal) return ov.outer_radius_m.value_or(tg.pitch_radius_m + o.ring_rim_modules * tg.tooth_form.normal_module_m);
  return ov.bore_radius_m.value_or(o.bore_to_pitch_ratio * tg.pitch_radius_m);
}

}  // namespace

void ResolveBodyParameters(TrainAssembly& a) {
  for (int i = 0; i < a.train.num_members(); ++i) {
    const Member& m = a.train.members[i];
    a.tm.member_params.push_back(ResolveBody(a, m.name, m.gear, m.kind == MemberKind::kCarrier, m.stage));
  }
  for (const PlanetSet& ps : a.train.planet_sets)
    a.tm.planet_params.push_back(ResolveBody(a, ps.name, ps.gear, false, ps.stage));
}

GearPair MakeTrainGearPair(const PlanetaryTrain& train, int mesh, const TrainModelOptions& o,
                           double fallback_face_width_m) {
  const TrainMesh& m = train.meshes.at(mesh);
  const auto [a, b] = TrainSpecGears(m);
  // Hands: gear a right in an external mesh (the sun, or the first planet of a planet pair),
  // left in an internal one (the planet, with the ring: equal hands); gear b left.
  const Gear g1 = MakeTrainGear(train, a, m.kind == MeshKind::kExternal, o, fallback_face_width_m);
  const Gear g2 = MakeTrainGear(train, b, false, o, fallback_face_width_m);
  const double dist = (TrainGearCentre(train, a, 0) - TrainGearCentre(train, b, 0)).norm();
  try {
    return GearPair(g1, g2, dist);
  } catch (const std::invalid_argument& e) {
    FailTrain("mesh '" + m.name + "': " + e.what() +
              " (give profile shifts or addendum coefficients as member overrides)");
  }
}

namespace {

std::string Num(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

// The number after `key` in a reduce input's source text ("gear z=23, m_n=0.002 m, ..."), NaN
// when absent.
double SourceNumber(const std::string& source, const std::string& key) {
  const std::size_t at = source.find(key);
  if (at == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  try {
    return std::stod(source.substr(at + key.size()));
  } catch (const std::exception&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

// Train gear of a flexible body ("S.planet1": its planet set's gear; "S.sun": the member's), -1.
int FlexibleBodyGear(const PlanetaryTrain& train, const std::string& body) {
  if (const auto m = train.member_by_name.find(body); m != train.member_by_name.end())
    return train.members[m->second].gear;
  for (const PlanetSet& ps : train.planet_sets)
    for (std::size_t i = 0; i < ps.angles_rad.size(); ++i)
      if (ps.name + std::to_string(i + 1) == body) return ps.gear;
  return -1;
}

// The tip radius of the body's FE surface: the largest radius (about B's z axis) of the nodes of
// its surface triangles, the smallest for an internal gear; NaN without a surface.
double SurfaceTipRadius(const FlexibleBodyModes& modes, bool internal) {
  double r = std::numeric_limits<double>::quiet_NaN();
  for (const std::array<int, 3>& t : modes.surface_triangles)
    for (int n : t) {
      const Vec3& p = modes.nodes[n].position;
      const double rn = std::hypot(p.x(), p.y());
      if (std::isnan(r) || (internal ? rn < r : rn > r)) r = rn;
    }
  return r;
}

}  // namespace

void CheckFlexibleGearBodies(const PlanetaryTrain& train, const TrainModelOptions& o) {
  for (const auto& [body, flexible] : o.flexible_bodies) {
    const int g = FlexibleBodyGear(train, body);
    if (g < 0 || !train.gears[g].has_tooth_form || !flexible.modes) continue;
    const TrainGear& tg = train.gears[g];
    const double mn = tg.tooth_form.normal_module_m;
    const Gear gear = MakeTrainGear(train, g, true, o, 10 * mn);
    const bool width_given = OverrideOf(o, TrainGearOwnerName(train, g)).face_width_m || o.face_width_m > 0;
    const std::string what = "flexible body '" + body + "' (" + (flexible.source.empty() ? "no source" : flexible.source) +
                             ") is not the gear '" + tg.name + "' (z = " + std::to_string(tg.teeth) + ", m_n = " +
                             Num(mn) + " m" + (width_given ? ", b = " + Num(gear.spec().face_width_m) + " m" : "") + "): ";
    // What the reduce input says it reduced
    if (flexible.source.rfind("gear z=", 0) == 0) {
      const double z = SourceNumber(flexible.source, "z="), m = SourceNumber(flexible.source, "m_n="),
                   b = SourceNumber(flexible.source, "b=");
      if (z != tg.teeth) FailTrain(what + "its tooth count is " + Num(z));
      if (!(std::abs(m - mn) <= 1e-9 * mn)) FailTrain(what + "its normal module is " + Num(m) + " m");
      if (width_given && !(std::abs(b - gear.spec().face_width_m) <= 1e-9 * gear.spec().face_width_m))
        FailTrain(what + "its face width is " + Num(b) + " m");
    }
    // What its surface shows
    const double r_tip = SurfaceTipRadius(*flexible.modes, tg.internal);
    if (!std::isnan(r_tip) && !(std::abs(r_tip - gear.tip_radius_m()) <= 0.25 * mn))
      FailTrain(what + "its surface reaches radius " + Num(r_tip) + " m, the gear's tip circle is at " +
                Num(gear.tip_radius_m()) + " m");
  }
}

void CheckTrainGearGeometry(const PlanetaryTrain& train, const TrainModelOptions& o) {
  for (int g = 0; g < static_cast<int>(train.gears.size()); ++g)
    if (train.gears[g].has_tooth_form) MakeTrainGear(train, g, true, o, 10 * train.gears[g].tooth_form.normal_module_m);
}

TvmsOptions MakeTrainTvmsOptions(const PlanetaryTrain& train, int mesh, const TrainModelOptions& o) {
  const auto [a, b] = TrainSpecGears(train.meshes.at(mesh));
  return TvmsOptions{.material1 = o.gear_material, .material2 = o.gear_material,
                     .bore_radius1_m = RimRadius(train, a, o), .rim_radius2_m = RimRadius(train, b, o)};
}

}  // namespace orrery::gears

#include "contact/train_contact.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "contact/contact_element.h"

namespace orrery::contact {

namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void Fail(const std::string& what) {
  throw std::invalid_argument("BuildTrainContactModel: " + what);
}

std::string OwnerName(const gears::PlanetaryTrain& train, int g) {
  const gears::TrainGear& tg = train.gears[g];
  return tg.planet_set >= 0 ? train.planet_sets[tg.planet_set].name : train.members[tg.member].name;
}

// Involute gear of train gear g (as MakeTrainGearPair, rings with the contact's coefficients).
gears::Gear ContactGear(const gears::PlanetaryTrain& train, int g, gears::HelixHand hand,
                        const gears::TrainModelOptions& o, const TrainContactOptions& c) {
  const gears::TrainGear& tg = train.gears[g];
  if (!tg.has_tooth_form) Fail("gear '" + tg.name + "' has no tooth form");
  const auto it = o.members.find(OwnerName(train, g));
  const gears::TrainMemberOverride ov = it == o.members.end() ? gears::TrainMemberOverride{} : it->second;
  gears::GearSpec spec;
  spec.teeth = tg.teeth;
  spec.normal_module_m = tg.tooth_form.normal_module_m;
  spec.normal_pressure_angle_rad = tg.tooth_form.normal_pressure_angle_rad;
  spec.helix_angle_rad = std::abs(tg.tooth_form.helix_angle_rad);
  spec.hand = hand;
  spec.profile_shift = ov.profile_shift.value_or(0.0);
  spec.addendum_coef = ov.addendum_coefficient.value_or(
      tg.internal ? c.ring_addendum_coefficient : tg.tooth_form.addendum_coefficient);
  if (tg.internal) spec.root_fillet_coef = c.ring_root_fillet_coefficient;
  spec.face_width_m = ov.face_width_m.value_or(o.face_width_m);
  spec.internal = tg.internal;
  try {
    return gears::Gear(spec);
  } catch (const std::invalid_argument& e) {
    Fail("gear '" + tg.name + "': " + e.what());
  }
}

// (gear 1, gear 2) of a mesh: the external central gear or the planet first.
std::pair<int, int> PairGears(const gears::TrainMesh& m) {
  if (m.kind == gears::MeshKind::kInternal) return {m.gear_b, m.gear_a};
  return {m.gear_a, m.gear_b};
}

}  // namespace

gears::GearPair MakeTrainContactPair(const gears::PlanetaryTrain& train, int mesh,
                                     const gears::TrainModelOptions& o,
                                     const TrainContactOptions& c) {
  const gears::TrainMesh& m = train.meshes[mesh];
  const auto [g1, g2] = PairGears(m);
  if (train.gears[g1].planet_set >= 0 && train.gears[g2].planet_set >= 0)
    Fail("mesh '" + m.name + "': planet-planet meshes are not supported by the contact model yet");
  const bool internal = m.kind == gears::MeshKind::kInternal;
  // Hands: sun right, planet left, ring left (an internal pair has equal hands).
  const gears::Gear gear1 = ContactGear(train, g1, internal ? gears::HelixHand::kLeft
                                                            : gears::HelixHand::kRight, o, c);
  const gears::Gear gear2 = ContactGear(train, g2, gears::HelixHand::kLeft, o, c);
  const int ps = train.gears[internal ? g1 : g2].planet_set;
  try {
    return gears::GearPair(gear1, gear2, train.planet_sets[ps].center_radius_m);
  } catch (const std::invalid_argument& e) {
    Fail("mesh '" + m.name + "': " + e.what());
  }
}

TrainContactModel BuildTrainContactModel(const gears::PlanetaryTrain& train, int range,
                                         gears::TrainModelOptions options,
                                         const TrainContactOptions& contact) {
  // The contact meshes.
  std::vector<int> meshes;
  if (contact.meshes.empty()) {
    for (int i = 0; i < static_cast<int>(train.meshes.size()); ++i) meshes.push_back(i);
  } else {
    for (const std::string& name : contact.meshes) {
      const auto it = std::find_if(train.meshes.begin(), train.meshes.end(),
                                   [&](const gears::TrainMesh& m) { return m.name == name; });
      if (it == train.meshes.end()) Fail("no mesh '" + name + "' in the train");
      meshes.push_back(static_cast<int>(it - train.meshes.begin()));
    }
  }
  for (const auto& mt : contact.missing_teeth)
    if (std::none_of(train.gears.begin(), train.gears.end(),
                     [&](const gears::TrainGear& g) { return g.name == mt.gear; }))
      Fail("missing teeth: no gear '" + mt.gear + "' in the train");
  // Pairs first (geometry errors before the model is built).
  std::vector<gears::GearPair> pairs;
  for (int mi : meshes) {
    pairs.push_back(MakeTrainContactPair(train, mi, options, contact));
    options.meshes_without_element.insert(train.meshes[mi].name);
  }

  auto out = std::make_shared<std::vector<TrainContactMesh>>();
  options.before_finalize = [&, out](ModelBuilder& b, const gears::TrainModel& tm) {
    int next_force = static_cast<int>(b.draft().external_forces.size());
    for (size_t k = 0; k < meshes.size(); ++k) {
      const gears::TrainMesh& m = train.meshes[meshes[k]];
      const auto [g1, g2] = PairGears(m);
      const bool internal = m.kind == gears::MeshKind::kInternal;
      const int planet_gear = internal ? g1 : g2;
      const gears::PlanetSet& ps = train.planet_sets[train.gears[planet_gear].planet_set];
      const double zs = internal ? 0 : train.gears[g1].teeth;  // sun teeth (sun-planet)
      const double zp = train.gears[planet_gear].teeth;
      // The sun of the stage for the planet phasing of a ring mesh.
      double z_sun = zs;
      if (internal)
        for (const gears::TrainMesh& other : train.meshes)
          if (other.stage == m.stage && other.kind == gears::MeshKind::kExternal &&
              other.gear_b == planet_gear && train.gears[other.gear_a].planet_set < 0)
            z_sun = train.gears[other.gear_a].teeth;
      for (int i = 0; i < static_cast<int>(ps.angles_rad.size()); ++i) {
        const std::string planet_name = ps.name + std::to_string(i + 1);
        if (options.flexible_planets.count(planet_name))
          Fail("mesh '" + m.name + "': planet '" + planet_name + "' is flexible (contact needs rigid gears)");
        auto body_of = [&](int g) {
          const gears::TrainGear& tg = train.gears[g];
          const JointIndex j = tg.planet_set >= 0 ? tm.planet_joints[tg.planet_set][i]
                                                  : tm.member_joints[tg.member];
          return b.draft().joints[j].spec.child;
        };
        auto missing = [&](int g) {
          std::vector<int> teeth;
          for (const auto& mt : contact.missing_teeth)
            if (mt.gear == train.gears[g].name && (train.gears[g].planet_set < 0 || mt.branch == i))
              teeth.insert(teeth.end(), mt.teeth.begin(), mt.teeth.end());
          return teeth;
        };
        // Gear frames in the body frames (see the header).
        const double psi = ps.angles_rad[i];
        const double planet_rot = kPi + kPi / zp + z_sun / zp * psi;
        TrainContactMesh e;
        if (internal) {
          const double zr = train.gears[g2].teeth;
          e.rotation1_rad = planet_rot;
          e.rotation2_rad = psi + kPi / zr + zp / zr * planet_rot;
        } else {
          e.rotation1_rad = 0;
          e.rotation2_rad = planet_rot;
        }
        GearContactOptions go = contact.gear;
        go.X_B1G1 = Transform(AxisAngle(Vec3::UnitZ(), e.rotation1_rad), Vec3::Zero());
        go.X_B2G2 = Transform(AxisAngle(Vec3::UnitZ(), e.rotation2_rad), Vec3::Zero());
        go.missing_teeth1 = missing(g1);
        go.missing_teeth2 = missing(g2);
        go.normal_backlash_m = contact.normal_backlash_m;
        go.backlash_share1 = internal ? 0.0 : 1.0;  // the central gear takes the thinning
        e.name = m.name + "#" + std::to_string(i + 1);
        e.train_mesh = meshes[k];
        e.branch = i;
        e.body1 = body_of(g1);
        e.body2 = body_of(g2);
        const gears::GearPair pair =
            WithNormalBacklash(pairs[k], go.normal_backlash_m, go.backlash_share1);
        e.base_radius1_m = pair.gear1().base_radius_m();
        e.base_radius2_m = pair.gear2().base_radius_m();
        e.base_helix_angle_rad = pair.gear1().base_helix_angle_rad();
        e.transverse_pressure_angle_rad = pair.working_pressure_angle_rad();
        e.calibration = CalibrateGearContact(pair, go);
        go.normal_backlash_m = 0;  // already in `pair`
        b.AddExternalForce(std::make_shared<ContactElement>(
            MakeGearContactSpec(e.name, pair, e.body1, e.body2, go)));
        e.external_force = next_force++;
        out->push_back(e);
      }
    }
  };
  TrainContactModel result;
  result.train_model = gears::BuildTrainModel(train, range, options);
  result.contacts = *out;
  return result;
}

}  // namespace orrery::contact

#include "contact/train_contact.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>

#include "contact/contact_element.h"
#include "contact/flexible_contact_element.h"
#include "contact/flexible_gear_mesh.h"
#include "contact/triangle_geometry.h"
#include "models/gear_fe_mesh.h"

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

// The contact surface of a flexible planet (header): the analytic tooth outlines of `gear` turned
// by rot_B about B's z and shifted by z0 along it, embedded in the FE surface of the tooth node
// sets of `modes`. *z0 receives the lowest z of the FE tooth nodes in B.
std::shared_ptr<const FlexibleContactSurface> FlexiblePlanetSurface(
    const std::string& planet, const gears::Gear& gear,
    const std::shared_ptr<const FlexibleBodyModes>& modes, double rot_B,
    const std::vector<int>& missing, const TrainContactOptions& c, double* z0) {
  const std::string what = "flexible planet '" + planet + "': ";
  const FlexibleBodyModes& m = *modes;
  const int z = gear.teeth();
  // The tooth node sets (all of them: the surface must be whole).
  std::vector<std::string> sets;
  for (int k = 0; k < z; ++k)
    for (const char* part : {"FLANK_PLUS", "FLANK_MINUS", "FILLET_PLUS", "FILLET_MINUS", "TIP"})
      sets.push_back(gears::ToothSetName(k, part));
  sets.push_back("ROOT");
  for (const std::string& set : sets)
    if (!m.node_sets.count(set))
      Fail(what + "its reduced body has no node set '" + set + "' (a gear of " + std::to_string(z) +
           " teeth from the gear mesher, reduced with its surface nodes exported, has them)");
  if (m.node_sets.count(gears::ToothSetName(z, "TIP")))
    Fail(what + "its reduced body has more teeth than the train's planet (" + std::to_string(z) + ")");
  // Axial offset and the FE triangles of the sets.
  std::vector<char> allowed(m.nodes.size(), 0);
  *z0 = 1e300;
  for (const std::string& set : sets)
    for (int i : m.node_sets.at(set)) {
      allowed[i] = 1;
      *z0 = std::min(*z0, m.nodes[i].position.z());
    }
  struct Tri {
    Vec3 a, b, c, centre;
    double radius;
  };
  std::vector<Tri> tris;
  for (const auto& t : m.surface_triangles) {
    if (!allowed[t[0]] || !allowed[t[1]] || !allowed[t[2]]) continue;
    Tri tr{m.nodes[t[0]].position, m.nodes[t[1]].position, m.nodes[t[2]].position, Vec3::Zero(), 0};
    tr.centre = (tr.a + tr.b + tr.c) / 3;
    tr.radius = std::max({(tr.a - tr.centre).norm(), (tr.b - tr.centre).norm(), (tr.c - tr.centre).norm()});
    tris.push_back(tr);
  }
  if (tris.empty()) Fail(what + "its reduced body has no surface triangles on the tooth node sets");
  const double tol = c.flexible.embed_tolerance_m;
  auto distance = [&](const Vec3& v) {
    double best = 1e300;
    for (const Tri& t : tris) {
      if ((v - t.centre).norm() - t.radius > std::min(best, tol)) continue;
      best = std::min(best, (ClosestPointOnTriangle(v, t.a, t.b, t.c).point - v).norm());
    }
    return best;
  };
  // Analytic outlines (the rigid builder's resolution), placed in B; triangles with a vertex off
  // the FE surface left out, an involute or tip vertex off it an error.
  const gears::ProfileResolution res{.root = c.gear.root_intervals, .fillet = c.gear.fillet_intervals,
                                     .involute = c.gear.involute_intervals, .tip = c.gear.tip_intervals};
  const Transform X_BG(AxisAngle(Vec3::UnitZ(), rot_B), Vec3(0, 0, *z0));
  std::vector<TriangleMesh> parts;
  for (int t = 0; t < z; ++t) {
    if (std::find(missing.begin(), missing.end(), t) != missing.end()) continue;
    const TriangleMesh full = gears::MakeToothSurfaceMesh(gear, t, res, c.flexible.face_intervals);
    const int nv = static_cast<int>(full.vertices.size());
    std::vector<char> on(nv);
    for (int v = 0; v < nv; ++v) {
      const double d = distance(X_BG * full.vertices[v]);
      on[v] = d <= tol;
      if (!on[v] && std::hypot(full.vertices[v].x(), full.vertices[v].y()) > gear.form_radius_m() + 1e-9)
        Fail(what + "tooth " + std::to_string(t) + ": a flank or tip point lies " + std::to_string(d) +
             " m from the FE surface (embed tolerance " + std::to_string(tol) +
             " m): does the reduce input's gear match the train's planet?");
    }
    TriangleMesh part;
    std::vector<int> index(nv, -1);
    for (const auto& tri : full.triangles) {
      if (!on[tri[0]] || !on[tri[1]] || !on[tri[2]]) continue;
      std::array<int, 3> out;
      for (int k = 0; k < 3; ++k) {
        if (index[tri[k]] < 0) {
          index[tri[k]] = static_cast<int>(part.vertices.size());
          part.vertices.push_back(X_BG * full.vertices[tri[k]]);
        }
        out[k] = index[tri[k]];
      }
      part.triangles.push_back(out);
    }
    if (!part.triangles.empty()) parts.push_back(std::move(part));
  }
  if (parts.empty()) Fail(what + "no tooth left");
  const FlexibleContactSurfaceSpec spec{.node_sets = sets, .gap_margin_m = c.gear.margin_m,
                                        .deformation_allowance_m = c.flexible.deformation_allowance_m,
                                        .slack_m = c.gear.slack_m};
  try {
    return std::make_shared<const FlexibleContactSurface>(modes, parts, spec, tol);
  } catch (const std::invalid_argument& e) {
    Fail(what + e.what());
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
    // Flexible planets: surface (both meshes share it) and axial offset, by planet name.
    std::map<std::string, std::pair<std::shared_ptr<const FlexibleContactSurface>, double>> flexible;
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
        const auto flex_it = options.flexible_planets.find(planet_name);
        const bool flexible_planet = flex_it != options.flexible_planets.end();
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
        if (!flexible_planet) {
          e.calibration = CalibrateGearContact(pair, go);
          go.normal_backlash_m = 0;  // already in `pair`
          b.AddExternalForce(std::make_shared<ContactElement>(
              MakeGearContactSpec(e.name, pair, e.body1, e.body2, go)));
          e.external_force = next_force++;
          out->push_back(e);
          continue;
        }
        // Flexible planet: its joint starts at delta, its FE teeth on the rigid planet's (header).
        e.flexible_side = internal ? 1 : 2;
        const double pitch = 2 * kPi / zp;
        const double whole = pitch * std::round(planet_rot / pitch);
        e.planet_initial_angle_rad = planet_rot - whole;
        auto [it, made] = flexible.try_emplace(planet_name);
        if (made) {
          const gears::Gear& planet_gear_geometry = internal ? pair.gear1() : pair.gear2();
          it->second.first = FlexiblePlanetSurface(planet_name, planet_gear_geometry,
                                                   flex_it->second.modes, whole,
                                                   missing(planet_gear), contact, &it->second.second);
          const JointIndex j = tm.planet_joints[train.gears[planet_gear].planet_set][i];
          const JointSpec& js = b.draft().joints[j].spec;
          const double delta = e.planet_initial_angle_rad;
          Eigen::VectorXd q = Eigen::VectorXd::Zero(JointNq(js.type));
          if (js.type == JointType::kRevolute) {
            q(0) = delta;
          } else if (js.type == JointType::kPlanar) {
            q(2) = delta;
          } else if (js.type == JointType::kFree) {
            q(3) = std::cos(delta / 2), q(6) = std::sin(delta / 2);
          } else {
            Fail("planet '" + planet_name + "': joint type " + JointTypeName(js.type) + " not supported");
          }
          b.SetJointPosition(j, q);
        }
        const double z0 = it->second.second;
        // The rigid side: the rigid builder's surface, shifted by z0 along the axis.
        const bool rigid1 = e.flexible_side == 2;
        const int rigid_gear = rigid1 ? g1 : g2;
        const gears::Gear& rigid_geometry = rigid1 ? pair.gear1() : pair.gear2();
        const Transform X_BG(AxisAngle(Vec3::UnitZ(), rigid1 ? e.rotation1_rad : e.rotation2_rad),
                             Vec3(0, 0, z0));
        const auto rigid_surface = MakeGearContactSurface(rigid_geometry, go, missing(rigid_gear), X_BG);
        // Penalty: Hertz in series with the rigid gear's tooth (its bore or ring rim).
        const gears::TrainGear& rg = train.gears[rigid_gear];
        const auto ov_it = options.members.find(OwnerName(train, rigid_gear));
        const gears::TrainMemberOverride ov =
            ov_it == options.members.end() ? gears::TrainMemberOverride{} : ov_it->second;
        const double r_ref = rigid_geometry.reference_radius_m();
        const double rim = rg.internal ? ov.outer_radius_m.value_or(r_ref + options.ring_rim_modules *
                                                                                rg.tooth_form.normal_module_m)
                                       : ov.bore_radius_m.value_or(options.bore_to_pitch_ratio * r_ref);
        FlexiblePairPenalty penalty;
        (rigid1 ? penalty.rigid1 : penalty.rigid2) = true;
        (rigid1 ? penalty.rim_radius1_m : penalty.rim_radius2_m) = rim;
        try {
          e.calibration = CalibrateFlexibleGearContact(pair, options.gear_material,
                                                       go.calibration_load_n, penalty);
        } catch (const std::invalid_argument& err) {
          Fail("mesh '" + e.name + "': " + err.what());
        }
        ContactSide rigid_side{.body = rigid1 ? e.body1 : e.body2, .rigid = rigid_surface};
        ContactSide flexible_side{.body = rigid1 ? e.body2 : e.body1, .flexible = it->second.first};
        FlexibleContactElementSpec spec{
            .name = e.name, .a = rigid1 ? rigid_side : flexible_side, .b = rigid1 ? flexible_side : rigid_side,
            .law = {.stiffness_per_area = e.calibration.stiffness_per_area,
                    .hunt_crossley_s_per_m = go.hunt_crossley_s_per_m,
                    .friction_coefficient = go.friction_coefficient,
                    .slip_velocity_m_s = go.slip_velocity_m_s}};
        // Gear frames: the rigid side's as its surface; the planet's analytic teeth turned by the
        // whole pitches in B (its joint starts at delta), both shifted by z0.
        const Transform X_BG_planet(AxisAngle(Vec3::UnitZ(), whole), Vec3(0, 0, z0));
        spec.gear = GearMeshInfo{.X_AG1 = rigid1 ? X_BG : X_BG_planet,
                                 .X_BG2 = rigid1 ? X_BG_planet : X_BG,
                                 .base_radius1_m = e.base_radius1_m,
                                 .base_radius2_m = e.base_radius2_m,
                                 .teeth1 = pair.gear1().teeth(), .teeth2 = pair.gear2().teeth(),
                                 .internal = internal};
        spec.record_points = go.record_points;
        b.AddExternalForce(std::make_shared<FlexibleContactElement>(std::move(spec)));
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

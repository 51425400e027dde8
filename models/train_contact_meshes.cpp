// The contact branches of BuildTrainModel's mesh stage (models/train_contact.h): per branch a
// ContactElement between the rigid gear surfaces, or a FlexibleContactElement where a gear of the
// branch is a flexible body (its analytic flanks embedded in its FE tooth surface).
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "contact/flexible_contact_element.h"
#include "contact/triangle_geometry.h"
#include "models/flexible_gear_mesh.h"
#include "models/gear_fe_mesh.h"
#include "models/tooth_fault_geometry.h"
#include "models/imported_gear.h"
#include "models/train_assembly.h"

namespace orrery::gears {

using contact::ContactElement;
using contact::ContactSide;
using contact::FlexibleContactElement;
using contact::FlexibleContactElementSpec;
using contact::FlexibleContactSurface;
using contact::FlexibleContactSurfaceSpec;

namespace {

constexpr double kPi = std::numbers::pi;

// (gear 1, gear 2) of a mesh: the external central gear or the planet first.
std::pair<int, int> PairGears(const TrainMesh& m) {
  if (m.kind == MeshKind::kInternal) return {m.gear_b, m.gear_a};
  return {m.gear_a, m.gear_b};
}

// "flexible planet 'S.planet1': " or "flexible gear 'S.sun': ".
std::string FlexibleWhat(const TrainAssembly& a, int gear, const std::string& body) {
  return std::string(a.train.gears[gear].planet_set >= 0 ? "flexible planet '" : "flexible gear '") + body + "': ";
}

// The FE triangles of a reduced gear's tooth node sets (all of them: the surface must be whole;
// a broken tooth's fracture surface instead of its lost tip), the sets, and the lowest z of their
// nodes in B; for a reduced body without tooth node sets (a part from a mesh file, `orrery
// reduce planet.stl`) every exported surface triangle, no sets.
struct ToothFaces {
  struct Tri {
    Vec3 a, b, c, centre;
    double radius;
  };
  std::vector<std::string> sets;
  std::vector<Tri> tris;
  double z0 = 1e300;
};

ToothFaces ReducedToothFaces(const std::string& what, const FlexibleBodyModes& m, int z) {
  ToothFaces f;
  std::vector<char> allowed(m.nodes.size(), 0);
  if (!m.node_sets.count("ROOT") && !m.node_sets.count(ToothSetName(0, "FLANK_PLUS"))) {
    // A part from a mesh file (no tooth node sets): its whole exported surface
    for (const auto& t : m.surface_triangles)
      for (int i : t) {
        allowed[i] = 1;
        f.z0 = std::min(f.z0, m.nodes[i].position.z());
      }
  } else {
    for (int k = 0; k < z; ++k) {
      // A tooth broken across the whole face has a fracture surface instead of its tip
      // (models/gear_fe_mesh.h, faults)
      const bool broken = m.node_sets.count(ToothSetName(k, "FRACTURE")) > 0;
      for (const char* part : {"FLANK_PLUS", "FLANK_MINUS", "FILLET_PLUS", "FILLET_MINUS", "TIP", "FRACTURE"}) {
        const std::string set = ToothSetName(k, part);
        if (std::string(part) == "FRACTURE" ? broken : !(broken && std::string(part) == "TIP" && !m.node_sets.count(set)))
          f.sets.push_back(set);
      }
    }
    f.sets.push_back("ROOT");
  }
  for (const std::string& set : f.sets)
    if (!m.node_sets.count(set))
      FailTrain(what + "its reduced body has no node set '" + set + "' (a gear of " + std::to_string(z) +
                " teeth from the gear mesher, reduced with its surface nodes exported, has them)");
  if (m.node_sets.count(ToothSetName(z, "TIP")))
    FailTrain(what + "its reduced body has more teeth than the train's gear (" + std::to_string(z) +
              ")");
  for (const std::string& set : f.sets)
    for (int i : m.node_sets.at(set)) {
      allowed[i] = 1;
      f.z0 = std::min(f.z0, m.nodes[i].position.z());
    }
  for (const auto& t : m.surface_triangles) {
    if (!allowed[t[0]] || !allowed[t[1]] || !allowed[t[2]]) continue;
    ToothFaces::Tri tr{m.nodes[t[0]].position, m.nodes[t[1]].position, m.nodes[t[2]].position, Vec3::Zero(), 0};
    tr.centre = (tr.a + tr.b + tr.c) / 3;
    tr.radius = std::max({(tr.a - tr.centre).norm(), (tr.b - tr.centre).norm(), (tr.c - tr.centre).norm()});
    f.tris.push_back(tr);
  }
  if (f.tris.empty()) FailTrain(what + "its reduced body has no surface triangles on the tooth node sets");
  return f;
}

// Tooth t's analytic outline placed by X_BG, keeping the triangles whose vertices lie on the FE
// faces; an involute or tip vertex off them is an error.
TriangleMesh EmbeddedTooth(const std::string& what, const Gear& gear, int t, const ToothFaces& faces,
                           const Transform& X_BG, const TrainContactOptions& c,
                           const std::vector<ToothFaultSpec>& faults) {
  // A spall's floor lies its depth below the FE flank it is embedded in.
  double tol = c.flexible.embed_tolerance_m;
  bool reshaped = false;
  for (const ToothFaultSpec& f : faults) {
    if (f.tooth != t || f.kind == ToothFaultSpec::Kind::kRootCrack) continue;
    reshaped = true;
    if (f.kind == ToothFaultSpec::Kind::kSpall) tol += f.depth_m;
  }
  auto distance = [&](const Vec3& v) {
    double best = 1e300;
    for (const ToothFaces::Tri& tr : faces.tris) {
      if ((v - tr.centre).norm() - tr.radius > std::min(best, tol)) continue;
      best = std::min(best, (contact::ClosestPointOnTriangle(v, tr.a, tr.b, tr.c).point - v).norm());
    }
    return best;
  };
  const ProfileResolution res{.root = c.gear.root_intervals, .fillet = c.gear.fillet_intervals,
                              .involute = c.gear.involute_intervals, .tip = c.gear.tip_intervals,
                              .fillet_max_sag_m = c.gear.fillet_max_sag_m};
  const TriangleMesh full = reshaped ? MakeFaultyToothSurfaceMesh(gear, t, res, c.flexible.face_intervals, faults)
                                     : MakeToothSurfaceMesh(gear, t, res, c.flexible.face_intervals);
  const int nv = static_cast<int>(full.vertices.size());
  std::vector<char> on(nv);
  for (int v = 0; v < nv; ++v) {
    const double d = distance(X_BG * full.vertices[v]);
    on[v] = d <= tol;
    if (!on[v] && std::hypot(full.vertices[v].x(), full.vertices[v].y()) > gear.form_radius_m() + 1e-9)
      FailTrain(what + "tooth " + std::to_string(t) + ": a flank or tip point lies " + std::to_string(d) +
                " m from the FE surface (embed tolerance " + std::to_string(tol) +
                " m): does the reduce input's gear match the train's?");
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
  return part;
}

// The contact surface of a flexible gear (train_contact.h): its analytic tooth outlines in the
// gear frame, which is B, shifted by the FE teeth's lowest z, embedded in the FE surface of its
// tooth node sets; *z0 receives that z.
std::shared_ptr<const FlexibleContactSurface> FlexibleGearSurface(
    const std::string& what, const Gear& gear, const std::shared_ptr<const FlexibleBodyModes>& modes,
    const std::vector<int>& missing, const std::vector<ToothFaultSpec>& faults,
    const TrainContactOptions& c, double* z0) {
  const ToothFaces faces = ReducedToothFaces(what, *modes, gear.teeth());
  *z0 = faces.z0;
  const Transform X_BG(Mat3::Identity(), Vec3(0, 0, faces.z0));
  std::vector<TriangleMesh> parts;
  std::vector<double> angles;  // tooth t about 2 pi t / z in the gear frame (the ring zone)
  for (int t = 0; t < gear.teeth(); ++t) {
    if (std::find(missing.begin(), missing.end(), t) != missing.end()) continue;
    TriangleMesh part = EmbeddedTooth(what, gear, t, faces, X_BG, c, faults);
    if (part.triangles.empty()) continue;
    parts.push_back(std::move(part));
    angles.push_back(2 * kPi * t / gear.teeth());
  }
  if (parts.empty()) FailTrain(what + "no tooth left");
  const FlexibleContactSurfaceSpec spec{
      .node_sets = faces.sets,
      .gap_margin_m = c.gear.margin_m,
      .deformation_allowance_m = c.flexible.deformation_allowance_m,
      .slack_m = c.gear.slack_m,
      .part_ring = contact::MeasurePartRing(parts, X_BG, std::move(angles)),
      .smooth_normals = c.gear.smooth_normals};
  try {
    return std::make_shared<const FlexibleContactSurface>(modes, parts, spec, c.flexible.embed_tolerance_m);
  } catch (const std::invalid_argument& e) {
    FailTrain(what + e.what());
  }
}

// Teeth of train gear g removed on branch `branch` (missing_teeth).
std::vector<int> MissingTeeth(const TrainAssembly& a, int g, int branch) {
  std::vector<int> teeth;
  for (const auto& mt : a.o.contact.missing_teeth)
    if (mt.gear == a.train.gears[g].name && (a.train.gears[g].planet_set < 0 || mt.branch == branch))
      teeth.insert(teeth.end(), mt.teeth.begin(), mt.teeth.end());
  return teeth;
}

// Gear frames in the body frames (train_contact.h, "Gear frames and tooth phasing").
void PlaceGearFrames(const TrainAssembly& a, int g1, int g2, int branch, TrainContactMesh* e) {
  e->rotation1_rad = GearFrameRotation(a.train, g1, branch);
  e->rotation2_rad = GearFrameRotation(a.train, g2, branch);
}

// The faults of gear g on a branch in the gear frame that branch's surface uses: a ring's frame
// turns by whole pitches m_i from branch to branch (equal spacing), so physical tooth k (branch
// 0's frame, train_dynamics.h "Tooth faults") is tooth k - m_i there.
std::vector<ToothFaultSpec> BranchFaults(const TrainAssembly& a, int g, int branch) {
  std::vector<ToothFaultSpec> faults = GearFaults(a, g, branch);
  const TrainGear& gear = a.train.gears[g];
  if (faults.empty() || !gear.internal || branch == 0) return faults;
  const double pitch = 2 * kPi / gear.teeth;
  const double turns = (GearFrameRotation(a.train, g, branch) - GearFrameRotation(a.train, g, 0)) / pitch;
  if (std::abs(turns - std::round(turns)) > 1e-6)
    FailTrain("tooth fault on '" + gear.name + "': a ring fault with unequally spaced planets (each ring-planet "
              "contact carries its own ring surface) is not supported");
  const int m = static_cast<int>(std::lround(turns));
  for (ToothFaultSpec& f : faults) f.tooth = ((f.tooth - m) % gear.teeth + gear.teeth) % gear.teeth;
  return faults;
}

// The tooth parts of an imported planet (train_dynamics.h, "Imported gears"), split once per body
// against the train's planet gear; null for a generated gear.
std::shared_ptr<const std::vector<TriangleMesh>> ImportedTeeth(TrainAssembly& a, int gear,
                                                               int branch, const Gear& geometry) {
  const std::string body = a.GearBodyName(gear, branch);
  const TrainImportedGear* imported = a.Imported(body);
  if (!imported) return nullptr;
  auto [it, made] = a.imported_teeth.try_emplace(body);
  if (!made) return it->second;
  try {
    it->second = std::make_shared<const std::vector<TriangleMesh>>(
        SplitImportedGearTeeth(imported->surface, geometry, imported->source));
  } catch (const std::invalid_argument& e) {
    FailTrain("imported gear '" + body + "': " + e.what());
  }
  return it->second;
}

// The surface of a flexible gear, made once per body (its branches share it): its body frame is
// its gear frame (FE tooth k is gear-frame tooth k), so its joint starts at the gear frame's
// rotation (a planet's delta, train_contact.h).
std::pair<std::shared_ptr<const FlexibleContactSurface>, double> FlexibleSurfaceOf(
    TrainAssembly& a, int gear, int branch, const Gear& geometry, double rotation, double* delta) {
  const std::string body = a.GearBodyName(gear, branch);
  *delta = rotation;
  auto [it, made] = a.flexible_surfaces.try_emplace(body);
  if (!made) return it->second;
  double z0 = 0;
  const std::vector<ToothFaultSpec> faults = BranchFaults(a, gear, branch);
  try {
    ValidateToothFaults(geometry, faults);
  } catch (const std::invalid_argument& e) {
    FailTrain("tooth fault on '" + a.train.gears[gear].name + "': " + e.what());
  }
  it->second.first = FlexibleGearSurface(FlexibleWhat(a, gear, body), geometry, a.Flexible(body)->modes,
                                         MissingTeeth(a, gear, branch), faults, a.o.contact, &z0);
  it->second.second = z0;
  if (*delta == 0) return it->second;
  const JointIndex j = a.GearJoint(gear, branch);
  const JointSpec& js = a.b.draft().joints[j].spec;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(JointNq(js.type));
  if (js.type == JointType::kRevolute) {
    q(0) = *delta;
  } else if (js.type == JointType::kPlanar) {
    q(2) = *delta;
  } else if (js.type == JointType::kFree) {
    q(3) = std::cos(*delta / 2), q(6) = std::sin(*delta / 2);
  } else {
    FailTrain("flexible body '" + body + "': joint type " + JointTypeName(js.type) + " not supported");
  }
  a.b.SetJointPosition(j, q);
  return it->second;
}

// A rigid partner's share of the penalty (its own tooth compliance: bore or ring rim).
double PartnerRim(const TrainAssembly& a, int gear, const Gear& geometry) {
  const TrainGear& rg = a.train.gears[gear];
  const TrainMemberOverride& ov = a.Override(TrainGearOwnerName(a.train, gear));
  const double r_ref = geometry.reference_radius_m();
  return rg.internal ? ov.outer_radius_m.value_or(r_ref + a.o.ring_rim_modules * rg.tooth_form.normal_module_m)
                     : ov.bore_radius_m.value_or(a.o.bore_to_pitch_ratio * r_ref);
}

// A branch with a flexible gear: FlexibleContactElement (train_contact.h, "Flexible gears").
void AddFlexibleContact(TrainAssembly& a, const TrainMesh& m, int g1, int g2, int branch, const GearPair& pair,
                        const GearContactOptions& go, TrainContactMesh& e) {
  const bool flex1 = a.Flexible(a.GearBodyName(g1, branch)) != nullptr;
  const bool flex2 = a.Flexible(a.GearBodyName(g2, branch)) != nullptr;
  e.flexible_side = (flex1 ? 1 : 0) + (flex2 ? 2 : 0);
  // Each side: its surface and its gear frame in its body.
  std::array<ContactSide, 2> sides;
  std::array<Transform, 2> X_BG;
  double z0 = 0;
  const std::array<int, 2> gear{g1, g2};
  const std::array<bool, 2> flexible{flex1, flex2};
  const std::array<double, 2> rotation{e.rotation1_rad, e.rotation2_rad};
  for (int s = 0; s < 2; ++s) {
    if (!flexible[s]) continue;
    double delta = 0;
    const auto [surface, z] = FlexibleSurfaceOf(a, gear[s], branch, s == 0 ? pair.gear1() : pair.gear2(),
                                                rotation[s], &delta);
    if (a.train.gears[gear[s]].planet_set >= 0) e.planet_initial_angle_rad = delta;
    sides[s] = ContactSide{.body = s == 0 ? e.body1 : e.body2, .flexible = surface};
    X_BG[s] = Transform(AxisAngle(Vec3::UnitZ(), rotation[s] - delta), Vec3(0, 0, z));
    z0 = z;
  }
  FlexiblePairPenalty penalty;
  for (int s = 0; s < 2; ++s) {
    if (flexible[s]) continue;
    // The rigid side: the rigid builder's surface, shifted by the flexible gear's z0.
    const Gear& geometry = s == 0 ? pair.gear1() : pair.gear2();
    X_BG[s] = Transform(AxisAngle(Vec3::UnitZ(), rotation[s]), Vec3(0, 0, z0));
    const auto imported = ImportedTeeth(a, gear[s], branch, geometry);
    sides[s] = ContactSide{.body = s == 0 ? e.body1 : e.body2,
                           .rigid = MakeGearContactSurface(geometry, go, MissingTeeth(a, gear[s], branch), X_BG[s],
                                                           s == 0 ? go.faults1 : go.faults2,
                                                           CrackStiffnessScales(pair, s + 1, go), imported.get())};
    (s == 0 ? penalty.rigid1 : penalty.rigid2) = true;
    (s == 0 ? penalty.rim_radius1_m : penalty.rim_radius2_m) = PartnerRim(a, gear[s], geometry);
  }
  try {
    e.calibration = CalibrateFlexibleGearContact(pair, a.o.gear_material, go.calibration_load_n, penalty);
  } catch (const std::invalid_argument& err) {
    FailTrain("mesh '" + e.name + "': " + err.what());
  }
  FlexibleContactElementSpec spec{
      .name = e.name, .a = sides[0], .b = sides[1],
      .law = {.stiffness_per_area = e.calibration.stiffness_per_area,
              .hunt_crossley_s_per_m = go.hunt_crossley_s_per_m,
              .friction_coefficient = go.friction_coefficient,
              .slip_velocity_m_s = go.slip_velocity_m_s}};
  spec.monitor = std::make_shared<const GearMeshMonitor>(
      GearMeshInfo{.X_AG1 = X_BG[0], .X_BG2 = X_BG[1], .base_radius1_m = e.base_radius1_m,
                   .base_radius2_m = e.base_radius2_m, .teeth1 = pair.gear1().teeth(),
                   .teeth2 = pair.gear2().teeth(), .internal = m.kind == MeshKind::kInternal});
  spec.record_points = go.record_points;
  spec.penetration_limit = GearPenetrationLimit(pair);
  a.b.AddExternalForce(std::make_shared<FlexibleContactElement>(std::move(spec)));
}

}  // namespace

void AddContactMesh(TrainAssembly& a, int mesh, int branch, const GearPair& unthinned) {
  const TrainMesh& m = a.train.meshes[mesh];
  const auto [g1, g2] = PairGears(m);
  const bool internal = m.kind == MeshKind::kInternal;
  TrainContactMesh e;
  e.name = m.name + "#" + std::to_string(branch + 1);
  e.train_mesh = mesh;
  e.branch = branch;
  e.body1 = a.GearBody(g1, branch);
  e.body2 = a.GearBody(g2, branch);
  PlaceGearFrames(a, g1, g2, branch, &e);
  GearContactOptions go = a.o.contact.gear;
  go.X_B1G1 = Transform(AxisAngle(Vec3::UnitZ(), e.rotation1_rad), Vec3::Zero());
  go.X_B2G2 = Transform(AxisAngle(Vec3::UnitZ(), e.rotation2_rad), Vec3::Zero());
  go.missing_teeth1 = MissingTeeth(a, g1, branch);
  go.missing_teeth2 = MissingTeeth(a, g2, branch);
  // Tooth faults (train_dynamics.h, "Tooth faults"): geometry, and a crack's stiffness ratio from
  // the gears' blanks and material.
  go.faults1 = BranchFaults(a, g1, branch);
  go.faults2 = BranchFaults(a, g2, branch);
  go.rim_radius1_m = PartnerRim(a, g1, unthinned.gear1());
  go.rim_radius2_m = PartnerRim(a, g2, unthinned.gear2());
  go.material = a.o.gear_material;
  go.normal_backlash_m = a.o.contact.normal_backlash_m;
  go.backlash_share1 = internal ? 0.0 : 1.0;  // the central gear takes the thinning
  const GearPair pair = WithNormalBacklash(unthinned, go.normal_backlash_m, go.backlash_share1);
  e.base_radius1_m = pair.gear1().base_radius_m();
  e.base_radius2_m = pair.gear2().base_radius_m();
  e.base_helix_angle_rad = pair.gear1().base_helix_angle_rad();
  e.transverse_pressure_angle_rad = pair.working_pressure_angle_rad();
  e.external_force = static_cast<int>(a.b.draft().external_forces.size());
  try {
    if (a.Flexible(a.GearBodyName(g1, branch)) || a.Flexible(a.GearBodyName(g2, branch))) {
      AddFlexibleContact(a, m, g1, g2, branch, pair, go, e);
    } else {
      go.imported_teeth1 = ImportedTeeth(a, g1, branch, pair.gear1());
      go.imported_teeth2 = ImportedTeeth(a, g2, branch, pair.gear2());
      e.calibration = CalibrateGearContact(pair, go);
      go.normal_backlash_m = 0;  // already in `pair`
      a.b.AddExternalForce(std::make_shared<ContactElement>(MakeGearContactSpec(e.name, pair, e.body1, e.body2, go)));
    }
  } catch (const std::invalid_argument& err) {
    const std::string what = err.what();
    if (what.rfind("train model:", 0) == 0) throw;
    FailTrain("mesh '" + e.name + "': " + what);
  }
  a.tm.branches.push_back({.train_mesh = mesh, .branch = branch, .model = MeshModel::kContact,
                           .index = static_cast<int>(a.tm.contacts.size())});
  a.tm.contacts.push_back(e);
}

}  // namespace orrery::gears

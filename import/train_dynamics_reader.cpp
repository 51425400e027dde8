// The `dynamics:` map of a gear_train into TrainModelOptions (docs/scene_format.md, "dynamics"):
// DOF set, mesh models (per mesh and per branch), lumped mesh stiffness, member and mesh
// overrides, tooth contact, flexible bodies (their reduced-body files by path: gear_scene.cpp
// loads them), imported planets (their mesh files read here). Names are checked against the names
// the train's stages give.
#include <algorithm>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "import/gear_train_reader.h"
#include "import/tooth_fault_reader.h"
#include "import/length_unit.h"
#include "import/solid_mesh.h"
#include "import/unit_keys.h"

namespace orrery::scene_reader {
namespace {

using gears::TrainModelOptions;

gears::TrainMemberOverride ReadMemberOverride(const Context& ctx, const Item& item) {
  std::vector<std::string> allowed{"mass", "inertia", "transverse_inertia", "bearing_stiffness",
                                   "axial_bearing_stiffness", "tilt_bearing_stiffness",
                                   "bearing_damping", "ground_torsional_stiffness", "brake_stiffness",
                                   "profile_shift", "addendum_coefficient"};
  for (const auto& group : {RadiusKeys("base"), RadiusKeys("bore"), RadiusKeys("outer"), LengthMm("face_width")})
    Append(allowed, Names(group));
  const MapReader m(ctx, item, allowed);
  gears::TrainMemberOverride o;
  auto positive = [&](const std::vector<std::pair<std::string, double>>& keys, std::optional<double>& to) {
    if (FindOneOf(m, keys)) to = OptScaled(m, keys, 0, true);
  };
  auto non_negative = [&](const std::vector<std::pair<std::string, double>>& keys, std::optional<double>& to) {
    if (FindOneOf(m, keys)) to = OptScaled(m, keys, 0, false);
  };
  positive(Plain("mass"), o.mass_kg);
  positive(Plain("inertia"), o.polar_inertia_kg_m2);
  positive(Plain("transverse_inertia"), o.transverse_inertia_kg_m2);
  positive(RadiusKeys("base"), o.base_radius_m);
  positive(LengthMm("face_width"), o.face_width_m);
  non_negative(RadiusKeys("bore"), o.bore_radius_m);
  positive(RadiusKeys("outer"), o.outer_radius_m);
  non_negative(Plain("bearing_stiffness"), o.radial_bearing_stiffness_n_per_m);
  non_negative(Plain("axial_bearing_stiffness"), o.axial_bearing_stiffness_n_per_m);
  non_negative(Plain("tilt_bearing_stiffness"), o.tilt_bearing_stiffness_n_m_per_rad);
  non_negative(Plain("bearing_damping"), o.bearing_damping_n_s_per_m);
  non_negative(Plain("ground_torsional_stiffness"), o.ground_torsional_stiffness_n_m_per_rad);
  positive(Plain("brake_stiffness"), o.brake_stiffness_n_m_per_rad);
  // Gears: stiffness geometry (ISO 21771 sign, any real; the pair's checks judge the value)
  if (m.Has("profile_shift")) o.profile_shift = m.Number("profile_shift");
  non_negative(Plain("addendum_coefficient"), o.addendum_coefficient);
  return o;
}

gears::MeshModel ToMeshModel(const std::string& name) {
  return name == "kinematic" ? gears::MeshModel::kKinematic
         : name == "contact" ? gears::MeshModel::kContact
                             : gears::MeshModel::kLumped;
}

std::vector<double> Scaled(const Context& ctx, const std::pair<Item, double>& found) {
  std::vector<double> v = ToNumbers(ctx, found.first, -1);
  for (double& x : v) x *= found.second;
  return v;
}

// A train mesh's entry: its model and the lumped overrides (all branches).
void ReadMeshEntry(const Context& ctx, const Item& item, const std::string& name, TrainModelOptions& options) {
  std::vector<std::string> allowed{"model", "stiffness", "stiffness_table", "table_cycles", "damping_ratio",
                                   "contact", "phase_cycles"};
  const auto backlash = std::vector<std::pair<std::string, double>>{{"backlash", 1.0}, {"backlash_um", 1e-6}};
  const auto ste = std::vector<std::pair<std::string, double>>{{"ste_amplitudes", 1.0}, {"ste_amplitudes_um", 1e-6}};
  for (const auto& group : {Angle("working_pressure_angle"), Angle("ste_phases"), backlash, ste})
    Append(allowed, Names(group));
  const MapReader m(ctx, item, allowed);
  if (m.Has("model")) options.mesh_models[name] = ToMeshModel(m.Choice("model", {"kinematic", "lumped", "contact"}));
  gears::TrainMeshOverride o;
  if (m.Has("stiffness")) o.stiffness_n_per_m = NeedScaled(m, Plain("stiffness"));
  if (const auto t = m.Find("stiffness_table")) {
    o.stiffness_table_n_per_m = ToNumbers(ctx, *t, -1);
    if (o.stiffness_table_n_per_m->empty()) ctx.Fail(*t, "needs at least one value");
  }
  if (m.Has("table_cycles")) {
    o.table_cycles = m.Int("table_cycles", 1);
    if (*o.table_cycles < 1) ctx.Fail(m.Need("table_cycles"), "must be >= 1");
  }
  if (const auto a = ScaledOf(m, Angle("working_pressure_angle"))) {
    if (!(*a > 0 && *a < std::numbers::pi / 2))
      ctx.Fail(FindOneOf(m, Angle("working_pressure_angle"))->first, "must be in (0, 90) degrees");
    o.working_pressure_angle_rad = *a;
  }
  if (m.Has("damping_ratio")) o.damping_ratio = NeedScaled(m, Plain("damping_ratio"), true);
  if (FindOneOf(m, backlash)) o.backlash_m = NeedScaled(m, backlash, true);
  if (const auto a = FindOneOf(m, ste)) o.ste_amplitudes_m = Scaled(ctx, *a);
  if (const auto p = FindOneOf(m, Angle("ste_phases"))) o.ste_phases_rad = Scaled(ctx, *p);
  if (m.Has("contact"))
    o.contact = m.Choice("contact", {"drive", "coast"}) == "drive" ? GearMeshSpec::Contact::kLinearDrive
                                                                   : GearMeshSpec::Contact::kLinearCoast;
  if (const auto p = m.Find("phase_cycles")) o.phase_cycles = ToNumbers(ctx, *p, -1);
  const bool only_model = m.Has("model") && item.node.size() == 1;
  if (!only_model) options.meshes[name] = o;
}

// Keys of `name: {...}` maps (member and mesh overrides, flexible bodies), checked against the
// train's names.
std::vector<std::pair<std::string, Item>> NamedEntries(const Context& ctx, const Item& item,
                                                       const std::vector<std::string>& known,
                                                       const std::string& what) {
  std::vector<std::pair<std::string, Item>> entries;
  if (item.node.IsNull()) return entries;
  if (!item.node.IsMap()) ctx.Fail(item, "expected a map of " + what + " names, got " + Describe(item.node));
  for (auto it = item.node.begin(); it != item.node.end(); ++it) {
    const std::string name = it->first.IsScalar() ? it->first.Scalar() : "?";
    const Item entry{it->second, item.path + "[" + name + "]", it->first.Mark()};
    if (std::find(known.begin(), known.end(), name) == known.end())
      ctx.Fail(entry, "no " + what + " named '" + name + "'" + SuggestOrList(name, known, what + "s"));
    for (const auto& [seen, seen_item] : entries)
      if (seen == name) ctx.Fail(entry, "duplicate " + what + " '" + name + "'");
    entries.emplace_back(name, entry);
  }
  return entries;
}

// A branch entry ("S.sun-planet#2"): its model only.
void ReadBranchEntry(const Context& ctx, const Item& item, const std::string& name, TrainModelOptions& o) {
  const MapReader m(ctx, item, {"model"}, {{"stiffness", "a branch ('" + name + "') takes only 'model'; "
                                                         "lumped parameters are per mesh"}});
  o.mesh_models[name] = ToMeshModel(m.Choice("model", {"kinematic", "lumped", "contact"}));
}

// A flexible body: its reduced-body file (made by `orrery reduce`, checked against the reduce
// input when one is named) and its options; the file is read when the scene is assembled.
void ReadFlexibleBody(const Context& ctx, const Item& item, const std::string& body, GearTrainRead& r) {
  const MapReader m(ctx, item, {"reduced_body", "reduce_input", "mesh_interface", "damping_ratio",
                                "rayleigh_alpha", "rayleigh_beta", "geometric_stiffening", "frozen",
                                "record_surface", "record_node_sets"});
  const std::filesystem::path dir = std::filesystem::path(ctx.file()).parent_path();
  auto resolve = [&](const std::string& p) {
    const std::filesystem::path path(p);
    return (path.is_absolute() ? path : dir / path).lexically_normal().string();
  };
  FlexibleBodyFile f{.body = body, .item = item};
  f.reduced_body_item = m.Need("reduced_body");
  f.reduced_body = resolve(m.String("reduced_body"));
  if (const auto in = m.Find("reduce_input")) {
    f.reduce_input = resolve(m.String("reduce_input"));
    f.reduce_input_item = in;
  }
  f.mesh_interface_item = m.Find("mesh_interface");
  f.geometric_stiffening_item = m.Find("geometric_stiffening");
  f.record_node_sets_item = m.Find("record_node_sets");
  gears::TrainFlexibleBody& b = r.description.options.flexible_bodies[body];
  b.mesh_interface = m.Has("mesh_interface") ? m.String("mesh_interface") : "";
  if (m.Has("damping_ratio")) b.options.damping_ratios = {OptScaled(m, Plain("damping_ratio"), 0)};
  b.options.rayleigh_alpha = OptScaled(m, Plain("rayleigh_alpha"), 0);
  b.options.rayleigh_beta = OptScaled(m, Plain("rayleigh_beta"), 0);
  b.options.geometric_stiffening = m.Bool("geometric_stiffening", false);
  b.options.frozen = m.Bool("frozen", false);
  b.options.record_surface = m.Bool("record_surface", false);
  if (const auto sets = m.Find("record_node_sets"))
    for (const Item& set : ListItems(ctx, sets)) b.options.record_node_sets.push_back(ToString(ctx, set));
  r.flexible_files.push_back(f);
}

// An imported planet (models/train_dynamics.h, "Imported gears"): its mesh file, read now
// (mass properties, surface), relative to the scene; unit required but for STEP/IGES; density
// default the train's; a STEP/IGES file's largest triangle (mesh_size[_mm], default gmsh's 48
// elements per 2 pi of curvature).
void ReadImportedGearEntry(const Context& ctx, const Item& item, const std::string& body,
                           TrainModelOptions& o) {
  std::vector<std::string> allowed{"file", "unit", "density"};
  Append(allowed, Names(LengthMm("mesh_size")));
  const MapReader m(ctx, item, allowed);
  const Item file_item = m.Need("file");
  std::filesystem::path file = ToString(ctx, file_item);
  if (file.is_relative()) file = std::filesystem::path(ctx.file()).parent_path() / file;
  SurfaceReadOptions options;
  const bool cad = DetectMeshFileFormat(file) == MeshFileFormat::kCad;
  if (const auto unit = m.Find("unit")) {
    if (cad) ctx.Fail(*unit, "a STEP/IGES file states its own length unit: remove 'unit'");
    const std::string u = ToString(ctx, *unit);
    options.unit = ParseLengthUnit(u);
    if (!options.unit)
      ctx.Fail(*unit, "unknown length unit '" + u + "' (expected " + kLengthUnitChoices + ")");
  } else if (!cad) {
    m.FailMissing("unit", "missing required key 'unit': a mesh file has no unit of its own (" +
                              std::string(kLengthUnitChoices) + ")");
  }
  if (const auto size = FindOneOf(m, LengthMm("mesh_size"))) {
    if (!cad) ctx.Fail(size->first, "only a STEP/IGES file is triangulated on reading; a mesh file keeps its triangles");
    options.cad.max_size_m = OptScaled(m, LengthMm("mesh_size"), 0, true);
  }
  const double density = OptScaled(m, Plain("density"), o.density_kg_m3, true);
  try {
    o.imported_gears[body] = ReadImportedGear(file, options, density);
  } catch (const std::exception& e) {
    ctx.Fail(file_item, "imported gear '" + body + "': " + e.what());
  }
}

// `tooth_contact:` of the contact meshes -> TrainContactOptions (models/train_contact.h): flank
// resolution, penalty calibration, damping, friction, broken teeth and flexible surfaces;
// margins and slack keep the gear-contact defaults.
void ReadToothContact(const Context& ctx, const std::optional<Item>& item, const TrainNames& names,
                      gears::TrainContactOptions& c) {
  if (!item || item->node.IsNull()) return;
  const auto margin = std::vector<std::pair<std::string, double>>{{"margin", 1.0}, {"margin_um", 1e-6}};
  std::vector<std::string> allowed{
      "involute_intervals", "single_pair_stiffness", "calibration_load",
      "hunt_crossley",      "friction_coefficient",  "missing_teeth",
      "flexible",           "record_points",         "smooth_normals"};
  Append(allowed, Names(margin));
  const MapReader m(ctx, *item, allowed,
                    {{"meshes", "choose the meshes with dynamics.mesh_model and dynamics.meshes[NAME].model"}});
  if (m.Has("involute_intervals")) {
    c.gear.involute_intervals = m.Int("involute_intervals", c.gear.involute_intervals);
    if (c.gear.involute_intervals < 4) ctx.Fail(m.Need("involute_intervals"), "must be >= 4");
  }
  c.gear.smooth_normals = m.Bool("smooth_normals", c.gear.smooth_normals);
  if (m.Has("record_points")) {
    c.gear.record_points = m.Int("record_points", 0);
    if (c.gear.record_points < 0 || c.gear.record_points > 1000) ctx.Fail(m.Need("record_points"), "must be in 0..1000");
  }
  if (m.Has("single_pair_stiffness")) c.gear.single_pair_stiffness_n_per_m = NeedScaled(m, Plain("single_pair_stiffness"));
  c.gear.calibration_load_n = OptScaled(m, Plain("calibration_load"), c.gear.calibration_load_n, true);
  // Contact margin: above the largest penetration of the run (a few um per 1000 N of one pair).
  c.gear.margin_m = OptScaled(m, margin, c.gear.margin_m, true);
  c.gear.hunt_crossley_s_per_m = OptScaled(m, Plain("hunt_crossley"), 0);
  c.gear.friction_coefficient = OptScaled(m, Plain("friction_coefficient"), 0);
  if (const auto f = m.Find("flexible")) {
    const auto embed = std::vector<std::pair<std::string, double>>{{"embed_tolerance", 1.0}, {"embed_tolerance_um", 1e-6}};
    const auto allowance = std::vector<std::pair<std::string, double>>{{"deformation_allowance", 1.0},
                                                                       {"deformation_allowance_um", 1e-6}};
    std::vector<std::string> keys{"face_intervals"};
    Append(keys, Names(embed));
    Append(keys, Names(allowance));
    const MapReader fm(ctx, *f, keys);
    if (fm.Has("face_intervals")) {
      c.flexible.face_intervals = fm.Int("face_intervals", c.flexible.face_intervals);
      if (c.flexible.face_intervals < 1) ctx.Fail(fm.Need("face_intervals"), "must be >= 1");
    }
    c.flexible.embed_tolerance_m = OptScaled(fm, embed, c.flexible.embed_tolerance_m, true);
    c.flexible.deformation_allowance_m = OptScaled(fm, allowance, c.flexible.deformation_allowance_m);
  }
  // Broken teeth: [{gear: S.planet, branch: 1, teeth: [0]}] (branch 1-based, planets only).
  for (const Item& it : OneOrMany(ctx, m.Find("missing_teeth"))) {
    const MapReader t(ctx, it, {"gear", "branch", "teeth"});
    gears::TrainContactOptions::MissingTeeth mt;
    mt.gear = t.String("gear");
    if (std::find(names.gears.begin(), names.gears.end(), mt.gear) == names.gears.end())
      ctx.Fail(t.Need("gear"), "no gear named '" + mt.gear + "'" + SuggestOrList(mt.gear, names.gears, "gears"));
    const bool planet = std::find(names.planet_sets.begin(), names.planet_sets.end(), mt.gear) != names.planet_sets.end();
    if (planet) {
      const int n = names.set_planets.at(mt.gear);
      const int branch = t.Int("branch", 1);
      if (branch < 1 || branch > n)
        ctx.Fail(t.Need("branch"), "must be in 1.." + std::to_string(n) + " (the planet of the set)");
      mt.branch = branch - 1;
    } else if (t.Has("branch")) {
      ctx.Fail(t.Need("branch"), "a branch is for planets; '" + mt.gear + "' is a central gear");
    }
    const int z = names.gear_teeth.at(mt.gear);
    for (double x : ToNumbers(ctx, t.Need("teeth"), -1)) {
      if (x != std::floor(x) || x < 0 || x >= z)
        ctx.Fail(t.Need("teeth"), "tooth indices are integers in 0.." + std::to_string(z - 1));
      mt.teeth.push_back(static_cast<int>(x));
    }
    c.missing_teeth.push_back(mt);
  }
}

// `faults:` tooth faults of the train's gears (models/train_dynamics.h, "Tooth faults"): a map or a
// list of maps {gear, branch (planets, 1-based), the fault's keys (import/tooth_fault_reader.h)},
// tooth indices in the gear frame. Checked here: the gear, the branch, the tooth index; against
// the gear's geometry by the assembler (errors at the entry, gear_scene.cpp).
void ReadTrainFaults(const Context& ctx, const std::optional<Item>& item, const TrainNames& names,
                     GearTrainRead& r) {
  for (const Item& it : OneOrMany(ctx, item)) {
    const gears::ToothFaultSpec spec = ReadToothFault(ctx, it, {"gear", "branch"});
    // The keys were checked by ReadToothFault; read gear and branch from the same map.
    std::vector<std::string> keys;
    for (auto k = it.node.begin(); k != it.node.end(); ++k) keys.push_back(k->first.Scalar());
    const MapReader t(ctx, it, keys);
    gears::TrainToothFault f{.gear = t.String("gear"), .branch = 0, .spec = spec};
    if (std::find(names.gears.begin(), names.gears.end(), f.gear) == names.gears.end())
      ctx.Fail(t.Need("gear"), "no gear named '" + f.gear + "'" + SuggestOrList(f.gear, names.gears, "gears"));
    const bool planet = std::find(names.planet_sets.begin(), names.planet_sets.end(), f.gear) != names.planet_sets.end();
    if (planet) {
      const int n = names.set_planets.at(f.gear);
      if (!t.Has("branch"))
        ctx.Fail(it, "a planet's fault needs 'branch' (1.." + std::to_string(n) + ": which planet of the set)");
      const int branch = t.Int("branch", 1);
      if (branch < 1 || branch > n) ctx.Fail(t.Need("branch"), "must be in 1.." + std::to_string(n) + " (the planet of the set)");
      f.branch = branch - 1;
    } else if (t.Has("branch")) {
      ctx.Fail(t.Need("branch"), "a branch is for planets; '" + f.gear + "' is a central gear");
    }
    const int z = names.gear_teeth.at(f.gear);
    if (spec.tooth < 0 || spec.tooth >= z)
      ctx.Fail(t.Need("tooth"), "tooth index " + std::to_string(spec.tooth) + " is not in 0.." + std::to_string(z - 1) +
                                    " ('" + f.gear + "' has " + std::to_string(z) + " teeth)");
    r.description.options.tooth_faults.push_back(f);
    r.sources.dynamics_entries.emplace_back(f.gear, it);
  }
}

// `housing:` {mass, polar_inertia, transverse_inertia, mount_radial_stiffness,
// mount_axial_stiffness, mount_torsional_stiffness, mount_tilt_stiffness, mount_damping_ratio}.
gears::TrainHousing ReadHousing(const MapReader& dynamics, const Item& item) {
  const MapReader m(dynamics.ctx(), item,
                    {"mass", "polar_inertia", "transverse_inertia", "mount_radial_stiffness",
                     "mount_axial_stiffness", "mount_torsional_stiffness", "mount_tilt_stiffness",
                     "mount_damping_ratio"});
  gears::TrainHousing h;
  h.mass_kg = NeedScaled(m, Plain("mass"));
  h.polar_inertia_kg_m2 = NeedScaled(m, Plain("polar_inertia"));
  h.transverse_inertia_kg_m2 = OptScaled(m, Plain("transverse_inertia"), 0, true);
  const bool planar = dynamics.Choice("dofs", {"torsional", "planar", "spatial"}, "torsional") != "torsional";
  const bool spatial = dynamics.Choice("dofs", {"torsional", "planar", "spatial"}, "torsional") == "spatial";
  h.mount_torsional_stiffness_n_m_per_rad = NeedScaled(m, Plain("mount_torsional_stiffness"));
  if (planar) h.mount_radial_stiffness_n_per_m = NeedScaled(m, Plain("mount_radial_stiffness"));
  if (spatial) {
    h.mount_axial_stiffness_n_per_m = NeedScaled(m, Plain("mount_axial_stiffness"));
    h.mount_tilt_stiffness_n_m_per_rad = NeedScaled(m, Plain("mount_tilt_stiffness"));
  }
  for (const char* key : {"mount_radial_stiffness", "mount_axial_stiffness", "mount_tilt_stiffness",
                          "transverse_inertia"})
    if (m.Has(key) && ((std::string(key) == "mount_radial_stiffness" && !planar) ||
                       (std::string(key) != "mount_radial_stiffness" && !spatial)))
      m.ctx().Fail(m.Need(key), std::string("not used with dofs: ") +
                                    dynamics.Choice("dofs", {"torsional", "planar", "spatial"}, "torsional"));
  h.mount_damping_ratio = OptScaled(m, Plain("mount_damping_ratio"), 0);
  return h;
}

// Scalar options of the dynamics map.
void ReadDynamicsScalars(const MapReader& m, TrainModelOptions& o) {
  o.mesh_damping_ratio = OptScaled(m, Plain("mesh_damping_ratio"), 0);
  o.mesh_phasing = m.Bool("mesh_phasing", true);
  o.port_loads = m.Bool("port_loads", true);
  o.unloaded_mesh_stiffness_factor = OptScaled(m, Plain("unloaded_mesh_stiffness_factor"), o.unloaded_mesh_stiffness_factor, true);
  o.mesh_stiffness_per_face_width_n_per_m2 = OptScaled(m, Plain("mesh_stiffness_per_face_width"), o.mesh_stiffness_per_face_width_n_per_m2, true);
  o.density_kg_m3 = OptScaled(m, Plain("density"), o.density_kg_m3, true);
  o.bore_to_pitch_ratio = OptScaled(m, Plain("bore_to_pitch_ratio"), o.bore_to_pitch_ratio);
  o.ring_rim_modules = OptScaled(m, Plain("ring_rim_modules"), o.ring_rim_modules, true);
  o.stage_spacing_m = OptScaled(m, LengthMm("stage_spacing"), 0);
  o.connection_stiffness_n_m_per_rad = OptScaled(m, Plain("connection_stiffness"), o.connection_stiffness_n_m_per_rad, true);
  o.clutch_stiffness_n_m_per_rad = OptScaled(m, Plain("clutch_stiffness"), o.clutch_stiffness_n_m_per_rad, true);
  o.brake_stiffness_n_m_per_rad = OptScaled(m, Plain("brake_stiffness"), o.brake_stiffness_n_m_per_rad, true);
  o.radial_bearing_stiffness_n_per_m = OptScaled(m, Plain("bearing_stiffness"), o.radial_bearing_stiffness_n_per_m);
  o.axial_bearing_stiffness_n_per_m = OptScaled(m, Plain("axial_bearing_stiffness"), o.axial_bearing_stiffness_n_per_m);
  o.tilt_bearing_stiffness_n_m_per_rad = OptScaled(m, Plain("tilt_bearing_stiffness"), o.tilt_bearing_stiffness_n_m_per_rad);
  o.bearing_damping_n_s_per_m = OptScaled(m, Plain("bearing_damping"), 0);
  if (const auto p = m.Find("stage_phase_cycles")) o.stage_phase_cycles = ToNumbers(m.ctx(), *p, -1);
}

// Mean mesh stiffness: c_gamma b (default), one value for all meshes, ISO 6336 or TVMS.
void ReadMeshStiffness(const MapReader& m, GearTrainRead& r) {
  TrainModelOptions& o = r.description.options;
  const auto k = m.Find("mesh_stiffness");
  if (!k) return;
  r.sources.mesh_stiffness = k;
  if (k->node.IsScalar() && IsPlainScalar(k->node)) {
    double x = 0;
    if (YAML::convert<double>::decode(k->node, x)) {
      if (!(x > 0)) m.ctx().Fail(*k, "must be > 0 (N/m), got " + Num(x));
      o.mesh_stiffness_n_per_m = x;
      r.mesh_stiffness = "value";
      return;
    }
  }
  r.mesh_stiffness = m.Choice("mesh_stiffness", {"c_gamma", "iso6336", "tvms", "tvms_mean"});
  o.mesh_stiffness_source = r.mesh_stiffness == "iso6336"     ? gears::MeshStiffnessSource::kIso6336
                            : r.mesh_stiffness == "tvms"      ? gears::MeshStiffnessSource::kTvms
                            : r.mesh_stiffness == "tvms_mean" ? gears::MeshStiffnessSource::kTvmsMean
                                                              : gears::MeshStiffnessSource::kGiven;
}

// Mesh model and backlash: the default mesh model; lumped meshes take `backlash` with
// `contact: two_sided`, contact meshes as their normal backlash.
void ReadMeshModel(const MapReader& m, TrainModelOptions& o) {
  const auto backlash = std::vector<std::pair<std::string, double>>{{"backlash", 1.0}, {"backlash_um", 1e-6}};
  o.two_sided_contact = m.Choice("contact", {"linear", "two_sided"}, "linear") == "two_sided";
  o.mesh_model = ToMeshModel(m.Choice("mesh_model", {"kinematic", "lumped", "contact"}, "lumped"));
  const double b = OptScaled(m, backlash, 0);
  o.contact.normal_backlash_m = b;
  o.backlash_m = b;
  const bool any_contact = o.mesh_model == gears::MeshModel::kContact ||
                           std::any_of(o.mesh_models.begin(), o.mesh_models.end(),
                                       [](const auto& e) { return e.second == gears::MeshModel::kContact; });
  if (const auto tc = m.Find("tooth_contact"); tc && !any_contact)
    m.ctx().Fail(*tc, "tooth_contact needs a contact mesh ('mesh_model: contact' or a mesh's 'model: contact')");
  const bool any_lumped = o.mesh_model == gears::MeshModel::kLumped ||
                          std::any_of(o.mesh_models.begin(), o.mesh_models.end(),
                                      [](const auto& e) { return e.second == gears::MeshModel::kLumped; });
  if (FindOneOf(m, backlash) && any_lumped && !o.two_sided_contact && !any_contact)
    m.ctx().Fail(FindOneOf(m, backlash)->first, "backlash needs 'contact: two_sided' (or contact meshes)");
}

}  // namespace

void ReadTrainDynamics(const Context& ctx, const std::optional<Item>& item, GearTrainRead& r) {
  if (!item) return;
  TrainModelOptions& o = r.description.options;
  const TrainNames names = NamesOf(r.description.train);
  std::vector<std::string> allowed{"dofs", "contact", "mesh_damping_ratio", "mesh_stiffness",
                                   "mesh_stiffness_per_face_width", "mesh_phasing",
                                   "unloaded_mesh_stiffness_factor", "density", "bore_to_pitch_ratio",
                                   "ring_rim_modules", "connection_stiffness", "clutch_stiffness",
                                   "brake_stiffness", "bearing_stiffness", "axial_bearing_stiffness",
                                   "tilt_bearing_stiffness", "bearing_damping", "port_loads",
                                   "stage_phase_cycles", "members", "meshes", "backlash", "backlash_um",
                                   "flexible_bodies", "mesh_model", "tooth_contact", "housing", "faults",
                                   "imported_gears"};
  Append(allowed, Names(LengthMm("stage_spacing")));
  const MapReader m(ctx, *item, allowed,
                    {{"damping_ratio", "write 'mesh_damping_ratio'"},
                     {"flexible_planets", "write 'flexible_bodies' (planets \"S.planet1\" and central gears \"S.sun\")"}});
  const std::string dofs = m.Choice("dofs", {"torsional", "planar", "spatial"}, "torsional");
  o.dofs = dofs == "torsional" ? gears::TrainDofs::kTorsional
           : dofs == "planar"  ? gears::TrainDofs::kPlanar
                               : gears::TrainDofs::kSpatial;
  // Overrides by member / planet-set name, by mesh or branch name, flexible bodies by body name.
  if (const auto members = m.Find("members")) {
    std::vector<std::string> known = names.members;
    Append(known, names.planet_sets);
    for (const auto& [name, entry] : NamedEntries(ctx, *members, known, "member or planet set")) {
      o.members[name] = ReadMemberOverride(ctx, entry);
      r.sources.dynamics_entries.emplace_back(name, entry);
    }
  }
  if (const auto meshes = m.Find("meshes")) {
    std::vector<std::string> known = names.meshes;
    Append(known, names.branches);
    for (const auto& [name, entry] : NamedEntries(ctx, *meshes, known, "mesh")) {
      if (name.find('#') == std::string::npos) ReadMeshEntry(ctx, entry, name, o);
      else ReadBranchEntry(ctx, entry, name, o);
      r.sources.dynamics_entries.emplace_back(name, entry);
    }
  }
  if (const auto bodies = m.Find("flexible_bodies")) {
    std::vector<std::string> known = names.planets;
    for (const std::string& member : names.members)
      if (!member.ends_with(".carrier")) known.push_back(member);
    for (const auto& [name, entry] : NamedEntries(ctx, *bodies, known, "flexible body")) {
      ReadFlexibleBody(ctx, entry, name, r);
      r.sources.dynamics_entries.emplace_back(name, entry);
    }
  }
  if (const auto h = m.Find("housing")) o.housing = ReadHousing(m, *h);
  ReadMeshModel(m, o);
  ReadToothContact(ctx, m.Find("tooth_contact"), names, o.contact);
  ReadTrainFaults(ctx, m.Find("faults"), names, r);
  ReadDynamicsScalars(m, o);
  if (const auto bodies = m.Find("imported_gears"))
    for (const auto& [name, entry] : NamedEntries(ctx, *bodies, names.planets, "imported gear")) {
      ReadImportedGearEntry(ctx, entry, name, o);
      r.sources.dynamics_entries.emplace_back(name, entry);
    }
  ReadMeshStiffness(m, r);
}

}  // namespace orrery::scene_reader

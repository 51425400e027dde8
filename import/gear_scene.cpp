// The gear model sections of a scene: `lumped_stage:` and `gear_train:` (docs/scene_format.md,
// "Gear model sections"). Values are SI unless a key carries its unit (`_mm`, `_deg`, `_rpm`,
// `_um`); every value is checked where it is read and reported at its key.
#include "import/gear_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "contact/train_contact.h"
#include "flex/reduced_body_file.h"
#include "import/reduce_input.h"
#include "import/train_mesh_geometry.h"
#include "models/mesh_stiffness.h"
#include "models/planetary_kinematics.h"
#include "models/planetary_power_flow.h"

namespace orrery::scene_reader {
namespace {

using gears::PlanetaryTrain;
using gears::TrainModelOptions;

// ---------------------------------------------------------------------------------------------
// Small readers

// One of several spellings of a quantity ({key, factor to SI}); at most one may be given.
std::optional<std::pair<Item, double>> FindOneOf(const MapReader& m,
                                                 const std::vector<std::pair<std::string, double>>& keys) {
  std::optional<std::pair<Item, double>> found;
  std::string found_key;
  for (const auto& [key, factor] : keys)
    if (const auto it = m.Find(key)) {
      if (found) m.ctx().Fail(*it, "give either '" + found_key + "' or '" + key + "', not both");
      found = std::make_pair(*it, factor);
      found_key = key;
    }
  return found;
}

std::string KeyList(const std::vector<std::pair<std::string, double>>& keys) {
  std::string s;
  for (const auto& [key, factor] : keys) s += (s.empty() ? "'" : ", '") + key + "'";
  return s;
}

// A value in SI from one of `keys`; nullopt if none is given.
std::optional<double> ScaledOf(const MapReader& m, const std::vector<std::pair<std::string, double>>& keys) {
  const auto found = FindOneOf(m, keys);
  if (!found) return std::nullopt;
  return ToNumber(m.ctx(), found->first) * found->second;
}

// Required, > 0 (or >= 0 with `allow_zero`), in SI.
double NeedScaled(const MapReader& m, const std::vector<std::pair<std::string, double>>& keys,
                  bool allow_zero = false) {
  const auto found = FindOneOf(m, keys);
  if (!found) m.FailMissing(keys.front().first, "missing required key (one of " + KeyList(keys) + ")");
  const double x = ToNumber(m.ctx(), found->first) * found->second;
  if (allow_zero ? !(x >= 0) : !(x > 0))
    m.ctx().Fail(found->first, std::string("must be ") + (allow_zero ? ">= 0" : "> 0") + ", got " +
                                   Num(ToNumber(m.ctx(), found->first)));
  return x;
}

// Optional with a default; checked >= 0 (or > 0).
double OptScaled(const MapReader& m, const std::vector<std::pair<std::string, double>>& keys,
                 double fallback, bool positive = false) {
  const auto found = FindOneOf(m, keys);
  if (!found) return fallback;
  const double x = ToNumber(m.ctx(), found->first) * found->second;
  if (positive ? !(x > 0) : !(x >= 0))
    m.ctx().Fail(found->first, std::string("must be ") + (positive ? "> 0" : ">= 0") + ", got " +
                                   Num(ToNumber(m.ctx(), found->first)));
  return x;
}

std::vector<std::pair<std::string, double>> Plain(const std::string& key) { return {{key, 1.0}}; }
std::vector<std::pair<std::string, double>> Angle(const std::string& key) {
  return {{key, 1.0}, {key + "_deg", kDegToRad}};
}
std::vector<std::pair<std::string, double>> LengthMm(const std::string& key) {
  return {{key, 1.0}, {key + "_mm", 1e-3}};
}
// A radius given as a diameter or a radius, in m or mm.
std::vector<std::pair<std::string, double>> RadiusKeys(const std::string& stem) {
  return {{stem + "_diameter", 0.5}, {stem + "_diameter_mm", 0.5e-3}, {stem + "_radius", 1.0},
          {stem + "_radius_mm", 1e-3}};
}
std::vector<std::string> Names(const std::vector<std::pair<std::string, double>>& keys) {
  std::vector<std::string> names;
  for (const auto& [key, factor] : keys) names.push_back(key);
  return names;
}
void Append(std::vector<std::string>& to, const std::vector<std::string>& more) {
  to.insert(to.end(), more.begin(), more.end());
}

// A list of angles (rad) from `key` or `key_deg`, `n` of them.
std::optional<std::vector<double>> AnglesOf(const MapReader& m, const std::string& key, int n) {
  const auto found = FindOneOf(m, Angle(key));
  if (!found) return std::nullopt;
  std::vector<double> a = ToNumbers(m.ctx(), found->first, n);
  for (double& x : a) x *= found->second;
  return a;
}

// A map or a list of maps (an entry that may repeat).
std::vector<Item> OneOrMany(const Context& ctx, const std::optional<Item>& item) {
  if (!item || item->node.IsNull()) return {};
  if (item->node.IsMap()) return {*item};
  return ListItems(ctx, item);
}

// Speeds: a function of time in rad/s ('_rpm' and '_deg' inside a function map).
FunctionUnits SpeedUnits() { return FunctionUnits{.scale = 1.0, .angle = true, .angular_speed = true}; }

// ---------------------------------------------------------------------------------------------
// lumped_stage

LumpedMember ReadLumpedMember(const Context& ctx, const Item& item, const std::string& kind) {
  const bool carrier = kind == "carrier";
  const std::string radius_stem = carrier ? "planet_circle" : "base";
  std::vector<std::string> allowed{"mass", "inertia", "inertia_over_r2", "bearing_stiffness",
                                   "bearing_damping", "torsional_stiffness", "torsional_stiffness_u",
                                   "torsional_damping", "axial_stiffness", "tilt_stiffness", "teeth"};
  Append(allowed, Names(RadiusKeys(radius_stem)));
  std::map<std::string, std::string> notes;
  for (const std::string& k : Names(RadiusKeys(carrier ? "base" : "planet_circle")))
    notes[k] = carrier ? "the carrier has no base circle: give the planet-centre circle "
                         "(planet_circle_diameter_mm, ...)"
                       : "only the carrier has a planet-centre circle: give the base circle "
                         "(base_diameter_mm, ...)";
  if (carrier) notes["teeth"] = "the carrier has no teeth";
  const MapReader m(ctx, item, allowed, notes);
  LumpedMember x;
  x.mass = NeedScaled(m, Plain("mass"));
  x.radius = NeedScaled(m, RadiusKeys(radius_stem));
  // Inertia about the axis, or I / r^2 (Lin & Parker's Table 1) with r the radius above.
  const auto inertia = FindOneOf(m, {{"inertia", 1.0}, {"inertia_over_r2", x.radius * x.radius}});
  if (!inertia) m.FailMissing("inertia", "missing required key (one of 'inertia', 'inertia_over_r2')");
  x.inertia = ToNumber(ctx, inertia->first) * inertia->second;
  if (!(x.inertia > 0)) ctx.Fail(inertia->first, "must be > 0, got " + Num(ToNumber(ctx, inertia->first)));
  x.bearing_stiffness = OptScaled(m, Plain("bearing_stiffness"), 0);
  x.bearing_damping = OptScaled(m, Plain("bearing_damping"), 0);
  // Torsional stiffness to ground: N m/rad, or N/m on u = r theta (k_u r^2 on theta).
  x.torsional_stiffness = OptScaled(m, {{"torsional_stiffness", 1.0},
                                        {"torsional_stiffness_u", x.radius * x.radius}}, 0);
  x.torsional_damping = OptScaled(m, Plain("torsional_damping"), 0);
  x.axial_stiffness = OptScaled(m, Plain("axial_stiffness"), 0);
  x.tilt_stiffness = OptScaled(m, Plain("tilt_stiffness"), 0);
  x.teeth = m.Int("teeth", 0);
  if (m.Has("teeth") && x.teeth < 1) ctx.Fail(m.Need("teeth"), "must be >= 1, got " + std::to_string(x.teeth));
  return x;
}

void ReadLumpedPorts(const Context& ctx, const std::optional<Item>& item, bool is_load,
                     std::vector<LumpedStagePort>& ports) {
  for (const Item& it : OneOrMany(ctx, item)) {
    const std::vector<std::string> allowed =
        is_load ? std::vector<std::string>{"member", "torque"}
                : std::vector<std::string>{"member", "speed", "torque"};
    std::map<std::string, std::string> notes;
    if (is_load) notes["speed"] = "a load is a torque; prescribe a speed under 'input:'";
    const MapReader m(ctx, it, allowed, notes);
    LumpedStagePort p;
    p.is_load = is_load;
    p.member = m.Choice("member", {"sun", "ring", "carrier"});
    if (m.Has("speed") == m.Has("torque"))
      ctx.Fail(it, "give exactly one of 'speed' (rad/s, a function of time) or 'torque' (N m)");
    if (const auto s = m.Find("speed")) {
      p.kind = LumpedStagePort::Kind::kSpeed;
      p.function = ToFunction(ctx, *s, SpeedUnits());
    } else {
      p.kind = LumpedStagePort::Kind::kTorque;
      p.function = ToFunction(ctx, m.Need("torque"), {});
    }
    ports.push_back(p);
  }
}

// ---------------------------------------------------------------------------------------------
// gear_train: stages

struct StageKeys {
  std::string type;
  std::vector<std::string> gears;  // gear keys of the type
};

const std::vector<StageKeys>& StageTypes() {
  static const std::vector<StageKeys> kTypes{
      {"single_planet", {"sun", "planet", "ring"}},
      {"double_planet", {"sun", "inner_planet", "outer_planet", "ring"}},
      {"ravigneaux", {"small_sun", "large_sun", "short_planet", "long_planet", "ring"}}};
  return kTypes;
}

// GEAR: a tooth count, or {teeth, tip_diameter[_mm] | tip_radius[_mm]}.
gears::TrainGearSpec ReadTrainGear(const Context& ctx, const Item& item) {
  gears::TrainGearSpec g;
  if (item.node.IsScalar()) {
    g.teeth = ToInt(ctx, item);
  } else {
    const MapReader m(ctx, item, [] {
      std::vector<std::string> k{"teeth"};
      Append(k, Names(RadiusKeys("tip")));
      return k;
    }());
    const Item teeth = m.Need("teeth");
    g.teeth = ToInt(ctx, teeth);
    g.tip_radius_m = OptScaled(m, RadiusKeys("tip"), 0, true);
  }
  if (g.teeth < 1) ctx.Fail(item, "teeth must be >= 1, got " + std::to_string(g.teeth));
  return g;
}

struct StageRead {
  std::string name;
  Item item;
  std::optional<double> face_width_m;
};

StageRead ReadStage(const Context& ctx, const Item& item, gears::PlanetaryTrainBuilder& builder) {
  std::vector<std::string> type_names;
  for (const StageKeys& t : StageTypes()) type_names.push_back(t.type);
  const std::string type = ItemType(ctx, item, type_names);
  const StageKeys& keys = *std::find_if(StageTypes().begin(), StageTypes().end(),
                                        [&](const StageKeys& t) { return t.type == type; });
  std::vector<std::string> allowed{"name", "type", "planets", "planet_angles", "planet_angles_deg",
                                   "planet_spacing", "addendum_coefficient"};
  for (const auto& group : {LengthMm("module"), Angle("pressure_angle"), Angle("helix_angle"),
                            LengthMm("face_width")})
    Append(allowed, Names(group));
  Append(allowed, keys.gears);
  std::map<std::string, std::string> notes;
  for (const StageKeys& t : StageTypes())
    for (const std::string& g : t.gears)
      if (std::find(keys.gears.begin(), keys.gears.end(), g) == keys.gears.end())
        notes[g] = "a " + type + " stage has the gears " + JoinQuoted(keys.gears);
  if (type == "single_planet") Append(allowed, Names(RadiusKeys("pin_circle")));
  else
    for (const std::string& k : Names(RadiusKeys("pin_circle")))
      notes[k] = "the pin circle is set only for single_planet stages (others follow the gears)";
  const MapReader m(ctx, item, allowed, notes);

  StageRead r{ToString(ctx, m.Need("name")), item, std::nullopt};
  const int planets = m.Int("planets", 0);
  if (!m.Has("planets")) m.FailMissing("planets", "missing required key 'planets'");
  if (planets < 1) ctx.Fail(m.Need("planets"), "must be >= 1, got " + std::to_string(planets));
  // Tooth form, when the module is given.
  std::optional<gears::ToothForm> form;
  if (const auto module = ScaledOf(m, LengthMm("module"))) {
    gears::ToothForm f;
    f.normal_module_m = *module;
    if (!(f.normal_module_m > 0)) ctx.Fail(FindOneOf(m, LengthMm("module"))->first, "must be > 0");
    f.normal_pressure_angle_rad = ScaledOf(m, Angle("pressure_angle")).value_or(f.normal_pressure_angle_rad);
    f.helix_angle_rad = ScaledOf(m, Angle("helix_angle")).value_or(0.0);
    f.addendum_coefficient = m.Number("addendum_coefficient", 1.0);
    form = f;
  } else {
    for (const auto& group : {Angle("pressure_angle"), Angle("helix_angle"), Plain("addendum_coefficient")})
      if (const auto it = FindOneOf(m, group)) ctx.Fail(it->first, "a tooth form needs 'module_mm' (or 'module')");
  }
  if (const auto b = FindOneOf(m, LengthMm("face_width"))) {
    r.face_width_m = ToNumber(ctx, b->first) * b->second;
    if (!(*r.face_width_m > 0)) ctx.Fail(b->first, "must be > 0");
  }
  // Gears, in the order of the type's keys.
  std::vector<gears::TrainGearSpec> g;
  for (const std::string& k : keys.gears) g.push_back(ReadTrainGear(ctx, m.Need(k)));
  // Planet positions: explicit angles, equal spacing (default) or the assemblable positions
  // nearest to equal spacing.
  std::vector<double> angles = AnglesOf(m, "planet_angles", planets).value_or(std::vector<double>{});
  if (const auto spacing = m.Find("planet_spacing")) {
    if (!angles.empty()) ctx.Fail(*spacing, "give either planet_spacing or planet_angles, not both");
    if (m.Choice("planet_spacing", {"equal", "assemblable"}) == "assemblable") {
      if (type == "ravigneaux")
        ctx.Fail(*spacing, "'assemblable' is for single_planet and double_planet stages; give "
                           "planet_angles_deg");
      const int sum = type == "single_planet" ? g[0].teeth + g[2].teeth : g[3].teeth - g[0].teeth;
      try {
        angles = gears::AssemblablePlanetAngles(sum, planets);
      } catch (const std::invalid_argument& e) {
        ctx.Fail(*spacing, e.what());
      }
    }
  }
  // Builder errors: place them at the key they mention.
  Build(m, {{"planet angles", "planet_angles_deg"}, {"planet angles", "planet_angles"},
            {"planet ", "planet_angles_deg"}, {"spacing", "planets"}, {"overlap", "planets"},
            {"num_planets", "planets"}, {"ring teeth", "ring"}, {"module", "module_mm"},
            {"pressure angle", "pressure_angle_deg"}, {"helix", "helix_angle_deg"},
            {"stage name", "name"}, {"duplicate stage", "name"}, {"pin radii", "inner_planet"},
            {"equally", "planets"}},
        [&] {
          if (type == "single_planet")
            builder.AddSinglePlanetStage({.name = r.name, .sun = g[0], .planet = g[1], .ring = g[2],
                                          .num_planets = planets, .tooth_form = form,
                                          .planet_angles_rad = angles,
                                          .pin_radius_m = OptScaled(m, RadiusKeys("pin_circle"), 0, true)});
          else if (type == "double_planet")
            builder.AddDoublePlanetStage({.name = r.name, .sun = g[0], .inner_planet = g[1],
                                          .outer_planet = g[2], .ring = g[3], .num_planets = planets,
                                          .tooth_form = form, .planet_angles_rad = angles});
          else
            builder.AddRavigneauxStage({.name = r.name, .small_sun = g[0], .large_sun = g[1],
                                        .short_planet = g[2], .long_planet = g[3], .ring = g[4],
                                        .num_planets = planets, .tooth_form = form,
                                        .planet_angles_rad = angles});
        });
  return r;
}

// A member name of the train being built, with suggestions.
std::string MemberRef(const Context& ctx, const Item& item, const gears::PlanetaryTrainBuilder& b) {
  const std::string name = ToString(ctx, item);
  if (b.draft().member_by_name.count(name)) return name;
  std::vector<std::string> known;
  for (const gears::Member& mem : b.draft().members) known.push_back(mem.name);
  ctx.Fail(item, "no member named '" + name + "'" + SuggestOrList(name, known, "members"));
}

// ---------------------------------------------------------------------------------------------
// gear_train: dynamics options

gears::TrainMemberOverride ReadMemberOverride(const Context& ctx, const Item& item) {
  std::vector<std::string> allowed{"mass", "inertia", "transverse_inertia", "bearing_stiffness",
                                   "axial_bearing_stiffness", "tilt_bearing_stiffness",
                                   "bearing_damping", "ground_torsional_stiffness", "brake_stiffness"};
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
  non_negative(Plain("bearing_stiffness"), o.radial_bearing_stiffness_N_m);
  non_negative(Plain("axial_bearing_stiffness"), o.axial_bearing_stiffness_N_m);
  non_negative(Plain("tilt_bearing_stiffness"), o.tilt_bearing_stiffness_N_m_rad);
  non_negative(Plain("bearing_damping"), o.bearing_damping_N_s_m);
  non_negative(Plain("ground_torsional_stiffness"), o.ground_torsional_stiffness_N_m_rad);
  positive(Plain("brake_stiffness"), o.brake_stiffness_N_m_rad);
  return o;
}

gears::TrainMeshOverride ReadMeshOverride(const Context& ctx, const Item& item) {
  std::vector<std::string> allowed{"stiffness", "stiffness_table", "table_cycles", "damping_ratio",
                                   "contact", "phase_cycles"};
  for (const auto& group : {Angle("working_pressure_angle"), Angle("ste_phases"),
                            std::vector<std::pair<std::string, double>>{{"backlash", 1.0}, {"backlash_um", 1e-6}},
                            std::vector<std::pair<std::string, double>>{{"ste_amplitudes", 1.0}, {"ste_amplitudes_um", 1e-6}}})
    Append(allowed, Names(group));
  const MapReader m(ctx, item, allowed);
  gears::TrainMeshOverride o;
  if (m.Has("stiffness")) o.stiffness_N_m = NeedScaled(m, Plain("stiffness"));
  if (const auto t = m.Find("stiffness_table")) {
    o.stiffness_table_N_m = ToNumbers(ctx, *t, -1);
    if (o.stiffness_table_N_m->empty()) ctx.Fail(*t, "needs at least one value");
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
  if (FindOneOf(m, {{"backlash", 1.0}, {"backlash_um", 1e-6}}))
    o.backlash_m = NeedScaled(m, {{"backlash", 1.0}, {"backlash_um", 1e-6}}, true);
  if (const auto a = FindOneOf(m, {{"ste_amplitudes", 1.0}, {"ste_amplitudes_um", 1e-6}})) {
    std::vector<double> v = ToNumbers(ctx, a->first, -1);
    for (double& x : v) x *= a->second;
    o.ste_amplitudes_m = v;
  }
  if (const auto p = FindOneOf(m, Angle("ste_phases"))) {
    std::vector<double> v = ToNumbers(ctx, p->first, -1);
    for (double& x : v) x *= p->second;
    o.ste_phases_rad = v;
  }
  if (m.Has("contact"))
    o.contact = m.Choice("contact", {"drive", "coast"}) == "drive" ? GearMeshSpec::Contact::kLinearDrive
                                                                   : GearMeshSpec::Contact::kLinearCoast;
  if (const auto p = m.Find("phase_cycles")) o.phase_cycles = ToNumbers(ctx, *p, -1);
  return o;
}

// Keys of `name: {...}` maps (member and mesh overrides), checked against the train's names.
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

// A flexible planet: its reduced-body file (made by `orrery reduce`), checked against the reduce
// input when one is named (a stale file is rejected with the reasons), and its options.
gears::TrainModelOptions::FlexiblePlanet ReadFlexiblePlanet(const Context& ctx, const Item& item) {
  const MapReader m(ctx, item, {"reduced_body", "reduce_input", "mesh_interface", "damping_ratio",
                                "rayleigh_alpha", "rayleigh_beta", "geometric_stiffening", "frozen",
                                "record_surface", "record_node_sets"});
  const std::filesystem::path dir = std::filesystem::path(ctx.file()).parent_path();
  auto resolve = [&](const std::string& p) {
    const std::filesystem::path path(p);
    return (path.is_absolute() ? path : dir / path).lexically_normal().string();
  };
  const Item body_item = m.Need("reduced_body");
  const std::string body_path = resolve(m.String("reduced_body"));
  std::optional<flex::ReducedBodyProvenance> expected;
  std::optional<GearReduction> job;
  std::string input_path;
  if (const auto in = m.Find("reduce_input")) {
    input_path = resolve(m.String("reduce_input"));
    try {
      job = PrepareGearReduction(LoadReduceInput(input_path));
      expected = flex::MakeReducedBodyProvenance(job->mesh, job->cb_options, job->interfaces, job->outputs, "");
      expected->source = "the reduce input " + input_path;
    } catch (const std::exception& e) {
      ctx.Fail(*in, e.what());
    }
  }
  const std::string remake = input_path.empty() ? std::string("make it with `orrery reduce INPUT -o ") + body_path + "`"
                                                : "make it with `orrery reduce " + input_path + " -o " + body_path + "`";
  ctx.NoteInput(body_path);
  if (!input_path.empty()) ctx.NoteInput(input_path);
  // A missing file is made from the reduce input (once; later runs reuse it), by `orrery run` only.
  if (!std::filesystem::exists(body_path)) {
    if (!job) ctx.Fail(body_item, "no reduced-body file " + body_path + "; " + remake + ", or name its reduce_input");
    if (!ctx.make_reduced_bodies())
      ctx.Fail(body_item, "no reduced-body file " + body_path + " (this command writes no files); " + remake +
                              ", or let `orrery run` make it");
    try {
      flex::WriteReducedBody(body_path, ReduceBody(job->mesh, job->interfaces, job->cb_options, job->outputs,
                                                   job->source).body);
    } catch (const std::exception& e) {
      ctx.Fail(body_item, "could not make " + body_path + " from " + input_path + ": " + e.what());
    }
  }
  gears::TrainModelOptions::FlexiblePlanet planet;
  try {
    planet.modes = std::make_shared<FlexibleBodyModes>(
        flex::ReadReducedBody(body_path, expected ? &*expected : nullptr).modes);
  } catch (const flex::StaleReducedBodyError& e) {
    ctx.Fail(body_item, std::string(e.what()) + "; re" + remake.substr(1));
  } catch (const std::exception& e) {
    ctx.Fail(body_item, e.what());
  }
  planet.mesh_interface = m.Has("mesh_interface") ? m.String("mesh_interface") : "";
  if (!planet.mesh_interface.empty()) {
    const auto set = planet.modes->node_sets.find(planet.mesh_interface);
    if (set == planet.modes->node_sets.end() || set->second.size() != 1)
      ctx.Fail(m.Need("mesh_interface"), "'" + planet.mesh_interface + "' is not an interface of " + body_path);
  }
  if (m.Has("damping_ratio")) planet.options.damping_ratios = {OptScaled(m, Plain("damping_ratio"), 0)};
  planet.options.rayleigh_alpha = OptScaled(m, Plain("rayleigh_alpha"), 0);
  planet.options.rayleigh_beta = OptScaled(m, Plain("rayleigh_beta"), 0);
  planet.options.geometric_stiffening = m.Bool("geometric_stiffening", false);
  if (planet.options.geometric_stiffening && planet.modes->geometric_stiffness.empty())
    ctx.Fail(m.Need("geometric_stiffening"), body_path + " has no geometric stiffness (reduce with "
                                                         "outputs.geometric_stiffness: true)");
  planet.options.frozen = m.Bool("frozen", false);
  planet.options.record_surface = m.Bool("record_surface", false);
  if (const auto sets = m.Find("record_node_sets")) {
    for (const Item& set : ListItems(ctx, sets)) planet.options.record_node_sets.push_back(ToString(ctx, set));
    for (const std::string& set : planet.options.record_node_sets)
      if (!planet.modes->node_sets.count(set))
        ctx.Fail(*sets, "no node set '" + set + "' in " + body_path +
                            " (export it with outputs.export_node_sets when reducing)");
  }
  return planet;
}

// `tooth_contact:` of the contact mesh model -> TrainContactOptions (contact/train_contact.h).
// Only what a run needs: which meshes, flank resolution, penalty calibration, damping, friction
// and broken teeth; margins and slack keep the gear-contact defaults.
void ReadToothContact(const Context& ctx, const std::optional<Item>& item, const PlanetaryTrain& train,
                      contact::TrainContactOptions& c) {
  if (!item || item->node.IsNull()) return;
  const auto margin = std::vector<std::pair<std::string, double>>{{"margin", 1.0}, {"margin_um", 1e-6}};
  std::vector<std::string> allowed{"meshes", "involute_intervals", "single_pair_stiffness",
                                   "calibration_load", "hunt_crossley", "friction_coefficient",
                                   "missing_teeth", "flexible", "record_points"};
  Append(allowed, Names(margin));
  const MapReader m(ctx, *item, allowed);
  if (const auto meshes = m.Find("meshes")) {
    std::vector<std::string> known;
    for (const gears::TrainMesh& x : train.meshes) known.push_back(x.name);
    if (!meshes->node.IsSequence()) ctx.Fail(*meshes, "expected a list of mesh names, got " + Describe(meshes->node));
    for (size_t i = 0; i < meshes->node.size(); ++i) {
      const Item e = Element(*meshes, i);
      const std::string name = ToString(ctx, e);
      if (std::find(known.begin(), known.end(), name) == known.end())
        ctx.Fail(e, "no mesh named '" + name + "'" + SuggestOrList(name, known, "meshes"));
      c.meshes.push_back(name);
    }
  }
  if (m.Has("involute_intervals")) {
    c.gear.involute_intervals = m.Int("involute_intervals", c.gear.involute_intervals);
    if (c.gear.involute_intervals < 4) ctx.Fail(m.Need("involute_intervals"), "must be >= 4");
  }
  if (m.Has("record_points")) {
    c.gear.record_points = m.Int("record_points", 0);
    if (c.gear.record_points < 0 || c.gear.record_points > 1000)
      ctx.Fail(m.Need("record_points"), "must be in 0..1000");
  }
  if (m.Has("single_pair_stiffness")) c.gear.single_pair_stiffness_n_per_m = NeedScaled(m, Plain("single_pair_stiffness"));
  c.gear.calibration_load_n = OptScaled(m, Plain("calibration_load"), c.gear.calibration_load_n, true);
  // Contact margin: above the largest penetration of the run (a few um per 1000 N of one pair).
  c.gear.margin_m = OptScaled(m, margin, c.gear.margin_m, true);
  c.gear.hunt_crossley_s_per_m = OptScaled(m, Plain("hunt_crossley"), 0);
  c.gear.friction_coefficient = OptScaled(m, Plain("friction_coefficient"), 0);
  // Flexible planets' surfaces (contact/train_contact.h): {face_intervals, embed_tolerance_um,
  // deformation_allowance_um}.
  if (const auto f = m.Find("flexible")) {
    const auto embed = std::vector<std::pair<std::string, double>>{{"embed_tolerance", 1.0},
                                                                   {"embed_tolerance_um", 1e-6}};
    const auto allowance = std::vector<std::pair<std::string, double>>{
        {"deformation_allowance", 1.0}, {"deformation_allowance_um", 1e-6}};
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
    contact::TrainContactOptions::MissingTeeth mt;
    mt.gear = t.String("gear");
    const auto gear = std::find_if(train.gears.begin(), train.gears.end(),
                                   [&](const gears::TrainGear& x) { return x.name == mt.gear; });
    if (gear == train.gears.end()) {
      std::vector<std::string> known;
      for (const gears::TrainGear& x : train.gears) known.push_back(x.name);
      ctx.Fail(t.Need("gear"), "no gear named '" + mt.gear + "'" + SuggestOrList(mt.gear, known, "gears"));
    }
    if (gear->planet_set >= 0) {
      const int n = static_cast<int>(train.planet_sets[gear->planet_set].angles_rad.size());
      const int branch = t.Int("branch", 1);
      if (branch < 1 || branch > n)
        ctx.Fail(t.Need("branch"), "must be in 1.." + std::to_string(n) + " (the planet of the set)");
      mt.branch = branch - 1;
    } else if (t.Has("branch")) {
      ctx.Fail(t.Need("branch"), "a branch is for planets; '" + mt.gear + "' is a central gear");
    }
    for (double x : ToNumbers(ctx, t.Need("teeth"), -1)) {
      if (x != std::floor(x) || x < 0 || x >= gear->teeth)
        ctx.Fail(t.Need("teeth"), "tooth indices are integers in 0.." + std::to_string(gear->teeth - 1));
      mt.teeth.push_back(static_cast<int>(x));
    }
    c.missing_teeth.push_back(mt);
  }
}

// The dynamics map -> TrainModelOptions (mesh stiffness method returned separately); the
// contact mesh model's options into `contact` when `mesh_model: contact`.
std::string ReadDynamics(const Context& ctx, const std::optional<Item>& item, const PlanetaryTrain& train,
                         TrainModelOptions& o, std::optional<Item>& stiffness_item,
                         std::optional<contact::TrainContactOptions>& contact) {
  if (!item) return "c_gamma";
  std::vector<std::string> allowed{"dofs", "contact", "mesh_damping_ratio", "mesh_stiffness",
                                   "mesh_stiffness_per_face_width", "mesh_phasing",
                                   "unloaded_mesh_stiffness_factor", "density", "bore_to_pitch_ratio",
                                   "ring_rim_modules", "connection_stiffness", "clutch_stiffness",
                                   "brake_stiffness", "bearing_stiffness", "axial_bearing_stiffness",
                                   "tilt_bearing_stiffness", "bearing_damping", "port_loads",
                                   "stage_phase_cycles", "members", "meshes", "backlash", "backlash_um",
                                   "flexible_planets", "mesh_model", "tooth_contact"};
  Append(allowed, Names(LengthMm("stage_spacing")));
  const MapReader m(ctx, *item, allowed, {{"damping_ratio", "write 'mesh_damping_ratio'"}});
  const std::string dofs = m.Choice("dofs", {"torsional", "planar", "spatial"}, "torsional");
  o.dofs = dofs == "torsional" ? gears::TrainDofs::kTorsional
           : dofs == "planar"  ? gears::TrainDofs::kPlanar
                               : gears::TrainDofs::kSpatial;
  o.two_sided_contact = m.Choice("contact", {"linear", "two_sided"}, "linear") == "two_sided";
  const auto backlash = std::vector<std::pair<std::string, double>>{{"backlash", 1.0}, {"backlash_um", 1e-6}};
  // Mesh model: lumped springs, or tooth contact on the gears' surfaces (the backlash is then
  // the contact meshes' normal backlash).
  if (m.Choice("mesh_model", {"lumped", "contact"}, "lumped") == "contact") {
    contact.emplace();
    contact->normal_backlash_m = OptScaled(m, backlash, 0);
    ReadToothContact(ctx, m.Find("tooth_contact"), train, *contact);
  } else {
    if (const auto tc = m.Find("tooth_contact")) ctx.Fail(*tc, "tooth_contact needs 'mesh_model: contact'");
    o.backlash_m = OptScaled(m, backlash, 0);
    if (FindOneOf(m, backlash) && !o.two_sided_contact)
      ctx.Fail(FindOneOf(m, backlash)->first, "backlash needs 'contact: two_sided' (or 'mesh_model: contact')");
  }
  o.mesh_damping_ratio = OptScaled(m, Plain("mesh_damping_ratio"), 0);
  o.mesh_phasing = m.Bool("mesh_phasing", true);
  o.port_loads = m.Bool("port_loads", true);
  o.unloaded_mesh_stiffness_factor = OptScaled(m, Plain("unloaded_mesh_stiffness_factor"), o.unloaded_mesh_stiffness_factor, true);
  o.mesh_stiffness_per_face_width_N_m2 = OptScaled(m, Plain("mesh_stiffness_per_face_width"), o.mesh_stiffness_per_face_width_N_m2, true);
  o.density_kg_m3 = OptScaled(m, Plain("density"), o.density_kg_m3, true);
  o.bore_to_pitch_ratio = OptScaled(m, Plain("bore_to_pitch_ratio"), o.bore_to_pitch_ratio);
  o.ring_rim_modules = OptScaled(m, Plain("ring_rim_modules"), o.ring_rim_modules, true);
  o.stage_spacing_m = OptScaled(m, LengthMm("stage_spacing"), 0);
  o.connection_stiffness_N_m_rad = OptScaled(m, Plain("connection_stiffness"), o.connection_stiffness_N_m_rad, true);
  o.clutch_stiffness_N_m_rad = OptScaled(m, Plain("clutch_stiffness"), o.clutch_stiffness_N_m_rad, true);
  o.brake_stiffness_N_m_rad = OptScaled(m, Plain("brake_stiffness"), o.brake_stiffness_N_m_rad, true);
  o.radial_bearing_stiffness_N_m = OptScaled(m, Plain("bearing_stiffness"), o.radial_bearing_stiffness_N_m);
  o.axial_bearing_stiffness_N_m = OptScaled(m, Plain("axial_bearing_stiffness"), o.axial_bearing_stiffness_N_m);
  o.tilt_bearing_stiffness_N_m_rad = OptScaled(m, Plain("tilt_bearing_stiffness"), o.tilt_bearing_stiffness_N_m_rad);
  o.bearing_damping_N_s_m = OptScaled(m, Plain("bearing_damping"), 0);
  if (const auto p = m.Find("stage_phase_cycles")) o.stage_phase_cycles = ToNumbers(ctx, *p, -1);
  // Overrides by member / planet-set name and by mesh name.
  if (const auto members = m.Find("members")) {
    std::vector<std::string> known;
    for (const gears::Member& x : train.members) known.push_back(x.name);
    for (const gears::PlanetSet& x : train.planet_sets) known.push_back(x.name);
    for (const auto& [name, entry] : NamedEntries(ctx, *members, known, "member or planet set"))
      o.members[name] = ReadMemberOverride(ctx, entry);
  }
  if (const auto meshes = m.Find("meshes")) {
    std::vector<std::string> known;
    for (const gears::TrainMesh& x : train.meshes) known.push_back(x.name);
    for (const auto& [name, entry] : NamedEntries(ctx, *meshes, known, "mesh"))
      o.meshes[name] = ReadMeshOverride(ctx, entry);
  }
  if (const auto planets = m.Find("flexible_planets")) {
    std::vector<std::string> known;
    for (const gears::PlanetSet& x : train.planet_sets)
      for (size_t i = 0; i < x.angles_rad.size(); ++i) known.push_back(x.name + std::to_string(i + 1));
    for (const auto& [name, entry] : NamedEntries(ctx, *planets, known, "planet"))
      o.flexible_planets[name] = ReadFlexiblePlanet(ctx, entry);
  }
  // Mean mesh stiffness: c_gamma b (default), one value for all meshes, ISO 6336 or TVMS.
  const auto k = m.Find("mesh_stiffness");
  if (!k) return "c_gamma";
  stiffness_item = k;
  if (k->node.IsScalar() && IsPlainScalar(k->node)) {
    double x = 0;
    if (YAML::convert<double>::decode(k->node, x)) {
      if (!(x > 0)) ctx.Fail(*k, "must be > 0 (N/m), got " + Num(x));
      o.mesh_stiffness = [x](const PlanetaryTrain&, int, double) { return x; };
      return "value";
    }
  }
  return m.Choice("mesh_stiffness", {"c_gamma", "iso6336", "tvms"});
}

// The value of largest magnitude of f over [0, end_time] (the operating point of a run-up).
double PeakValue(const TimeFunction& f, double end_time) {
  double best = f.Value(0.0);
  const int n = 2000;
  for (int i = 1; i <= n; ++i) {
    const double v = f.Value(end_time * i / n);
    if (std::abs(v) > std::abs(best)) best = v;
  }
  return best;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

void ReadLumpedStage(const Context& ctx, const Item& section, Scene& scene) {
  std::vector<std::string> allowed{"dofs", "planets", "planet_angles", "planet_angles_deg", "sun", "ring",
                                   "carrier", "planet", "mesh_stiffness_sun", "mesh_stiffness_ring",
                                   "mesh_damping_ratio", "lines_of_action_on_carrier",
                                   "check_centre_distance", "input", "load"};
  for (const auto& group : {Angle("pressure_angle_sun"), Angle("pressure_angle_ring"), Angle("helix_angle")})
    Append(allowed, Names(group));
  const MapReader m(ctx, section, allowed);
  auto s = std::make_shared<LumpedStageScene>();
  LumpedStageParams& p = s->params;
  const std::string dofs = m.Choice("dofs", {"torsional", "planar", "spatial"}, "planar");
  p.dofs = dofs == "torsional" ? LumpedStageParams::Dofs::kTorsional
           : dofs == "planar"  ? LumpedStageParams::Dofs::kPlanar
                               : LumpedStageParams::Dofs::kSpatial;
  s->rotation_coordinate = dofs == "torsional" ? 0 : dofs == "planar" ? 2 : 5;
  if (!m.Has("planets")) m.FailMissing("planets", "missing required key 'planets'");
  p.planets = m.Int("planets", 0);
  if (p.planets < 1) ctx.Fail(m.Need("planets"), "must be >= 1, got " + std::to_string(p.planets));
  p.planet_angles = AnglesOf(m, "planet_angles", p.planets).value_or(std::vector<double>{});
  p.sun = ReadLumpedMember(ctx, m.Need("sun"), "sun");
  p.ring = ReadLumpedMember(ctx, m.Need("ring"), "ring");
  p.carrier = ReadLumpedMember(ctx, m.Need("carrier"), "carrier");
  p.planet = ReadLumpedMember(ctx, m.Need("planet"), "planet");
  p.mesh_stiffness_sun = NeedScaled(m, Plain("mesh_stiffness_sun"));
  p.mesh_stiffness_ring = NeedScaled(m, Plain("mesh_stiffness_ring"));
  // Working transverse pressure angles, (0, 90) degrees.
  for (const auto& [key, to] : {std::pair{std::string("pressure_angle_sun"), &p.pressure_angle_sun},
                                std::pair{std::string("pressure_angle_ring"), &p.pressure_angle_ring}}) {
    *to = NeedScaled(m, Angle(key));
    if (!(*to < std::numbers::pi / 2)) ctx.Fail(FindOneOf(m, Angle(key))->first, "must be below 90 degrees");
  }
  p.helix_angle = ScaledOf(m, Angle("helix_angle")).value_or(0.0);
  p.mesh_damping_ratio = OptScaled(m, Plain("mesh_damping_ratio"), 0);
  p.lines_of_action_on_carrier = m.Bool("lines_of_action_on_carrier", true);
  p.check_centre_distance = m.Bool("check_centre_distance", false);
  ReadLumpedPorts(ctx, m.Find("input"), false, s->ports);
  ReadLumpedPorts(ctx, m.Find("load"), true, s->ports);
  // Build, with the ports as drivers (and initial speeds) and joint loads on the spin coordinate.
  const int rot = s->rotation_coordinate;
  const std::vector<LumpedStagePort> ports = s->ports;
  s->stage = Build(m, {{"planet_angles", "planet_angles_deg"}, {"mesh stiffness", "mesh_stiffness_sun"}}, [&] {
    return BuildLumpedStage(p, [&](ModelBuilder& b, const LumpedStage& stage) {
      for (const LumpedStagePort& port : ports) {
        const JointIndex j = port.member == "sun" ? stage.sun : port.member == "ring" ? stage.ring : stage.carrier;
        const std::string what = port.is_load ? "load_" : "input_";
        if (port.kind == LumpedStagePort::Kind::kSpeed) {
          b.AddDriver({.name = what + port.member, .joint = j, .coordinate = rot,
                       .mode = DriverSpec::Mode::kSpeed, .function = port.function});
          Eigen::VectorXd v = Eigen::VectorXd::Zero(b.draft().joints[j].nv);
          v(rot) = port.function.Value(0.0);
          b.SetJointVelocity(j, v);
        } else {
          b.AddJointLoad({.name = what + port.member, .joint = j, .coordinate = rot, .function = port.function});
        }
      }
    });
  });
  scene.kind = SceneKind::kLumpedStage;
  scene.model = s->stage.model;
  scene.lumped_stage = s;
}

void ReadGearTrain(const Context& ctx, const Item& section, Scene& scene) {
  std::vector<std::string> allowed{"stages", "connections", "clutches", "brakes", "ranges", "inputs",
                                   "output", "range", "drive", "input_speeds", "input_torque",
                                   "output_torque", "dynamics", "input_speed", "input_speed_rpm"};
  const MapReader m(ctx, section, allowed, {{"seed", "scenes spell the train out (stages, "
                                                     "connections, ...); there is no seed shortcut"}});
  gears::PlanetaryTrainBuilder b;
  // Stages.
  std::vector<StageRead> stages;
  const std::vector<Item> stage_items = ListItems(ctx, m.Need("stages"));
  if (stage_items.empty()) ctx.Fail(m.Need("stages"), "a gear train needs at least one stage");
  for (const Item& item : stage_items) stages.push_back(ReadStage(ctx, item, b));
  // Connections and clutches: {name, between: [member, member]}; brakes: {name, member}.
  auto couplings = [&](const std::string& key, bool clutch) {
    for (const Item& item : ListItems(ctx, m.Find(key))) {
      const MapReader c(ctx, item, {"name", "between"});
      const std::string name = ToString(ctx, c.Need("name"));
      const Item between = c.Need("between");
      if (!between.node.IsSequence() || between.node.size() != 2)
        ctx.Fail(between, "expected a list of 2 member names, got " + Describe(between.node));
      const std::string a = MemberRef(ctx, Element(between, 0), b), bb = MemberRef(ctx, Element(between, 1), b);
      Build(c, {{"name", "name"}, {"joins", "between"}, {"stage", "between"}}, [&] {
        clutch ? b.AddClutch(name, a, bb) : b.AddConnection(name, a, bb);
      });
    }
  };
  couplings("connections", false);
  couplings("clutches", true);
  std::vector<std::string> engageable;
  for (const gears::Coupling& c : b.draft().clutches) engageable.push_back(c.name);
  for (const Item& item : ListItems(ctx, m.Find("brakes"))) {
    const MapReader c(ctx, item, {"name", "member"});
    const std::string name = ToString(ctx, c.Need("name"));
    const std::string member = MemberRef(ctx, c.Need("member"), b);
    Build(c, {{"name", "name"}}, [&] { b.AddBrake(name, member); });
    engageable.push_back(name);
  }
  // Ranges: {NAME: [engaged clutches and brakes], ...} in order.
  const Item ranges = m.Need("ranges");
  if (!ranges.node.IsMap() || ranges.node.size() == 0)
    ctx.Fail(ranges, "expected a map of gear ranges (NAME: [engaged clutches and brakes]), got " +
                         Describe(ranges.node));
  std::vector<std::pair<std::string, Item>> range_items;
  for (auto it = ranges.node.begin(); it != ranges.node.end(); ++it) {
    const std::string name = it->first.IsScalar() ? it->first.Scalar() : "?";
    const Item entry{it->second, ranges.path + "." + name, it->first.Mark()};
    std::vector<std::string> engaged;
    if (!entry.node.IsNull()) {
      if (!entry.node.IsSequence()) ctx.Fail(entry, "expected a list of clutch and brake names, got " + Describe(entry.node));
      for (size_t i = 0; i < entry.node.size(); ++i) {
        const Item e = Element(entry, i);
        const std::string en = ToString(ctx, e);
        if (std::find(engageable.begin(), engageable.end(), en) == engageable.end())
          ctx.Fail(e, "no clutch or brake named '" + en + "'" + SuggestOrList(en, engageable, "clutches and brakes"));
        engaged.push_back(en);
      }
    }
    try {
      b.AddRange(name, engaged);
    } catch (const std::invalid_argument& e) {
      ctx.Fail(entry, StripElementPrefix(e.what()));
    }
    range_items.emplace_back(name, entry);
  }
  // Ports.
  const Item inputs = m.Need("inputs");
  if (!inputs.node.IsSequence() || inputs.node.size() == 0)
    ctx.Fail(inputs, "expected a list of input member names, got " + Describe(inputs.node));
  for (size_t i = 0; i < inputs.node.size(); ++i) {
    const Item e = Element(inputs, i);
    const std::string name = MemberRef(ctx, e, b);
    try {
      b.AddInput(name);
    } catch (const std::invalid_argument& ex) {
      ctx.Fail(e, ex.what());
    }
  }
  const std::string output = MemberRef(ctx, m.Need("output"), b);
  b.SetOutput(output);
  std::shared_ptr<const PlanetaryTrain> train;
  try {
    train = std::move(b).Finalize();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    for (const auto& [name, entry] : range_items)
      if (what.find("'" + name + "'") != std::string::npos) ctx.Fail(entry, what);
    if (what.find("output") != std::string::npos) ctx.Fail(m.Need("output"), what);
    ctx.Fail(section, what);
  }

  auto g = std::make_shared<GearTrainScene>();
  g->train = train;
  // The analysed / simulated range.
  if (const auto r = m.Find("range")) {
    const std::string name = ToString(ctx, *r);
    if (!train->range_by_name.count(name)) {
      std::vector<std::string> known;
      for (const gears::GearRange& x : train->ranges) known.push_back(x.name);
      ctx.Fail(*r, "no gear range named '" + name + "'" + SuggestOrList(name, known, "ranges"));
    }
    g->range = train->RangeIndex(name);
  }
  // Input speeds: one function per input (input_speed for one input, input_speeds for several).
  const int num_inputs = static_cast<int>(train->inputs.size());
  const auto speed_key = FindOneOf(m, {{"input_speed", 1.0}, {"input_speed_rpm", kRpmToRadPerS}, {"input_speeds", 1.0}});
  if (speed_key) {
    const Item& it = speed_key->first;
    if (it.path.ends_with("input_speeds")) {
      if (!it.node.IsSequence() || static_cast<int>(it.node.size()) != num_inputs)
        ctx.Fail(it, "expected a list of " + std::to_string(num_inputs) + " speeds (one per input), got " + Describe(it.node));
      for (int i = 0; i < num_inputs; ++i)
        g->input_speed_functions.push_back(ToFunction(ctx, Element(it, i), SpeedUnits()));
    } else {
      if (num_inputs != 1)
        ctx.Fail(it, "the train has " + std::to_string(num_inputs) + " inputs: give 'input_speeds' (a list)");
      if (speed_key->second != 1.0 && !it.node.IsScalar())
        ctx.Fail(it, "'input_speed_rpm' takes a number; a function states its unit inside (w1_rpm, value_rpm, ...)");
      TimeFunction f = ToFunction(ctx, it, SpeedUnits());
      if (speed_key->second != 1.0) f = TimeFunction::Constant(ToNumber(ctx, it) * kRpmToRadPerS);
      g->input_speed_functions.push_back(f);
    }
  }
  for (const TimeFunction& f : g->input_speed_functions) g->input_speeds_rad_s.push_back(PeakValue(f, scene.simulation.end_time));
  if (g->input_speed_functions.empty()) g->input_speeds_rad_s.assign(num_inputs, 0.0);
  // Drive: speed (the inputs follow their speed functions), torque (input_torque on the first
  // input) or none (a free train).
  const std::string drive = m.Choice("drive", {"speed", "torque", "none"},
                                     speed_key ? "speed" : (m.Has("input_torque") || m.Has("output_torque")) ? "torque" : "none");
  if (drive == "speed" && !speed_key)
    m.FailMissing("input_speed", "'drive: speed' needs 'input_speed' (or 'input_speed_rpm', 'input_speeds')");
  // Torque: on the first input, or on the output (converted through the power flow).
  if (m.Has("input_torque") && m.Has("output_torque"))
    ctx.Fail(m.Need("output_torque"), "give either 'input_torque' or 'output_torque', not both");
  if (m.Has("input_torque")) g->input_torque_Nm = m.Number("input_torque");
  if (const auto t = m.Find("output_torque")) {
    Eigen::VectorXd w = Eigen::VectorXd::Ones(num_inputs);
    for (int i = 0; i < num_inputs; ++i)
      if (g->input_speeds_rad_s[i] != 0) w(i) = g->input_speeds_rad_s[i];
    try {
      const gears::PlanetaryKinematics k = gears::SolvePlanetaryKinematics(*train, g->range, w);
      const gears::PlanetaryPowerFlow p = gears::CalcPlanetaryPowerFlow(*train, k, train->output, m.Number("output_torque"));
      g->input_torque_Nm = p.port_torques_Nm(train->inputs[0]);
    } catch (const std::exception& e) {
      ctx.Fail(*t, e.what());
    }
  }
  if (drive == "torque" && g->input_torque_Nm == 0)
    ctx.Fail(section, "'drive: torque' needs a non-zero 'input_torque' or 'output_torque'");

  // Dynamics options; per-stage face widths become member overrides where none is given.
  TrainModelOptions& o = g->options;
  std::optional<Item> stiffness_item;
  std::optional<contact::TrainContactOptions> tooth_contact;
  g->mesh_stiffness = ReadDynamics(ctx, m.Find("dynamics"), *train, o, stiffness_item, tooth_contact);
  for (const StageRead& st : stages) {
    if (!st.face_width_m) continue;
    const gears::Stage& stage = *std::find_if(train->stages.begin(), train->stages.end(),
                                              [&](const gears::Stage& x) { return x.name == st.name; });
    if (o.face_width_m == 0) o.face_width_m = *st.face_width_m;
    for (int mi : stage.members)
      if (!o.members[train->members[mi].name].face_width_m) o.members[train->members[mi].name].face_width_m = st.face_width_m;
    for (int ps : stage.planet_sets)
      if (!o.members[train->planet_sets[ps].name].face_width_m) o.members[train->planet_sets[ps].name].face_width_m = st.face_width_m;
  }
  o.input = drive == "speed" ? TrainModelOptions::Input::kSpeed
            : drive == "torque" ? TrainModelOptions::Input::kTorque
                                : TrainModelOptions::Input::kNone;
  o.input_torque_Nm = g->input_torque_Nm;
  o.input_speeds_rad_s.clear();
  for (const TimeFunction& f : g->input_speed_functions) o.input_speeds_rad_s.push_back(f.Value(0.0));
  // MESH STIFFNESS HOOK: ISO 6336-1 c_gamma_alpha b, or the mean of the TVMS.
  if (g->mesh_stiffness == "iso6336" || g->mesh_stiffness == "tvms") {
    const TrainModelOptions geometry = o;
    const bool tvms = g->mesh_stiffness == "tvms";
    o.mesh_stiffness = [geometry, tvms](const PlanetaryTrain& t, int mesh, double) {
      const gears::GearPair pair = MakeTrainMeshPair(t, mesh, geometry);
      return tvms ? gears::CalcTvms(pair, TrainMeshTvmsOptions(t, mesh, geometry)).mean_n_per_m
                  : gears::CalcIso6336Stiffness(pair).c_gamma_alpha_n_per_m;
    };
  }
  // Build the model of the range; errors at the dynamics (or the range) they come from.
  const Item where = stiffness_item.value_or(m.Find("dynamics").value_or(section));
  gears::TrainModel tm;
  try {
    if (tooth_contact) {
      contact::TrainContactModel cm = contact::BuildTrainContactModel(*train, g->range, o, *tooth_contact);
      tm = std::move(cm.train_model);
      g->mesh_model = "contact";
      for (const contact::TrainContactMesh& c : cm.contacts) g->contact_meshes.push_back(c.name);
    } else {
      tm = gears::BuildTrainModel(*train, g->range, o);
    }
  } catch (const std::invalid_argument& e) {
    ctx.Fail(where, e.what());
  } catch (const std::runtime_error& e) {
    ctx.Fail(m.Find("range").value_or(section), e.what());
  }
  // The speed drivers follow the scene's functions (BuildTrainModel drives at constant speed).
  if (drive == "speed") {
    auto model = std::make_shared<Model>(*tm.model);
    for (int i = 0; i < num_inputs; ++i)
      for (Driver& d : model->drivers)
        if (d.spec.name == "drive_" + train->members[train->inputs[i]].name) d.spec.function = g->input_speed_functions[i];
    tm.model = model;
  }
  g->model = std::make_shared<const gears::TrainModel>(std::move(tm));
  scene.kind = SceneKind::kGearTrain;
  scene.model = g->model->model;
  scene.gear_train = g;
}

}  // namespace orrery::scene_reader

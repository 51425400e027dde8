// The `gear_train:` section into a GearTrainDescription (docs/scene_format.md, "gear_train"): the
// stages, connections, clutches, brakes, ranges, inputs and output, and the drive (input speeds
// and torques). Nothing is built here: names are checked against the names the stages will give
// (StageMemberNames), geometry and kinematics are the assembly's (gear_scene.cpp).
#include "import/gear_train_reader.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "import/unit_keys.h"

namespace orrery::scene_reader {
namespace {

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
    std::vector<std::string> keys{"teeth"};
    Append(keys, Names(RadiusKeys("tip")));
    const MapReader m(ctx, item, keys);
    g.teeth = ToInt(ctx, m.Need("teeth"));
    g.tip_radius_m = OptScaled(m, RadiusKeys("tip"), 0, true);
  }
  if (g.teeth < 1) ctx.Fail(item, "teeth must be >= 1, got " + std::to_string(g.teeth));
  return g;
}

// The keys a stage of `type` allows, and notes for keys of other types.
MapReader StageReader(const Context& ctx, const Item& item, const StageKeys& keys) {
  std::vector<std::string> allowed{"name", "type", "planets", "planet_angles", "planet_angles_deg",
                                   "planet_spacing", "addendum_coefficient"};
  for (const auto& group : {LengthMm("module"), Angle("pressure_angle"), Angle("helix_angle"), LengthMm("face_width")})
    Append(allowed, Names(group));
  Append(allowed, keys.gears);
  std::map<std::string, std::string> notes;
  for (const StageKeys& t : StageTypes())
    for (const std::string& g : t.gears)
      if (std::find(keys.gears.begin(), keys.gears.end(), g) == keys.gears.end())
        notes[g] = "a " + keys.type + " stage has the gears " + JoinQuoted(keys.gears);
  if (keys.type == "single_planet") Append(allowed, Names(RadiusKeys("pin_circle")));
  else
    for (const std::string& k : Names(RadiusKeys("pin_circle")))
      notes[k] = "the pin circle is set only for single_planet stages (others follow the gears)";
  return MapReader(ctx, item, allowed, notes);
}

// Tooth form, when the module is given.
std::optional<gears::ToothForm> ReadToothForm(const MapReader& m) {
  const Context& ctx = m.ctx();
  const auto module = ScaledOf(m, LengthMm("module"));
  if (!module) {
    for (const auto& group : {Angle("pressure_angle"), Angle("helix_angle"), Plain("addendum_coefficient")})
      if (const auto it = FindOneOf(m, group)) ctx.Fail(it->first, "a tooth form needs 'module_mm' (or 'module')");
    return std::nullopt;
  }
  gears::ToothForm f;
  f.normal_module_m = *module;
  if (!(f.normal_module_m > 0)) ctx.Fail(FindOneOf(m, LengthMm("module"))->first, "must be > 0");
  f.normal_pressure_angle_rad = ScaledOf(m, Angle("pressure_angle")).value_or(f.normal_pressure_angle_rad);
  f.helix_angle_rad = ScaledOf(m, Angle("helix_angle")).value_or(0.0);
  f.addendum_coefficient = m.Number("addendum_coefficient", 1.0);
  return f;
}

// Planet positions: explicit angles, equal spacing (default) or the assemblable positions
// nearest to equal spacing.
std::vector<double> ReadPlanetAngles(const MapReader& m, const std::string& type, int planets,
                                     const std::vector<gears::TrainGearSpec>& g) {
  std::vector<double> angles = AnglesOf(m, "planet_angles", planets).value_or(std::vector<double>{});
  const auto spacing = m.Find("planet_spacing");
  if (!spacing) return angles;
  if (!angles.empty()) m.ctx().Fail(*spacing, "give either planet_spacing or planet_angles, not both");
  if (m.Choice("planet_spacing", {"equal", "assemblable"}) != "assemblable") return angles;
  if (type == "ravigneaux")
    m.ctx().Fail(*spacing, "'assemblable' is for single_planet and double_planet stages; give planet_angles_deg");
  const int sum = type == "single_planet" ? g[0].teeth + g[2].teeth : g[3].teeth - g[0].teeth;
  try {
    return gears::AssemblablePlanetAngles(sum, planets);
  } catch (const std::invalid_argument& e) {
    m.ctx().Fail(*spacing, e.what());
  }
}

// One stage: its spec (by type) and face width.
void ReadStage(const Context& ctx, const Item& item, GearTrainRead& r) {
  std::vector<std::string> type_names;
  for (const StageKeys& t : StageTypes()) type_names.push_back(t.type);
  const std::string type = ItemType(ctx, item, type_names);
  const StageKeys& keys = *std::find_if(StageTypes().begin(), StageTypes().end(),
                                        [&](const StageKeys& t) { return t.type == type; });
  const MapReader m = StageReader(ctx, item, keys);
  const std::string name = ToString(ctx, m.Need("name"));
  if (!m.Has("planets")) m.FailMissing("planets", "missing required key 'planets'");
  const int planets = m.Int("planets", 0);
  if (planets < 1) ctx.Fail(m.Need("planets"), "must be >= 1, got " + std::to_string(planets));
  const std::optional<gears::ToothForm> form = ReadToothForm(m);
  if (const auto b = FindOneOf(m, LengthMm("face_width"))) {
    const double width = ToNumber(ctx, b->first) * b->second;
    if (!(width > 0)) ctx.Fail(b->first, "must be > 0");
    r.description.train.stage_face_widths_m[name] = width;
  }
  std::vector<gears::TrainGearSpec> g;
  for (const std::string& k : keys.gears) g.push_back(ReadTrainGear(ctx, m.Need(k)));
  const std::vector<double> angles = ReadPlanetAngles(m, type, planets, g);
  gears::StageSpec spec;
  if (type == "single_planet")
    spec = gears::SinglePlanetStageSpec{.name = name, .sun = g[0], .planet = g[1], .ring = g[2],
                                        .num_planets = planets, .tooth_form = form, .planet_angles_rad = angles,
                                        .pin_radius_m = OptScaled(m, RadiusKeys("pin_circle"), 0, true)};
  else if (type == "double_planet")
    spec = gears::DoublePlanetStageSpec{.name = name, .sun = g[0], .inner_planet = g[1], .outer_planet = g[2],
                                        .ring = g[3], .num_planets = planets, .tooth_form = form,
                                        .planet_angles_rad = angles};
  else
    spec = gears::RavigneauxStageSpec{.name = name, .small_sun = g[0], .large_sun = g[1], .short_planet = g[2],
                                      .long_planet = g[3], .ring = g[4], .num_planets = planets,
                                      .tooth_form = form, .planet_angles_rad = angles};
  r.description.train.stages.push_back(spec);
  r.sources.stages.emplace_back(name, m);
}

// A member name of the train being read, with suggestions.
std::string MemberRef(const Context& ctx, const Item& item, const gears::PlanetaryTrainDescription& train) {
  const std::string name = ToString(ctx, item);
  const std::vector<std::string> known = NamesOf(train).members;
  if (std::find(known.begin(), known.end(), name) != known.end()) return name;
  ctx.Fail(item, "no member named '" + name + "'" + SuggestOrList(name, known, "members"));
}

// Connections and clutches {name, between: [member, member]}, brakes {name, member}.
void ReadCouplings(const Context& ctx, const MapReader& m, GearTrainRead& r) {
  gears::PlanetaryTrainDescription& t = r.description.train;
  auto couplings = [&](const std::string& key, std::vector<gears::CouplingSpec>& to) {
    for (const Item& item : ListItems(ctx, m.Find(key))) {
      const MapReader c(ctx, item, {"name", "between"});
      const std::string name = ToString(ctx, c.Need("name"));
      const Item between = c.Need("between");
      if (!between.node.IsSequence() || between.node.size() != 2)
        ctx.Fail(between, "expected a list of 2 member names, got " + Describe(between.node));
      to.push_back({name, MemberRef(ctx, Element(between, 0), t), MemberRef(ctx, Element(between, 1), t)});
      r.sources.couplings.emplace_back(name, item);
    }
  };
  couplings("connections", t.connections);
  couplings("clutches", t.clutches);
  for (const Item& item : ListItems(ctx, m.Find("brakes"))) {
    const MapReader c(ctx, item, {"name", "member"});
    const std::string name = ToString(ctx, c.Need("name"));
    t.brakes.push_back({name, MemberRef(ctx, c.Need("member"), t)});
    r.sources.couplings.emplace_back(name, item);
  }
}

// Ranges: {NAME: [engaged clutches and brakes], ...} in order.
void ReadRanges(const Context& ctx, const MapReader& m, GearTrainRead& r) {
  gears::PlanetaryTrainDescription& t = r.description.train;
  std::vector<std::string> engageable;
  for (const gears::CouplingSpec& c : t.clutches) engageable.push_back(c.name);
  for (const gears::BrakeSpec& b : t.brakes) engageable.push_back(b.name);
  const Item ranges = m.Need("ranges");
  if (!ranges.node.IsMap() || ranges.node.size() == 0)
    ctx.Fail(ranges, "expected a map of gear ranges (NAME: [engaged clutches and brakes]), got " + Describe(ranges.node));
  for (auto it = ranges.node.begin(); it != ranges.node.end(); ++it) {
    const std::string name = it->first.IsScalar() ? it->first.Scalar() : "?";
    const Item entry{it->second, ranges.path + "." + name, it->first.Mark()};
    gears::RangeSpec range{.name = name};
    if (!entry.node.IsNull()) {
      if (!entry.node.IsSequence()) ctx.Fail(entry, "expected a list of clutch and brake names, got " + Describe(entry.node));
      for (size_t i = 0; i < entry.node.size(); ++i) {
        const Item e = Element(entry, i);
        const std::string en = ToString(ctx, e);
        if (std::find(engageable.begin(), engageable.end(), en) == engageable.end())
          ctx.Fail(e, "no clutch or brake named '" + en + "'" + SuggestOrList(en, engageable, "clutches and brakes"));
        if (std::find(range.engaged.begin(), range.engaged.end(), en) != range.engaged.end())
          ctx.Fail(e, "'" + en + "' listed twice");
        range.engaged.push_back(en);
      }
    }
    for (const gears::RangeSpec& other : t.ranges)
      if (other.name == name) ctx.Fail(entry, "duplicate gear range '" + name + "'");
    t.ranges.push_back(range);
    r.sources.ranges.emplace_back(name, entry);
  }
  if (const auto range = m.Find("range")) {
    const std::string name = ToString(ctx, *range);
    std::vector<std::string> known;
    for (const gears::RangeSpec& x : t.ranges) known.push_back(x.name);
    if (std::find(known.begin(), known.end(), name) == known.end())
      ctx.Fail(*range, "no gear range named '" + name + "'" + SuggestOrList(name, known, "ranges"));
    r.description.range = name;
    r.sources.range = range;
  }
}

// Inputs (a list of members) and the output.
void ReadPorts(const Context& ctx, const MapReader& m, GearTrainRead& r) {
  gears::PlanetaryTrainDescription& t = r.description.train;
  const Item inputs = m.Need("inputs");
  if (!inputs.node.IsSequence() || inputs.node.size() == 0)
    ctx.Fail(inputs, "expected a list of input member names, got " + Describe(inputs.node));
  for (size_t i = 0; i < inputs.node.size(); ++i) {
    const Item e = Element(inputs, i);
    const std::string name = MemberRef(ctx, e, t);
    if (std::find(t.inputs.begin(), t.inputs.end(), name) != t.inputs.end())
      ctx.Fail(e, "input: member '" + name + "' is already an input");
    t.inputs.push_back(name);
  }
  t.output = MemberRef(ctx, m.Need("output"), t);
  r.sources.inputs = inputs;
  r.sources.output = m.Need("output");
}

// Input speeds: one function per input (input_speed for one input, input_speeds for several).
std::optional<Item> ReadSpeeds(const Context& ctx, const MapReader& m, double end_time, GearTrainRead& r) {
  const int num_inputs = static_cast<int>(r.description.train.inputs.size());
  const auto speed_key = FindOneOf(m, {{"input_speed", 1.0}, {"input_speed_rpm", kRpmToRadPerS}, {"input_speeds", 1.0}});
  if (speed_key) {
    const Item& it = speed_key->first;
    if (it.path.ends_with("input_speeds")) {
      if (!it.node.IsSequence() || static_cast<int>(it.node.size()) != num_inputs)
        ctx.Fail(it, "expected a list of " + std::to_string(num_inputs) + " speeds (one per input), got " + Describe(it.node));
      for (int i = 0; i < num_inputs; ++i) r.input_speed_functions.push_back(ToFunction(ctx, Element(it, i), SpeedUnits()));
    } else {
      if (num_inputs != 1)
        ctx.Fail(it, "the train has " + std::to_string(num_inputs) + " inputs: give 'input_speeds' (a list)");
      if (speed_key->second != 1.0 && !it.node.IsScalar())
        ctx.Fail(it, "'input_speed_rpm' takes a number; a function states its unit inside (w1_rpm, value_rpm, ...)");
      TimeFunction f = ToFunction(ctx, it, SpeedUnits());
      if (speed_key->second != 1.0) f = TimeFunction::Constant(ToNumber(ctx, it) * kRpmToRadPerS);
      r.input_speed_functions.push_back(f);
    }
  }
  for (const TimeFunction& f : r.input_speed_functions) r.input_speeds_rad_s.push_back(PeakValue(f, end_time));
  if (r.input_speed_functions.empty()) r.input_speeds_rad_s.assign(num_inputs, 0.0);
  return speed_key ? std::optional<Item>(speed_key->first) : std::nullopt;
}

// Drive: speed (the inputs follow their speed functions), torque (input_torque on the first
// input, or output_torque through the power flow) or none (a free train).
void ReadDrive(const Context& ctx, const MapReader& m, const Item& section, double end_time, GearTrainRead& r) {
  gears::TrainModelOptions& o = r.description.options;
  const std::optional<Item> speed_key = ReadSpeeds(ctx, m, end_time, r);
  const bool torque_given = m.Has("input_torque") || m.Has("output_torque");
  const std::string drive = m.Choice("drive", {"speed", "torque", "none"}, speed_key ? "speed" : torque_given ? "torque" : "none");
  if (drive == "speed" && !speed_key)
    m.FailMissing("input_speed", "'drive: speed' needs 'input_speed' (or 'input_speed_rpm', 'input_speeds')");
  if (m.Has("input_torque") && m.Has("output_torque"))
    ctx.Fail(m.Need("output_torque"), "give either 'input_torque' or 'output_torque', not both");
  if (m.Has("input_torque")) o.input_torque_n_m = m.Number("input_torque");
  if (m.Has("output_torque")) {
    // A number, or a function of time (a load taken up gradually): the power flow and the
    // kinematics use its value of largest magnitude over the run, the output carries it as written.
    const Item it = m.Need("output_torque");
    if (it.node.IsScalar()) {
      o.output_port_torque_n_m = m.Number("output_torque");
    } else {
      if (drive != "speed")
        ctx.Fail(it, "'output_torque' as a function needs 'drive: speed' (a torque-driven input keeps its constant torque)");
      const TimeFunction f = ToFunction(ctx, it, FunctionUnits{});
      o.output_port_torque_n_m = PeakValue(f, end_time);
      o.output_torque_n_m = f;
    }
    o.operating_speeds_rad_s = r.input_speeds_rad_s;
  }
  if (drive == "torque" && o.input_torque_n_m == 0 && o.output_port_torque_n_m.value_or(0) == 0)
    ctx.Fail(section, "'drive: torque' needs a non-zero 'input_torque' or 'output_torque'");
  o.input = drive == "speed" ? gears::TrainModelOptions::Input::kSpeed
            : drive == "torque" ? gears::TrainModelOptions::Input::kTorque
                                : gears::TrainModelOptions::Input::kNone;
  if (drive == "speed") {
    o.input_speed_functions = r.input_speed_functions;
  } else {
    for (const TimeFunction& f : r.input_speed_functions) o.input_speeds_rad_s.push_back(f.Value(0.0));
  }
}

}  // namespace

// Tooth counts of a stage's gears, in the order of its member then planet-set names (carriers
// skipped).
std::vector<int> StageTeeth(const gears::StageSpec& stage) {
  if (const auto* s = std::get_if<gears::SinglePlanetStageSpec>(&stage)) return {s->sun.teeth, s->ring.teeth, s->planet.teeth};
  if (const auto* s = std::get_if<gears::DoublePlanetStageSpec>(&stage))
    return {s->sun.teeth, s->ring.teeth, s->inner_planet.teeth, s->outer_planet.teeth};
  const auto& s = std::get<gears::RavigneauxStageSpec>(stage);
  return {s.small_sun.teeth, s.large_sun.teeth, s.ring.teeth, s.short_planet.teeth, s.long_planet.teeth};
}

TrainNames NamesOf(const gears::PlanetaryTrainDescription& train) {
  TrainNames n;
  for (const gears::StageSpec& s : train.stages) {
    const std::vector<int> teeth = StageTeeth(s);
    size_t next = 0;
    for (const std::string& m : gears::StageMemberNames(s))
      if (!m.ends_with(".carrier")) n.gear_teeth[m] = teeth[next++];
    for (const std::string& p : gears::StagePlanetSetNames(s)) {
      n.gear_teeth[p] = teeth[next++];
      n.set_planets[p] = gears::StagePlanetCount(s);
    }
    for (const std::string& m : gears::StageMemberNames(s)) {
      n.members.push_back(m);
      if (!m.ends_with(".carrier")) n.gears.push_back(m);
    }
    for (const std::string& p : gears::StagePlanetSetNames(s)) {
      n.planet_sets.push_back(p);
      n.gears.push_back(p);
      for (int i = 1; i <= gears::StagePlanetCount(s); ++i) n.planets.push_back(p + std::to_string(i));
    }
    for (const std::string& mesh : gears::StageMeshNames(s)) {
      n.meshes.push_back(mesh);
      for (int i = 1; i <= gears::StagePlanetCount(s); ++i) n.branches.push_back(mesh + "#" + std::to_string(i));
    }
  }
  return n;
}

GearTrainRead ReadGearTrainDescription(const Context& ctx, const Item& section, double end_time) {
  const std::vector<std::string> allowed{"stages", "connections", "clutches", "brakes", "ranges", "inputs",
                                         "output", "range", "drive", "input_speeds", "input_torque",
                                         "output_torque", "dynamics", "input_speed", "input_speed_rpm"};
  const MapReader m(ctx, section, allowed, {{"seed", "scenes spell the train out (stages, connections, ...); "
                                                     "there is no seed shortcut"}});
  GearTrainRead r;
  r.sources.section = section;
  const std::vector<Item> stage_items = ListItems(ctx, m.Need("stages"));
  if (stage_items.empty()) ctx.Fail(m.Need("stages"), "a gear train needs at least one stage");
  for (const Item& item : stage_items) ReadStage(ctx, item, r);
  ReadCouplings(ctx, m, r);
  ReadRanges(ctx, m, r);
  ReadPorts(ctx, m, r);
  ReadDrive(ctx, m, section, end_time, r);
  r.sources.dynamics = m.Find("dynamics");
  ReadTrainDynamics(ctx, m.Find("dynamics"), r);
  return r;
}

}  // namespace orrery::scene_reader

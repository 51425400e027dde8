// `sensors:` and `output.sensors:` of a scene -> ModelBuilder::AddSensor, SensorSamplingOptions.
#include "import/sensor_reader.h"

#include <string>
#include <vector>

namespace orrery::scene_reader {
namespace {

const std::vector<std::pair<std::string, SensorKind>>& SensorTypes() {
  static const std::vector<std::pair<std::string, SensorKind>> kTypes{
      {"accelerometer", SensorKind::kAccelerometer},
      {"velocity", SensorKind::kVelocity},
      {"displacement", SensorKind::kDisplacement},
      {"gyroscope", SensorKind::kGyroscope},
      {"angular_accelerometer", SensorKind::kAngularAccelerometer},
      {"encoder", SensorKind::kEncoder},
      {"tachometer", SensorKind::kTachometer},
      {"gear_mesh", SensorKind::kGearMesh},
      {"element_output", SensorKind::kElementOutput}};
  return kTypes;
}

// The index of the element named by `key` among `names`, or an error at the key.
int ResolveName(const MapReader& m, const std::string& key, const std::vector<std::string>& names,
                const std::string& kind, const std::string& plural) {
  const Item item = m.Need(key);
  const std::string name = ToString(m.ctx(), item);
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  m.ctx().Fail(item, "no " + kind + " named '" + name + "'" + SuggestOrList(name, names, plural));
}

std::vector<std::string> BodyNames(const Model& m) {
  std::vector<std::string> names;
  for (const Body& b : m.bodies) names.push_back(b.name);
  return names;
}
std::vector<std::string> FrameNames(const Model& m) {
  std::vector<std::string> names;
  for (const Frame& f : m.frames) names.push_back(f.name);
  return names;
}

// axes: [x, y, z] (any 1 to 3 of them, in the order to record).
std::vector<int> ReadAxes(const Context& ctx, const Item& it) {
  if (!it.node.IsSequence() || it.node.size() < 1 || it.node.size() > 3)
    ctx.Fail(it, "expected a list of 1 to 3 axes out of x, y, z, got " + Describe(it.node));
  std::vector<int> axes;
  for (size_t i = 0; i < it.node.size(); ++i) {
    const Item a = Element(it, i);
    const std::string name = ToString(ctx, a);
    if (name != "x" && name != "y" && name != "z")
      ctx.Fail(a, "unknown axis '" + name + "' (axes: x, y, z)");
    const int k = name[0] - 'x';
    if (std::find(axes.begin(), axes.end(), k) != axes.end()) ctx.Fail(a, "axis " + name + " given twice");
    axes.push_back(k);
  }
  return axes;
}

// Where a frame sensor sits: `frame`, or `body` with `position`/`rotation` (the sensor's pose on
// the body's own frame: no frame is added) or `node` (a node frame "sensor:<name>").
void ReadSensorPlace(const MapReader& m, const std::string& name, double length_unit, ModelBuilder& b,
                     SensorSpec& spec) {
  const Context& ctx = m.ctx();
  const Model& draft = b.draft();
  if (m.Has("frame")) {
    for (const char* key : {"body", "position", "rotation", "node"})
      if (const auto it = m.Find(key))
        ctx.Fail(*it, std::string("give either 'frame' or 'body' (with position, rotation, node), not both"));
    spec.frame = ResolveName(m, "frame", FrameNames(draft), "frame", "frames");
    return;
  }
  if (!m.Has("body")) m.FailMissing("frame", "missing 'frame' (or 'body' with 'position' or 'node')");
  const BodyIndex body = ResolveName(m, "body", BodyNames(draft), "body", "bodies");
  Transform X;
  if (const auto r = m.Find("rotation")) X.R = ToRotation(ctx, *r);
  if (const auto node_item = m.Find("node")) {
    // A node of a flexible body (by its FE id): the frame follows the node's elastic motion.
    if (draft.bodies[body].flexible < 0)
      ctx.Fail(*node_item, "body '" + draft.bodies[body].name + "' is rigid; 'node' is for flexible bodies");
    const int id = ToInt(ctx, *node_item);
    const int node = Build(m, {{"node", "node"}}, [&] { return b.FindNode(body, id); });
    const auto& modes = *draft.flexible_bodies[draft.bodies[body].flexible].modes;
    X.p = m.Has("position") ? Vec3(m.Vector("position", Vec3::Zero()) * length_unit)
                            : modes.nodes[node].position;
    spec.frame = Build(m, {{"frame", "name"}}, [&] { return b.AddNodeFrame("sensor:" + name, body, node, X); });
    return;
  }
  X.p = m.Vector("position", Vec3::Zero()) * length_unit;
  spec.frame = b.body_frame(body);
  spec.X_FS = X;
}

void ReadSensor(const Context& ctx, const Item& item, double length_unit, ModelBuilder& b) {
  std::vector<std::string> type_names;
  for (const auto& [n, k] : SensorTypes()) type_names.push_back(n);
  const std::string type = ItemType(ctx, item, type_names);
  SensorSpec spec;
  for (const auto& [n, k] : SensorTypes())
    if (n == type) spec.kind = k;
  // The keys of each type; others are refused with the reason.
  const bool frame_kind = spec.kind == SensorKind::kAccelerometer || spec.kind == SensorKind::kVelocity ||
                          spec.kind == SensorKind::kDisplacement || spec.kind == SensorKind::kGyroscope ||
                          spec.kind == SensorKind::kAngularAccelerometer;
  const bool joint_kind = spec.kind == SensorKind::kEncoder || spec.kind == SensorKind::kTachometer;
  std::vector<std::string> allowed{"name", "type"};
  std::map<std::string, std::string> notes;
  auto keys = [&](bool here, std::initializer_list<const char*> list, const std::string& note) {
    for (const char* k : list) {
      if (here) allowed.push_back(k);
      else notes[k] = note;
    }
  };
  const std::string a = "a " + type + " sensor ";
  keys(frame_kind, {"frame", "body", "position", "rotation", "node", "measured_in", "axes"},
       a + "reads no frame");
  keys(joint_kind, {"joint", "coordinate"}, a + "reads no joint");
  keys(spec.kind == SensorKind::kAccelerometer, {"include_gravity"}, "only accelerometers sense gravity");
  keys(spec.kind == SensorKind::kGearMesh, {"mesh", "quantity"}, a + "reads no gear mesh");
  keys(spec.kind == SensorKind::kElementOutput, {"element", "output"}, a + "reads no element output");
  const MapReader m(ctx, item, allowed, notes);
  spec.name = m.String("name");
  const Model& draft = b.draft();
  if (frame_kind) {
    ReadSensorPlace(m, spec.name, length_unit, b, spec);
    // measured_in: sensor (own axes) | world | a frame; a displacement defaults to the world.
    const bool displacement = spec.kind == SensorKind::kDisplacement;
    const std::string in = m.Has("measured_in") ? ToString(ctx, m.Need("measured_in"))
                                                : (displacement ? "world" : "sensor");
    if (in == "sensor") spec.measured_in = kSensorAxes;
    else if (in == "world") spec.measured_in = kWorldFrame;
    else spec.measured_in = ResolveName(m, "measured_in", FrameNames(draft), "frame", "frames");
    if (const auto axes = m.Find("axes")) spec.axes = ReadAxes(ctx, *axes);
    spec.include_gravity = m.Bool("include_gravity", false);
  } else if (joint_kind) {
    std::vector<std::string> joints;
    for (const Joint& j : draft.joints) joints.push_back(j.spec.name);
    spec.joint = ResolveName(m, "joint", joints, "joint", "joints");
    spec.coordinate = m.Int("coordinate", 0);
  } else if (spec.kind == SensorKind::kGearMesh) {
    std::vector<std::string> meshes;
    for (const GearMesh& g : draft.gear_meshes) meshes.push_back(g.spec.name);
    spec.gear_mesh = ResolveName(m, "mesh", meshes, "lumped gear mesh", "lumped gear meshes");
    const std::string q = m.Choice("quantity", {"force", "deflection", "transmission_error"}, "force");
    spec.mesh_quantity = q == "force" ? MeshQuantity::kForce
                         : q == "deflection" ? MeshQuantity::kDeflection
                                             : MeshQuantity::kTransmissionError;
  } else {
    std::vector<std::string> elements;
    for (const auto& e : draft.external_forces) elements.push_back(e->name());
    spec.element = ResolveName(m, "element", elements, "element", "elements with outputs");
    spec.output = m.String("output");
  }
  Build(m, {{"name already used", "name"}, {"axes", "axes"}, {"relative to", "measured_in"},
            {"measured_in", "measured_in"}, {"coordinate", "coordinate"}, {"quaternion", "coordinate"},
            {"output", "output"}},
        [&] { b.AddSensor(spec); });
}

// One sensor of a gear-train scene (ReadTrainSensors).
gears::TrainSensor ReadTrainSensor(const Context& ctx, const Item& item) {
  std::vector<std::string> type_names;
  for (const auto& [n, k] : SensorTypes())
    if (k != SensorKind::kElementOutput) type_names.push_back(n);
  const std::string type = ItemType(ctx, item, type_names);
  gears::TrainSensor s;
  for (const auto& [n, k] : SensorTypes())
    if (n == type) s.kind = k;
  const bool point = s.kind != SensorKind::kEncoder && s.kind != SensorKind::kTachometer &&
                     s.kind != SensorKind::kGearMesh;
  const bool joint = s.kind == SensorKind::kEncoder || s.kind == SensorKind::kTachometer;
  std::vector<std::string> allowed{"name", "type"};
  std::map<std::string, std::string> notes;
  auto keys = [&](bool here, std::initializer_list<const char*> list, const std::string& note) {
    for (const char* k : list) {
      if (here) allowed.push_back(k);
      else notes[k] = note;
    }
  };
  const std::string a = "a " + type + " sensor ";
  keys(point, {"body", "node", "position", "rotation", "measured_in", "axes"}, a + "sits on no body point");
  keys(joint, {"joint", "coordinate"}, a + "reads no joint");
  keys(s.kind == SensorKind::kAccelerometer, {"include_gravity"}, "only accelerometers sense gravity");
  keys(s.kind == SensorKind::kGearMesh, {"mesh", "quantity"}, a + "reads no gear mesh");
  const MapReader m(ctx, item, allowed, notes);
  s.name = m.String("name");
  if (point) {
    s.body = m.String("body");
    if (const auto node = m.Find("node")) s.node = ToInt(ctx, *node);
    if (m.Has("position")) s.position_m = m.Vector("position", Vec3::Zero());
    if (const auto r = m.Find("rotation")) s.rotation = ToRotation(ctx, *r);
    if (m.Has("measured_in")) s.measured_in = m.String("measured_in");
    else if (s.kind == SensorKind::kDisplacement) s.measured_in = "world";
    if (const auto axes = m.Find("axes")) s.axes = ReadAxes(ctx, *axes);
    s.include_gravity = m.Bool("include_gravity", false);
  } else if (joint) {
    s.joint = m.String("joint");
    s.coordinate = m.Int("coordinate", -1);
    if (m.Has("coordinate") && s.coordinate < 0) ctx.Fail(m.Need("coordinate"), "must be >= 0");
  } else {
    s.mesh = m.String("mesh");
    const std::string q = m.Choice("quantity", {"force", "deflection", "transmission_error"}, "force");
    s.quantity = q == "force" ? MeshQuantity::kForce
                 : q == "deflection" ? MeshQuantity::kDeflection
                                     : MeshQuantity::kTransmissionError;
  }
  return s;
}

}  // namespace

void ReadSensors(const Context& ctx, const std::optional<Item>& list, double length_unit,
                 ModelBuilder& builder) {
  for (const Item& item : ListItems(ctx, list)) ReadSensor(ctx, item, length_unit, builder);
}

std::vector<gears::TrainSensor> ReadTrainSensors(const Context& ctx, const std::optional<Item>& list,
                                                 std::vector<std::pair<std::string, Item>>& items) {
  std::vector<gears::TrainSensor> sensors;
  for (const Item& item : ListItems(ctx, list)) {
    sensors.push_back(ReadTrainSensor(ctx, item));
    for (const auto& [name, earlier] : items)
      if (name == sensors.back().name) ctx.Fail(item, "sensor name '" + name + "' already used");
    items.emplace_back(sensors.back().name, item);
  }
  return sensors;
}

SensorSamplingOptions ReadSensorSampling(const Context& ctx, const Item& item) {
  const MapReader m(ctx, item, {"anti_alias", "oversampling", "passband_fraction",
                                "stopband_attenuation_db"});
  SensorSamplingOptions o;
  o.anti_alias = m.Bool("anti_alias", o.anti_alias);
  o.oversampling = m.Int("oversampling", o.oversampling);
  if (o.oversampling < 0 || o.oversampling > 1000)
    ctx.Fail(m.Need("oversampling"), "must be in 1..1000 (0: automatic), got " + std::to_string(o.oversampling));
  o.passband_fraction = m.Number("passband_fraction", o.passband_fraction);
  if (!(o.passband_fraction > 0 && o.passband_fraction < 1))
    ctx.Fail(m.Need("passband_fraction"), "must be in (0, 1) (the passband edge over the Nyquist "
                                          "frequency), got " + Num(o.passband_fraction));
  o.stopband_attenuation_db = m.Number("stopband_attenuation_db", o.stopband_attenuation_db);
  if (!(o.stopband_attenuation_db >= 20 && o.stopband_attenuation_db <= 200))
    ctx.Fail(m.Need("stopband_attenuation_db"), "must be in [20, 200] dB, got " + Num(o.stopband_attenuation_db));
  if (!o.anti_alias)
    for (const char* key : {"oversampling", "passband_fraction", "stopband_attenuation_db"})
      if (const auto it = m.Find(key)) ctx.Fail(*it, "has no effect with anti_alias: false (point sampling)");
  return o;
}

}  // namespace orrery::scene_reader

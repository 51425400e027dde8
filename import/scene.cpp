// Scene files: YAML text -> validated ModelBuilder calls -> Model + SimulationOptions.
//
// Reading is strict: every map is checked against its allowed keys before anything is read, so a
// misspelt key is reported as unknown (with a suggestion) rather than as a missing one. Every
// error names the file, the 1-based line and the key path ("bodies[crank].mass"); values set by
// --set overrides are reported as "--set KEY" instead of a line. The schema: docs/scene_format.md.
#include "import/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <regex>
#include <sstream>
#include <utility>

#include <Eigen/SVD>
#include <yaml-cpp/yaml.h>

#include "contact/contact_element.h"
#include "contact/contact_surface.h"
#include "import/gear_scene.h"
#include "import/length_unit.h"
#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/scene_reader.h"
#include "import/sensor_reader.h"
#include "import/solid_mesh.h"
#include "import/surface_mesh.h"
#include "mbd/file_checks.h"

namespace orrery {
namespace {

using namespace scene_reader;

// ---------------------------------------------------------------------------------------------
// Joint coordinates and their units

// Kind of position coordinate k (velocity == false) or velocity coordinate k of a joint type
// (joint_types.h); the angular velocity of a quaternion block is read as angle rates.
CoordinateKind KindOf(JointType type, int k, bool velocity) {
  const JointTypeInfo& info = JointInfo(type);
  if (!velocity) return info.q_kind[k];
  return info.v_kind[k] == CoordinateKind::kQuaternion ? CoordinateKind::kAngle : info.v_kind[k];
}

bool HasAngularCoordinate(JointType type) {
  const JointTypeInfo& info = JointInfo(type);
  for (int k = 0; k < info.nv; ++k)
    if (info.v_kind[k] != CoordinateKind::kLength) return true;
  return false;
}

// Type names for joints (all types) or loop closures (the types that constrain something).
std::vector<std::string> JointTypeNames(bool loop_closure = false) {
  std::vector<std::string> names;
  for (const JointTypeInfo& info : AllJointTypes())
    if (loop_closure ? info.loop_rows > 0 : info.position != nullptr) names.emplace_back(info.name);
  return names;
}

// The type of a name taken from JointTypeNames().
JointType JointTypeFromName(const std::string& name) {
  JointType type = JointType::kRevolute;
  JointTypeFromName(std::string_view(name), &type);
  return type;
}

// ---------------------------------------------------------------------------------------------
// The loader

class Loader {
 public:
  Loader(Context& ctx, std::string default_name) : ctx_(ctx), name_(std::move(default_name)) {}

  Scene Load(const YAML::Node& root);

 private:
  struct Named {
    int index = -1;
    Item item;
  };

  void ReadUnits(const MapReader& root);
  void ReadBodies(const MapReader& root);
  // A body's `mesh:` map: the surface read, checked and oriented, its mass properties.
  MassProperties ReadBodyMesh(const std::string& body, const Item& item);
  void ReadContact(const Item& item, int index);
  void ReadFrame(const Item& item, BodyIndex body);
  void ReadJoints(const MapReader& root);
  void ReadLoopClosures(const MapReader& root);
  void ReadDrivers(const MapReader& root);
  void ReadForceElements(const MapReader& root);
  void ReadSolver(const MapReader& root, Scene& scene);
  void ReadOutput(const MapReader& root, Scene& scene);

  // Registers a unique name of `kind` (duplicates are errors naming the first definition).
  std::string UniqueName(const MapReader& m, std::map<std::string, Named>& table,
                         const std::string& kind, int index);
  // References by name, resolved with suggestions.
  int Resolve(const MapReader& m, const std::string& key, const std::map<std::string, Named>& table,
              const std::string& kind) const;
  BodyIndex BodyRef(const MapReader& m, const std::string& key) const;
  FrameIndex FrameRef(const MapReader& m, const std::string& key) const;
  JointIndex JointRef(const MapReader& m, const std::string& key) const;
  // The coordinate index of a joint (default 0), checked against the joint's velocity count.
  int CoordinateOf(const MapReader& m, JointIndex joint) const;
  JointType TypeOf(JointIndex joint) const { return builder_.draft().joints[joint].spec.type; }
  // {position, rotation} pose, or (joint frames) the name of a frame on `body`.
  Transform ToPose(const Item& it, BodyIndex body, bool allow_frame_name) const;
  // initial_position / initial_velocity of a joint: scalar or list, converted to SI.
  std::optional<Eigen::VectorXd> JointValues(const MapReader& m, const std::string& key,
                                             JointType type, bool velocity) const;

  double Length(double x) const { return x * length_; }
  Vec3 Length(const Vec3& x) const { return x * length_; }

  Context& ctx_;
  std::string name_;
  double length_ = 1.0;  // metres per scene length unit
  ModelBuilder builder_;
  std::map<std::string, Named> bodies_, frames_, joints_, loops_, drivers_, forces_;
  // Contact surfaces of bodies with a `mesh:` (body frame, m): the region's triangles.
  std::map<std::string, TriangleMesh> surfaces_;
};

std::string Loader::UniqueName(const MapReader& m, std::map<std::string, Named>& table,
                               const std::string& kind, int index) {
  const Item item = m.Need("name");
  const std::string name = ToString(ctx_, item);
  const auto it = table.find(name);
  if (it != table.end())
    ctx_.Fail(item, "duplicate " + kind + " name '" + name + "'" +
                        (it->second.item.mark.line >= 0
                             ? " (first defined at line " +
                                   std::to_string(it->second.item.mark.line + 1) + ")"
                             : ""));
  table[name] = Named{index, m.item()};
  return name;
}

int Loader::Resolve(const MapReader& m, const std::string& key,
                    const std::map<std::string, Named>& table, const std::string& kind) const {
  const Item item = m.Need(key);
  const std::string name = ToString(ctx_, item);
  const auto it = table.find(name);
  if (it != table.end()) return it->second.index;
  std::vector<std::string> known;
  for (const auto& [n, named] : table) known.push_back(n);
  const std::string plural = kind == "body" ? "bodies" : kind + "s";
  ctx_.Fail(item, "no " + kind + " named '" + name + "'" + SuggestOrList(name, known, plural));
}

BodyIndex Loader::BodyRef(const MapReader& m, const std::string& key) const {
  return Resolve(m, key, bodies_, "body");
}
FrameIndex Loader::FrameRef(const MapReader& m, const std::string& key) const {
  return Resolve(m, key, frames_, "frame");
}
JointIndex Loader::JointRef(const MapReader& m, const std::string& key) const {
  return Resolve(m, key, joints_, "joint");
}

int Loader::CoordinateOf(const MapReader& m, JointIndex joint) const {
  const int k = m.Int("coordinate", 0);
  const Joint& j = builder_.draft().joints[joint];
  if (k < 0 || k >= j.nv)
    ctx_.Fail(m.Need("coordinate"), "joint '" + j.spec.name + "' (" + JointTypeName(j.spec.type) +
                                        ") has coordinates 0.." + std::to_string(j.nv - 1) +
                                        ", got " + std::to_string(k));
  return k;
}

Transform Loader::ToPose(const Item& it, BodyIndex body, bool allow_frame_name) const {
  // A frame name: its pose on its body, which must be `body`.
  if (allow_frame_name && it.node.IsScalar()) {
    const std::string name = ToString(ctx_, it);
    const auto f = frames_.find(name);
    if (f == frames_.end()) {
      std::vector<std::string> known;
      for (const auto& [n, named] : frames_)
        if (builder_.draft().frames[named.index].body == body) known.push_back(n);
      ctx_.Fail(it, "no frame named '" + name + "'" +
                        SuggestOrList(name, known, "frames on body '" +
                                                       builder_.draft().bodies[body].name + "'"));
    }
    const Frame& frame = builder_.draft().frames[f->second.index];
    if (frame.body != body)
      ctx_.Fail(it, "frame '" + name + "' is on body '" + builder_.draft().bodies[frame.body].name +
                        "', not on '" + builder_.draft().bodies[body].name + "'");
    return frame.X_BF;
  }
  const MapReader m(ctx_, it, {"position", "rotation"});
  Transform X;
  X.p = Length(m.Vector("position", Vec3::Zero()));
  if (const auto r = m.Find("rotation")) X.R = ToRotation(ctx_, *r);
  return X;
}

std::optional<Eigen::VectorXd> Loader::JointValues(const MapReader& m, const std::string& key,
                                                   JointType type, bool velocity) const {
  const auto found = m.FindScaled(key, {{"", 1.0}, {"_deg", kDegToRad}});
  if (!found) return std::nullopt;
  const auto& [item, angle_factor] = *found;
  const int n = velocity ? JointNv(type) : JointNq(type);
  std::vector<double> x;
  if (item.node.IsScalar() && n == 1) {
    x.push_back(ToNumber(ctx_, item));
  } else if (item.node.IsScalar()) {
    ctx_.Fail(item, std::string("a ") + JointTypeName(type) + " joint has " + std::to_string(n) +
                        " " + (velocity ? "velocity" : "position") +
                        " coordinates: expected a list of " + std::to_string(n) + " numbers, got " +
                        Describe(item.node));
  } else {
    x = ToNumbers(ctx_, item, n);
  }
  Eigen::VectorXd values(n);
  bool has_quaternion = false;
  for (int k = 0; k < n; ++k) {
    switch (KindOf(type, k, velocity)) {
      case CoordinateKind::kAngle: values(k) = x[k] * angle_factor; break;
      case CoordinateKind::kLength: values(k) = Length(x[k]); break;
      case CoordinateKind::kQuaternion:
        if (angle_factor != 1.0)
          ctx_.Fail(item, "quaternion coordinates take no '_deg'; write '" + key + "'");
        values(k) = x[k];
        has_quaternion = true;
        break;
    }
  }
  if (has_quaternion && !(values.tail<4>().norm() > 1e-12))
    ctx_.Fail(item, "the quaternion (last 4 values) is zero");
  return values;
}

void Loader::ReadUnits(const MapReader& root) {
  const auto units = root.Find("units");
  if (!units) return;
  const MapReader m(ctx_, *units, {"length"});
  const std::string length = m.Choice("length", {"m", "cm", "mm"}, "m");
  length_ = length == "mm" ? 1e-3 : length == "cm" ? 1e-2 : 1.0;
}

void Loader::ReadBodies(const MapReader& root) {
  const std::vector<Item> items = ListItems(ctx_, root.Need("bodies"));
  if (items.empty()) ctx_.Fail(root.Need("bodies"), "a scene needs at least one body");
  const std::vector<std::string> keys{"name", "mass", "com", "inertia", "frames", "mesh"};
  // Bodies first (their names are frames too), then the frames on them.
  for (const Item& item : items) {
    const MapReader m(ctx_, item, keys);
    if (ToString(ctx_, m.Need("name")) == "world")
      ctx_.Fail(m.Need("name"), "'world' is reserved for the ground body");
    const std::string name = UniqueName(m, bodies_, "body", -1);
    BodyIndex b = -1;
    if (const auto mesh = m.Find("mesh")) {
      // Mass properties from the mesh: mass, com and inertia are not given as well
      for (const char* key : {"mass", "com", "inertia"})
        if (const auto given = m.Find(key))
          ctx_.Fail(*given, "body '" + name + "' takes its mass properties from its mesh: remove '" + key + "'");
      const MassProperties p = ReadBodyMesh(name, *mesh);
      b = Build(m, {{"mass", "mesh"}, {"inertia", "mesh"}},
                [&] { return builder_.AddBody(name, p.mass_kg, p.center_of_mass_m, p.inertia_kg_m2); });
    } else {
      const double mass = m.Number("mass");
      const Vec3 com = Length(m.Vector("com", Vec3::Zero()));
      // Inertia about the centre of mass: 3 principal values or 6 matrix entries.
      const Item inertia_item = m.Need("inertia");
      if (!inertia_item.node.IsSequence() ||
          (inertia_item.node.size() != 3 && inertia_item.node.size() != 6))
        ctx_.Fail(inertia_item, "expected a list of 3 numbers [Ixx, Iyy, Izz] or 6 numbers "
                                "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz], got " + Describe(inertia_item.node));
      const std::vector<double> I = ToNumbers(ctx_, inertia_item, -1);
      Mat3 inertia = Vec3(I[0], I[1], I[2]).asDiagonal();
      if (I.size() == 6) {
        inertia(0, 1) = inertia(1, 0) = I[3];
        inertia(0, 2) = inertia(2, 0) = I[4];
        inertia(1, 2) = inertia(2, 1) = I[5];
      }
      inertia *= length_ * length_;
      b = Build(m, {{"principal moments", "inertia"}, {"inertia", "inertia"},
                    {"centre of mass", "com"}, {"mass", "mass"}},
                [&] { return builder_.AddBody(name, mass, com, inertia); });
    }
    bodies_[name].index = b;
    frames_[name] = Named{builder_.body_frame(b), item};
  }
  for (const Item& item : items) {
    const MapReader m(ctx_, item, keys);
    const BodyIndex b = bodies_.at(ToString(ctx_, m.Need("name"))).index;
    for (const Item& frame : ListItems(ctx_, m.Find("frames"))) ReadFrame(frame, b);
  }
}

MassProperties Loader::ReadBodyMesh(const std::string& body, const Item& item) {
  const MapReader m(ctx_, item, {"file", "unit", "density", "contact_region"});
  // The file, relative to the scene's directory
  const Item file_item = m.Need("file");
  std::filesystem::path file = ToString(ctx_, file_item);
  if (file.is_relative()) file = std::filesystem::path(ctx_.file()).parent_path() / file;
  SurfaceReadOptions options;
  const bool cad = DetectMeshFileFormat(file) == MeshFileFormat::kCad;
  if (const auto unit = m.Find("unit")) {
    if (cad) ctx_.Fail(*unit, "a STEP/IGES file states its own length unit: remove 'unit'");
    const std::string u = ToString(ctx_, *unit);
    options.unit = ParseLengthUnit(u);
    if (!options.unit) ctx_.Fail(*unit, "unknown length unit '" + u + "' (expected " + kLengthUnitChoices + ")");
  } else if (!cad) {
    m.FailMissing("unit", "missing required key 'unit': a mesh file has no unit of its own (" +
                              std::string(kLengthUnitChoices) + ")");
  }
  const Item density_item = m.Need("density");
  const double density = ToNumber(ctx_, density_item);
  if (!(density > 0) || !std::isfinite(density))
    ctx_.Fail(density_item, "density must be > 0 (kg/m^3), got " + density_item.node.Scalar());
  // Read, check, orient; a valid solid boundary only
  SolidMesh solid;
  try {
    solid = ReadSolidMesh(file, options, density);
  } catch (const std::exception& e) {
    ctx_.Fail(file_item, e.what());
  }
  SurfaceMesh& surface = solid.surface;
  const MassProperties p = solid.mass;
  // The contact surface: the whole mesh or one named region
  TriangleMesh& contact = surfaces_[body];
  if (const auto region = m.Find("contact_region")) {
    const std::string name = ToString(ctx_, *region);
    const auto at = std::find(surface.region_names.begin(), surface.region_names.end(), name);
    if (at == surface.region_names.end())
      ctx_.Fail(*region, "no region '" + name + "' in " + file.string() +
                             SuggestOrList(name, surface.region_names, "regions"));
    const int r = static_cast<int>(at - surface.region_names.begin());
    contact.vertices = surface.mesh.vertices;
    for (std::size_t t = 0; t < surface.mesh.triangles.size(); ++t)
      if (surface.triangle_region[t] == r) contact.triangles.push_back(surface.mesh.triangles[t]);
  } else {
    contact = std::move(surface.mesh);
  }
  // Degenerate triangles carry no contact area (the contact surface refuses them)
  std::erase_if(contact.triangles, [&](const std::array<int, 3>& t) {
    const Vec3 n = (contact.vertices[t[1]] - contact.vertices[t[0]]).cross(contact.vertices[t[2]] - contact.vertices[t[0]]);
    return !(n.norm() > 0);
  });
  return p;
}

void Loader::ReadContact(const Item& item, int index) {
  const MapReader m(ctx_, item, {"type", "name", "body_a", "body_b", "stiffness_per_area", "exponent", "hunt_crossley",
                                 "friction", "slip_velocity", "margin"});
  const std::string name = UniqueName(m, forces_, "force element", index);
  contact::ContactElementSpec spec;
  spec.name = name;
  std::shared_ptr<const contact::ContactSurface> surfaces[2];
  const char* keys[2] = {"body_a", "body_b"};
  // Each side: a body with a mesh
  for (int side = 0; side < 2; ++side) {
    const BodyIndex b = BodyRef(m, keys[side]);
    const std::string body = ToString(ctx_, m.Need(keys[side]));
    const auto surface = surfaces_.find(body);
    if (b == kWorldBody || surface == surfaces_.end())
      ctx_.Fail(m.Need(keys[side]), "body '" + body + "' has no mesh: a contact needs bodies with a 'mesh:'");
    (side == 0 ? spec.body_a : spec.body_b) = b;
  }
  // The law, in the scene's length unit (stiffness per area N/length^(2+e))
  contact::ContactLaw& law = spec.law;
  law.exponent = m.Number("exponent", 1.0);
  law.stiffness_per_area = m.Number("stiffness_per_area") / std::pow(length_, 2 + law.exponent);
  law.hunt_crossley_s_per_m = m.Number("hunt_crossley", 0.0) / length_;
  law.friction_coefficient = m.Number("friction", 0.0);
  law.slip_velocity_m_s = Length(m.Number("slip_velocity", law.slip_velocity_m_s / length_));
  const double margin = Length(m.Number("margin"));
  try {
    contact::ValidateContactLaw(law);
    for (int side = 0; side < 2; ++side) {
      const std::string body = ToString(ctx_, m.Need(keys[side]));
      surfaces[side] = std::make_shared<const contact::ContactSurface>(std::vector<TriangleMesh>{surfaces_.at(body)}, margin);
    }
  } catch (const std::invalid_argument& e) {
    ctx_.Fail(m.item(), e.what());
  }
  spec.surface_a = surfaces[0];
  spec.surface_b = surfaces[1];
  Build(m, {}, [&] { builder_.AddExternalForce(std::make_shared<contact::ContactElement>(spec)); });
}

void Loader::ReadFrame(const Item& item, BodyIndex body) {
  const MapReader m(ctx_, item, {"name", "position", "rotation"});
  const Item name_item = m.Need("name");
  const std::string name = ToString(ctx_, name_item);
  if (bodies_.count(name))
    ctx_.Fail(name_item, "'" + name + "' is already a body (and the name of its body frame)");
  UniqueName(m, frames_, "frame", -1);
  Transform X_BF;
  X_BF.p = Length(m.Vector("position", Vec3::Zero()));
  if (const auto r = m.Find("rotation")) X_BF.R = ToRotation(ctx_, *r);
  frames_[name].index = Build(m, {{"rotation", "rotation"}},
                              [&] { return builder_.AddFrame(name, body, X_BF); });
}

void Loader::ReadJoints(const MapReader& root) {
  for (const Item& item : ListItems(ctx_, root.Need("joints"))) {
    // The type decides which keys a joint has.
    const JointType type = JointTypeFromName(ItemType(ctx_, item, JointTypeNames()));
    const bool has_axis = JointInfo(type).axes >= 1;
    const bool has_axis2 = JointInfo(type).axes >= 2;
    std::vector<std::string> allowed{"name", "type", "parent", "child", "parent_frame",
                                     "child_frame"};
    std::map<std::string, std::string> notes;
    const std::string a = std::string("a ") + JointTypeName(type) + " joint ";
    if (has_axis) allowed.push_back("axis");
    else notes["axis"] = a + "has no axis";
    if (has_axis2) allowed.push_back("axis2");
    else notes["axis2"] = a + "has no second axis (universal and planar joints do)";
    if (type != JointType::kFixed) {
      allowed.insert(allowed.end(), {"initial_position", "initial_velocity"});
      if (HasAngularCoordinate(type))
        allowed.insert(allowed.end(), {"initial_position_deg", "initial_velocity_deg"});
      else
        notes["initial_position_deg"] = notes["initial_velocity_deg"] = a + "has no angles";
    } else {
      for (const char* k : {"initial_position", "initial_velocity", "initial_position_deg",
                            "initial_velocity_deg"})
        notes[k] = a + "has no coordinates";
    }
    const MapReader m(ctx_, item, allowed, notes);
    const std::string name = UniqueName(m, joints_, "joint", -1);
    JointSpec spec;
    spec.name = name;
    spec.type = type;
    spec.parent = BodyRef(m, "parent");
    spec.child = BodyRef(m, "child");
    if (spec.child == kWorldBody) ctx_.Fail(m.Need("child"), "the world cannot be a child");
    if (const auto f = m.Find("parent_frame")) spec.X_PF = ToPose(*f, spec.parent, true);
    if (const auto f = m.Find("child_frame")) spec.X_CM = ToPose(*f, spec.child, true);
    spec.axis = m.Vector("axis", Vec3::UnitZ());
    spec.axis2 = m.Vector("axis2", Vec3::UnitX());
    const JointIndex j = Build(
        m, {{"axis2", "axis2"}, {"axis", "axis"}, {"already has parent joint", "child"},
            {"same body", "child"}, {"child", "child"}, {"parent", "parent"}},
        [&] { return builder_.AddJoint(spec); });
    joints_[name].index = j;
    // Initial values.
    if (const auto q = JointValues(m, "initial_position", type, false))
      Build(m, {{"position", "initial_position"}, {"position", "initial_position_deg"}},
            [&] { builder_.SetJointPosition(j, *q); });
    if (const auto v = JointValues(m, "initial_velocity", type, true))
      Build(m, {{"velocity", "initial_velocity"}, {"velocity", "initial_velocity_deg"}},
            [&] { builder_.SetJointVelocity(j, *v); });
  }
}

void Loader::ReadLoopClosures(const MapReader& root) {
  for (const Item& item : ListItems(ctx_, root.Find("loop_closures"))) {
    const MapReader m(ctx_, item, {"name", "type", "frame_a", "frame_b"});
    LoopClosureSpec spec;
    spec.name = UniqueName(m, loops_, "loop closure", static_cast<int>(loops_.size()));
    spec.type = JointTypeFromName(m.Choice("type", JointTypeNames(/*loop_closure=*/true)));
    spec.frame_a = FrameRef(m, "frame_a");
    spec.frame_b = FrameRef(m, "frame_b");
    Build(m, {{"same body", "frame_b"}}, [&] { builder_.AddLoopClosure(spec); });
  }
}

void Loader::ReadDrivers(const MapReader& root) {
  for (const Item& item : ListItems(ctx_, root.Find("drivers"))) {
    const MapReader m(ctx_, item, {"name", "joint", "coordinate", "mode", "function"});
    DriverSpec spec;
    spec.name = UniqueName(m, drivers_, "driver", static_cast<int>(drivers_.size()));
    spec.joint = JointRef(m, "joint");
    spec.coordinate = CoordinateOf(m, spec.joint);
    spec.mode = m.Choice("mode", {"speed", "position"}) == "speed" ? DriverSpec::Mode::kSpeed
                                                                   : DriverSpec::Mode::kPosition;
    // Values in the coordinate's unit: length (per second) or angle (per second, or rpm).
    const bool angular = KindOf(TypeOf(spec.joint), spec.coordinate, true) == CoordinateKind::kAngle;
    FunctionUnits units;
    units.scale = angular ? 1.0 : length_;
    units.angle = angular;
    units.angular_speed = angular && spec.mode == DriverSpec::Mode::kSpeed;
    spec.function = ToFunction(ctx_, m.Need("function"), units);
    Build(m, {{"position driver", "mode"}, {"already driven", "coordinate"},
              {"coordinate", "coordinate"}},
          [&] { builder_.AddDriver(spec); });
  }
}

void Loader::ReadForceElements(const MapReader& root) {
  static const std::vector<std::string> kTypes{
      "applied_load",      "joint_load",        "translational_spring", "rotational_spring",
      "coordinate_spring", "torsional_spring_to_ground", "bushing", "contact"};
  // Spring keywords in builder messages -> keys.
  const std::initializer_list<std::pair<const char*, const char*>> kSpringKeys{
      {"stiffness", "stiffness"}, {"damping", "damping"}, {"free length", "free_length"},
      {"quaternion", "joint"}, {"coordinate", "coordinate"}};
  int index = 0;
  for (const Item& item : ListItems(ctx_, root.Find("force_elements"))) {
    const std::string type = ItemType(ctx_, item, kTypes);
    // Contact between the mesh surfaces of two bodies.
    if (type == "contact") {
      ReadContact(item, index++);
    // Applied load: force N, torque N m (N length-unit), scale dimensionless.
    } else if (type == "applied_load") {
      const MapReader m(ctx_, item, {"type", "name", "frame", "force", "torque", "scale",
                                     "in_frame_axes"});
      AppliedLoadSpec spec;
      spec.name = UniqueName(m, forces_, "force element", index++);
      spec.frame = FrameRef(m, "frame");
      spec.force = m.Vector("force", Vec3::Zero());
      spec.torque = Length(m.Vector("torque", Vec3::Zero()));
      if (const auto s = m.Find("scale")) spec.scale = ToFunction(ctx_, *s, {});
      spec.in_frame_axes = m.Bool("in_frame_axes", false);
      Build(m, {}, [&] { builder_.AddAppliedLoad(spec); });
    // Joint load: force on a translational coordinate, torque on a rotational one.
    } else if (type == "joint_load") {
      const MapReader m(ctx_, item, {"type", "name", "joint", "coordinate", "function"});
      JointLoadSpec spec;
      spec.name = UniqueName(m, forces_, "force element", index++);
      spec.joint = JointRef(m, "joint");
      spec.coordinate = CoordinateOf(m, spec.joint);
      const bool angular =
          KindOf(TypeOf(spec.joint), spec.coordinate, true) == CoordinateKind::kAngle;
      FunctionUnits units;
      units.scale = angular ? length_ : 1.0;
      spec.function = ToFunction(ctx_, m.Need("function"), units);
      Build(m, {{"coordinate", "coordinate"}}, [&] { builder_.AddJointLoad(spec); });
    // Point-to-point spring: N/length, N s/length, length, N.
    } else if (type == "translational_spring") {
      const MapReader m(ctx_, item, {"type", "name", "frame_a", "frame_b", "stiffness", "damping",
                                     "free_length", "preload"});
      TranslationalSpringSpec spec;
      spec.name = UniqueName(m, forces_, "force element", index++);
      spec.frame_a = FrameRef(m, "frame_a");
      spec.frame_b = FrameRef(m, "frame_b");
      spec.stiffness = m.Number("stiffness") / length_;
      spec.damping = m.Number("damping", 0.0) / length_;
      spec.free_length = Length(m.Number("free_length", 0.0));
      spec.preload = m.Number("preload", 0.0);
      Build(m, kSpringKeys, [&] { builder_.AddTranslationalSpring(spec); });
    // Rotational spring about z: N m/rad, N m s/rad (m: the length unit), rad.
    } else if (type == "rotational_spring") {
      const MapReader m(ctx_, item, {"type", "name", "frame_a", "frame_b", "stiffness", "damping",
                                     "angle0", "angle0_deg"});
      RotationalSpringSpec spec;
      spec.name = UniqueName(m, forces_, "force element", index++);
      spec.frame_a = FrameRef(m, "frame_a");
      spec.frame_b = FrameRef(m, "frame_b");
      spec.stiffness = Length(m.Number("stiffness"));
      spec.damping = Length(m.Number("damping", 0.0));
      if (const auto a = m.FindScaled("angle0", {{"", 1.0}, {"_deg", kDegToRad}}))
        spec.angle0 = ToNumber(ctx_, a->first) * a->second;
      Build(m, kSpringKeys, [&] { builder_.AddRotationalSpring(spec); });
    // Coordinate spring: units of the coordinate (translational or rotational).
    } else if (type == "coordinate_spring" || type == "torsional_spring_to_ground") {
      const MapReader m(ctx_, item, {"type", "name", "joint", "coordinate", "stiffness", "damping",
                                     "q0", "q0_deg"});
      CoordinateSpringSpec spec;
      spec.name = UniqueName(m, forces_, "force element", index++);
      spec.joint = JointRef(m, "joint");
      spec.coordinate = CoordinateOf(m, spec.joint);
      const CoordinateKind kind = KindOf(TypeOf(spec.joint), spec.coordinate, true);
      const bool angular = kind == CoordinateKind::kAngle;
      const double k_scale = angular ? length_ : 1.0 / length_;
      spec.stiffness = m.Number("stiffness") * k_scale;
      spec.damping = m.Number("damping", 0.0) * k_scale;
      if (const auto q0 = m.FindScaled("q0", {{"", 1.0}, {"_deg", kDegToRad}})) {
        if (!angular && q0->second != 1.0)
          ctx_.Fail(q0->first, "coordinate " + std::to_string(spec.coordinate) +
                                   " is a translation: give 'q0' in length units");
        spec.q0 = ToNumber(ctx_, q0->first) * (angular ? q0->second : length_);
      }
      Build(m, kSpringKeys, [&] { builder_.AddCoordinateSpring(spec); });
    // Bushing: K, D 6 diagonal values or 6x6; rows (force, torque), columns (translation, rotation).
    } else {
      const MapReader m(ctx_, item, {"type", "name", "frame_a", "frame_b", "stiffness", "damping"});
      BushingSpec spec;
      spec.name = UniqueName(m, forces_, "force element", index++);
      spec.frame_a = FrameRef(m, "frame_a");
      spec.frame_b = FrameRef(m, "frame_b");
      auto matrix = [&](const Item& it) {
        Mat6 K = Mat6::Zero();
        if (it.node.IsSequence() && it.node.size() == 6 && it.node[0].IsSequence()) {
          for (int r = 0; r < 6; ++r) {
            const std::vector<double> row = ToNumbers(ctx_, Element(it, r), 6);
            for (int c = 0; c < 6; ++c) K(r, c) = row[c];
          }
        } else {
          if (!it.node.IsSequence() || it.node.size() != 6)
            ctx_.Fail(it, "expected a list of 6 numbers (the diagonal) or a 6x6 nested list, got " +
                              Describe(it.node));
          const std::vector<double> d = ToNumbers(ctx_, it, 6);
          for (int i = 0; i < 6; ++i) K(i, i) = d[i];
        }
        // To SI: torque rows carry a length, translation columns divide by one.
        for (int r = 0; r < 6; ++r)
          for (int c = 0; c < 6; ++c) K(r, c) *= (r >= 3 ? length_ : 1.0) / (c < 3 ? length_ : 1.0);
        return K;
      };
      spec.stiffness = matrix(m.Need("stiffness"));
      if (const auto d = m.Find("damping")) spec.damping = matrix(*d);
      Build(m, {{"stiffness", "stiffness"}, {"damping", "damping"}},
            [&] { builder_.AddBushing(spec); });
    }
  }
}

void Loader::ReadSolver(const MapReader& root, Scene& scene) {
  const MapReader m(ctx_, root.Need("solver"),
                    {"integrator", "end_time", "rtol", "atol", "atol_multiplier", "max_step",
                     "initial_step", "max_order", "max_steps_per_output", "step", "rho_inf",
                     "alpha_m", "alpha_f", "beta", "gamma", "max_newton_iterations",
                     "newton_tolerance", "max_step_halvings", "matrix_refresh_rate",
                     "newton_estimate", "threads"});
  SimulationOptions& sim = scene.simulation;
  IntegratorOptions& o = sim.integrator;
  // A number with a condition, reported at its key.
  auto checked = [&](const std::string& key, double fallback, auto ok, const char* rule) {
    const double x = m.Number(key, fallback);
    if (!ok(x)) ctx_.Fail(m.Find(key).value_or(m.item()), std::string("must be ") + rule + ", got " + Num(x));
    return x;
  };
  auto positive = [](double x) { return x > 0; };
  auto non_negative = [](double x) { return x >= 0; };
  o.kind = m.Choice("integrator", {"ida", "generalized_alpha"}, "ida") == "ida"
               ? IntegratorKind::kIda
               : IntegratorKind::kGeneralizedAlpha;
  sim.end_time = m.Number("end_time");
  if (!(sim.end_time > 0)) ctx_.Fail(m.Need("end_time"), "must be > 0, got " + Num(sim.end_time));
  // IDA.
  o.rtol = checked("rtol", o.rtol, positive, "> 0");
  o.atol = checked("atol", o.atol, positive, "> 0");
  o.atol_multiplier = checked("atol_multiplier", o.atol_multiplier, positive, "> 0");
  o.max_step = checked("max_step", o.max_step, non_negative, ">= 0 (0: unlimited)");
  o.initial_step = checked("initial_step", o.initial_step, non_negative, ">= 0 (0: automatic)");
  o.max_order = m.Int("max_order", o.max_order);
  if (o.max_order < 1 || o.max_order > 5)
    ctx_.Fail(*m.Find("max_order"), "must be in 1..5, got " + std::to_string(o.max_order));
  o.max_steps_per_output = m.Int("max_steps_per_output", static_cast<int>(o.max_steps_per_output));
  if (o.max_steps_per_output < 1)
    ctx_.Fail(*m.Find("max_steps_per_output"), "must be >= 1");
  // Generalized-alpha.
  o.step = checked("step", o.step, positive, "> 0");
  o.rho_inf = checked("rho_inf", o.rho_inf, [](double x) { return x >= 0 && x <= 1; }, "in [0, 1]");
  const int explicit_params = int(m.Has("alpha_m")) + int(m.Has("alpha_f")) + int(m.Has("beta")) +
                              int(m.Has("gamma"));
  if (explicit_params != 0 && explicit_params != 4)
    ctx_.Fail(m.item(), "give all four of alpha_m, alpha_f, beta, gamma or none (rho_inf sets them)");
  if (explicit_params == 4) {
    o.alpha_m = m.Number("alpha_m");
    o.alpha_f = m.Number("alpha_f");
    o.beta = checked("beta", 0, positive, "> 0");
    o.gamma = checked("gamma", 0, positive, "> 0");
  }
  o.max_newton_iterations = m.Int("max_newton_iterations", o.max_newton_iterations);
  if (o.max_newton_iterations < 1) ctx_.Fail(*m.Find("max_newton_iterations"), "must be >= 1");
  o.newton_tolerance = checked("newton_tolerance", o.newton_tolerance, positive, "> 0");
  o.matrix_refresh_rate = checked("matrix_refresh_rate", o.matrix_refresh_rate,
                                  [](double x) { return x > 0 && x < 1; }, "in (0, 1)");
  o.newton_estimate = m.Bool("newton_estimate", o.newton_estimate);
  o.max_step_halvings = m.Int("max_step_halvings", o.max_step_halvings);
  if (o.max_step_halvings < 0 || o.max_step_halvings > 20)
    ctx_.Fail(*m.Find("max_step_halvings"), "must be in [0, 20]");
  // Threads for the tooth contacts of one evaluation (0 or absent: OMP_NUM_THREADS, else 1).
  o.threads = m.Int("threads", o.threads);
  if (o.threads < 0 || o.threads > 4096)
    ctx_.Fail(*m.Find("threads"), "must be in [0, 4096] (0: OMP_NUM_THREADS, else 1), got " +
                                      std::to_string(o.threads));
}

void Loader::ReadOutput(const MapReader& root, Scene& scene) {
  const MapReader m(ctx_, root.Need("output"), {"interval", "file", "flush_interval", "sensors"});
  scene.simulation.output_interval = m.Number("interval");
  if (!(scene.simulation.output_interval > 0))
    ctx_.Fail(m.Need("interval"), "must be > 0, got " + Num(scene.simulation.output_interval));
  scene.simulation.flush_interval_s = m.Number("flush_interval", scene.simulation.flush_interval_s);
  if (!(scene.simulation.flush_interval_s > 0))
    ctx_.Fail(m.Need("flush_interval"), "must be > 0 (wall-clock seconds)");
  if (const auto f = m.Find("file")) scene.output_path = ToString(ctx_, *f);
  if (const auto s = m.Find("sensors")) scene.simulation.sensors = ReadSensorSampling(ctx_, *s);
}

Scene Loader::Load(const YAML::Node& root_node) {
  const MapReader root(ctx_, Item{root_node, "", root_node.Mark()},
                       {"name", "units", "gravity", "bodies", "world_frames", "joints",
                        "loop_closures", "drivers", "force_elements", "sensors", "solver", "output",
                        "lumped_stage", "gear_train"});
  Scene scene;
  scene.name = root.Has("name") ? root.String("name") : name_;
  // Exactly one model section: bodies + joints, lumped_stage or gear_train.
  const auto lumped = root.Find("lumped_stage"), train = root.Find("gear_train");
  if (lumped && train)
    ctx_.Fail(*train, "a scene has exactly one model section: bodies + joints, lumped_stage or gear_train");
  if (lumped || train) {
    const std::string section = lumped ? "lumped_stage" : "gear_train";
    for (const char* key : {"bodies", "joints", "world_frames", "loop_closures", "drivers",
                            "force_elements", "gravity", "units"})
      if (const auto it = root.Find(key))
        ctx_.Fail(*it, std::string("key not allowed with ") + section + ": a scene has exactly one " +
                           "model section (bodies + joints, lumped_stage or gear_train); " + section +
                           " values are SI or carry their unit in the key (_mm, _deg, _rpm)");
    if (const auto it = root.Find("sensors"); it && lumped)
      ctx_.Fail(*it, "sensors are read for bodies + joints and gear_train scenes; for lumped_stage "
                     "scenes add them in C++ (ModelBuilder::AddSensor)");
    ReadSolver(root, scene);
    ReadOutput(root, scene);
    if (lumped) ReadLumpedStage(ctx_, *lumped, scene);
    else ReadGearTrain(ctx_, *train, root.Find("sensors"), scene);
    scene.simulation.scene_name = scene.name;
    return scene;
  }
  if (!root.Has("bodies") && !root.Has("joints"))
    root.FailMissing("bodies", "missing model section: give bodies + joints, lumped_stage or gear_train");
  ReadUnits(root);
  // Model: bodies and frames, joints, constraints, loads.
  bodies_["world"] = Named{kWorldBody, root.item()};
  frames_["world"] = Named{kWorldFrame, root.item()};
  ReadBodies(root);
  for (const Item& frame : ListItems(ctx_, root.Find("world_frames"))) ReadFrame(frame, kWorldBody);
  ReadJoints(root);
  // Every body hangs from a joint (the builder would say so only at Finalize, without a line).
  for (const auto& [name, named] : bodies_)
    if (named.index != kWorldBody && builder_.draft().bodies[named.index].parent_joint < 0)
      ctx_.Fail(named.item, "body '" + name + "' is not the child of any joint; give a floating "
                                             "body a free joint to world");
  ReadLoopClosures(root);
  ReadDrivers(root);
  ReadForceElements(root);
  ReadSensors(ctx_, root.Find("sensors"), length_, builder_);
  builder_.SetGravity(Length(root.Vector("gravity", Vec3::Zero())));
  // Finalize; its errors name a joint, or concern the constraints as a whole.
  try {
    scene.model = std::move(builder_).Finalize();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    for (const auto& [name, named] : joints_)
      if (what.find("joint '" + name + "'") != std::string::npos) ctx_.Fail(named.item, what);
    for (const char* key : {"loop_closures", "drivers", "joints"})
      if (const auto it = root.Find(key)) ctx_.Fail(*it, what);
    ctx_.Fail(root.item(), what);
  }
  ReadSolver(root, scene);
  ReadOutput(root, scene);
  scene.simulation.scene_name = scene.name;
  return scene;
}

// ---------------------------------------------------------------------------------------------
// Overrides: "a.b.c=value", maps by key, lists by item name (or index)

// "bodies.bob.mass" or "bodies[bob].mass" -> {"bodies", "bob", "mass"}.
std::vector<std::string> SplitKeyPath(const Context& ctx, const std::string& key) {
  std::vector<std::string> parts;
  std::string current;
  bool in_bracket = false, closed = false;
  for (char c : key) {
    if (in_bracket) {
      if (c == ']') in_bracket = false, closed = true, parts.push_back(current), current.clear();
      else current += c;
    } else if (c == '.' || c == '[') {
      if (!closed || !current.empty()) {
        if (current.empty()) ctx.FailOverride(key, "empty element in the key path");
        parts.push_back(current);
      }
      current.clear();
      closed = false;
      in_bracket = c == '[';
    } else {
      if (closed) ctx.FailOverride(key, "expected '.' or '[' after ']'");
      current += c;
    }
  }
  if (in_bracket) ctx.FailOverride(key, "unclosed '['");
  if (!closed || !current.empty()) {
    if (current.empty()) ctx.FailOverride(key, "empty element in the key path");
    parts.push_back(current);
  }
  return parts;
}

// The child of a map (by key) or of a list (by item name, else by index), with the line to
// report (the key's for map entries); nullopt if none.
std::optional<std::pair<YAML::Node, YAML::Mark>> ChildOf(YAML::Node node, const std::string& part) {
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it)
      if (it->first.IsScalar() && it->first.Scalar() == part)
        return std::make_pair(YAML::Node(it->second), it->first.Mark());
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) {
      YAML::Node item = node[i];
      if (item.IsMap())
        for (auto it = item.begin(); it != item.end(); ++it)
          if (it->first.IsScalar() && it->first.Scalar() == "name" && it->second.IsScalar() &&
              it->second.Scalar() == part)
            return std::make_pair(item, item.Mark());
    }
    if (!part.empty() && std::all_of(part.begin(), part.end(), ::isdigit)) {
      const size_t i = std::stoul(part);
      if (i < node.size()) return std::make_pair(YAML::Node(node[i]), node[i].Mark());
    }
  }
  return std::nullopt;
}

// Names a lookup could have meant: map keys or list item names.
std::vector<std::string> ChildNames(const YAML::Node& node) {
  std::vector<std::string> names;
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it)
      if (it->first.IsScalar()) names.push_back(it->first.Scalar());
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i)
      if (node[i].IsMap())
        for (auto it = node[i].begin(); it != node[i].end(); ++it)
          if (it->first.IsScalar() && it->first.Scalar() == "name" && it->second.IsScalar())
            names.push_back(it->second.Scalar());
  }
  return names;
}

void ApplyOverride(Context& ctx, YAML::Node& root, const std::string& setting) {
  const size_t eq = setting.find('=');
  if (eq == std::string::npos)
    ctx.FailOverride(setting, "expected KEY.PATH=VALUE (e.g. solver.end_time=2)");
  const std::string key = setting.substr(0, eq), text = setting.substr(eq + 1);
  const std::vector<std::string> parts = SplitKeyPath(ctx, key);
  if (parts.empty()) ctx.FailOverride(key, "empty key path");
  // The value, parsed as YAML.
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    ctx.FailOverride(key, "cannot parse the value '" + text + "' as YAML: " + e.msg);
  }
  if (value.IsNull() && text.find_first_not_of(" \t") == std::string::npos)
    ctx.FailOverride(key, "no value after '='");
  // Walk to the parent of the last element; every element on the way must exist.
  YAML::Node node = root;
  YAML::Mark mark = root.Mark();
  std::string path;
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    const std::string where =
        path.empty() ? "the scene"
                     : "'" + path + "'" +
                           (mark.line >= 0 ? " (line " + std::to_string(mark.line + 1) + ")" : "");
    if (!node.IsMap() && !node.IsSequence())
      ctx.FailOverride(key, where + " is " + Describe(node) + ", not a map or a list");
    const std::string next = node.IsMap() ? (path.empty() ? part : path + "." + part)
                                          : path + "[" + part + "]";
    const auto child = ChildOf(node, part);
    if (!child) {
      // A missing last key of a map is added (so optional keys can be set).
      if (last && node.IsMap()) {
        node[part] = value;
        ctx.overrides().push_back({key, next, value});
        return;
      }
      const std::string what = node.IsMap() ? "no key '" + part + "' in " + where
                                             : "no item named '" + part + "' in " + where;
      std::string hint = SuggestOrList(part, ChildNames(node), "known");
      if (node.IsMap()) hint += "; only the last element of a path may be new";
      ctx.FailOverride(key, what + hint);
    }
    if (last) {
      YAML::Node target = child->first;
      target = value;  // the tree's node now refers to the override's value
      ctx.overrides().push_back({key, next, value});
      return;
    }
    node.reset(child->first);  // rebind (assignment would overwrite the tree)
    mark = child->second;
    path = next;
  }
}

// ---------------------------------------------------------------------------------------------
// Scene text: the tree after overrides, emitted with quoted strings kept quoted

std::string SceneText(const std::string& original, const std::string& file, const YAML::Node& root,
                      const std::vector<std::string>& overrides) {
  if (overrides.empty()) return original;
  std::string text = "# " + file + " with overrides:\n";
  for (const std::string& o : overrides) text += "#   --set " + o + "\n";
  YAML::Emitter out;
  EmitYaml(out, root, false);
  return text + out.c_str() + "\n";
}

Scene Load(const std::string& text, const std::string& file, const std::string& source_path,
           const std::vector<std::string>& overrides, const SceneLoadOptions& options) {
  Context ctx(file);
  ctx.set_make_reduced_bodies(options.make_reduced_bodies);
  ctx.set_without_faults(options.without_faults);
  // Parse.
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SceneError(file + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw SceneError(file + ": YAML error: " + e.msg);
  }
  if (root.IsNull()) throw SceneError(file + ": the scene is empty");
  if (!root.IsMap()) throw SceneError(file + ":1: the scene must be a map of sections, got " + Describe(root));
  // Overrides, then the whole tree is validated as if it had been written so.
  for (const std::string& o : overrides) ApplyOverride(ctx, root, o);
  const std::string stem = std::filesystem::path(file).stem().string();
  Loader loader(ctx, stem.empty() ? "scene" : stem);
  Scene scene = loader.Load(root);
  scene.source_path = source_path;
  if (scene.output_path.empty()) scene.output_path = (stem.empty() ? "scene" : stem) + ".h5";
  scene.simulation.scene_text = SceneText(text, file, root, overrides);
  scene.input_files = ctx.inputs();
  return scene;
}

}  // namespace

Scene LoadScene(const std::string& path, const std::vector<std::string>& overrides,
                const SceneLoadOptions& options) {
  std::string text;
  try {
    text = ReadInputFile(path, "scene file", kMaxTextInputBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  return Load(text, path, path, overrides, options);
}

Scene LoadSceneFromString(const std::string& text, const std::string& name,
                          const std::vector<std::string>& overrides, const SceneLoadOptions& options) {
  return Load(text, name, "", overrides, options);
}

}  // namespace orrery

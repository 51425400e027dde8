// The sensors stage of BuildTrainModel (train_dynamics.h, "Sensors"): each TrainSensor's names
// resolved against the assembled bodies, joints and mesh branches, then ModelBuilder::AddSensor.
#include <string>
#include <vector>

#include "models/train_assembly.h"

namespace orrery::gears {
namespace {

[[noreturn]] void FailSensor(const TrainSensor& s, const std::string& what) {
  FailTrain("sensor '" + s.name + "': " + what);
}

// "a, b, c" of the names.
std::string List(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::vector<std::string> BodyNames(const Model& m) {
  std::vector<std::string> names;
  for (size_t b = 1; b < m.bodies.size(); ++b) names.push_back(m.bodies[b].name);
  return names;
}

// The body of that name (not the world), or an error listing the bodies.
BodyIndex FindTrainBody(const TrainAssembly& a, const TrainSensor& s, const std::string& name,
                        const char* key) {
  const Model& m = a.b.draft();
  for (size_t b = 1; b < m.bodies.size(); ++b)
    if (m.bodies[b].name == name) return static_cast<BodyIndex>(b);
  FailSensor(s, std::string(key) + " '" + name + "' is no body of the train (bodies: " + List(BodyNames(m)) + ")");
}

// Point sensors: the frame (the body's, or a node frame) and the sensor's pose in it.
void PlacePointSensor(TrainAssembly& a, const TrainSensor& s, SensorSpec& spec) {
  if (s.body.empty()) FailSensor(s, "a " + std::string(SensorKindName(s.kind)) + " needs a body");
  const BodyIndex body = FindTrainBody(a, s, s.body, "body");
  const Model& m = a.b.draft();
  if (s.node) {
    if (m.bodies[body].flexible < 0) FailSensor(s, "body '" + s.body + "' is rigid; a node is for flexible bodies");
    int node = -1;
    try {
      node = a.b.FindNode(body, *s.node);
    } catch (const std::exception& e) {
      FailSensor(s, e.what());
    }
    const FlexibleBodyModes& modes = *m.flexible_bodies[m.bodies[body].flexible].modes;
    const Transform X_BF(s.rotation, s.position_m.value_or(modes.nodes[node].position));
    spec.frame = a.b.AddNodeFrame("sensor:" + s.name, body, node, X_BF);
    return;
  }
  spec.frame = a.b.body_frame(body);
  spec.X_FS = Transform(s.rotation, s.position_m.value_or(Vec3::Zero()));
}

// measured_in: the sensor's axes, the world, or a body's frame.
int MeasuredIn(TrainAssembly& a, const TrainSensor& s) {
  if (s.measured_in == "sensor") return kSensorAxes;
  if (s.measured_in == "world") return kWorldFrame;
  return a.b.body_frame(FindTrainBody(a, s, s.measured_in, "measured_in"));
}

// Encoders and tachometers: the joint of the named body, its spin by default.
void PlaceJointSensor(TrainAssembly& a, const TrainSensor& s, SensorSpec& spec) {
  const std::string& name = s.joint.empty() ? s.body : s.joint;
  if (name.empty()) FailSensor(s, "an " + std::string(SensorKindName(s.kind)) + " needs a joint (a member, planet or 'housing')");
  const BodyIndex body = FindTrainBody(a, s, name, "joint");
  spec.joint = a.b.draft().bodies[body].parent_joint;
  spec.coordinate = s.coordinate >= 0 ? s.coordinate : a.rot;
}

// Mesh sensors: a lumped branch's mesh quantity, or a contact branch's element output.
void PlaceMeshSensor(TrainAssembly& a, const TrainSensor& s, SensorSpec& spec) {
  const Model& m = a.b.draft();
  std::vector<std::string> branches;
  for (size_t i = 0; i < m.gear_meshes.size(); ++i) {
    if (m.gear_meshes[i].spec.name != s.mesh) {
      branches.push_back(m.gear_meshes[i].spec.name);
      continue;
    }
    spec.kind = SensorKind::kGearMesh;
    spec.gear_mesh = static_cast<int>(i);
    spec.mesh_quantity = s.quantity;
    return;
  }
  for (const TrainContactMesh& c : a.tm.contacts) {
    if (c.name != s.mesh) {
      branches.push_back(c.name);
      continue;
    }
    for (size_t e = 0; e < m.external_forces.size(); ++e) {
      if (m.external_forces[e]->name() != c.name) continue;
      auto has = [&](const char* output) {
        for (const OutputDescription& d : m.external_forces[e]->outputs())
          if (d.name == output) return true;
        return false;
      };
      spec.kind = SensorKind::kElementOutput;
      spec.element = static_cast<int>(e);
      if (s.quantity == MeshQuantity::kForce)
        spec.output = has("line_of_action_force") ? "line_of_action_force" : "normal_force";
      else if (s.quantity == MeshQuantity::kTransmissionError && has("transmission_error"))
        spec.output = "transmission_error";
      else
        FailSensor(s, "the contact branch '" + s.mesh + "' records no " + MeshQuantityName(s.quantity) +
                          " (contact branches: force, transmission_error)");
      return;
    }
  }
  for (const GearConstraint& c : m.gear_constraints)
    if (c.spec.name == s.mesh)
      FailSensor(s, "mesh branch '" + s.mesh + "' is kinematic: it has no mesh signal (its force is recorded as "
                    "/gear_constraints/" + s.mesh + "/force)");
  FailSensor(s, "no lumped or contact mesh branch '" + s.mesh + "' (branches: " + List(branches) + ")");
}

}  // namespace

void AddSensors(TrainAssembly& a) {
  for (const TrainSensor& s : a.o.sensors) {
    SensorSpec spec{.name = s.name, .kind = s.kind};
    switch (s.kind) {
      case SensorKind::kAccelerometer:
      case SensorKind::kVelocity:
      case SensorKind::kDisplacement:
      case SensorKind::kGyroscope:
      case SensorKind::kAngularAccelerometer:
        PlacePointSensor(a, s, spec);
        spec.measured_in = MeasuredIn(a, s);
        if (s.kind == SensorKind::kDisplacement && spec.measured_in == kSensorAxes) spec.measured_in = kWorldFrame;
        spec.axes = s.axes;
        spec.include_gravity = s.include_gravity;
        break;
      case SensorKind::kEncoder:
      case SensorKind::kTachometer:
        PlaceJointSensor(a, s, spec);
        break;
      case SensorKind::kGearMesh:
        PlaceMeshSensor(a, s, spec);
        break;
      case SensorKind::kElementOutput:
        FailSensor(s, "give a mesh sensor (kGearMesh with a mesh branch); element outputs are chosen from it");
    }
    // The builder checks the rest (unique name, axes, coordinate) and names the sensor
    try {
      a.b.AddSensor(spec);
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      FailTrain(what.find("'" + s.name + "'") != std::string::npos ? what : "sensor '" + s.name + "': " + what);
    }
  }
}

}  // namespace orrery::gears

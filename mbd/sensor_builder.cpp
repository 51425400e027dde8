// Sensors in the model builder: validation (AddSensor) and the derived fields Finalize() fills
// (channels, quantities and units, initial positions of displacement sensors).
#include <algorithm>
#include <stdexcept>

#include "mbd/data.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"

namespace orrery {
namespace {

[[noreturn]] void Fail(const std::string& msg) { throw std::invalid_argument(msg); }

// Velocity coordinate k of a joint type is a rotation (else a translation).
bool IsAngularCoordinate(JointType type, int k) {
  switch (type) {
    case JointType::kPrismatic: return false;
    case JointType::kCylindrical: return k == 0;
    case JointType::kPlanar: return k == 2;
    case JointType::kFree: return k >= 3;
    default: return true;
  }
}

// The position coordinate behind velocity coordinate k is a scalar (not part of a quaternion).
bool HasScalarPosition(JointType type, int k) {
  if (type == JointType::kSpherical) return false;
  if (type == JointType::kFree) return k < 3;
  return true;
}

bool IsFrameKind(SensorKind kind) {
  return kind == SensorKind::kAccelerometer || kind == SensorKind::kVelocity ||
         kind == SensorKind::kDisplacement || kind == SensorKind::kGyroscope ||
         kind == SensorKind::kAngularAccelerometer;
}

const char* kAxisNames[3] = {"x", "y", "z"};

}  // namespace

const char* SensorKindName(SensorKind kind) {
  switch (kind) {
    case SensorKind::kAccelerometer: return "accelerometer";
    case SensorKind::kVelocity: return "velocity";
    case SensorKind::kDisplacement: return "displacement";
    case SensorKind::kGyroscope: return "gyroscope";
    case SensorKind::kAngularAccelerometer: return "angular_accelerometer";
    case SensorKind::kEncoder: return "encoder";
    case SensorKind::kTachometer: return "tachometer";
    case SensorKind::kGearMesh: return "gear_mesh";
    case SensorKind::kElementOutput: return "element_output";
  }
  return "?";
}

const char* MeshQuantityName(MeshQuantity q) {
  switch (q) {
    case MeshQuantity::kForce: return "force";
    case MeshQuantity::kDeflection: return "deflection";
    case MeshQuantity::kTransmissionError: return "transmission_error";
  }
  return "?";
}

int ModelBuilder::AddSensor(const SensorSpec& spec) {
  Model& m = *model_;
  CheckName("sensor", spec.name);
  const std::string what = "sensor '" + spec.name + "'";
  if (m.sensor_by_name_.count(spec.name)) Fail(what + ": name already used");
  const int nframes = static_cast<int>(m.frames.size());
  if (IsFrameKind(spec.kind)) {
    // Frame, axes and the frame the vector is measured in.
    if (spec.frame < 0 || spec.frame >= nframes)
      Fail(what + ": frame index " + std::to_string(spec.frame) + " does not exist");
    if (spec.measured_in != kSensorAxes && (spec.measured_in < 0 || spec.measured_in >= nframes))
      Fail(what + ": measured_in frame index " + std::to_string(spec.measured_in) + " does not exist");
    const Transform& X = spec.X_FS;
    if (!X.p.allFinite() || !X.R.allFinite() || (X.R.transpose() * X.R - Mat3::Identity()).norm() > 1e-9 ||
        X.R.determinant() < 0)
      Fail(what + ": its pose in the frame (X_FS) is not finite or its rotation not proper");
    if (spec.axes.empty() || spec.axes.size() > 3) Fail(what + ": axes must list 1 to 3 components");
    for (size_t i = 0; i < spec.axes.size(); ++i) {
      if (spec.axes[i] < 0 || spec.axes[i] > 2)
        Fail(what + ": axes must be 0 (x), 1 (y) or 2 (z), got " + std::to_string(spec.axes[i]));
      if (std::count(spec.axes.begin(), spec.axes.end(), spec.axes[i]) > 1)
        Fail(what + ": axes list component " + kAxisNames[spec.axes[i]] + " twice");
    }
    if (spec.kind == SensorKind::kDisplacement &&
        (spec.measured_in == kSensorAxes || spec.measured_in == spec.frame))
      Fail(what + ": a displacement is measured relative to another frame (the world, a housing, "
                  "the body's own frame for a node's deflection); relative to its own it never moves");
  } else if (spec.kind == SensorKind::kEncoder || spec.kind == SensorKind::kTachometer) {
    CheckCoordinate(what, spec.joint, spec.coordinate);
    const Joint& j = m.joints[spec.joint];
    if (spec.kind == SensorKind::kEncoder && !HasScalarPosition(j.spec.type, spec.coordinate))
      Fail(what + ": coordinate " + std::to_string(spec.coordinate) + " of " + JointTypeName(j.spec.type) +
           " joint '" + j.spec.name + "' is an orientation (a quaternion), which no encoder reads; put a "
           "gyroscope on the child body, or a tachometer on the coordinate");
  } else if (spec.kind == SensorKind::kGearMesh) {
    if (spec.gear_mesh < 0 || spec.gear_mesh >= static_cast<int>(m.gear_meshes.size()))
      Fail(what + ": gear mesh index " + std::to_string(spec.gear_mesh) + " does not exist");
  } else {
    if (spec.element < 0 || spec.element >= static_cast<int>(m.external_forces.size()))
      Fail(what + ": external element index " + std::to_string(spec.element) + " does not exist");
    const ExternalForceElement& e = *m.external_forces[spec.element];
    std::string known;
    bool found = false;
    for (const OutputDescription& o : e.outputs()) {
      found = found || o.name == spec.output;
      known += (known.empty() ? "" : ", ") + o.name;
    }
    if (!found)
      Fail(what + ": element '" + e.name() + "' has no output '" + spec.output + "'" +
           (known.empty() ? " (it has no outputs)" : " (outputs: " + known + ")"));
  }
  if (spec.include_gravity && spec.kind != SensorKind::kAccelerometer)
    Fail(what + ": include_gravity is for accelerometers");
  Sensor s;
  s.spec = spec;
  m.sensor_by_name_[spec.name] = static_cast<int>(m.sensors.size());
  m.sensors.push_back(s);
  return static_cast<int>(m.sensors.size()) - 1;
}

void ModelBuilder::FinalizeSensors() {
  Model& m = *model_;
  m.n_sensor_channels = 0;
  m.sensor_elements.clear();
  bool any_displacement = false;
  for (Sensor& s : m.sensors) {
    const SensorSpec& spec = s.spec;
    s.columns.clear();
    if (IsFrameKind(spec.kind)) {
      static const char* kQuantity[] = {"acceleration", "velocity", "displacement",
                                        "angular_velocity", "angular_acceleration"};
      static const char* kUnit[] = {"m/s^2", "m/s", "m", "rad/s", "rad/s^2"};
      const int k = static_cast<int>(spec.kind);
      s.quantity = kQuantity[k], s.unit = kUnit[k];
      for (int a : spec.axes) s.columns.push_back(kAxisNames[a]);
      s.needs_accelerations = spec.kind == SensorKind::kAccelerometer ||
                              spec.kind == SensorKind::kAngularAccelerometer;
      any_displacement = any_displacement || spec.kind == SensorKind::kDisplacement;
    } else if (spec.kind == SensorKind::kEncoder || spec.kind == SensorKind::kTachometer) {
      const Joint& j = m.joints[spec.joint];
      const bool angular = IsAngularCoordinate(j.spec.type, spec.coordinate);
      const bool encoder = spec.kind == SensorKind::kEncoder;
      s.quantity = encoder ? (angular ? "angle" : "position") : (angular ? "angular_velocity" : "velocity");
      s.unit = encoder ? (angular ? "rad" : "m") : (angular ? "rad/s" : "m/s");
      s.columns = {s.quantity};
      s.q_index = j.q_start + spec.coordinate;
      s.v_index = j.v_start + spec.coordinate;
    } else if (spec.kind == SensorKind::kGearMesh) {
      s.quantity = MeshQuantityName(spec.mesh_quantity);
      s.unit = spec.mesh_quantity == MeshQuantity::kForce ? "N" : "m";
      s.columns = {s.quantity};
    } else {
      // The output's place among the element's values.
      int offset = 0;
      for (const OutputDescription& o : m.external_forces[spec.element]->outputs()) {
        if (o.name == spec.output) {
          s.quantity = o.name, s.unit = o.unit, s.output_offset = offset;
          for (int c = 0; c < o.columns; ++c)
            s.columns.push_back(o.columns == 1 ? o.name : o.name + "_" + std::to_string(c));
        }
        offset += o.columns;
      }
      s.element_values = offset;
      if (std::find(m.sensor_elements.begin(), m.sensor_elements.end(), spec.element) ==
          m.sensor_elements.end())
        m.sensor_elements.push_back(spec.element);
    }
    s.channels = static_cast<int>(s.columns.size());
    s.channel_start = m.n_sensor_channels;
    m.n_sensor_channels += s.channels;
  }
  std::sort(m.sensor_elements.begin(), m.sensor_elements.end());
  // Displacements count from the initial configuration.
  if (!any_displacement) return;
  Data data(m);
  CalcPositionKinematics(m, m.q_initial, data);
  for (Sensor& s : m.sensors) {
    if (s.spec.kind != SensorKind::kDisplacement) continue;
    const Transform& X_WE = data.X_WFrame[s.spec.measured_in];
    s.p0_E = X_WE.R.transpose() * (data.X_WFrame[s.spec.frame] * s.spec.X_FS.p - X_WE.p);
  }
}

}  // namespace orrery

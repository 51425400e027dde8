#pragma once
// Virtual sensors: the channels a data-acquisition system would record on the model.
//
// A sensor is a model element (ModelBuilder::AddSensor) that reads one quantity:
// - at a point fixed in a frame (the sensor's pose X_FS in the frame: its origin is the measuring
//   point, its axes the sensor's axes): acceleration
//   (accelerometer), velocity, displacement, angular velocity (gyroscope) and angular
//   acceleration. The frame may be on any body: rigid, the reference frame of a flexible body, or
//   a node frame of a flexible body (ModelBuilder::AddNodeFrame), whose motion includes the
//   elastic deformation at the node. Vectors are expressed in the axes of `measured_in`: the
//   sensor's own axes (co-rotating, a sensor glued to the part), the world (a fixed housing) or
//   any other frame; one to three components are recorded.
// - on a joint coordinate: its position (encoder: an angle or a length) or its rate (tachometer).
// - on a lumped gear mesh (GearMeshSpec): tooth force, flank deflection or transmission error.
// - on an external force element (tooth contact): one of its outputs (all of its columns).
//
// Point kinematics (absolute, inertial; W world, B the body, P the frame origin, rho = p_P - p_B,
// omega and alpha the body's angular velocity and acceleration, u the elastic displacement of a
// node frame in B: Phi_P q_f plus the node's small rotation Psi_P q_f of the offset d from the
// node):
//   v_P = v_B + omega x rho + R u-dot,
//   a_P = a_B + alpha x rho + omega x (omega x rho) + 2 omega x R u-dot + R u-ddot,
//   u-dot = sum_k (Phi_k + Psi_k x d) q-dot_k,
//   u-ddot = sum_k (Phi_k + Psi_k x d) q-ddot_k + w_e x (w_e x d),  w_e = Psi_P q-dot,
//   omega_P = omega + R w_e,   alpha_P = alpha + R Psi_P q-ddot + omega x R w_e
// (the floating frame of reference: Shabana, "Dynamics of Multibody Systems", 4th ed., ch. 5).
// Frames cost every evaluation of the dynamics a pose; a sensor's own point and axes (X_FS)
// cost only its samples. The displacement of P is its position relative to frame
// E = measured_in (origin and axes),
// minus the same at the model's initial configuration: E = world gives the absolute
// displacement, E = the flexible body's own frame the elastic deflection at a node, E = a housing
// frame what a proximity probe on the housing sees.
//
// Sampling and the anti-alias filter are not part of the model: see sensor_sampler.h.
//
// Usage (a one-axis accelerometer on a housing, 0.2 m from its origin, along its radius):
//   b.AddSensor({.name = "housing_x", .kind = SensorKind::kAccelerometer,
//                .frame = b.body_frame(housing), .X_FS = Transform::Translation(Vec3(0.2, 0, 0)),
//                .measured_in = kSensorAxes, .axes = {0}});
#include <string>
#include <vector>

#include "mbd/spatial.h"

namespace orrery {

enum class SensorKind {
  kAccelerometer,         // acceleration of the frame origin (m/s^2)
  kVelocity,              // velocity of the frame origin (m/s)
  kDisplacement,          // position relative to measured_in, minus its initial value (m)
  kGyroscope,             // angular velocity of the frame (rad/s)
  kAngularAccelerometer,  // angular acceleration of the frame (rad/s^2)
  kEncoder,               // joint coordinate (rad or m)
  kTachometer,            // joint velocity coordinate (rad/s or m/s)
  kGearMesh,              // lumped gear mesh quantity
  kElementOutput,         // output of an external force element
};
const char* SensorKindName(SensorKind kind);  // "accelerometer", ... (the YAML type names)

enum class MeshQuantity {
  kForce,              // tooth force along the engaged flank's normal (N), Data::mesh_force
  kDeflection,         // compression of the engaged flank (m), Data::mesh_deflection
  kTransmissionError,  // rotational transmission coordinate r_ba theta_a + sigma r_bb theta_b,
                       //   wrapped to one base pitch (m, MeshState::e)
};
const char* MeshQuantityName(MeshQuantity q);  // "force", "deflection", "transmission_error"

// measured_in value: the sensor frame's own axes (glued to the part).
constexpr int kSensorAxes = -1;

struct SensorSpec {
  std::string name;  // unique among sensors; the result group /sensors/<name>
  SensorKind kind = SensorKind::kAccelerometer;
  // Frame sensors (accelerometer ... angular accelerometer).
  int frame = -1;                 // FrameIndex the sensor is fixed to (a body's own frame, a
                                  //   marker, a node frame)
  Transform X_FS;                 // the sensor's pose S in that frame: its point and its axes
                                  //   (a point on a body needs no frame of its own: give the
                                  //   body's frame and the point here)
  int measured_in = kSensorAxes;  // kSensorAxes, or a FrameIndex (0: the world); a displacement
                                  //   needs a frame other than its own
  std::vector<int> axes{0, 1, 2}; // components recorded (0 x, 1 y, 2 z), 1 to 3, no repeats
  bool include_gravity = false;   // accelerometer: record a - g, the specific force a seismic
                                  //   mass senses (at rest it reads 9.81 m/s^2 upwards)
  // Joint sensors (encoder, tachometer): a velocity coordinate of the joint; an encoder needs a
  // scalar position coordinate (not a quaternion).
  int joint = -1;
  int coordinate = 0;
  // Gear-mesh sensors: index into Model::gear_meshes.
  int gear_mesh = -1;
  MeshQuantity mesh_quantity = MeshQuantity::kForce;
  // Element outputs: index into Model::external_forces and the output's name.
  int element = -1;
  std::string output;
};

// A sensor as the model holds it (ModelBuilder::Finalize fills the derived fields).
struct Sensor {
  SensorSpec spec;
  std::string quantity;               // dataset name: "acceleration", "angle", "force", ...
  std::string unit;                   // SI unit of the values
  std::vector<std::string> columns;   // one name per channel ("x", "z", ...)
  int channel_start = 0;              // first channel in Data::sensor_values
  int channels = 0;                   // 1 to 3 (frame sensors), 1 (joint, mesh), or the output's
  int q_index = -1, v_index = -1;     // joint sensors: model-wide coordinate indices
  int output_offset = 0;              // element outputs: first value in the element's outputs
  int element_values = 0;             // element outputs: values the element's GetOutputs writes
  bool needs_accelerations = false;   // accelerometer, angular accelerometer
  Vec3 p0_E = Vec3::Zero();           // displacement: position in E at the initial configuration
};

}  // namespace orrery

#pragma once
// A spatial planetary stage as seed 002 builds it, small: sun, ring and carrier on free joints
// on the world, each on a bearing to the world; two planets on free joints on the carrier with
// pin bearings; lumped sun-planet and ring-planet meshes (linear drive flank) in the carrier's
// frame; a speed driver on the carrier's rotation about z. Optionally a translational spring
// between the sun and the ring (it couples their subtrees). For the grouped differences of
// DaeSystem::Tangents and the generalized-alpha projection by articulated solves
// (grouped_differences_test.cpp, no_allocation_test.cpp).
#include <cmath>
#include <memory>
#include <string>

#include "mbd/model.h"

namespace orrery::test_support {

inline std::shared_ptr<const Model> SpatialStage(bool spring_between_sun_and_ring) {
  constexpr double kAlpha = 20 * 3.14159265358979323846 / 180;
  ModelBuilder mb;
  const Mat3 I = Vec3(1e-3, 1e-3, 2e-3).asDiagonal();
  auto rz = [](double a) { return AxisAngle(Vec3::UnitZ(), a); };
  const double rba = 0.03, rbb = 0.05, rbr = rba + 2 * rbb;  // base radii: sun, planet, ring
  const int za = 30, zb = 50;
  const double d_sp = (rba + rbb) / std::cos(kAlpha);
  const BodyIndex sun = mb.AddBody("sun", 1.0, Vec3::Zero(), I);
  const BodyIndex ring = mb.AddBody("ring", 3.0, Vec3::Zero(), 3 * I);
  const BodyIndex carrier = mb.AddBody("carrier", 2.0, Vec3::Zero(), 2 * I);
  mb.AddJoint({.name = "j_sun", .type = JointType::kFree, .child = sun});
  mb.AddJoint({.name = "j_ring",
               .type = JointType::kFree,
               .child = ring,
               .X_PF = Transform(rz(0.4), Vec3::Zero())});
  const JointIndex j_carrier = mb.AddJoint({.name = "j_carrier",
                                            .type = JointType::kFree,
                                            .child = carrier,
                                            .X_PF = Transform(rz(0.3), Vec3(0, 0, 0.02))});
  for (const BodyIndex b : {sun, ring, carrier})
    mb.AddBearing({.name = "bearing_" + std::to_string(b),
                   .frame_a = kWorldFrame,
                   .frame_b = mb.body_frame(b),
                   .radial_stiffness = 2e8,
                   .axial_stiffness = 1e8,
                   .tilt_stiffness = 1e5,
                   .radial_damping = 50,
                   .axial_damping = 20,
                   .tilt_damping = 1});
  const FrameIndex reference = mb.body_frame(carrier);
  for (int i = 0; i < 2; ++i) {
    const std::string name = "planet" + std::to_string(i);
    const BodyIndex planet = mb.AddBody(name, 0.5, Vec3::Zero(), I);
    const double psi = 0.5 + 2.5 * i;
    const Transform X_CP(rz(psi), d_sp * Vec3(std::cos(psi), std::sin(psi), 0));
    mb.AddJoint({.name = "j_" + name,
                 .type = JointType::kFree,
                 .parent = carrier,
                 .child = planet,
                 .X_PF = X_CP});
    mb.AddBearing({.name = "pin_" + name,
                   .frame_a = mb.AddFrame(name + "_pin", carrier, X_CP),
                   .frame_b = mb.body_frame(planet),
                   .radial_stiffness = 1e8,
                   .axial_stiffness = 5e7,
                   .tilt_stiffness = 1e5,
                   .radial_damping = 30,
                   .axial_damping = 10,
                   .tilt_damping = 1});
    for (int k = 0; k < 2; ++k) {
      GearMeshSpec s;
      s.name = (k ? "ring-" : "sun-") + name;
      s.contact = GearMeshSpec::Contact::kLinearDrive;
      s.gear_a = k ? mb.body_frame(planet) : mb.body_frame(sun);
      s.gear_b = k ? mb.body_frame(ring) : mb.body_frame(planet);
      s.reference = reference;
      s.teeth_a = k ? zb : za;
      s.teeth_b = k ? za + 2 * zb : zb;
      s.base_radius_a = k ? rbb : rba;
      s.base_radius_b = k ? rbr : rbb;
      s.internal_b = k == 1;
      s.working_pressure_angle = kAlpha;
      s.stiffness = 4e8;
      s.damping = 200;
      mb.AddGearMesh(s);
    }
  }
  if (spring_between_sun_and_ring)
    mb.AddTranslationalSpring({.name = "tie",
                               .frame_a = mb.body_frame(sun),
                               .frame_b = mb.body_frame(ring),
                               .stiffness = 1e4,
                               .damping = 1,
                               .free_length = 0});
  DriverSpec d;
  d.name = "drive", d.joint = j_carrier, d.coordinate = 5, d.mode = DriverSpec::Mode::kSpeed;
  d.function = TimeFunction::Sine(0.5, 3.0, 0.0, 2.0);
  mb.AddDriver(d);
  return std::move(mb).Finalize();
}

}  // namespace orrery::test_support

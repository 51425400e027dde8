#include "models/lumped_planetary.h"

#include <cmath>
#include <stdexcept>

namespace orrery {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Inertia tensor of a gear-like body: I_zz = inertia, a disc's I_xx = I_yy = I_zz / 2 (only the
// planar and torsional DOF sets ignore them; the spatial set uses them for tilting).
Mat3 DiscInertia(double izz) { return Vec3(0.5 * izz, 0.5 * izz, izz).asDiagonal(); }

void CheckMember(const std::string& name, const LumpedMember& m) {
  auto fail = [&](const std::string& what, double v) {
    throw std::invalid_argument("lumped stage: " + name + "." + what + " must be " +
                                (what == "mass" || what == "inertia" || what == "radius" ? "> 0" : ">= 0") +
                                ", got " + std::to_string(v));
  };
  if (!(m.mass > 0)) fail("mass", m.mass);
  if (!(m.inertia > 0)) fail("inertia", m.inertia);
  if (!(m.radius > 0)) fail("radius", m.radius);
  if (!(m.bearing_stiffness >= 0)) fail("bearing_stiffness", m.bearing_stiffness);
  if (!(m.torsional_stiffness >= 0)) fail("torsional_stiffness", m.torsional_stiffness);
  if (!(m.bearing_damping >= 0)) fail("bearing_damping", m.bearing_damping);
  if (!(m.torsional_damping >= 0)) fail("torsional_damping", m.torsional_damping);
  if (!(m.axial_stiffness >= 0)) fail("axial_stiffness", m.axial_stiffness);
  if (!(m.tilt_stiffness >= 0)) fail("tilt_stiffness", m.tilt_stiffness);
}

}  // namespace

LumpedStage BuildLumpedStage(const LumpedStageParams& p, const LumpedStageExtras& extras) {
  CheckMember("sun", p.sun);
  CheckMember("ring", p.ring);
  CheckMember("carrier", p.carrier);
  CheckMember("planet", p.planet);
  if (p.planet.torsional_stiffness != 0 || p.planet.torsional_damping != 0)
    throw std::invalid_argument("lumped stage: planet.torsional_stiffness and planet.torsional_damping must be 0: "
                                "a planet turns freely on its pin (its spin is held by its meshes)");
  if (p.planets < 1) throw std::invalid_argument("lumped stage: needs at least one planet");
  if (!p.planet_angles.empty() && static_cast<int>(p.planet_angles.size()) != p.planets)
    throw std::invalid_argument("lumped stage: planet_angles must list one angle per planet");
  if (!(p.mesh_stiffness_sun > 0) || !(p.mesh_stiffness_ring > 0))
    throw std::invalid_argument("lumped stage: mesh stiffnesses must be > 0");
  const bool torsional = p.dofs == LumpedStageParams::Dofs::kTorsional;
  const bool spatial = p.dofs == LumpedStageParams::Dofs::kSpatial;

  ModelBuilder b;
  LumpedStage stage;
  // Central members: on joints to the world with their bearing and torsional springs.
  auto central = [&](const std::string& name, const LumpedMember& m) {
    const BodyIndex body = b.AddBody(name, m.mass, Vec3::Zero(), DiscInertia(m.inertia));
    JointSpec j{.name = name, .parent = kWorldBody, .child = body, .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()};
    j.type = torsional ? JointType::kRevolute : spatial ? JointType::kFree : JointType::kPlanar;
    const JointIndex joint = b.AddJoint(j);
    if (torsional) {
      if (m.torsional_stiffness > 0 || m.torsional_damping > 0)
        b.AddCoordinateSpring({.name = name + "_torsion", .joint = joint, .coordinate = 0,
                               .stiffness = m.torsional_stiffness, .damping = m.torsional_damping});
    } else if (spatial) {
      b.AddBearing({.name = name + "_bearing", .frame_a = kWorldFrame, .frame_b = b.body_frame(body),
                    .radial_stiffness = m.bearing_stiffness, .axial_stiffness = m.axial_stiffness,
                    .tilt_stiffness = m.tilt_stiffness, .radial_damping = m.bearing_damping,
                    .axial_damping = m.bearing_damping});
      if (m.torsional_stiffness > 0 || m.torsional_damping > 0)
        b.AddRotationalSpring({.name = name + "_torsion", .frame_a = kWorldFrame, .frame_b = b.body_frame(body),
                               .stiffness = m.torsional_stiffness, .damping = m.torsional_damping});
    } else {
      for (int k = 0; k < 2; ++k)
        b.AddCoordinateSpring({.name = name + (k ? "_bearing_y" : "_bearing_x"), .joint = joint, .coordinate = k,
                               .stiffness = m.bearing_stiffness, .damping = m.bearing_damping});
      if (m.torsional_stiffness > 0 || m.torsional_damping > 0)
        b.AddCoordinateSpring({.name = name + "_torsion", .joint = joint, .coordinate = 2,
                               .stiffness = m.torsional_stiffness, .damping = m.torsional_damping});
    }
    return std::pair{body, joint};
  };
  const auto [sun, sun_joint] = central("sun", p.sun);
  const auto [ring, ring_joint] = central("ring", p.ring);
  const auto [carrier, carrier_joint] = central("carrier", p.carrier);
  stage.sun = sun_joint;
  stage.ring = ring_joint;
  stage.carrier = carrier_joint;

  const FrameIndex mesh_reference = p.lines_of_action_on_carrier ? b.body_frame(carrier) : kWorldFrame;
  // Planets: on the carrier at radius r_c, joint frame turned by psi (x radial, y tangential).
  for (int n = 0; n < p.planets; ++n) {
    const double psi = p.planet_angles.empty() ? 2 * kPi * n / p.planets : p.planet_angles[n];
    const std::string name = "planet" + std::to_string(n + 1);
    const BodyIndex planet = b.AddBody(name, p.planet.mass, Vec3::Zero(), DiscInertia(p.planet.inertia));
    JointSpec j{.name = name, .parent = carrier, .child = planet, .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()};
    j.X_PF = Transform(AxisAngle(Vec3::UnitZ(), psi),
                       p.carrier.radius * Vec3(std::cos(psi), std::sin(psi), 0));
    j.type = torsional ? JointType::kRevolute : spatial ? JointType::kFree : JointType::kPlanar;
    const JointIndex joint = b.AddJoint(j);
    stage.planets.push_back(joint);
    if (spatial) {
      const FrameIndex pin = b.AddFrame(name + "_pin", carrier, j.X_PF);
      b.AddBearing({.name = name + "_bearing", .frame_a = pin, .frame_b = b.body_frame(planet),
                    .radial_stiffness = p.planet.bearing_stiffness, .axial_stiffness = p.planet.axial_stiffness,
                    .tilt_stiffness = p.planet.tilt_stiffness, .radial_damping = p.planet.bearing_damping,
                    .axial_damping = p.planet.bearing_damping});
    } else if (!torsional) {
      for (int k = 0; k < 2; ++k)
        b.AddCoordinateSpring({.name = name + (k ? "_bearing_y" : "_bearing_x"), .joint = joint, .coordinate = k,
                               .stiffness = p.planet.bearing_stiffness, .damping = p.planet.bearing_damping});
    }
    // Meshes, measured in the carrier frame.
    GearMeshSpec sp{.name = "sun_" + name, .gear_a = b.body_frame(sun), .gear_b = b.body_frame(planet),
                    .reference = mesh_reference, .teeth_a = std::max(p.sun.teeth, 1),
                    .teeth_b = std::max(p.planet.teeth, 1), .base_radius_a = p.sun.radius,
                    .base_radius_b = p.planet.radius, .working_pressure_angle = p.pressure_angle_sun,
                    .base_helix_angle = p.helix_angle, .internal_b = false,
                    .contact = GearMeshSpec::Contact::kLinearDrive, .stiffness = p.mesh_stiffness_sun,
                    .damping_ratio = p.mesh_damping_ratio, .check_centre_distance = p.check_centre_distance};
    b.AddGearMesh(sp);
    GearMeshSpec rp{.name = "ring_" + name, .gear_a = b.body_frame(planet), .gear_b = b.body_frame(ring),
                    .reference = mesh_reference, .teeth_a = std::max(p.planet.teeth, 1),
                    .teeth_b = std::max(p.ring.teeth, 1), .base_radius_a = p.planet.radius,
                    .base_radius_b = p.ring.radius, .working_pressure_angle = p.pressure_angle_ring,
                    .base_helix_angle = -p.helix_angle, .internal_b = true,
                    .contact = GearMeshSpec::Contact::kLinearCoast, .stiffness = p.mesh_stiffness_ring,
                    .damping_ratio = p.mesh_damping_ratio, .check_centre_distance = p.check_centre_distance};
    b.AddGearMesh(rp);
  }
  if (extras) extras(b, stage);
  stage.model = std::move(b).Finalize();
  return stage;
}

LumpedStageParams LinParker1999Example(int planets) {
  // Table 1 of Lin & Parker (1999): masses, I/r^2, base diameters (carrier: planet-centre circle),
  // bearing stiffnesses 1e8 N/m, ring torsional stiffness 1e9 N/m on u = r theta, meshes 5e8 N/m,
  // pressure angles 24.6 deg.
  LumpedStageParams p;
  p.dofs = LumpedStageParams::Dofs::kPlanar;
  p.planets = planets;
  auto member = [](double m, double i_over_r2, double diameter_mm, double k_bearing, double k_u) {
    LumpedMember x;
    x.mass = m;
    x.radius = 0.5e-3 * diameter_mm;
    x.inertia = i_over_r2 * x.radius * x.radius;
    x.bearing_stiffness = k_bearing;
    x.torsional_stiffness = k_u * x.radius * x.radius;  // k_u on u = r theta -> k_u r^2 on theta
    return x;
  };
  p.sun = member(0.4, 0.39, 77.4, 1e8, 0);
  p.ring = member(2.35, 3.00, 275.0, 1e8, 1e9);
  p.carrier = member(5.43, 6.29, 176.8, 1e8, 0);
  p.planet = member(0.66, 0.61, 100.3, 1e8, 0);
  p.mesh_stiffness_sun = p.mesh_stiffness_ring = 5e8;
  p.pressure_angle_sun = p.pressure_angle_ring = 24.6 * kPi / 180;
  p.lines_of_action_on_carrier = false;  // carrier speed 0
  return p;
}

}  // namespace orrery

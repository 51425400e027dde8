// The `lumped_stage:` section of a scene (docs/scene_format.md, "Gear model sections"): explicit
// lumped parameters of one planetary stage -> BuildLumpedStage (models/lumped_planetary.h), with
// optional member drivers and loads.
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "import/gear_scene.h"
#include "import/unit_keys.h"

namespace orrery::scene_reader {
namespace {

// Keys a member takes that would not act on the model of this DOF set (each key must act or be
// refused): a planet turns freely on its pin (no torsional spring to ground: a planet's spin is
// held by its meshes only); the torsional set has no translations (no bearings, and the sun's,
// ring's and carrier's masses do not act: a planet's mass does, as m r_c^2 on the carrier); axial
// and tilt stiffness act in the spatial set only.
std::map<std::string, std::string> IdleMemberKeys(const std::string& kind, const std::string& dofs) {
  std::map<std::string, std::string> idle;
  if (kind == "planet")
    for (const char* k : {"torsional_stiffness", "torsional_stiffness_u", "torsional_damping"})
      idle[k] = "a planet turns freely on its pin: it has no torsional spring (its spin is held by its meshes; "
                "give the sun, ring or carrier a torsional stiffness)";
  if (dofs == "torsional")
    for (const char* k : {"bearing_stiffness", "bearing_damping"})
      idle[k] = "not used with dofs: torsional (no translations; use dofs: planar or spatial)";
  if (dofs == "torsional" && kind != "planet")
    idle["mass"] = "not used with dofs: torsional (the " + kind +
                   " only turns: its inertia acts, its mass does not; use dofs: planar or spatial)";
  if (dofs != "spatial")
    for (const char* k : {"axial_stiffness", "tilt_stiffness"})
      idle[k] = "not used with dofs: " + dofs + " (axial and tilting motions are in dofs: spatial only)";
  return idle;
}

LumpedMember ReadLumpedMember(const Context& ctx, const Item& item, const std::string& kind,
                             const std::string& dofs) {
  const bool carrier = kind == "carrier";
  const std::string radius_stem = carrier ? "planet_circle" : "base";
  std::map<std::string, std::string> notes = IdleMemberKeys(kind, dofs);
  std::vector<std::string> allowed;
  for (const char* k : {"mass", "inertia", "inertia_over_r2", "bearing_stiffness", "bearing_damping",
                        "torsional_stiffness", "torsional_stiffness_u", "torsional_damping", "axial_stiffness",
                        "tilt_stiffness", "teeth"})
    if (!notes.count(k)) allowed.push_back(k);
  Append(allowed, Names(RadiusKeys(radius_stem)));
  for (const std::string& k : Names(RadiusKeys(carrier ? "base" : "planet_circle")))
    notes[k] = carrier ? "the carrier has no base circle: give the planet-centre circle "
                         "(planet_circle_diameter_mm, ...)"
                       : "only the carrier has a planet-centre circle: give the base circle "
                         "(base_diameter_mm, ...)";
  if (carrier) notes["teeth"] = "the carrier has no teeth";
  const MapReader m(ctx, item, allowed, notes);
  LumpedMember x;
  // A member that cannot translate still is a body: its mass is a placeholder that never acts.
  x.mass = notes.count("mass") ? 1.0 : NeedScaled(m, Plain("mass"));
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

}  // namespace

void ReadLumpedStage(const Context& ctx, const Item& section, Scene& scene) {
  std::vector<std::string> allowed{"dofs", "planets", "planet_angles", "planet_angles_deg", "sun", "ring",
                                   "carrier", "planet", "mesh_stiffness_sun", "mesh_stiffness_ring",
                                   "mesh_damping_ratio", "lines_of_action_on_carrier",
                                   "check_centre_distance", "input", "load"};
  for (const auto& group : {Angle("pressure_angle_sun"), Angle("pressure_angle_ring"), Angle("helix_angle")})
    Append(allowed, Names(group));
  // The lines of action's directions act through translations only.
  const std::string dofs = MapReader(ctx, section, allowed).Choice("dofs", {"torsional", "planar", "spatial"}, "planar");
  std::map<std::string, std::string> notes;
  if (dofs == "torsional")
    for (const auto& group : {Angle("pressure_angle_sun"), Angle("pressure_angle_ring")})
      for (const std::string& k : Names(group)) {
        std::erase(allowed, k);
        notes[k] = "not used with dofs: torsional (the meshes act on the base circles; the lines of action's "
                   "directions matter with translations only: use dofs: planar or spatial)";
      }
  const MapReader m(ctx, section, allowed, notes);
  auto s = std::make_shared<LumpedStageScene>();
  LumpedStageParams& p = s->params;
  p.dofs = dofs == "torsional" ? LumpedStageParams::Dofs::kTorsional
           : dofs == "planar"  ? LumpedStageParams::Dofs::kPlanar
                               : LumpedStageParams::Dofs::kSpatial;
  s->rotation_coordinate = dofs == "torsional" ? 0 : dofs == "planar" ? 2 : 5;
  if (!m.Has("planets")) m.FailMissing("planets", "missing required key 'planets'");
  p.planets = m.Int("planets", 0);
  if (p.planets < 1) ctx.Fail(m.Need("planets"), "must be >= 1, got " + std::to_string(p.planets));
  p.planet_angles = AnglesOf(m, "planet_angles", p.planets).value_or(std::vector<double>{});
  p.sun = ReadLumpedMember(ctx, m.Need("sun"), "sun", dofs);
  p.ring = ReadLumpedMember(ctx, m.Need("ring"), "ring", dofs);
  p.carrier = ReadLumpedMember(ctx, m.Need("carrier"), "carrier", dofs);
  p.planet = ReadLumpedMember(ctx, m.Need("planet"), "planet", dofs);
  p.mesh_stiffness_sun = NeedScaled(m, Plain("mesh_stiffness_sun"));
  p.mesh_stiffness_ring = NeedScaled(m, Plain("mesh_stiffness_ring"));
  // Working transverse pressure angles, (0, 90) degrees.
  for (const auto& [key, to] : {std::pair{std::string("pressure_angle_sun"), &p.pressure_angle_sun},
                                std::pair{std::string("pressure_angle_ring"), &p.pressure_angle_ring}}) {
    if (dofs == "torsional") {  // a nominal 20 degrees, which does not act
      *to = 20 * std::numbers::pi / 180;
      continue;
    }
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

}  // namespace orrery::scene_reader

#include "models/train_dynamics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

#include "mbd/evaluate.h"
#include "mbd/kinematics.h"
#include "mbd/linearization.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

[[noreturn]] void Fail(const std::string& msg) { throw std::invalid_argument("train model: " + msg); }

// Involute(alpha) = tan(alpha) - alpha comes from gear_geometry.h.

// x mod 1 in [0, 1).
double Frac(double x) {
  const double f = x - std::floor(x);
  return f >= 1.0 ? 0.0 : f;
}

// Centre of gear `g` on branch `branch` in the carrier frame (central gears on the axis).
Vec3 GearCentre(const PlanetaryTrain& train, int g, int branch) {
  const TrainGear& gear = train.gears[g];
  if (gear.planet_set < 0) return Vec3::Zero();
  const PlanetSet& ps = train.planet_sets[gear.planet_set];
  const double psi = ps.angles_rad[branch];
  return ps.center_radius_m * Vec3(std::cos(psi), std::sin(psi), 0);
}

// Spec gears of a train mesh: (a, b); a ring is always b (internal), a planet is b of an
// external mesh with a central gear.
std::pair<int, int> SpecGears(const TrainMesh& m) {
  if (m.kind == MeshKind::kInternal) return {m.gear_b, m.gear_a};
  return {m.gear_a, m.gear_b};
}

// Half the base-circle tooth angle of a gear of standard tooth thickness (s = pi m_t / 2 at the
// reference circle, no profile shift): theta_b = s / (2 r) + inv(alpha_t) = pi / (2 Z) + inv.
double HalfBaseToothAngle(const TrainGear& g, double alpha_w) {
  const double alpha_t = g.has_tooth_form ? g.transverse_pressure_angle_rad : alpha_w;
  return kPi / (2.0 * g.teeth) + Involute(alpha_t);
}

// Inertia tensor of an axisymmetric body in its own axes (z the axis).
Mat3 AxisymmetricInertia(double polar, double transverse) {
  return Vec3(transverse, transverse, polar).asDiagonal();
}

// Annulus r_in..r_out of thickness b: mass, polar and transverse inertia about its centre.
TrainBodyParams Annulus(double rho, double r_in, double r_out, double b) {
  TrainBodyParams p;
  p.face_width_m = b;
  p.mass_kg = rho * kPi * (r_out * r_out - r_in * r_in) * b;
  p.polar_inertia_kg_m2 = 0.5 * p.mass_kg * (r_out * r_out + r_in * r_in);
  p.transverse_inertia_kg_m2 = p.mass_kg * (3.0 * (r_out * r_out + r_in * r_in) + b * b) / 12.0;
  return p;
}

// Member / planet-set parameters: derived from geometry and material, then overridden.
TrainBodyParams ResolveBody(const PlanetaryTrain& train, const std::string& name, int gear,
                            bool carrier, int stage, const TrainModelOptions& o) {
  const auto it = o.members.find(name);
  const TrainMemberOverride none;
  const TrainMemberOverride& ov = it == o.members.end() ? none : it->second;
  const double b = ov.face_width_m.value_or(o.face_width_m);
  TrainBodyParams p;
  const bool all_given = ov.mass_kg && ov.polar_inertia_kg_m2;
  if (!all_given && !(b > 0)) Fail("'" + name + "' needs a face width (options.face_width_m or an override)");
  if (carrier) {
    // Crude default: a steel disc reaching the tip circles of the planets.
    double r_out = 0;
    for (int ps : train.stages[stage].planet_sets) {
      const PlanetSet& set = train.planet_sets[ps];
      const TrainGear& g = train.gears[set.gear];
      r_out = std::max(r_out, set.center_radius_m + (g.has_tooth_form ? g.tip_radius_m : 0.0));
    }
    r_out = ov.outer_radius_m.value_or(r_out);
    if (!all_given) p = Annulus(o.density_kg_m3, ov.bore_radius_m.value_or(0.0), r_out, b);
  } else {
    const TrainGear& g = train.gears[gear];
    if (!g.has_tooth_form && !ov.base_radius_m)
      Fail("gear '" + g.name + "' has no tooth form: give its base radius as an override");
    if (!all_given) {
      if (!g.has_tooth_form) Fail("gear '" + g.name + "' has no tooth form: give mass and inertia");
      const double r = g.pitch_radius_m;
      if (g.internal) {
        const double r_out = ov.outer_radius_m.value_or(r + o.ring_rim_modules * g.tooth_form.normal_module_m);
        p = Annulus(o.density_kg_m3, r, r_out, b);
      } else {
        p = Annulus(o.density_kg_m3, ov.bore_radius_m.value_or(o.bore_to_pitch_ratio * r), r, b);
      }
    }
    p.base_radius_m = ov.base_radius_m.value_or(g.base_radius_m);
  }
  p.face_width_m = b > 0 ? b : p.face_width_m;
  if (ov.mass_kg) p.mass_kg = *ov.mass_kg;
  if (ov.polar_inertia_kg_m2) p.polar_inertia_kg_m2 = *ov.polar_inertia_kg_m2;
  // Transverse inertia: given, derived, or a thin disc's I_z / 2 + m b^2 / 12.
  if (ov.transverse_inertia_kg_m2) p.transverse_inertia_kg_m2 = *ov.transverse_inertia_kg_m2;
  else if (ov.mass_kg || ov.polar_inertia_kg_m2) p.transverse_inertia_kg_m2 = 0.5 * p.polar_inertia_kg_m2 + p.mass_kg * b * b / 12.0;
  if (!(p.mass_kg > 0) || !(p.polar_inertia_kg_m2 > 0) || !(p.transverse_inertia_kg_m2 > 0))
    Fail("'" + name + "': mass and inertias must be > 0");
  return p;
}

// Name under which a gear's member or planet set is overridden.
const std::string& GearOwnerName(const PlanetaryTrain& train, int g) {
  const TrainGear& gear = train.gears[g];
  return gear.planet_set < 0 ? train.members[gear.member].name : train.planet_sets[gear.planet_set].name;
}

const TrainMemberOverride& OverrideOf(const TrainModelOptions& o, const std::string& name) {
  static const TrainMemberOverride kNone;
  const auto it = o.members.find(name);
  return it == o.members.end() ? kNone : it->second;
}

// Involute gear of train gear g for the stiffness models (see the header).
Gear MakeStiffnessGear(const PlanetaryTrain& train, int g, bool right_hand, const TrainModelOptions& o) {
  const TrainGear& tg = train.gears[g];
  if (!tg.has_tooth_form) Fail("gear '" + tg.name + "' has no tooth form: its stiffness cannot come from geometry");
  const TrainMemberOverride& ov = OverrideOf(o, GearOwnerName(train, g));
  GearSpec spec;
  spec.teeth = tg.teeth;
  spec.normal_module_m = tg.tooth_form.normal_module_m;
  spec.normal_pressure_angle_rad = tg.tooth_form.normal_pressure_angle_rad;
  spec.helix_angle_rad = std::abs(tg.tooth_form.helix_angle_rad);
  spec.hand = right_hand ? HelixHand::kRight : HelixHand::kLeft;
  spec.profile_shift = ov.profile_shift.value_or(0.0);
  spec.addendum_coef = ov.addendum_coefficient.value_or(tg.internal ? o.ring_addendum_coefficient
                                                                   : tg.tooth_form.addendum_coefficient);
  spec.face_width_m = ov.face_width_m.value_or(o.face_width_m);
  spec.internal = tg.internal;
  try {
    return Gear(spec);
  } catch (const std::invalid_argument& e) {
    Fail("gear '" + tg.name + "': " + e.what());
  }
}

// Bore radius of an external gear, outer rim radius of a ring (as for the inertias).
double RimRadius(const PlanetaryTrain& train, int g, const TrainModelOptions& o) {
  const TrainGear& tg = train.gears[g];
  const TrainMemberOverride& ov = OverrideOf(o, GearOwnerName(train, g));
  if (tg.internal) return ov.outer_radius_m.value_or(tg.pitch_radius_m + o.ring_rim_modules * tg.tooth_form.normal_module_m);
  return ov.bore_radius_m.value_or(o.bore_to_pitch_ratio * tg.pitch_radius_m);
}

// Periodic linear interpolation of TVMS samples at gear-1 cycles u.
double TvmsAt(const Tvms& t, int samples_per_cycle, double u) {
  const int n = static_cast<int>(t.stiffness_n_per_m.size());
  double x = std::fmod(u * samples_per_cycle, static_cast<double>(n));
  if (x < 0) x += n;
  const int i = std::min(static_cast<int>(x), n - 1);
  const double f = x - i;
  return (1 - f) * t.stiffness_n_per_m[i] + f * t.stiffness_n_per_m[(i + 1) % n];
}

}  // namespace

GearPair MakeTrainGearPair(const PlanetaryTrain& train, int mesh, const TrainModelOptions& o) {
  const TrainMesh& m = train.meshes.at(mesh);
  const auto [a, b] = SpecGears(m);
  const bool internal = m.kind == MeshKind::kInternal;
  const Gear g1 = MakeStiffnessGear(train, a, true, o);
  const Gear g2 = MakeStiffnessGear(train, b, internal, o);
  const double dist = (GearCentre(train, a, 0) - GearCentre(train, b, 0)).norm();
  try {
    return GearPair(g1, g2, dist);
  } catch (const std::invalid_argument& e) {
    Fail("mesh '" + m.name + "': " + e.what() +
         " (give profile shifts or addendum coefficients as member overrides)");
  }
}

std::vector<std::vector<double>> CalcStageMeshPhases(const PlanetaryTrain& train, int stage,
                                                     const std::vector<bool>& drive,
                                                     const std::vector<double>& pressure_angles,
                                                     double reference_phase) {
  const Stage& st = train.stages.at(stage);
  const int n = st.num_planets;
  if (drive.size() != st.meshes.size() || pressure_angles.size() != st.meshes.size())
    Fail("stage '" + st.name + "': one flank and one pressure angle per mesh are needed");
  // tau = Z chi / 2 pi (mod 1) of a tooth centre chi of each gear in the carrier frame; central
  // gears have one value for all branches (key branch -1).
  std::map<std::pair<int, int>, double> tau;
  auto key = [&](int g, int branch) {
    return std::pair{g, train.gears[g].planet_set < 0 ? -1 : branch};
  };
  std::vector<std::vector<double>> phases(st.meshes.size(), std::vector<double>(n, 0.0));
  for (size_t k = 0; k < st.meshes.size(); ++k) {
    const TrainMesh& m = train.meshes[st.meshes[k]];
    const auto [a, b] = SpecGears(m);
    const bool internal = m.kind == MeshKind::kInternal;
    const double sigma = drive[k] ? 1.0 : -1.0;
    const double inv_w = Involute(pressure_angles[k]);
    for (int i = 0; i < n; ++i) {
      const Vec3 ca = GearCentre(train, a, i), cb = GearCentre(train, b, i);
      // Per external gear G of the mesh: eps, Z, the pitch-point direction phi_P and the flank
      // offset sigma (theta_b - inv alpha_w), all in cycles of G's teeth.
      struct Side { int g; double eps, z, phi_p, offset; };
      auto side = [&](int g, double eps, const Vec3& from, const Vec3& to, bool outward) {
        const Vec3 d = outward ? from : Vec3(to - from);
        const TrainGear& gear = train.gears[g];
        return Side{g, eps, double(gear.teeth), std::atan2(d.y(), d.x()),
                    sigma * (HalfBaseToothAngle(gear, pressure_angles[k]) - inv_w)};
      };
      const Side sa = side(a, 1.0, ca, cb, internal);  // internal: a planet, P away from the axis
      const bool b_external = !internal;
      const Side sb = b_external ? side(b, -1.0, cb, ca, false) : Side{};
      // Phase seen from G's teeth, and G's teeth from a phase (conjugacy).
      auto phase_from = [&](const Side& s, double t) {
        return s.eps * (t - s.z * s.phi_p / (2 * kPi) + s.z * s.offset / (2 * kPi));
      };
      auto tau_from = [&](const Side& s, double psi) {
        return Frac(s.eps * psi + s.z * s.phi_p / (2 * kPi) - s.z * s.offset / (2 * kPi));
      };
      double psi;
      if (tau.count(key(a, i))) psi = phase_from(sa, tau[key(a, i)]);
      else if (b_external && tau.count(key(b, i))) psi = phase_from(sb, tau[key(b, i)]);
      else psi = reference_phase;  // the reference mesh fixes the sun's teeth
      if (!tau.count(key(a, i))) tau[key(a, i)] = tau_from(sa, psi);
      if (b_external && !tau.count(key(b, i))) tau[key(b, i)] = tau_from(sb, psi);
      phases[k][i] = Frac(psi);
    }
  }
  return phases;
}

TrainModel BuildTrainModel(const PlanetaryTrain& train, int range, const TrainModelOptions& o) {
  if (range < 0 || range >= static_cast<int>(train.ranges.size()))
    Fail("gear range index " + std::to_string(range) + " out of range");
  const int num_inputs = static_cast<int>(train.inputs.size());
  if (!o.input_speeds_rad_s.empty() && static_cast<int>(o.input_speeds_rad_s.size()) != num_inputs)
    Fail("input_speeds_rad_s needs one speed per train input (" + std::to_string(num_inputs) + ")");
  for (const auto& [name, ov] : o.members)
    if (!train.member_by_name.count(name) && !train.planet_set_by_name.count(name))
      Fail("member override '" + name + "' names no member or planet set");
  for (const auto& [name, ov] : o.meshes)
    if (!train.mesh_by_name.count(name)) Fail("mesh override '" + name + "' names no mesh");
  if (o.two_sided_contact && !(o.backlash_m >= 0)) Fail("backlash must be >= 0");
  if (o.tvms_samples_per_cycle < 2) Fail("tvms_samples_per_cycle must be >= 2");
  // Tooth faults: train gear index per fault.
  std::vector<int> fault_gear;
  for (const TrainToothFault& f : o.tooth_faults) {
    int g = -1;
    for (int k = 0; k < static_cast<int>(train.gears.size()); ++k)
      if (train.gears[k].name == f.gear) g = k;
    if (g < 0) Fail("tooth fault on '" + f.gear + "': no such gear");
    const TrainGear& tg = train.gears[g];
    if (tg.planet_set >= 0 && (f.branch < 0 || f.branch >= static_cast<int>(train.planet_sets[tg.planet_set].angles_rad.size())))
      Fail("tooth fault on '" + f.gear + "': branch " + std::to_string(f.branch) + " out of range");
    if (f.fault.tooth < 0 || f.fault.tooth >= tg.teeth)
      Fail("tooth fault on '" + f.gear + "': tooth " + std::to_string(f.fault.tooth) + " out of range");
    fault_gear.push_back(g);
  }

  TrainModel tm;
  tm.train = std::make_shared<const PlanetaryTrain>(train);
  tm.range = range;
  tm.dofs = o.dofs;
  const bool torsional = o.dofs == TrainDofs::kTorsional;
  const bool spatial = o.dofs == TrainDofs::kSpatial;
  tm.rotation_coordinate = torsional ? 0 : spatial ? 5 : 2;

  // Kinematics at the given speeds and at unit input speed (directions of the mesh phases).
  if (!o.input_speed_functions.empty()) {
    if (static_cast<int>(o.input_speed_functions.size()) != num_inputs)
      Fail("input_speed_functions needs one function per train input (" + std::to_string(num_inputs) + ")");
    if (!o.input_speeds_rad_s.empty()) Fail("give input_speeds_rad_s or input_speed_functions, not both");
    if (o.input != TrainModelOptions::Input::kSpeed) Fail("input_speed_functions need Input::kSpeed");
  }
  Eigen::VectorXd speeds = Eigen::VectorXd::Zero(num_inputs);
  for (int i = 0; i < static_cast<int>(o.input_speeds_rad_s.size()); ++i) speeds(i) = o.input_speeds_rad_s[i];
  for (int i = 0; i < static_cast<int>(o.input_speed_functions.size()); ++i) speeds(i) = o.input_speed_functions[i].Value(0.0);
  tm.kinematics = SolvePlanetaryKinematics(train, range, speeds);
  Eigen::VectorXd unit = Eigen::VectorXd::Ones(num_inputs);
  if (speeds.cwiseAbs().maxCoeff() > 0) {
    if (speeds(0) == 0) Fail("the first input's speed is 0 while others are not: cannot scale");
    unit = speeds / speeds(0);
  }
  tm.unit_kinematics = SolvePlanetaryKinematics(train, range, unit);
  // Power flow: the loaded flanks (from 1 N m if no torque is given) and the port torques.
  const double t_flow = o.input_torque_Nm != 0 ? o.input_torque_Nm : 1.0;
  tm.power_flow = CalcPlanetaryPowerFlow(train, tm.unit_kinematics, train.inputs[0], t_flow);
  const double load_scale = o.input_torque_Nm != 0 ? 1.0 : 0.0;

  // Parameters of members and planet sets.
  for (int i = 0; i < train.num_members(); ++i) {
    const Member& m = train.members[i];
    tm.member_params.push_back(
        ResolveBody(train, m.name, m.gear, m.kind == MemberKind::kCarrier, m.stage, o));
  }
  for (const PlanetSet& ps : train.planet_sets)
    tm.planet_params.push_back(ResolveBody(train, ps.name, ps.gear, false, ps.stage, o));
  auto override_of = [&](const std::string& name) {
    const auto it = o.members.find(name);
    return it == o.members.end() ? TrainMemberOverride{} : it->second;
  };

  ModelBuilder b;
  const double spacing = o.stage_spacing_m > 0 ? o.stage_spacing_m : 3.0 * o.face_width_m;
  const JointType joint_type = torsional ? JointType::kRevolute : spatial ? JointType::kFree : JointType::kPlanar;
  const int rot = tm.rotation_coordinate;
  auto joint_velocity = [&](double w) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(torsional ? 1 : spatial ? 6 : 3);
    v(rot) = w;
    return v;
  };
  // Torsional spring of a member to ground (brakes, k_jg).
  auto ground_spring = [&](const std::string& name, int member, double k) {
    const JointIndex j = tm.member_joints[member];
    if (spatial) {
      const BodyIndex body = b.draft().joints[j].spec.child;
      const FrameIndex housing = b.AddFrame(name + "_ground", kWorldBody, b.draft().joints[j].spec.X_PF);
      b.AddRotationalSpring({.name = name, .frame_a = housing, .frame_b = b.body_frame(body), .stiffness = k});
    } else {
      b.AddCoordinateSpring({.name = name, .joint = j, .coordinate = rot, .stiffness = k});
    }
  };

  // Central members: bodies on joints to the world, stage j at z = j * spacing (spatial).
  std::vector<BodyIndex> member_body(train.num_members());
  for (int i = 0; i < train.num_members(); ++i) {
    const Member& m = train.members[i];
    const TrainBodyParams& p = tm.member_params[i];
    const TrainMemberOverride ov = override_of(m.name);
    member_body[i] = b.AddBody(m.name, p.mass_kg, Vec3::Zero(),
                               AxisymmetricInertia(p.polar_inertia_kg_m2, p.transverse_inertia_kg_m2));
    const Vec3 origin(0, 0, spatial ? m.stage * spacing : 0.0);
    const JointIndex j = b.AddJoint({.name = m.name, .type = joint_type, .parent = kWorldBody,
                                     .child = member_body[i], .X_PF = Transform(Mat3::Identity(), origin),
                                     .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
    tm.member_joints.push_back(j);
    b.SetJointVelocity(j, joint_velocity(tm.kinematics.speeds_rad_s(i)));
    // Bearings to the housing.
    const double kr = ov.radial_bearing_stiffness_N_m.value_or(o.radial_bearing_stiffness_N_m);
    const double cr = ov.bearing_damping_N_s_m.value_or(o.bearing_damping_N_s_m);
    if (spatial) {
      // A bearing, not a bushing: members spin past half a turn.
      const FrameIndex housing = b.AddFrame(m.name + "_housing", kWorldBody, Transform(Mat3::Identity(), origin));
      b.AddBearing({.name = m.name + "_bearing", .frame_a = housing, .frame_b = b.body_frame(member_body[i]),
                    .radial_stiffness = kr,
                    .axial_stiffness = ov.axial_bearing_stiffness_N_m.value_or(o.axial_bearing_stiffness_N_m),
                    .tilt_stiffness = ov.tilt_bearing_stiffness_N_m_rad.value_or(o.tilt_bearing_stiffness_N_m_rad),
                    .radial_damping = cr, .axial_damping = cr});
    } else if (!torsional) {
      for (int k = 0; k < 2; ++k)
        b.AddCoordinateSpring({.name = m.name + (k ? "_bearing_y" : "_bearing_x"), .joint = j,
                               .coordinate = k, .stiffness = kr, .damping = cr});
    }
    if (ov.ground_torsional_stiffness_N_m_rad)
      ground_spring(m.name + "_ground", i, *ov.ground_torsional_stiffness_N_m_rad);
  }

  // Planets on their carriers: joint frame turned by psi (x radial, y tangential).
  std::vector<std::vector<BodyIndex>> planet_body(train.planet_sets.size());
  std::vector<std::vector<FrameIndex>> planet_mesh_frame(train.planet_sets.size());  // meshes act here
  tm.planet_joints.resize(train.planet_sets.size());
  for (size_t s = 0; s < train.planet_sets.size(); ++s) {
    const PlanetSet& ps = train.planet_sets[s];
    const TrainBodyParams& p = tm.planet_params[s];
    const TrainMemberOverride ov = override_of(ps.name);
    const BodyIndex carrier = member_body[train.stages[ps.stage].carrier];
    const double w_rel = tm.kinematics.speeds_rad_s(train.num_members() + s) -
                         tm.kinematics.speeds_rad_s(train.stages[ps.stage].carrier);
    for (size_t i = 0; i < ps.angles_rad.size(); ++i) {
      const double psi = ps.angles_rad[i];
      const std::string name = ps.name + std::to_string(i + 1);
      const auto flex_it = o.flexible_planets.find(name);
      const bool flexible = flex_it != o.flexible_planets.end();
      const BodyIndex body =
          flexible ? b.AddFlexibleBody(name, flex_it->second.modes, flex_it->second.options)
                   : b.AddBody(name, p.mass_kg, Vec3::Zero(),
                               AxisymmetricInertia(p.polar_inertia_kg_m2, p.transverse_inertia_kg_m2));
      const Transform X_PF(AxisAngle(Vec3::UnitZ(), psi), ps.center_radius_m * Vec3(std::cos(psi), std::sin(psi), 0));
      const JointIndex j = b.AddJoint({.name = name, .type = joint_type, .parent = carrier, .child = body,
                                       .X_PF = X_PF, .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
      b.SetJointVelocity(j, joint_velocity(w_rel));
      planet_body[s].push_back(body);
      planet_mesh_frame[s].push_back(b.body_frame(body));
      if (flexible && !flex_it->second.mesh_interface.empty()) {
        const FlexibleBodyModes& modes = *flex_it->second.modes;
        const auto set = modes.node_sets.find(flex_it->second.mesh_interface);
        if (set == modes.node_sets.end() || set->second.size() != 1)
          throw std::invalid_argument("flexible planet '" + name + "': mesh_interface '" +
                                      flex_it->second.mesh_interface +
                                      "' is not an interface of its reduced body");
        const int node = set->second[0];
        planet_mesh_frame[s].back() =
            b.AddNodeFrame(name + "_mesh", body, node, Transform::Translation(modes.nodes[node].position));
      }
      tm.planet_joints[s].push_back(j);
      // Planet bearings on the pin (seed 002 eq. 10; no torsional stiffness).
      const double kr = ov.radial_bearing_stiffness_N_m.value_or(o.radial_bearing_stiffness_N_m);
      const double cr = ov.bearing_damping_N_s_m.value_or(o.bearing_damping_N_s_m);
      int bearing_index = -1;
      if (spatial) {
        const FrameIndex pin = b.AddFrame(name + "_pin", carrier, X_PF);
        bearing_index = static_cast<int>(b.draft().bearings.size());
        b.AddBearing({.name = name + "_bearing", .frame_a = pin, .frame_b = b.body_frame(body),
                      .radial_stiffness = kr,
                      .axial_stiffness = ov.axial_bearing_stiffness_N_m.value_or(o.axial_bearing_stiffness_N_m),
                      .tilt_stiffness = ov.tilt_bearing_stiffness_N_m_rad.value_or(o.tilt_bearing_stiffness_N_m_rad),
                      .radial_damping = cr, .axial_damping = cr});
      } else if (!torsional) {
        bearing_index = static_cast<int>(b.draft().coordinate_springs.size());
        for (int k = 0; k < 2; ++k)
          b.AddCoordinateSpring({.name = name + (k ? "_bearing_y" : "_bearing_x"), .joint = j,
                                 .coordinate = k, .stiffness = kr, .damping = cr});
      }
      tm.planet_bearings.resize(train.planet_sets.size());
      tm.planet_bearings[s].push_back(bearing_index);
    }
  }

  // Unknown flexible planets are an error, not a silent rigid planet.
  for (const auto& [name, planet] : o.flexible_planets) {
    bool found = false;
    for (size_t s = 0; s < train.planet_sets.size(); ++s)
      for (size_t i = 0; i < train.planet_sets[s].angles_rad.size(); ++i)
        found = found || train.planet_sets[s].name + std::to_string(i + 1) == name;
    if (!found) throw std::invalid_argument("flexible planet '" + name + "': no planet of that name in the train");
  }

  // Frame the meshes act on, base radius and face width by train gear index and branch.
  auto gear_frame = [&](int g, int branch) {
    const TrainGear& gear = train.gears[g];
    return gear.planet_set < 0 ? b.body_frame(member_body[gear.member]) : planet_mesh_frame[gear.planet_set][branch];
  };
  auto gear_params = [&](int g) -> const TrainBodyParams& {
    const TrainGear& gear = train.gears[g];
    return gear.planet_set < 0 ? tm.member_params[gear.member] : tm.planet_params[gear.planet_set];
  };

  // Meshes stage by stage: flank, pressure angle and stiffness per train mesh, phases per branch.
  for (size_t si = 0; si < train.stages.size(); ++si) {
    const Stage& st = train.stages[si];
    const FrameIndex reference = b.body_frame(member_body[st.carrier]);
    std::vector<bool> drive;
    std::vector<double> alpha;
    std::vector<bool> geometric;  // centre distance consistent with the base radii
    for (int mi : st.meshes) {
      const TrainMesh& m = train.meshes[mi];
      const auto [a, bb] = SpecGears(m);
      const auto ito = o.meshes.find(m.name);
      const TrainMeshOverride ov = ito == o.meshes.end() ? TrainMeshOverride{} : ito->second;
      // Loaded flank: the mesh torque on spec gear a is Z_a lambda (external) or -Z_p lambda
      // (internal: a is the planet); drive when it is negative.
      const double lambda = tm.power_flow.mesh_loads_Nm(mi);
      const double t_a = (m.kind == MeshKind::kInternal ? -1.0 : 1.0) * train.gears[a].teeth * lambda;
      bool d = !(t_a > 0);
      if (ov.contact) d = *ov.contact != GearMeshSpec::Contact::kLinearCoast;
      drive.push_back(d);
      // Working pressure angle from the centre distance (profile-shifted or not) unless given.
      const double rba = gear_params(a).base_radius_m, rbb = gear_params(bb).base_radius_m;
      const double dist = (GearCentre(train, a, 0) - GearCentre(train, bb, 0)).norm();
      const double c = (m.kind == MeshKind::kInternal ? rbb - rba : rba + rbb) / dist;
      if (!ov.working_pressure_angle_rad && !(c > 0 && c < 1))
        Fail("mesh '" + m.name + "': base radii " + std::to_string(rba) + ", " + std::to_string(rbb) +
             " m do not fit the centre distance " + std::to_string(dist) + " m");
      alpha.push_back(ov.working_pressure_angle_rad.value_or(std::acos(std::clamp(c, -1.0, 1.0))));
      geometric.push_back(!ov.working_pressure_angle_rad);
    }
    std::vector<std::vector<double>> phases(st.meshes.size(), std::vector<double>(st.num_planets, 0.0));
    const double gamma = si < o.stage_phase_cycles.size() ? o.stage_phase_cycles[si] : 0.0;
    if (o.mesh_phasing) phases = CalcStageMeshPhases(train, static_cast<int>(si), drive, alpha, gamma);
    else for (auto& row : phases) std::fill(row.begin(), row.end(), Frac(gamma));

    for (size_t k = 0; k < st.meshes.size(); ++k) {
      const int mi = st.meshes[k];
      const TrainMesh& m = train.meshes[mi];
      const auto [a, bb] = SpecGears(m);
      const bool internal = m.kind == MeshKind::kInternal;
      const auto ito = o.meshes.find(m.name);
      const TrainMeshOverride ov = ito == o.meshes.end() ? TrainMeshOverride{} : ito->second;
      // Mean stiffness: override, else the MESH STIFFNESS HOOK, else c_gamma b; or from geometry.
      const double face = std::min(gear_params(a).face_width_m, gear_params(bb).face_width_m);
      const bool given = ov.stiffness_N_m || ov.stiffness_table_N_m;
      const MeshStiffnessSource source =
          given ? MeshStiffnessSource::kGiven : ov.stiffness_source.value_or(o.mesh_stiffness_source);
      double k_mesh = ov.stiffness_N_m ? *ov.stiffness_N_m
                      : o.mesh_stiffness ? o.mesh_stiffness(train, mi, face)
                                         : o.mesh_stiffness_per_face_width_N_m2 * face;
      std::vector<double> table = ov.stiffness_table_N_m.value_or(std::vector<double>{});
      // Faults on a gear of this mesh: (train gear, branch or -1 for every branch, fault).
      struct MeshFault { int gear, branch; ToothFault fault; };
      std::vector<MeshFault> faults;
      for (size_t f = 0; f < o.tooth_faults.size(); ++f) {
        const int g = fault_gear[f];
        if (g != a && g != bb) continue;
        faults.push_back({g, train.gears[g].planet_set >= 0 ? o.tooth_faults[f].branch : -1, o.tooth_faults[f].fault});
      }
      if (!faults.empty() && source != MeshStiffnessSource::kTvms)
        Fail("mesh '" + m.name + "': tooth faults need the kTvms stiffness source");
      for (const MeshFault& f : faults)
        if (f.gear != faults[0].gear)
          Fail("mesh '" + m.name + "': faults on both of its gears are not supported");
      std::optional<GearPair> pair;
      if (source != MeshStiffnessSource::kGiven) pair.emplace(MakeTrainGearPair(train, mi, o));
      if (source == MeshStiffnessSource::kIso6336) k_mesh = CalcIso6336Stiffness(*pair, o.iso6336).c_gamma_alpha_n_per_m;
      // TVMS tables per branch (one unless a planet is faulted): samples over `cycles` mesh cycles
      // at psi_j = j / samples_per_cycle, read at u = u_P + sigma psi (see the header).
      const int spc = o.tvms_samples_per_cycle;
      const int fault_g = faults.empty() ? -1 : faults[0].gear;
      const int cycles = fault_g < 0 ? 1 : train.gears[fault_g].teeth;
      const double sigma = drive[k] ? 1.0 : -1.0;
      auto tvms_table = [&](int branch) {
        TvmsOptions to{.material1 = o.gear_material, .material2 = o.gear_material,
                       .bore_radius1_m = RimRadius(train, a, o), .rim_radius2_m = RimRadius(train, bb, o),
                       .samples_per_period = spc, .periods = cycles};
        for (const MeshFault& f : faults) {
          if (f.branch >= 0 && f.branch != branch) continue;
          ToothFault tf = f.fault;
          tf.gear = f.gear == a ? 1 : 2;
          // Physical order (tooth e reaches P e-th as the phase grows) to CalcTvms' mesh order.
          if (sigma < 0) tf.tooth = (cycles - tf.tooth) % cycles;
          to.faults.push_back(tf);
        }
        const Tvms t = CalcTvms(*pair, to);
        const double pb = pair->transverse_base_pitch_m();
        const double u_p = (pair->pitch_point_m() - pair->contact_start_m()) / pb -
                           0.5 * pair->face_width_m() * std::tan(pair->gear1().base_helix_angle_rad()) / pb;
        std::vector<double> tab(static_cast<size_t>(cycles) * spc);
        for (size_t j = 0; j < tab.size(); ++j) tab[j] = TvmsAt(t, spc, u_p + sigma * double(j) / spc);
        return tab;
      };
      std::vector<std::vector<double>> branch_tables;  // (branches) when a planet is faulted
      if (source == MeshStiffnessSource::kTvms) {
        const bool planet_fault = fault_g >= 0 && train.gears[fault_g].planet_set >= 0;
        if (planet_fault) {
          for (int i = 0; i < st.num_planets; ++i) branch_tables.push_back(tvms_table(i));
          table = branch_tables[0];
        } else {
          table = tvms_table(-1);
        }
      }
      const bool loaded = tm.power_flow.mesh_loaded[mi];
      if (!loaded) {
        k_mesh *= o.unloaded_mesh_stiffness_factor;
        for (double& x : table) x *= o.unloaded_mesh_stiffness_factor;
        for (auto& t : branch_tables)
          for (double& x : t) x *= o.unloaded_mesh_stiffness_factor;
      }
      if (!table.empty()) {
        k_mesh = 0;
        for (double x : table) k_mesh += x / table.size();
      }
      if (!(k_mesh > 0)) Fail("mesh '" + m.name + "': stiffness must be > 0");
      if (ov.phase_cycles && static_cast<int>(ov.phase_cycles->size()) != st.num_planets)
        Fail("mesh '" + m.name + "': phase_cycles needs one phase per branch");
      // Base helix angle signed by gear a's hand (central external gears +, alternating across
      // external meshes, a ring like its planet).
      const TrainGear& ga = train.gears[a];
      double beta_b = 0;
      if (spatial && ga.has_tooth_form && ga.tooth_form.helix_angle_rad != 0) {
        const double hand = (ga.planet_set < 0) ? 1.0 : -1.0;
        beta_b = hand * std::atan(std::tan(std::abs(ga.tooth_form.helix_angle_rad)) *
                                  std::cos(ga.transverse_pressure_angle_rad));
      }
      const GearMeshSpec::Contact contact =
          o.two_sided_contact ? GearMeshSpec::Contact::kTwoSided
                              : (drive[k] ? GearMeshSpec::Contact::kLinearDrive : GearMeshSpec::Contact::kLinearCoast);
      const int table_cycles = fault_g >= 0 ? cycles : ov.table_cycles.value_or(1);
      // Phase of branch i: over Z_G cycles for a faulted central gear (one physical tooth meets
      // every branch), else as derived.
      auto branch_phase = [&](int i) {
        if (ov.phase_cycles) return (*ov.phase_cycles)[i];
        if (fault_g < 0 || train.gears[fault_g].planet_set >= 0) return phases[k][i];
        const int ps = train.gears[internal ? a : bb].planet_set;
        const double psi = train.planet_sets[ps].angles_rad[i] - train.planet_sets[ps].angles_rad[0];
        const double p = std::fmod(phases[k][0] - cycles * psi / (2 * kPi), double(cycles));
        return p < 0 ? p + cycles : p;
      };
      for (int i = 0; i < st.num_planets; ++i) {
        if (o.meshes_without_element.count(m.name)) break;  // modelled by the before_finalize hook
        const std::vector<double>& tab = branch_tables.empty() ? table : branch_tables[i];
        GearMeshSpec spec{
            .name = m.name + "#" + std::to_string(i + 1), .gear_a = gear_frame(a, i),
            .gear_b = gear_frame(bb, i), .reference = reference,
            .teeth_a = train.gears[a].teeth, .teeth_b = train.gears[bb].teeth,
            .base_radius_a = gear_params(a).base_radius_m, .base_radius_b = gear_params(bb).base_radius_m,
            .working_pressure_angle = alpha[k], .base_helix_angle = beta_b, .internal_b = internal,
            .contact = contact, .backlash = o.two_sided_contact ? ov.backlash_m.value_or(o.backlash_m) : 0.0,
            .stiffness = tab.empty() ? k_mesh : 0.0, .stiffness_table = tab,
            .table_cycles = table_cycles,
            .phase_gear = fault_g == bb ? GearMeshSpec::PhaseGear::kB : GearMeshSpec::PhaseGear::kA,
            .phase = branch_phase(i),
            .damping_ratio = ov.damping_ratio.value_or(o.mesh_damping_ratio),
            .ste_amplitudes = ov.ste_amplitudes_m.value_or(std::vector<double>{}),
            .ste_phases = ov.ste_phases_rad.value_or(std::vector<double>{}),
            .check_centre_distance = geometric[k]};
        b.AddGearMesh(spec);
        TrainMeshElement e;
        e.train_mesh = mi;
        e.branch = i;
        e.stage = static_cast<int>(si);
        e.model_mesh = static_cast<int>(tm.meshes.size());
        e.stiffness_N_m = k_mesh;
        e.working_pressure_angle_rad = alpha[k];
        e.contact = drive[k] ? GearMeshSpec::Contact::kLinearDrive : GearMeshSpec::Contact::kLinearCoast;
        e.phase_cycles = spec.phase;
        e.loaded = loaded;
        e.phase_gear_speed = train.gears[a].speed_index;
        e.stiffness_source = source;
        e.stiffness_min_N_m = tab.empty() ? k_mesh : *std::min_element(tab.begin(), tab.end());
        e.stiffness_max_N_m = tab.empty() ? k_mesh : *std::max_element(tab.begin(), tab.end());
        e.table_cycles = table_cycles;
        e.faulted_gear = fault_g;
        tm.meshes.push_back(e);
      }
    }
  }

  // Connections and engaged clutches: stiff torsional springs between members.
  auto coupling = [&](const std::string& name, const Coupling& c, double k) {
    b.AddRotationalSpring({.name = name, .frame_a = b.body_frame(member_body[c.member_a]),
                           .frame_b = b.body_frame(member_body[c.member_b]), .stiffness = k});
  };
  for (const Coupling& c : train.connections) coupling(c.name, c, o.connection_stiffness_N_m_rad);
  const GearRange& gr = train.ranges[range];
  for (int ci : gr.clutches) coupling(train.clutches[ci].name, train.clutches[ci], o.clutch_stiffness_N_m_rad);
  // Engaged brakes: torsional springs to ground.
  for (int bi : gr.brakes) {
    const Brake& br = train.brakes[bi];
    const TrainMemberOverride ov = override_of(train.members[br.member].name);
    ground_spring(br.name, br.member, ov.brake_stiffness_N_m_rad.value_or(o.brake_stiffness_N_m_rad));
  }

  // Ports: speed drivers or the input torque; the other ports' power-flow torques as loads.
  for (int i = 0; i < num_inputs; ++i) {
    const int member = train.inputs[i];
    const JointIndex j = tm.member_joints[member];
    if (o.input == TrainModelOptions::Input::kSpeed) {
      b.AddDriver({.name = "drive_" + train.members[member].name, .joint = j, .coordinate = rot,
                   .mode = DriverSpec::Mode::kSpeed,
                   .function = o.input_speed_functions.empty() ? TimeFunction::Constant(speeds(i))
                                                               : o.input_speed_functions[i]});
    } else if (o.input == TrainModelOptions::Input::kTorque && i == 0) {
      b.AddJointLoad({.name = "torque_" + train.members[member].name, .joint = j, .coordinate = rot,
                      .function = TimeFunction::Constant(o.input_torque_Nm)});
    } else if (o.port_loads && load_scale != 0 && i > 0) {
      b.AddJointLoad({.name = "torque_" + train.members[member].name, .joint = j, .coordinate = rot,
                      .function = TimeFunction::Constant(tm.power_flow.port_torques_Nm(member))});
    }
  }
  if (o.output_torque_Nm)
    b.AddJointLoad({.name = "load_" + train.members[train.output].name, .joint = tm.member_joints[train.output],
                    .coordinate = rot, .function = *o.output_torque_Nm});
  else if (o.port_loads && load_scale != 0)
    b.AddJointLoad({.name = "load_" + train.members[train.output].name, .joint = tm.member_joints[train.output],
                    .coordinate = rot, .function = TimeFunction::Constant(tm.power_flow.port_torques_Nm(train.output))});

  if (o.before_finalize) o.before_finalize(b, tm);
  tm.model = std::move(b).Finalize();
  return tm;
}

State SolveTrainStaticState(const TrainModel& tm, const State& guess, int max_iterations) {
  const Model& m = *tm.model;
  State x = guess;
  Data d(m);
  const Eigen::VectorXd zero_a = Eigen::VectorXd::Zero(m.nv);
  const Eigen::VectorXd zero_l = Eigen::VectorXd::Zero(m.n_constraints);
  double r0 = -1, r = 0;
  for (int it = 0; it <= max_iterations; ++it) {
    // Residual on the free coordinates: T^T (C - Q) at zero acceleration.
    EvaluateDynamics(m, x.t, x.q, x.v, zero_a, d);
    const LinearModel lin = Linearize(m, x, zero_a, zero_l);
    const Eigen::VectorXd rr = lin.T.transpose() * d.tau_id;
    r = rr.lpNorm<Eigen::Infinity>();
    if (r0 < 0) r0 = r;
    if (r <= 1e-9 * r0 || r == 0) return x;
    if (it == max_iterations) break;
    // Newton step on the null-space coordinates.
    const Eigen::VectorXd dx = lin.K_r.colPivHouseholderQr().solve(-rr);
    const Eigen::VectorXd dq = lin.T * dx;
    IntegratePositions(m, dq, x.q);
  }
  throw std::runtime_error("train model: static equilibrium not found (residual " + std::to_string(r) +
                           " of initial " + std::to_string(r0) + " after " + std::to_string(max_iterations) +
                           " Newton iterations)");
}

std::vector<double> CalcPlanetPinForces(const TrainModel& tm, const State& x, Data& data) {
  std::vector<double> out;
  if (tm.dofs == TrainDofs::kTorsional) return out;
  const Model& m = *tm.model;
  CalcPositionKinematics(m, x.q, data);
  CalcVelocityKinematics(m, x.v, data);
  for (size_t s = 0; s < tm.planet_bearings.size(); ++s) {
    for (int idx : tm.planet_bearings[s]) {
      if (tm.dofs == TrainDofs::kPlanar) {
        // x and y coordinate springs of the planet joint.
        double f2 = 0;
        for (int k = 0; k < 2; ++k) {
          const CoordinateSpringSpec& cs = m.coordinate_springs[idx + k];
          const double f = cs.stiffness * (x.q(m.coordinate_spring_q_index[idx + k]) - cs.q0) +
                           cs.damping * x.v(m.coordinate_spring_v_index[idx + k]);
          f2 += f * f;
        }
        out.push_back(std::sqrt(f2));
        continue;
      }
      // Spatial: the bearing's radial spring-damper force in the pin frame's axes (as in
      // force_elements.cpp).
      const BearingSpec& bs = m.bearings[idx];
      const BodyIndex ba = m.frames[bs.frame_a].body, bb = m.frames[bs.frame_b].body;
      const Transform& Xa = data.X_WFrame[bs.frame_a];
      const Transform& Xb = data.X_WFrame[bs.frame_b];
      const Vec3 delta = Xb.p - Xa.p;
      const Vec3 w_a = data.V_WB[ba].head<3>();
      const Vec3 delta_dot = PointVelocity(data.V_WB[bb], Xb.p) - PointVelocity(data.V_WB[ba], Xa.p);
      const Vec3 d = Xa.R.transpose() * delta;
      const Vec3 d_dot = Xa.R.transpose() * (delta_dot - w_a.cross(delta));
      const double fx = bs.radial_stiffness * d.x() + bs.radial_damping * d_dot.x();
      const double fy = bs.radial_stiffness * d.y() + bs.radial_damping * d_dot.y();
      out.push_back(std::hypot(fx, fy));
    }
  }
  return out;
}

}  // namespace orrery::gears

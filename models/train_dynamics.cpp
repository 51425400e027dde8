#include "models/train_dynamics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

[[noreturn]] void Fail(const std::string& msg) { throw std::invalid_argument("train model: " + msg); }

double Involute(double alpha) { return std::tan(alpha) - alpha; }

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

}  // namespace

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

  TrainModel tm;
  tm.train = std::make_shared<const PlanetaryTrain>(train);
  tm.range = range;
  tm.dofs = o.dofs;
  const bool torsional = o.dofs == TrainDofs::kTorsional;
  const bool spatial = o.dofs == TrainDofs::kSpatial;
  tm.rotation_coordinate = torsional ? 0 : spatial ? 5 : 2;

  // Kinematics at the given speeds and at unit input speed (directions of the mesh phases).
  Eigen::VectorXd speeds = Eigen::VectorXd::Zero(num_inputs);
  for (int i = 0; i < static_cast<int>(o.input_speeds_rad_s.size()); ++i) speeds(i) = o.input_speeds_rad_s[i];
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
      const FrameIndex housing = b.AddFrame(m.name + "_housing", kWorldBody, Transform(Mat3::Identity(), origin));
      BushingSpec bearing{.name = m.name + "_bearing", .frame_a = housing, .frame_b = b.body_frame(member_body[i])};
      const double kt = ov.tilt_bearing_stiffness_N_m_rad.value_or(o.tilt_bearing_stiffness_N_m_rad);
      bearing.stiffness.diagonal() << kr, kr, ov.axial_bearing_stiffness_N_m.value_or(o.axial_bearing_stiffness_N_m), kt, kt, 0;
      bearing.damping.diagonal() << cr, cr, cr, 0, 0, 0;
      b.AddBushing(bearing);
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
      const BodyIndex body = b.AddBody(name, p.mass_kg, Vec3::Zero(),
                                       AxisymmetricInertia(p.polar_inertia_kg_m2, p.transverse_inertia_kg_m2));
      const Transform X_PF(AxisAngle(Vec3::UnitZ(), psi), ps.center_radius_m * Vec3(std::cos(psi), std::sin(psi), 0));
      const JointIndex j = b.AddJoint({.name = name, .type = joint_type, .parent = carrier, .child = body,
                                       .X_PF = X_PF, .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
      b.SetJointVelocity(j, joint_velocity(w_rel));
      planet_body[s].push_back(body);
      tm.planet_joints[s].push_back(j);
      // Planet bearings on the pin (seed 002 eq. 10; no torsional stiffness).
      const double kr = ov.radial_bearing_stiffness_N_m.value_or(o.radial_bearing_stiffness_N_m);
      const double cr = ov.bearing_damping_N_s_m.value_or(o.bearing_damping_N_s_m);
      if (spatial) {
        const FrameIndex pin = b.AddFrame(name + "_pin", carrier, X_PF);
        BushingSpec bearing{.name = name + "_bearing", .frame_a = pin, .frame_b = b.body_frame(body)};
        const double kt = ov.tilt_bearing_stiffness_N_m_rad.value_or(o.tilt_bearing_stiffness_N_m_rad);
        bearing.stiffness.diagonal() << kr, kr, ov.axial_bearing_stiffness_N_m.value_or(o.axial_bearing_stiffness_N_m), kt, kt, 0;
        bearing.damping.diagonal() << cr, cr, cr, 0, 0, 0;
        b.AddBushing(bearing);
      } else if (!torsional) {
        for (int k = 0; k < 2; ++k)
          b.AddCoordinateSpring({.name = name + (k ? "_bearing_y" : "_bearing_x"), .joint = j,
                                 .coordinate = k, .stiffness = kr, .damping = cr});
      }
    }
  }

  // Gear body, base radius and face width by train gear index and branch.
  auto gear_body = [&](int g, int branch) {
    const TrainGear& gear = train.gears[g];
    return gear.planet_set < 0 ? member_body[gear.member] : planet_body[gear.planet_set][branch];
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
      // Mean stiffness: override, else the MESH STIFFNESS HOOK, else c_gamma b.
      const double face = std::min(gear_params(a).face_width_m, gear_params(bb).face_width_m);
      double k_mesh = ov.stiffness_N_m ? *ov.stiffness_N_m
                      : o.mesh_stiffness ? o.mesh_stiffness(train, mi, face)
                                         : o.mesh_stiffness_per_face_width_N_m2 * face;
      std::vector<double> table = ov.stiffness_table_N_m.value_or(std::vector<double>{});
      const bool loaded = tm.power_flow.mesh_loaded[mi];
      if (!loaded) {
        k_mesh *= o.unloaded_mesh_stiffness_factor;
        for (double& x : table) x *= o.unloaded_mesh_stiffness_factor;
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
      for (int i = 0; i < st.num_planets; ++i) {
        GearMeshSpec spec{
            .name = m.name + "#" + std::to_string(i + 1), .gear_a = b.body_frame(gear_body(a, i)),
            .gear_b = b.body_frame(gear_body(bb, i)), .reference = reference,
            .teeth_a = train.gears[a].teeth, .teeth_b = train.gears[bb].teeth,
            .base_radius_a = gear_params(a).base_radius_m, .base_radius_b = gear_params(bb).base_radius_m,
            .working_pressure_angle = alpha[k], .base_helix_angle = beta_b, .internal_b = internal,
            .contact = contact, .backlash = o.two_sided_contact ? ov.backlash_m.value_or(o.backlash_m) : 0.0,
            .stiffness = table.empty() ? k_mesh : 0.0, .stiffness_table = table,
            .table_cycles = ov.table_cycles.value_or(1),
            .phase = ov.phase_cycles ? (*ov.phase_cycles)[i] : phases[k][i],
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
                   .mode = DriverSpec::Mode::kSpeed, .function = TimeFunction::Constant(speeds(i))});
    } else if (o.input == TrainModelOptions::Input::kTorque && i == 0) {
      b.AddJointLoad({.name = "torque_" + train.members[member].name, .joint = j, .coordinate = rot,
                      .function = TimeFunction::Constant(o.input_torque_Nm)});
    } else if (o.port_loads && load_scale != 0 && i > 0) {
      b.AddJointLoad({.name = "torque_" + train.members[member].name, .joint = j, .coordinate = rot,
                      .function = TimeFunction::Constant(tm.power_flow.port_torques_Nm(member))});
    }
  }
  if (o.port_loads && load_scale != 0)
    b.AddJointLoad({.name = "load_" + train.members[train.output].name, .joint = tm.member_joints[train.output],
                    .coordinate = rot, .function = TimeFunction::Constant(tm.power_flow.port_torques_Nm(train.output))});

  tm.model = std::move(b).Finalize();
  return tm;
}

}  // namespace orrery::gears

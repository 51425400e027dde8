// Stages 3 and 4 of BuildTrainModel: the bodies. Central members on joints to the housing (stage
// j at z = j * spacing in the spatial DOF set) with their bearings; planets on their carriers'
// pins, joint frames turned by the planet angle psi (x radial, y tangential), with their pin
// bearings. A body named in TrainModelOptions::flexible_bodies is its reduced FE body instead of
// a rigid one; a planet named in imported_gears has its mesh file's mass properties.
#include <cmath>

#include "models/train_assembly.h"

namespace orrery::gears {
namespace {

// Inertia tensor of an axisymmetric body in its own axes (z the axis).
Mat3 AxisymmetricInertia(double polar, double transverse) {
  return Vec3(transverse, transverse, polar).asDiagonal();
}

// A rigid body with lumped parameters, or the flexible body of that name.
BodyIndex AddTrainBody(TrainAssembly& a, const std::string& name, const TrainBodyParams& p) {
  if (const TrainFlexibleBody* f = a.Flexible(name)) return a.b.AddFlexibleBody(name, f->modes, f->options);
  return a.b.AddBody(name, p.mass_kg, Vec3::Zero(),
                     AxisymmetricInertia(p.polar_inertia_kg_m2, p.transverse_inertia_kg_m2));
}

// A planet: its imported gear's mass properties turned from its gear frame into the body frame
// (train_dynamics.h, "Imported gears"), or AddTrainBody's.
BodyIndex AddPlanetBody(TrainAssembly& a, const std::string& name, int set, int branch) {
  const TrainImportedGear* g = a.Imported(name);
  if (!g) return AddTrainBody(a, name, a.tm.planet_params[set]);
  const Mat3 R =
      AxisAngle(Vec3::UnitZ(), GearFrameRotation(a.train, a.train.planet_sets[set].gear, branch));
  return a.b.AddBody(name, g->mass_kg, R * g->center_of_mass_m,
                     R * g->inertia_kg_m2 * R.transpose());
}

// The frame lumped meshes act on: a flexible body's mesh interface master, else the body frame.
FrameIndex MeshFrame(TrainAssembly& a, const std::string& name, BodyIndex body) {
  const TrainFlexibleBody* f = a.Flexible(name);
  if (!f || f->mesh_interface.empty()) return a.b.body_frame(body);
  const FlexibleBodyModes& modes = *f->modes;
  const auto set = modes.node_sets.find(f->mesh_interface);
  if (set == modes.node_sets.end() || set->second.size() != 1)
    FailTrain("flexible body '" + name + "': mesh_interface '" + f->mesh_interface +
              "' is not an interface of its reduced body");
  const int node = set->second[0];
  return a.b.AddNodeFrame(name + "_mesh", body, node, Transform::Translation(modes.nodes[node].position));
}

// A bearing between frame `seat` and a body: radial, axial and tilt springs with free spin
// (spatial), x and y coordinate springs on the joint (planar), none (torsional). Returns the
// index of the bearing (spatial) or of the x spring (planar), -1 for none.
int AddTrainBearing(TrainAssembly& a, const std::string& name, FrameIndex seat, BodyIndex body,
                    JointIndex joint, const TrainMemberOverride& ov) {
  const TrainModelOptions& o = a.o;
  const double kr = ov.radial_bearing_stiffness_n_per_m.value_or(o.radial_bearing_stiffness_n_per_m);
  const double cr = ov.bearing_damping_n_s_per_m.value_or(o.bearing_damping_n_s_per_m);
  if (a.spatial) {
    // A bearing, not a bushing: members spin past half a turn.
    const int index = static_cast<int>(a.b.draft().bearings.size());
    a.b.AddBearing({.name = name + "_bearing", .frame_a = seat, .frame_b = a.b.body_frame(body),
                    .radial_stiffness = kr,
                    .axial_stiffness = ov.axial_bearing_stiffness_n_per_m.value_or(o.axial_bearing_stiffness_n_per_m),
                    .tilt_stiffness = ov.tilt_bearing_stiffness_n_m_per_rad.value_or(o.tilt_bearing_stiffness_n_m_per_rad),
                    .radial_damping = cr, .axial_damping = cr});
    return index;
  }
  if (a.torsional) return -1;
  const int index = static_cast<int>(a.b.draft().coordinate_springs.size());
  for (int k = 0; k < 2; ++k)
    a.b.AddCoordinateSpring({.name = name + (k ? "_bearing_y" : "_bearing_x"), .joint = joint,
                             .coordinate = k, .stiffness = kr, .damping = cr});
  return index;
}

}  // namespace

void AddTrainGroundSpring(TrainAssembly& a, const std::string& name, int member, double k) {
  const JointIndex j = a.tm.member_joints[member];
  if (a.spatial) {
    const BodyIndex body = a.b.draft().joints[j].spec.child;
    const FrameIndex housing = a.b.AddFrame(name + "_ground", a.HousingBody(), a.b.draft().joints[j].spec.X_PF);
    a.b.AddRotationalSpring({.name = name, .frame_a = housing, .frame_b = a.b.body_frame(body), .stiffness = k});
  } else {
    a.b.AddCoordinateSpring({.name = name, .joint = j, .coordinate = a.rot, .stiffness = k});
  }
}

void AddHousing(TrainAssembly& a) {
  if (!a.o.housing) return;
  const TrainHousing& h = *a.o.housing;
  if (!(h.mass_kg > 0) || !(h.polar_inertia_kg_m2 > 0))
    FailTrain("housing: mass and polar inertia must be > 0");
  const double transverse = h.transverse_inertia_kg_m2 > 0 ? h.transverse_inertia_kg_m2 : 0.5 * h.polar_inertia_kg_m2;
  const BodyIndex body = a.b.AddBody("housing", h.mass_kg, Vec3::Zero(), AxisymmetricInertia(h.polar_inertia_kg_m2, transverse));
  const JointIndex j = a.b.AddJoint({.name = "housing", .type = a.joint_type, .parent = kWorldBody, .child = body,
                                     .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
  a.tm.housing_body = body;
  a.tm.housing_joint = j;
  // Mounts: springs with damping c = 2 zeta sqrt(k m) on the joint's coordinates (torsional,
  // planar), or a 6-DOF bushing to the ground (spatial).
  auto damping = [&](double k, double m) { return 2 * h.mount_damping_ratio * std::sqrt(k * m); };
  const double kr = h.mount_radial_stiffness_n_per_m, kt = h.mount_torsional_stiffness_n_m_per_rad;
  if (a.spatial) {
    const double ka = h.mount_axial_stiffness_n_per_m, kb = h.mount_tilt_stiffness_n_m_per_rad;
    const Vec6 k(kr, kr, ka, kb, kb, kt);  // the bushing's deflection: translation, rotation
    const Vec6 m(h.mass_kg, h.mass_kg, h.mass_kg, transverse, transverse, h.polar_inertia_kg_m2);
    Vec6 c;
    for (int i = 0; i < 6; ++i) c(i) = damping(k(i), m(i));
    BushingSpec mount{.name = "housing_mount", .frame_a = kWorldFrame, .frame_b = a.b.body_frame(body)};
    mount.stiffness = k.asDiagonal();
    mount.damping = c.asDiagonal();
    a.b.AddBushing(mount);
    return;
  }
  if (!a.torsional)
    for (int k = 0; k < 2; ++k)
      a.b.AddCoordinateSpring({.name = k ? "housing_mount_y" : "housing_mount_x", .joint = j, .coordinate = k,
                               .stiffness = kr, .damping = damping(kr, h.mass_kg)});
  a.b.AddCoordinateSpring({.name = "housing_mount_torsion", .joint = j, .coordinate = a.rot, .stiffness = kt,
                           .damping = damping(kt, h.polar_inertia_kg_m2)});
}

void AddMembers(TrainAssembly& a) {
  const double spacing = a.o.stage_spacing_m > 0 ? a.o.stage_spacing_m : 3.0 * a.o.face_width_m;
  for (int i = 0; i < a.train.num_members(); ++i) {
    const Member& m = a.train.members[i];
    const TrainMemberOverride& ov = a.Override(m.name);
    const BodyIndex body = AddTrainBody(a, m.name, a.tm.member_params[i]);
    const Vec3 origin(0, 0, a.spatial ? m.stage * spacing : 0.0);
    const JointIndex j = a.b.AddJoint({.name = m.name, .type = a.joint_type, .parent = a.HousingBody(),
                                       .child = body, .X_PF = Transform(Mat3::Identity(), origin),
                                       .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
    a.tm.member_bodies.push_back(body);
    a.tm.member_joints.push_back(j);
    a.member_mesh_frame.push_back(MeshFrame(a, m.name, body));
    a.b.SetJointVelocity(j, a.JointVelocity(a.tm.kinematics.speeds_rad_s(i)));
    // Bearings to the housing.
    const FrameIndex housing =
        a.spatial ? a.b.AddFrame(m.name + "_housing", a.HousingBody(), Transform(Mat3::Identity(), origin)) : kWorldFrame;
    AddTrainBearing(a, m.name, housing, body, j, ov);
    if (ov.ground_torsional_stiffness_n_m_per_rad)
      AddTrainGroundSpring(a, m.name + "_ground", i, *ov.ground_torsional_stiffness_n_m_per_rad);
  }
}

void AddPlanets(TrainAssembly& a) {
  const PlanetaryTrain& train = a.train;
  a.tm.planet_joints.resize(train.planet_sets.size());
  a.tm.planet_bodies.resize(train.planet_sets.size());
  a.tm.planet_bearings.resize(train.planet_sets.size());
  a.planet_mesh_frame.resize(train.planet_sets.size());
  for (size_t s = 0; s < train.planet_sets.size(); ++s) {
    const PlanetSet& ps = train.planet_sets[s];
    const TrainMemberOverride& ov = a.Override(ps.name);
    const int carrier = train.stages[ps.stage].carrier;
    const BodyIndex carrier_body = a.tm.member_bodies[carrier];
    const double w_rel = a.tm.kinematics.speeds_rad_s(train.num_members() + s) - a.tm.kinematics.speeds_rad_s(carrier);
    for (size_t i = 0; i < ps.angles_rad.size(); ++i) {
      const double psi = ps.angles_rad[i];
      const std::string name = a.PlanetName(static_cast<int>(s), static_cast<int>(i));
      const BodyIndex body = AddPlanetBody(a, name, static_cast<int>(s), static_cast<int>(i));
      const Transform X_PF(AxisAngle(Vec3::UnitZ(), psi), ps.center_radius_m * Vec3(std::cos(psi), std::sin(psi), 0));
      const JointIndex j = a.b.AddJoint({.name = name, .type = a.joint_type, .parent = carrier_body, .child = body,
                                         .X_PF = X_PF, .axis = Vec3::UnitZ(), .axis2 = Vec3::UnitX()});
      a.b.SetJointVelocity(j, a.JointVelocity(w_rel));
      a.tm.planet_bodies[s].push_back(body);
      a.tm.planet_joints[s].push_back(j);
      a.planet_mesh_frame[s].push_back(MeshFrame(a, name, body));
      // Planet bearings on the pin (seed 002 eq. 10; no torsional stiffness).
      const FrameIndex pin = a.spatial ? a.b.AddFrame(name + "_pin", carrier_body, X_PF) : kWorldFrame;
      a.tm.planet_bearings[s].push_back(AddTrainBearing(a, name, pin, body, j, ov));
    }
  }
}

}  // namespace orrery::gears

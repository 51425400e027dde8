// BuildTrainModel: the table of contents of a train's assembly (train_dynamics.h), and what the
// stages share (train_assembly.h).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "models/train_assembly.h"

namespace orrery::gears {
namespace {

// Names in the options that name nothing are errors, not silently ignored settings.
void CheckOptionNames(const PlanetaryTrain& train, const TrainModelOptions& o) {
  for (const auto& [name, ov] : o.members)
    if (!train.member_by_name.count(name) && !train.planet_set_by_name.count(name))
      FailTrain("member override '" + name + "' names no member or planet set");
  for (const auto& [name, ov] : o.meshes)
    if (!train.mesh_by_name.count(name)) FailTrain("mesh override '" + name + "' names no mesh");
  for (const auto& [key, model] : o.mesh_models) {
    const std::string mesh = key.substr(0, key.find('#'));
    if (!train.mesh_by_name.count(mesh))
      FailTrain("mesh model '" + key + "' names no mesh (write 'S.sun-planet' or 'S.sun-planet#2')");
    if (key.size() == mesh.size()) continue;
    const Stage& st = train.stages[train.meshes[train.MeshIndex(mesh)].stage];
    const std::string branch = key.substr(mesh.size() + 1);
    const bool digits = !branch.empty() && std::all_of(branch.begin(), branch.end(), ::isdigit);
    if (!digits || std::stoi(branch) < 1 || std::stoi(branch) > st.num_planets)
      FailTrain("mesh model '" + key + "': branch must be 1.." + std::to_string(st.num_planets));
  }
  for (const auto& [name, body] : o.flexible_bodies) {
    bool found = train.member_by_name.count(name) > 0;
    for (size_t s = 0; s < train.planet_sets.size(); ++s)
      for (size_t i = 0; i < train.planet_sets[s].angles_rad.size(); ++i)
        found = found || train.planet_sets[s].name + std::to_string(i + 1) == name;
    if (!found) FailTrain("flexible body '" + name + "': no planet or member of that name in the train");
    if (!body.modes) FailTrain("flexible body '" + name + "': no reduced body (modes) given");
    const auto member = train.member_by_name.find(name);
    if (member != train.member_by_name.end() && train.members[member->second].kind == MemberKind::kCarrier)
      FailTrain("flexible body '" + name + "': a flexible carrier is not supported (its planets' "
                "pins would need joints on its interface nodes); keep it rigid");
  }
  for (const auto& [name, gear] : o.imported_gears) {
    bool found = false;
    for (size_t s = 0; s < train.planet_sets.size(); ++s)
      for (size_t i = 0; i < train.planet_sets[s].angles_rad.size(); ++i)
        found = found || train.planet_sets[s].name + std::to_string(i + 1) == name;
    if (!found)
      FailTrain("imported gear '" + name +
                "': no planet of that name in the train (only planets, \"S.planet1\")");
    if (o.flexible_bodies.count(name))
      FailTrain("imported gear '" + name +
                "' is also a flexible body: a flexible planet from a mesh file is the "
                "body reduced from it (orrery reduce)");
    if (!(gear.mass_kg > 0) || !(gear.inertia_kg_m2.trace() > 0) || gear.surface.triangles.empty())
      FailTrain("imported gear '" + name + "' (" + gear.source +
                "): no surface or mass properties");
  }
}

// Other option values that make no model.
void CheckOptionValues(const PlanetaryTrain& train, const TrainModelOptions& o) {
  const int num_inputs = static_cast<int>(train.inputs.size());
  if (!o.input_speeds_rad_s.empty() && static_cast<int>(o.input_speeds_rad_s.size()) != num_inputs)
    FailTrain("input_speeds_rad_s needs one speed per train input (" + std::to_string(num_inputs) + ")");
  if (!o.input_speed_functions.empty()) {
    if (static_cast<int>(o.input_speed_functions.size()) != num_inputs)
      FailTrain("input_speed_functions needs one function per train input (" + std::to_string(num_inputs) + ")");
    if (!o.input_speeds_rad_s.empty()) FailTrain("give input_speeds_rad_s or input_speed_functions, not both");
    if (o.input != TrainModelOptions::Input::kSpeed) FailTrain("input_speed_functions need Input::kSpeed");
  }
  if (!o.operating_speeds_rad_s.empty() && static_cast<int>(o.operating_speeds_rad_s.size()) != num_inputs)
    FailTrain("operating_speeds_rad_s needs one speed per train input (" + std::to_string(num_inputs) + ")");
  if (o.output_port_torque_n_m && o.input_torque_n_m != 0)
    FailTrain("give input_torque_n_m or output_port_torque_n_m, not both");
  if (o.two_sided_contact && !(o.backlash_m >= 0)) FailTrain("backlash must be >= 0");
  if (o.tvms_samples_per_cycle < 2) FailTrain("tvms_samples_per_cycle must be >= 2");
  if (o.mesh_stiffness_n_per_m && !(*o.mesh_stiffness_n_per_m > 0))
    FailTrain("mesh_stiffness_n_per_m must be > 0");
}

// Train gear index of every tooth fault, checked (the fault against its gear's geometry when
// the mesh stage builds it).
std::vector<int> FaultGears(const PlanetaryTrain& train, const TrainModelOptions& o) {
  std::vector<int> gears;
  for (const TrainToothFault& f : o.tooth_faults) {
    int g = -1;
    for (int k = 0; k < static_cast<int>(train.gears.size()); ++k)
      if (train.gears[k].name == f.gear) g = k;
    if (g < 0) FailTrain("tooth fault on '" + f.gear + "': no such gear");
    const TrainGear& tg = train.gears[g];
    if (tg.planet_set >= 0 && (f.branch < 0 || f.branch >= static_cast<int>(train.planet_sets[tg.planet_set].angles_rad.size())))
      FailTrain("tooth fault on '" + f.gear + "': branch " + std::to_string(f.branch) + " out of range");
    if (tg.planet_set < 0 && f.branch != 0)
      FailTrain("tooth fault on '" + f.gear + "': a branch is for planets ('" + f.gear + "' is a central gear)");
    if (f.spec.tooth < 0 || f.spec.tooth >= tg.teeth)
      FailTrain("tooth fault on '" + f.gear + "': tooth " + std::to_string(f.spec.tooth) + " out of range 0.." +
                std::to_string(tg.teeth - 1));
    gears.push_back(g);
  }
  return gears;
}

}  // namespace

void FailTrain(const std::string& what) { throw std::invalid_argument("train model: " + what); }

double Frac(double x) {
  const double f = x - std::floor(x);
  return f >= 1.0 ? 0.0 : f;
}

const char* MeshModelName(MeshModel model) {
  switch (model) {
    case MeshModel::kKinematic: return "kinematic";
    case MeshModel::kLumped: return "lumped";
    case MeshModel::kContact: return "contact";
  }
  return "?";
}

MeshModel MeshModelOf(const PlanetaryTrain& train, int mesh, int branch, const TrainModelOptions& o) {
  const std::string& name = train.meshes.at(mesh).name;
  if (const auto it = o.mesh_models.find(name + "#" + std::to_string(branch + 1)); it != o.mesh_models.end())
    return it->second;
  if (const auto it = o.mesh_models.find(name); it != o.mesh_models.end()) return it->second;
  return o.mesh_model;
}

TrainAssembly::TrainAssembly(const PlanetaryTrain& t, int r, const TrainModelOptions& options)
    : train(t), range(r), o(options) {
  if (range < 0 || range >= static_cast<int>(train.ranges.size()))
    FailTrain("gear range index " + std::to_string(range) + " out of range");
  CheckOptionNames(train, o);
  CheckOptionValues(train, o);
  CheckTrainGearGeometry(train, o);
  CheckFlexibleGearBodies(train, o);
  fault_gear = FaultGears(train, o);
  torsional = o.dofs == TrainDofs::kTorsional;
  spatial = o.dofs == TrainDofs::kSpatial;
  joint_type = torsional ? JointType::kRevolute : spatial ? JointType::kFree : JointType::kPlanar;
  rot = torsional ? 0 : spatial ? 5 : 2;
  tm.train = std::make_shared<const PlanetaryTrain>(train);
  tm.range = range;
  tm.options = options;
  tm.dofs = o.dofs;
  tm.rotation_coordinate = rot;
}

Eigen::VectorXd TrainAssembly::JointVelocity(double w) const {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(torsional ? 1 : spatial ? 6 : 3);
  v(rot) = w;
  return v;
}

std::string TrainAssembly::PlanetName(int set, int branch) const {
  return train.planet_sets[set].name + std::to_string(branch + 1);
}

std::string TrainAssembly::GearBodyName(int gear, int branch) const {
  const TrainGear& g = train.gears[gear];
  return g.planet_set < 0 ? train.members[g.member].name : PlanetName(g.planet_set, branch);
}

BodyIndex TrainAssembly::GearBody(int gear, int branch) const {
  const TrainGear& g = train.gears[gear];
  return g.planet_set < 0 ? tm.member_bodies[g.member] : tm.planet_bodies[g.planet_set][branch];
}

JointIndex TrainAssembly::GearJoint(int gear, int branch) const {
  const TrainGear& g = train.gears[gear];
  return g.planet_set < 0 ? tm.member_joints[g.member] : tm.planet_joints[g.planet_set][branch];
}

FrameIndex TrainAssembly::GearMeshFrame(int gear, int branch) const {
  const TrainGear& g = train.gears[gear];
  return g.planet_set < 0 ? member_mesh_frame[g.member] : planet_mesh_frame[g.planet_set][branch];
}

const TrainBodyParams& TrainAssembly::GearParams(int gear) const {
  const TrainGear& g = train.gears[gear];
  return g.planet_set < 0 ? tm.member_params[g.member] : tm.planet_params[g.planet_set];
}

const TrainMemberOverride& TrainAssembly::Override(const std::string& name) const {
  static const TrainMemberOverride kNone;
  const auto it = o.members.find(name);
  return it == o.members.end() ? kNone : it->second;
}

const TrainImportedGear* TrainAssembly::Imported(const std::string& body_name) const {
  const auto it = o.imported_gears.find(body_name);
  return it == o.imported_gears.end() ? nullptr : &it->second;
}

const TrainFlexibleBody* TrainAssembly::Flexible(const std::string& body_name) const {
  const auto it = o.flexible_bodies.find(body_name);
  return it == o.flexible_bodies.end() ? nullptr : &it->second;
}

Vec3 TrainGearCentre(const PlanetaryTrain& train, int g, int branch) {
  const TrainGear& gear = train.gears[g];
  if (gear.planet_set < 0) return Vec3::Zero();
  const PlanetSet& ps = train.planet_sets[gear.planet_set];
  const double psi = ps.angles_rad[branch];
  return ps.center_radius_m * Vec3(std::cos(psi), std::sin(psi), 0);
}

double GearFrameRotation(const PlanetaryTrain& train, int g, int branch) {
  const TrainGear& gear = train.gears[g];
  if (gear.planet_set < 0 && !gear.internal) return 0;
  // A planet: a space faces each tooth of the stage's external central gear on the line of
  // centres; a ring: from the planet of its mesh (train_contact.h).
  auto planet_rotation = [&](int planet_gear) {
    const PlanetSet& ps = train.planet_sets[train.gears[planet_gear].planet_set];
    const double zp = train.gears[planet_gear].teeth;
    double z_sun = 0;
    for (const TrainMesh& m : train.meshes)
      if (m.stage == ps.stage && m.kind == MeshKind::kExternal && m.gear_b == planet_gear &&
          train.gears[m.gear_a].planet_set < 0)
        z_sun = train.gears[m.gear_a].teeth;
    return std::numbers::pi + std::numbers::pi / zp + z_sun / zp * ps.angles_rad[branch];
  };
  if (gear.planet_set >= 0) return planet_rotation(g);
  for (const TrainMesh& m : train.meshes) {
    if (m.kind != MeshKind::kInternal || m.gear_a != g) continue;
    const PlanetSet& ps = train.planet_sets[train.gears[m.gear_b].planet_set];
    return ps.angles_rad[branch] + std::numbers::pi / gear.teeth +
           double(train.gears[m.gear_b].teeth) / gear.teeth * planet_rotation(m.gear_b);
  }
  return 0;
}

std::vector<ToothFaultSpec> GearFaults(const TrainAssembly& a, int g, int branch) {
  std::vector<ToothFaultSpec> faults;
  const bool planet = a.train.gears[g].planet_set >= 0;
  for (size_t f = 0; f < a.o.tooth_faults.size(); ++f)
    if (a.fault_gear[f] == g && (!planet || a.o.tooth_faults[f].branch == branch))
      faults.push_back(a.o.tooth_faults[f].spec);
  return faults;
}

std::pair<int, int> TrainSpecGears(const TrainMesh& m) {
  if (m.kind == MeshKind::kInternal) return {m.gear_b, m.gear_a};
  return {m.gear_a, m.gear_b};
}

const std::string& TrainGearOwnerName(const PlanetaryTrain& train, int g) {
  const TrainGear& gear = train.gears[g];
  return gear.planet_set < 0 ? train.members[gear.member].name : train.planet_sets[gear.planet_set].name;
}

TrainModel BuildTrainModel(const PlanetaryTrain& train, int range, const TrainModelOptions& options) {
  TrainAssembly a(train, range, options);
  ResolveOperatingPoint(a);
  ResolveBodyParameters(a);
  AddHousing(a);
  AddMembers(a);
  AddPlanets(a);
  AddMeshes(a);
  AddCouplings(a);
  AddDrives(a);
  AddSensors(a);
  a.tm.model = std::move(a.b).Finalize();
  CheckKinematicMeshes(a.tm);
  return std::move(a.tm);
}

}  // namespace orrery::gears

#pragma once
// The work of one BuildTrainModel call (train_dynamics.h), handed from stage to stage: the train
// and options it reads, the ModelBuilder and the TrainModel it fills, and what the early stages
// leave for the later ones. Internal to models/ (the stage files include it; users do not).
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "contact/flexible_contact_surface.h"
#include "models/train_dynamics.h"

namespace orrery::gears {

// std::invalid_argument("train model: " + what).
[[noreturn]] void FailTrain(const std::string& what);

// x mod 1 in [0, 1).
double Frac(double x);

struct TrainAssembly {
  TrainAssembly(const PlanetaryTrain& train, int range, const TrainModelOptions& options);

  const PlanetaryTrain& train;
  const int range;
  const TrainModelOptions& o;
  ModelBuilder b;
  TrainModel tm;

  // From the options (constructor).
  bool torsional = true, spatial = false;
  JointType joint_type = JointType::kRevolute;
  int rot = 0;                          // spin coordinate within a member joint (0, 2 or 5)
  std::vector<int> fault_gear;          // (tooth faults) train gear index of each
  // ResolveOperatingPoint.
  Eigen::VectorXd speeds;               // (inputs) input speeds at t = 0
  double load_scale = 0;                // 1 with an input torque, 0 without (signs only)
  // AddMembers / AddPlanets: the frames lumped meshes act on.
  std::vector<FrameIndex> member_mesh_frame;                // (members)
  std::vector<std::vector<FrameIndex>> planet_mesh_frame;   // (planet sets) x (branches)
  // AddContactMesh: each flexible gear's contact surface and its axial offset z0, by body name
  // (its contact branches share them).
  std::map<std::string, std::pair<std::shared_ptr<const contact::FlexibleContactSurface>, double>>
      flexible_surfaces;

  // Joint velocity of a member or planet joint spinning at w (rad/s).
  Eigen::VectorXd JointVelocity(double w) const;
  // "S.planet1": the body name of branch `branch` (0-based) of planet set `set`.
  std::string PlanetName(int set, int branch) const;
  // Body name of train gear `gear` on `branch`: its member's, or its planet's on that branch.
  std::string GearBodyName(int gear, int branch) const;
  BodyIndex GearBody(int gear, int branch) const;
  JointIndex GearJoint(int gear, int branch) const;
  FrameIndex GearMeshFrame(int gear, int branch) const;
  const TrainBodyParams& GearParams(int gear) const;
  // The body the members' joints and bearings seat in: the housing, or the world.
  BodyIndex HousingBody() const { return tm.housing_body >= 0 ? tm.housing_body : kWorldBody; }
  // The override of a member or planet set by name (an empty one if none).
  const TrainMemberOverride& Override(const std::string& name) const;
  // The flexible body of that name, or nullptr.
  const TrainFlexibleBody* Flexible(const std::string& body_name) const;
  // The imported gear of that name, or nullptr.
  const TrainImportedGear* Imported(const std::string& body_name) const;
  // AddContactMesh: each imported gear's tooth parts (gear frame), by body name.
  std::map<std::string, std::shared_ptr<const std::vector<TriangleMesh>>> imported_teeth;
};

// Centre of gear `g` on branch `branch` in the carrier frame (central gears on the axis).
Vec3 TrainGearCentre(const PlanetaryTrain& train, int g, int branch);

// Rotation (rad, about z) of train gear g's gear frame in its body at q = 0 on branch `branch`
// (train_dynamics.h, "Tooth faults"; train_contact.h, "Gear frames"): 0 for an external central
// gear, pi + pi / z_p + (z_s / z_p) psi for a planet (z_s: the stage's external central gear
// meshing it, 0 if none), psi + pi / z_r + (z_p / z_r) (the planet's) for a ring.
double GearFrameRotation(const PlanetaryTrain& train, int g, int branch);

// The faults of train gear g on branch `branch` (every branch for a central gear), gear-frame
// indices (tooth_faults).
std::vector<ToothFaultSpec> GearFaults(const TrainAssembly& a, int g, int branch);

// Spec gears of a train mesh (a, b): a ring is always b (internal), a planet is b of an external
// mesh with a central gear.
std::pair<int, int> TrainSpecGears(const TrainMesh& m);

// Name under which a gear's member or planet set is overridden.
const std::string& TrainGearOwnerName(const PlanetaryTrain& train, int g);

// The stages, in the order BuildTrainModel calls them (train_dynamics.h).
void ResolveOperatingPoint(TrainAssembly& a);   // train_operating_point.cpp
void ResolveBodyParameters(TrainAssembly& a);   // train_bodies.cpp
void AddHousing(TrainAssembly& a);              // train_members.cpp
void AddMembers(TrainAssembly& a);              // train_members.cpp
void AddPlanets(TrainAssembly& a);              // train_members.cpp
// A torsional spring of member `member` to ground (brakes, k_jg; train_members.cpp).
void AddTrainGroundSpring(TrainAssembly& a, const std::string& name, int member, double k);
void AddMeshes(TrainAssembly& a);               // train_meshes.cpp
void AddCouplings(TrainAssembly& a);            // train_couplings.cpp
void AddDrives(TrainAssembly& a);               // train_couplings.cpp
void AddSensors(TrainAssembly& a);              // train_sensors.cpp
// Before anything is built: every flexible body that stands for a gear with a tooth form is that
// gear (train_dynamics.h, "Flexible bodies"; train_bodies.cpp).
void CheckFlexibleGearBodies(const PlanetaryTrain& train, const TrainModelOptions& o);
// After Finalize(): refuses redundant kinematic meshes (train_meshes.cpp).
void CheckKinematicMeshes(const TrainModel& tm);

// The contact element of one mesh branch (train_contact_meshes.cpp); `pair` the mesh's GearPair
// (MakeTrainGearPair), `mesh` a train mesh index.
void AddContactMesh(TrainAssembly& a, int mesh, int branch, const GearPair& pair);

}  // namespace orrery::gears

#pragma once
// The dynamic model of an N-stage planetary train in one gear range: BuildTrainModel assembles an
// mbd Model from a PlanetaryTrain (planetary_train.h), its kinematics (planetary_kinematics.h),
// its power flow (planetary_power_flow.h) and the options below, choosing the fidelity of every
// mesh branch and every body on its own (DESIGN.md, "Fidelity ladder"):
//
//   mesh branch ("S.sun-planet#2")   kinematic   the ideal mesh, a constraint (GearConstraintSpec)
//                                    lumped      a spring-damper on the line of action (GearMeshSpec)
//                                    contact     tooth contact on the teeth's surfaces
//                                                (models/train_contact_meshes.cpp)
//   body ("S.planet1", "S.sun")      rigid       lumped mass and inertia
//                                    flexible    a Craig-Bampton-reduced FE body (flexible_bodies)
//
// The stages of the assembly, in order (train_assembler.cpp reads like this list):
//   operating point  kinematics at the input speeds and at unit input speed, power flow, the
//                    input torque from an output torque (train_operating_point.cpp);
//   bodies           lumped parameters of members and planet sets (train_bodies.cpp);
//   members          central members on joints to the housing, with their bearings;
//   planets          planets on their carriers' pins, with their bearings (train_members.cpp);
//   meshes           per stage the loaded flanks, working pressure angles and mesh phases, then
//                    per mesh branch its element (train_meshes.cpp: lumped and kinematic;
//                    train_contact_meshes.cpp: contact);
//   couplings        connections, engaged clutches and brakes (train_couplings.cpp);
//   drives           speed drivers, input torque and port loads (train_drives.cpp);
//   sensors          virtual sensors by the names of bodies, joints and mesh branches
//                    (train_sensors.cpp).
//
// DOF sets (TrainDofs):
//   torsional: every member on a revolute joint to the world, every planet on a revolute joint on
//              its carrier (seed 001 eqs. 7-9: single-planet, double-planet, Ravigneaux; the
//              carrier inertia of eq. 7a, I_c + n I_p + n M_p r_cp^2, comes out of the tree);
//   planar:    3 DOF per member (planar joints, x y bearing springs), planets 3 DOF on the carrier
//              (Lin & Parker 1999);
//   spatial:   6 DOF per member (free joints, bearings to the housing: radial, axial and tilt
//              springs with free spin, BearingSpec), planets on such bearings on their pins
//              (seed 002 eqs. 7-11; the long planet of a Ravigneaux stage is modelled in one
//              transverse plane).
// Mesh deflections. The mesh element (GearMeshSpec in mbd/model.h) measures gear angles relative
// to the carrier, so the sun-planet deflection is r_s (th_s - th_c) + r_p (th_p - th_c): seed 001
// eq. 7's delta_spi = r_s th_s - r_cp th_c + r_p th_pic with th_pic read as the absolute planet
// angle in delta (the reading consistent with Willis' eq. 1a; eq. 7d's inertia terms use the
// relative angle, as the planet joint on the carrier does here).
//
// Elements: per branch of every sun-planet, ring-planet and planet-planet mesh the element of its
// mesh model, lines of action in the carrier frame; connections and engaged clutches as
// RotationalSpringSpec between the members (seed 001: 1e8 N m/rad); engaged brakes as torsional
// springs to ground (seed 001: 1e10 N m/rad); the inputs driven at a speed or loaded by a torque,
// the other ports loaded by their power-flow torques.
//
// Kinematic meshes: one constraint row per branch (its multiplier is the tooth force along the
// drive flank's normal). A stage whose planets all mesh kinematically is statically
// indeterminate in its load sharing (n planets close n - 1 redundant loops in the torsional
// model): kinematic meshes are accepted on the branches of one planet per stage, the others must
// be lumped or contact (BuildTrainModel refuses redundant ones, naming them).
//
// Loaded flank (linear contact, seed 001 section 2.4): from the sign of the power-flow mesh load
// (tooth torque lambda, planetary_power_flow.h). The mesh element's drive flank is the one gear a
// pushes with when it turns +z, i.e. the mesh torque on gear a is negative. Unloaded meshes (an
// unloaded stage) get a stiffness scaled by `unloaded_mesh_stiffness_factor`, as seed 001 does
// ("very small gear mesh stiffnesses"), so they add near-zero modes (Table 3).
//
// Mesh phasing (GearMeshSpec::phase, in mesh cycles). Phase 0 of a mesh: a tooth pair of its
// loaded flank touches at the pitch point; the phase advances with gear a's rotation relative to
// the carrier, Z_a th_a / 2 pi. For an external gear G of the mesh (derived in train_meshes.cpp
// from the involute: the contact point on the line of action lies r_b (chi - phi_P) +-
// r_b (theta_b - inv alpha_w) from the pitch point, with chi a tooth centre angle):
//   phase = eps_G [ Z_G (chi_G - phi_P,G) / 2 pi + sigma Z_G (theta_bG - inv alpha_w) / 2 pi ]
//   eps_G = +1 if G is gear a, -1 if gear b;  sigma = +1 drive flank, -1 coast flank;
//   phi_P,G: direction from G's centre to the pitch point;  theta_bG = pi / (2 Z_G) + inv alpha_t,
//   half the base-circle tooth angle of a gear of standard tooth thickness (no profile shift).
// The sun's teeth fix the first mesh, every planet's teeth follow from its mesh with the sun
// (conjugacy: both gears give the same contact point), every other mesh of the branch is read
// from a planet. This reproduces Parker & Lin (2004), "Mesh phasing relationships in planetary
// and epicyclic gears", J. Mech. Des. 126: in the convention above,
//   sun-planet n:  phase_sn = phase_s1 - Z_s psi_n / 2 pi        (mod 1)
//   ring-planet n: phase_rn = phase_r1 - Z_r psi_n / 2 pi        (mod 1)
// (Parker & Lin's gamma_sn = Z_s psi_n / 2 pi, gamma_rn = -Z_r psi_n / 2 pi are time lags for a
// sun turning +z: the ring mesh phase runs backwards in time, hence the sign flip), and the
// sun-ring phase of one planet
//   phase_r1 + phase_s1 = Z_p / 2 - (Z_p / pi) theta_bp + Z_p (inv alpha_s + inv alpha_r) / 2 pi,
// which for standard gears at the reference centre distance is (Z_p - 1) / 2 mod 1: 0 for an odd
// planet tooth count, 1/2 for an even one (a planet tooth facing the sun faces a ring tooth or a
// ring space). Seed 001 eqs. 15-17 write the same phases as l Z_s psi_i, l gamma_sr per harmonic;
// the stage phase Gamma^(j) of eq. 15 is `stage_phase_cycles`.
// The static transmission error of each mesh (seed 001 eqs. 14-17, `ste_amplitudes_m`) is
// evaluated by the mesh element at its own phase, so planet-to-planet and sun-to-ring phasing of
// the excitation follows from GearMeshSpec::phase. Seed 001 writes E sin(l w t + phi); the mesh
// element's series is A cos(2 pi l psi + phi'): phi' = phi - pi / 2.
//
// Parameters. Every value is derived when not given and overridable per member (by member or
// planet-set name) and per mesh (by train mesh name), so a published lumped model is entered as
// printed:
//   external gears: steel annulus of face width b from the bore to the pitch radius;
//   rings: annulus from the pitch radius to pitch radius + `ring_rim_modules` m_n;
//   carriers: a crude default (steel disc of the planet tip circle radius, thickness b): give the
//             real value as an override;
//   mesh stiffness: `mesh_stiffness_source`, per mesh `stiffness_source` (below).
//
// Mesh stiffness (`mesh_stiffness_source`, per mesh `stiffness_source`):
//   kGiven:    the per-mesh override, else `mesh_stiffness_n_per_m` for every mesh, else c_gamma b
//              with `mesh_stiffness_per_face_width_n_per_m2` (ISO 6336-1's typical 20 N/(mm um)).
//   kIso6336:  ISO 6336-1 c_gamma_alpha b of the mesh's GearPair (mesh_stiffness.h).
//   kTvms:     the potential-energy TVMS of the GearPair (CalcTvms) as GearMeshSpec::stiffness_table
//              over one mesh cycle, `tvms_samples_per_cycle` samples per cycle; with a tooth fault
//              (`tooth_faults`) on one gear G of the mesh, over Z_G cycles (one turn of G relative
//              to the carrier) with GearMeshSpec::phase_gear = G.
//   kTvmsMean: the mean of that TVMS, constant (linear analyses about the mean mesh).
//   Explicit per-mesh stiffness_n_per_m / stiffness_table_n_per_m overrides win over every source.
//   GearPair of a train mesh (MakeTrainGearPair): gear 1 is the spec's gear a (the sun of a
//   sun-planet mesh, the planet of a ring-planet mesh), gear 2 gear b, at the train's centre
//   distance (pin radius); module, pressure and helix angle from the train's tooth forms; profile
//   shift 0 unless given (TrainMemberOverride::profile_shift, ISO 21771 sign); external gears take
//   the tooth form's addendum, ring gears `ring_addendum_coefficient` and
//   `ring_root_fillet_coefficient` (defaults 0.85 and 0.25: a standard 1.0 m_n ring tip reaches
//   into the root fillet of an 18-tooth planet, which GearPair rejects, seed 001; seed 003's 14/50
//   planet-ring pair needs h_a* < 0.897 for the ring tip to stay outside the planet's interference
//   point and rho_fP* < 0.38 for the ring's fillets to fit); face widths, bores
//   (bore_to_pitch_ratio) and ring rims (ring_rim_modules) as for the inertias. One geometry for
//   every level: the lumped stiffness models and tooth contact mesh the same gears. Helix hands:
//   sun (a central external gear) right-hand, planets left, rings left (an internal pair has
//   equal hands; the stiffness does not depend on the hand, and the model's helix signs are set
//   as described above). A tip diameter given in the train (TrainGearSpec::tip_radius_m, a
//   measured outside diameter) replaces the addendum's.
//   Table phase (CalcTvms samples pair 0 from the start of the contact path, s_0; the mesh phase
//   is 0 when a pair of the loaded flank is at the pitch point P): at mesh phase psi the TVMS is
//   read at gear-1 cycles u = (s_P - s_0) / p_bt - b tan(beta_b) / (2 p_bt) + sigma psi, sigma = +1
//   drive flank, -1 coast flank (gear a turning +z drives on its drive flank: the contact runs
//   from T1 towards the tip of gear 1; on the coast flank it runs back), i.e. phase 0 puts a
//   pair at P in the mid-face transverse section.
//   With a tooth fault on gear G of the mesh (below, "Tooth faults") the table spans Z_G cycles
//   (one turn of G relative to the carrier) with GearMeshSpec::phase_gear = G; a faulted planet
//   has its own table per branch, a faulted central gear one table whose branch-n phase is
//   phase_0 - Z_G psi_n / 2 pi mod Z_G (psi_n - psi_0 the planet angle: one physical tooth meets
//   every branch in turn).
//
// Tooth faults (`tooth_faults`, TrainToothFault: gear, branch, ToothFaultSpec of tooth_fault.h).
// One numbering for every level: the gear-frame index, tooth k centred on the polar angle
// 2 pi k / z of the gear frame, which the assembler places in the body at q = 0 as the contact
// level does (models/train_contact.h: the sun's tooth 0 on its body's +x, a planet's frame turned
// by pi + pi / z_p + (z_s / z_p) psi, the ring's from the planet's); a flexible gear's FE teeth
// have the same indices. The default phase of each stage's first mesh (no stage_phase_cycles) is
// the one these frames give (a lumped model's teeth stand where the contact model's do), so
// every level of one scene meets a fault at the same instant. Per mesh branch at its level:
//   lumped (kTvms only; another source with a fault on the mesh is an error): CalcTvms over a
//     turn of G with the fault at the mesh-order tooth of gear-frame tooth k: tooth k reaches the
//     pitch point on the loaded flank at the mesh phase n_k = round(psi_c(k) - f_G) mod Z_G,
//     psi_c(k) = phase_0 + (dpsi/dtheta_G) (phi_G - chi_k) the phase at which it is centred on
//     the line of centres (phi_G: direction from G's centre to the pitch point; chi_k: the
//     tooth's angle at q = 0), f_G = sigma Z_a (theta_ba - inv alpha_w) / 2 pi for gear a and
//     f_a - sigma / 2 for gear b (the mating tooth, half a pitch ahead); cracks and spalls act
//     on their own flank when it is loaded (drive: gear a's plus flank, an external gear b's
//     plus, a ring's minus; coast: the other);
//   contact: the faulty tooth surfaces and crack scales of gear_contact.h (faults1/faults2);
//   flexible: the FE mesh of the reduced body carries the fault (its reduce input's `fault:`,
//     made by the scene loader, import/gear_scene.cpp); the embedded contact surface is the
//     faulty one (a broken part has no FE face to embed in; a spall floor lies below the flank).
// A flexible planet's or gear's faults must be in its reduced body (the scene loader refuses a
// body whose provenance lacks them).

// Flexible bodies (`flexible_bodies`, by body name: planets "S.planet1", central members "S.sun",
// "S.ring"): the body is the reduced body (mbd/flexible_body.h; mass and inertia from its FE
// model instead of the lumped parameters), its frame B the reduction's reference interface (a
// gear's bore) on the pin or on the member's joint. Lumped meshes act on the master of the
// interface `mesh_interface` (for example an RBE3 over the root circle, so that the mesh load
// deforms rim and web) or on B if it is empty; the mesh stiffness should then be the teeth's and
// the contact's only (the FE body carries the rest): it is the scene's to choose. Contact meshes
// of a flexible gear use its FE tooth surfaces (models/train_contact.h). A flexible carrier is
// not supported (its planets' pins would need joints on its interface nodes).
// A flexible body must be the gear it stands for (a body reduced from another gear turns, meshes
// and rings as that gear): when its `source` is a reduce input's ("gear z=23, m_n=0.002 m, ...,
// b=0.02 m, ..."), tooth count, normal module and face width must equal the train gear's (to
// 1e-9); and, with a surface, its FE surface must reach the gear's tip circle (the largest radius
// of an external gear's surface nodes, the smallest of a ring's, within a quarter module: one
// tooth more or less moves the tip by half a module). Refused with both gears named.
//
// Imported gears (`imported_gears`, by body name; planets): a rigid planet whose body comes from a
// mesh file (models/imported_gear.h): its mass, centre of mass and inertia are the closed mesh's
// (gear frame G, turned into the body frame as the planet's gear frame is, train_contact.h)
// instead of the lumped parameters, and on its `contact` branches its tooth surface is the
// file's triangles (SplitImportedGearTeeth against the train's planet gear: tip radius, faces and
// tooth positions checked) instead of the generated outline. Its lumped meshes use the train's
// gear geometry as for any planet. A body is imported or flexible, not both; a flexible planet
// from a mesh file is a flexible body reduced from it (`orrery reduce planet.stl ... -o
// planet.h5`): its tooth contact then embeds the train's analytic teeth in its FE surface
// (train_contact.h, "Flexible gears").
//
// Housing (`housing`): a rigid body named "housing" on a joint to the ground of the DOF set's
// type (torsional: turning about the axis; planar: x, y and turning; spatial: free), held by
// elastic mounts (coordinate springs on its joint, or a 6-DOF bushing in the spatial set). The
// central members' joints, bearings, brakes and springs to ground seat in it instead of the
// ground, so that the mesh and bearing forces reach it through a transfer path and a sensor on it
// measures what an accelerometer on a gearbox case does (McFadden & Smith 1985: each planet's
// mesh seen through a path that changes as the planet passes). Speed drivers then drive a member
// relative to the housing (the motor sits in it).
//
// Sensors (`sensors`, TrainSensor): what a data-acquisition system records on the stage, sampled
// through the anti-alias chain of mbd/sensor_sampler.h. Names resolve against the assembled model:
// point sensors on a body ("S.sun", "S.carrier", "S.ring", "S.planet1", "housing"; on an FE node
// of a flexible body the elastic motion is included), encoders and tachometers on the joint of
// that body (default coordinate: the spin), mesh sensors on a branch ("S.ring-planet#1"): a lumped
// branch gives its tooth force, deflection or transmission error (SensorKind::kGearMesh), a
// contact branch its line-of-action force (or the contact's normal force) or transmission error
// (SensorKind::kElementOutput of the contact element); a kinematic branch has no mesh signal (its
// force is /gear_constraints/<branch>/force). Errors name the sensor: "sensor 'NAME': ...".
//
// Usage:
//   auto train = MakeSeed001AutomaticTransmission();
//   TrainModelOptions o;
//   o.face_width_m = 0.030;
//   o.input_torque_n_m = 300;
//   TrainModel tm = BuildTrainModel(*train, train->RangeIndex("1st"), o);
//   State x0 = State::Initial(*tm.model);  // members at their kinematic speeds
//   State x_static = SolveTrainStaticState(tm, x0);  // loads carried, no start-up step response
// Seed 002 start-up with TVMS meshes (tests/models/seed002_test.cpp):
//   o.dofs = TrainDofs::kSpatial;  o.input = TrainModelOptions::Input::kSpeed;
//   o.input_speed_functions = {TimeFunction::Trapezoid(0, 2.094, 0, 0.2, 0.04, 0.04, 0.6)};
//   o.mesh_stiffness_source = MeshStiffnessSource::kTvms;
// Mixed fidelity (seed 003: planet 1 flexible in tooth contact, planets 2 and 3 lumped):
//   o.mesh_stiffness_source = MeshStiffnessSource::kTvms;
//   o.mesh_models["S.sun-planet#1"] = o.mesh_models["S.ring-planet#1"] = MeshModel::kContact;
//   o.flexible_bodies["S.planet1"] = {.modes = planet_modes};
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "mbd/data.h"
#include "mbd/model.h"
#include "mbd/sensor.h"
#include "mbd/state.h"
#include "mbd/time_function.h"
#include "mbd/triangle_mesh.h"
#include "models/mesh_stiffness.h"
#include "models/planetary_kinematics.h"
#include "models/planetary_power_flow.h"
#include "models/planetary_train.h"
#include "models/train_contact.h"

namespace orrery::gears {

enum class TrainDofs { kTorsional, kPlanar, kSpatial };

// The model of one mesh branch (the mesh rungs of DESIGN.md's fidelity ladder).
enum class MeshModel { kKinematic, kLumped, kContact };
const char* MeshModelName(MeshModel model);  // "kinematic", "lumped", "contact"

// Where a lumped mesh's stiffness comes from (header, "Mesh stiffness").
enum class MeshStiffnessSource { kGiven, kIso6336, kTvms, kTvmsMean };

// A tooth fault on one gear of the train (header, "Tooth faults"), applied at the level of every
// mesh branch the gear meets: lumped (kTvms), contact, or the FE teeth of a flexible body.
struct TrainToothFault {
  std::string gear;       // train gear name: "S1.sun", "S1.planet", "S1.ring", ...
  int branch = 0;         // planets: the branch (0-based) whose planet is faulted; central gears: 0
  ToothFaultSpec spec;    // kind, gear-frame tooth (tooth k centred on 2 pi k / z), extent
};

// Per member ("S1.sun", "S1.carrier") or per planet set ("S1.planet"): every field replaces the
// derived value.
struct TrainMemberOverride {
  std::optional<double> mass_kg;
  std::optional<double> polar_inertia_kg_m2;       // about the gear axis
  std::optional<double> transverse_inertia_kg_m2;  // about a diameter (spatial DOF set)
  std::optional<double> base_radius_m;             // gears (a published lumped model)
  std::optional<double> face_width_m;
  std::optional<double> bore_radius_m;             // external gears and carriers
  std::optional<double> outer_radius_m;            // rings, carriers
  std::optional<double> radial_bearing_stiffness_n_per_m;   // planar, spatial
  std::optional<double> axial_bearing_stiffness_n_per_m;    // spatial
  std::optional<double> tilt_bearing_stiffness_n_m_per_rad; // spatial
  std::optional<double> bearing_damping_n_s_per_m;
  std::optional<double> ground_torsional_stiffness_n_m_per_rad;  // a spring to ground in every range
                                                             // (seed 001 k_jg; Lin & Parker's ring)
  std::optional<double> brake_stiffness_n_m_per_rad;   // when a brake on this member is engaged
  std::optional<double> profile_shift;             // gears: x (ISO 21771), stiffness geometry
  std::optional<double> addendum_coefficient;      // gears: h_a*, stiffness geometry
};

// Per train mesh ("S1.sun-planet", "S1.ring-planet", ...), applied to all of its branches.
struct TrainMeshOverride {
  std::optional<double> stiffness_n_per_m;
  std::optional<std::vector<double>> stiffness_table_n_per_m;  // over table_cycles mesh cycles
  std::optional<int> table_cycles;
  std::optional<double> working_pressure_angle_rad;  // published lumped data (no centre check)
  std::optional<double> damping_ratio;
  std::optional<double> backlash_m;
  std::optional<std::vector<double>> ste_amplitudes_m;  // harmonics 1, 2, ... (seed 001 Table 4)
  std::optional<std::vector<double>> ste_phases_rad;
  std::optional<GearMeshSpec::Contact> contact;         // replaces the power-flow flank
  std::optional<std::vector<double>> phase_cycles;      // per branch, replaces the derived phase
                                                        // (over table_cycles cycles)
  std::optional<MeshStiffnessSource> stiffness_source;  // replaces mesh_stiffness_source
};

// A gearbox housing (header, "Housing"): a rigid body on elastic mounts to the ground.
struct TrainHousing {
  double mass_kg = 0;
  double polar_inertia_kg_m2 = 0;         // about the train axis
  double transverse_inertia_kg_m2 = 0;    // about a diameter (spatial; 0: half the polar)
  double mount_radial_stiffness_n_per_m = 0;         // x and y (planar, spatial)
  double mount_axial_stiffness_n_per_m = 0;          // z (spatial)
  double mount_torsional_stiffness_n_m_per_rad = 0;  // about the axis
  double mount_tilt_stiffness_n_m_per_rad = 0;       // about x and y (spatial)
  double mount_damping_ratio = 0;   // per mount direction: c = 2 zeta sqrt(k m), m the housing's
                                    // mass or inertia in that direction
};

// A virtual sensor of the train (header, "Sensors"), by the names of what it reads; the sensors
// stage resolves the names against the assembled model and adds a SensorSpec (mbd/sensor.h).
struct TrainSensor {
  std::string name;   // unique among sensors: the result group /sensors/<name>
  SensorKind kind = SensorKind::kAccelerometer;
  // Point sensors (accelerometer, velocity, displacement, gyroscope, angular accelerometer).
  std::string body;   // "S.sun", "S.carrier", "S.ring", "S.planet1", "housing"
  std::optional<int> node;               // flexible body: FE node id; the sensor follows its
                                         //   elastic motion (a node frame "sensor:<name>")
  std::optional<Vec3> position_m;        // in the body frame; default: the body's origin, or
                                         //   the node's position
  Mat3 rotation = Mat3::Identity();      // the sensor's axes in the body frame
  std::string measured_in = "sensor";    // "sensor" (its own axes), "world", or a body name
                                         //   (that body's frame, e.g. "housing")
  std::vector<int> axes{0, 1, 2};        // components recorded (0 x, 1 y, 2 z)
  bool include_gravity = false;          // accelerometer: a - g
  // Joint sensors (encoder, tachometer): a member's, planet's or the housing's joint, by body
  // name; the coordinate within the joint's velocities (-1: the spin about the gear axis).
  std::string joint;
  int coordinate = -1;
  // Mesh sensors (kGearMesh): a mesh branch "S.sun-planet#1", lumped or contact.
  std::string mesh;
  MeshQuantity quantity = MeshQuantity::kForce;
};

// A flexible body of the train (header, "Flexible bodies").
struct TrainFlexibleBody {
  std::shared_ptr<const FlexibleBodyModes> modes;
  FlexibleBodyOptions options;
  std::string mesh_interface;  // lumped meshes act on this interface's master ("" : on B)
  std::string source;          // what was reduced (flex::ReducedBodyProvenance::source; "" unknown)
};

// A gear body from a mesh file (header, "Imported gears"), filled by the scene reader
// (import/solid_mesh.h ReadImportedGear) or by hand.
struct TrainImportedGear {
  TriangleMesh surface;  // the closed surface, gear frame (m; models/imported_gear.h)
  double mass_kg = 0;
  Vec3 center_of_mass_m = Vec3::Zero();  // gear frame
  Mat3 inertia_kg_m2 = Mat3::Zero();     // about the centre of mass, gear-frame axes
  std::string source;                    // the file, for messages
};

struct TrainModelOptions {
  TrainDofs dofs = TrainDofs::kTorsional;

  // Ports. kSpeed: every input driven at its speed (a velocity constraint); kTorque: the first
  // input loaded by input_torque_n_m; kNone: no input element (a free train, seed 001's modal
  // model). The other ports (further inputs, the output) carry their power-flow torques when
  // port_loads is set.
  enum class Input { kNone, kTorque, kSpeed } input = Input::kTorque;
  std::vector<double> input_speeds_rad_s;  // one per train input (empty: at rest)
  // kSpeed: one speed profile per input (e.g. TimeFunction::Trapezoid, seed 002 Fig. 3) replacing
  // the constant speeds; the initial speeds are their values at t = 0 (input_speeds_rad_s must
  // then be empty).
  std::vector<TimeFunction> input_speed_functions;
  // Load torque on the output member (N m, sign as PlanetaryPowerFlow::port_torques_n_m) as a
  // function of time, replacing the power-flow constant (e.g. a load step). Applied even when
  // port_loads is false.
  std::optional<TimeFunction> output_torque_n_m;
  double input_torque_n_m = 0;              // on train.inputs[0]; also sets the power flow
  // Instead of input_torque_n_m: the steady torque on the output port (N m, sign as
  // PlanetaryPowerFlow::port_torques_n_m), turned into the input torque by the power flow at
  // `operating_speeds_rad_s` (one per input; empty: the input speeds at t = 0; a zero speed
  // counts as 1 rad/s, only the ratios matter).
  std::optional<double> output_port_torque_n_m;
  std::vector<double> operating_speeds_rad_s;
  bool port_loads = true;

  // Geometry and material for derived parameters.
  double face_width_m = 0;          // default for every gear (required unless all are overridden)
  double density_kg_m3 = 7850;      // steel
  double bore_to_pitch_ratio = 0.4; // external gears: bore radius / pitch radius
  double ring_rim_modules = 3.5;    // ring outer radius = pitch radius + this * m_n
  double stage_spacing_m = 0;       // axial distance between stages (spatial; 0: 3 face widths)

  // Mesh models: the default of every mesh branch, replaced per train mesh ("S.sun-planet") or
  // per branch ("S.sun-planet#2", 1-based) by `mesh_models` (the branch entry wins).
  MeshModel mesh_model = MeshModel::kLumped;
  std::unordered_map<std::string, MeshModel> mesh_models;

  // Lumped mesh stiffness (header, "Mesh stiffness").
  MeshStiffnessSource mesh_stiffness_source = MeshStiffnessSource::kGiven;
  std::optional<double> mesh_stiffness_n_per_m;   // kGiven: every mesh (else c_gamma b)
  double mesh_stiffness_per_face_width_n_per_m2 = 2e10;
  double unloaded_mesh_stiffness_factor = 1e-12;  // seed 001: unloaded meshes "very small"; 1 keeps
  int tvms_samples_per_cycle = 64;                // kTvms table samples per mesh cycle
  double ring_addendum_coefficient = 0.85;        // h_a* of ring gears (every level's geometry)
  double ring_root_fillet_coefficient = 0.25;     // rho_fP* of ring gears
  GearMaterial gear_material;                     // TVMS, flexible contact penalty (both gears)
  Iso6336Options iso6336;                         // kIso6336
  std::vector<TrainToothFault> tooth_faults;      // header, "Tooth faults"; empty: a healthy train
  double mesh_damping_ratio = 0;                  // time-domain runs (GearMeshSpec::damping_ratio)

  // Lumped contact: linear on the loaded flank (the operating point), or two-sided with backlash.
  bool two_sided_contact = false;
  double backlash_m = 0;

  // Tooth contact of the `contact` meshes (models/train_contact.h).
  TrainContactOptions contact;

  // Phasing: derived mesh phases (false: all 0); stage phase Gamma^(j) / 2 pi per stage.
  bool mesh_phasing = true;
  std::vector<double> stage_phase_cycles;

  // Couplings (seed 001 section 3).
  double connection_stiffness_n_m_per_rad = 1e8;
  double clutch_stiffness_n_m_per_rad = 1e8;
  double brake_stiffness_n_m_per_rad = 1e10;

  // Bearings (planar and spatial DOF sets), central members to the housing and planets to pins.
  double radial_bearing_stiffness_n_per_m = 1e8;
  double axial_bearing_stiffness_n_per_m = 1e8;
  double tilt_bearing_stiffness_n_m_per_rad = 1e7;
  double bearing_damping_n_s_per_m = 0;

  std::unordered_map<std::string, TrainMemberOverride> members;  // by member or planet-set name
  std::unordered_map<std::string, TrainMeshOverride> meshes;     // by train mesh name

  // Flexible bodies, by body name: planets by set name and branch number ("S.planet1"), central
  // members by member name ("S.sun", "S.ring").
  std::unordered_map<std::string, TrainFlexibleBody> flexible_bodies;
  // Imported gears, by body name: planets ("S.planet1") only, rigid (header, "Imported gears").
  std::unordered_map<std::string, TrainImportedGear> imported_gears;

  // A housing the central members seat in (none: they seat in the ground).
  std::optional<TrainHousing> housing;

  // Virtual sensors (header, "Sensors"), added last (every body and mesh exists by then).
  std::vector<TrainSensor> sensors;
};

// Resolved lumped parameters of a member or planet set (filled by BuildTrainModel).
struct TrainBodyParams {
  double mass_kg = 0, polar_inertia_kg_m2 = 0, transverse_inertia_kg_m2 = 0;
  double base_radius_m = 0;  // gears; 0 for carriers
  double face_width_m = 0;
};

// One GearMeshSpec of the model: mesh `train_mesh` on branch `branch`.
struct TrainMeshElement {
  int train_mesh = -1, branch = -1, stage = -1;
  int model_mesh = -1;           // index into Model::gear_meshes
  double stiffness_n_per_m = 0;      // mean stiffness used
  double working_pressure_angle_rad = 0;
  GearMeshSpec::Contact contact = GearMeshSpec::Contact::kLinearDrive;  // loaded flank
  double phase_cycles = 0;       // GearMeshSpec::phase
  bool loaded = false;           // power flow
  int phase_gear_speed = -1;     // speed index of the spec's gear a (phase advances with it)
  MeshStiffnessSource stiffness_source = MeshStiffnessSource::kGiven;
  double stiffness_min_n_per_m = 0, stiffness_max_n_per_m = 0;  // over the table (= mean if constant)
  int table_cycles = 1;          // GearMeshSpec::table_cycles
  int faulted_gear = -1;         // train gear index of a faulted gear of this mesh, or -1
};

// One GearConstraintSpec of the model (a kinematic mesh branch).
struct TrainKinematicMesh {
  int train_mesh = -1, branch = -1, stage = -1;
  int model_constraint = -1;     // index into Model::gear_constraints
  double working_pressure_angle_rad = 0;
};

// What models a mesh branch: `index` into TrainModel::meshes (lumped), ::contacts (contact) or
// ::kinematic_meshes (kinematic).
struct TrainMeshBranch {
  int train_mesh = -1, branch = -1;
  MeshModel model = MeshModel::kLumped;
  int index = -1;
};

// Filled by BuildTrainModel.
struct TrainModel {
  std::shared_ptr<const Model> model;
  std::shared_ptr<const PlanetaryTrain> train;  // a copy of the train it was built from
  int range = -1;
  TrainModelOptions options;            // as built (a variant is built from them, not patched)
  TrainDofs dofs = TrainDofs::kTorsional;
  PlanetaryKinematics kinematics;       // at options.input_speeds_rad_s
  PlanetaryKinematics unit_kinematics;  // inputs scaled so that train.inputs[0] turns at 1 rad/s
                                        // (+1 on every input if all given speeds are 0)
  PlanetaryPowerFlow power_flow;        // at input_torque_n_m (1 N m if 0: signs only)
  double input_torque_n_m = 0;           // as used (given, or from output_port_torque_n_m)
  std::vector<JointIndex> member_joints;             // (members)
  std::vector<std::vector<JointIndex>> planet_joints;  // (planet sets) x (branches)
  BodyIndex housing_body = -1;                       // the housing, -1 without one
  JointIndex housing_joint = -1;
  std::vector<BodyIndex> member_bodies;              // (members)
  std::vector<std::vector<BodyIndex>> planet_bodies;   // (planet sets) x (branches)
  std::vector<TrainBodyParams> member_params;        // (members)
  std::vector<TrainBodyParams> planet_params;        // (planet sets)
  std::vector<TrainMeshElement> meshes;              // lumped branches, in Model order
  std::vector<TrainContactMesh> contacts;            // contact branches (models/train_contact.h)
  std::vector<TrainKinematicMesh> kinematic_meshes;  // kinematic branches, in Model order
  std::vector<TrainMeshBranch> branches;             // every mesh branch, stage by stage
  std::vector<std::vector<int>> planet_bearings;     // (planet sets) x (branches): index into
                                                     // Model::bearings (spatial) or of the x spring
                                                     // in Model::coordinate_springs (planar); -1
                                                     // torsional
  int rotation_coordinate = 0;  // index of the spin within a member joint's velocities (0, 2, 5)
};

// Builds the model of `train` in gear range `range`. Throws std::invalid_argument naming the
// member, mesh, body or option that is missing or non-physical (e.g. a gear without tooth form
// and no base radius override, an override key that names nothing, a mesh model key that names
// no mesh or branch, redundant kinematic meshes), std::runtime_error from the kinematics or power
// flow (an indeterminate range).
TrainModel BuildTrainModel(const PlanetaryTrain& train, int range, const TrainModelOptions& options);

// The mesh model of branch `branch` (0-based) of train mesh `mesh` under `options`.
MeshModel MeshModelOf(const PlanetaryTrain& train, int mesh, int branch,
                      const TrainModelOptions& options);

// GearPair of train mesh `mesh` with the geometry described above ("Mesh stiffness"). Throws
// std::invalid_argument naming the gear ("gear 'S.planet': undercut: ...") if a gear has no
// tooth form or Gear rejects it, naming the mesh if GearPair rejects the pair (with their
// reasons). fallback_face_width_m: the face width of a gear that has none from the options (0:
// none, an error).
GearPair MakeTrainGearPair(const PlanetaryTrain& train, int mesh, const TrainModelOptions& options,
                           double fallback_face_width_m = 0);

// The involute geometry of every gear that has a tooth form, whatever its meshes' models: the
// validation every command shares (BuildTrainModel calls it first, so `run`, `kinematics`,
// `mesh-stiffness` and `modes` refuse the same gears). A gear that cannot be cut (undercut,
// pointed tip, a root or tip radius that leaves no tooth: Gear's checks) makes kinematics,
// forces and frequencies of a gear that does not exist, even where a kinematic mesh or a given
// stiffness does not use the geometry. The pairs' checks (contact ratio, interference) stay with
// the meshes that use the pair's geometry (TVMS, ISO 6336, contact): published lumped models
// (seed 000, seed 002) state tooth counts and modules but not the ring's addendum their contact
// ratio depends on. The face width enters none of the checks of a tooth's form; a gear without
// one is checked at 10 modules. Throws std::invalid_argument as MakeTrainGearPair ("train model:
// gear 'S.planet': ...").
void CheckTrainGearGeometry(const PlanetaryTrain& train, const TrainModelOptions& options);

// TVMS options of that pair: the blank radii BuildTrainModel derives its bodies from (bore of an
// external gear, rim of a ring), the train's gear material.
TvmsOptions MakeTrainTvmsOptions(const PlanetaryTrain& train, int mesh, const TrainModelOptions& options);

// Static equilibrium at time `guess.t` with the velocities of `guess` held (accelerations 0, so
// centrifugal terms at a constant speed are balanced): Newton's method on the free coordinates
// (the null space of the constraint Jacobian; speed-driven coordinates keep their values), the
// stiffness from Linearize. Starting a run from it avoids the step response of loads applied to
// an undeformed train. Throws std::runtime_error if the residual does not fall below 1e-9 of the
// initial one within max_iterations.
State SolveTrainStaticState(const TrainModel& model, const State& guess, int max_iterations = 30);

// Planet-pin bearing forces (N): magnitude of the transverse (radial-plane) spring-damper force of
// every planet bearing at `state` (seed 002's p-c pair), in (planet sets) x (branches) order,
// flattened; empty for the torsional DOF set. Runs position and velocity kinematics in `data`.
std::vector<double> CalcPlanetPinForces(const TrainModel& model, const State& state, Data& data);

// Mesh phases of one stage's meshes in GearMeshSpec convention (see above), per train mesh of the
// stage (in Stage::meshes order) and branch, from the planet angles, tooth counts, flanks
// (`drive`: true for kLinearDrive, indexed like Stage::meshes) and working pressure angles
// (indexed like Stage::meshes). The first mesh of branch 0 has phase `reference_phase`.
// Gears without tooth form take alpha_w for their reference pressure angle. Throws
// std::invalid_argument if the flank or pressure-angle lists do not match the stage's meshes.
std::vector<std::vector<double>> CalcStageMeshPhases(const PlanetaryTrain& train, int stage,
                                                     const std::vector<bool>& drive,
                                                     const std::vector<double>& pressure_angles,
                                                     double reference_phase = 0);

}  // namespace orrery::gears

#pragma once
// The multibody model: `ModelBuilder` takes bodies, frames, joints, constraints and force
// elements, validates them, and `Finalize()` turns them into an immutable `Model` of flat arrays
// and indices. Names live here for look-up and output; the step works on indices only.
//
// Coordinates: q (model.nq) and v (model.nv), joint by joint in tree order, then the modal
// coordinates of each flexible body (flexible_body.h) in the order the bodies were added.
// q-dot = N(q) v: identity except for unit quaternions (spherical and free joints), whose
// velocity variables are angular velocities expressed in the joint's parent-side frame F.
//
// Usage:
//   ModelBuilder b;
//   BodyIndex link = b.AddBody("link", 1.0, Vec3(0.5, 0, 0), Mat3::Identity() * 0.01);
//   b.AddJoint({.name = "hinge", .type = JointType::kRevolute, .parent = kWorldBody,
//               .child = link, .axis = Vec3::UnitZ()});
//   b.SetGravity(Vec3(0, -9.81, 0));
//   std::shared_ptr<const Model> model = std::move(b).Finalize();
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "mbd/external_force.h"
#include "mbd/flexible_body.h"
#include "mbd/joint_types.h"
#include "mbd/sensor.h"
#include "mbd/spatial.h"
#include "mbd/time_function.h"

namespace orrery {

using BodyIndex = int;
using FrameIndex = int;
using JointIndex = int;
constexpr BodyIndex kWorldBody = 0;
constexpr FrameIndex kWorldFrame = 0;

// A joint between frame F on `parent` (pose X_PF) and frame M on `child` (pose X_CM); F and M
// coincide at q = 0. Coordinates by type (all axes in F, unit length after normalization):
//   fixed: none;  revolute: angle about `axis`;  prismatic: slide along `axis`;
//   cylindrical: (angle, slide) about/along `axis`;
//   universal: (angle about `axis`, angle about `axis2` turned by the first angle);
//   spherical: quaternion (w, x, y, z) of R_FM, v = angular velocity in F;
//   planar: (x, y, angle) in the plane normal to `axis`, x along `axis2`;
//   free: (x, y, z, qw, qx, qy, qz), v = (translational velocity in F, angular velocity in F).
struct JointSpec {
  std::string name;
  JointType type = JointType::kRevolute;
  BodyIndex parent = kWorldBody;
  BodyIndex child = -1;
  Transform X_PF;        // joint frame F on the parent
  Transform X_CM;        // joint frame M on the child
  Vec3 axis = Vec3::UnitZ();
  Vec3 axis2 = Vec3::UnitX();  // universal: second axis; planar: in-plane x direction
};

// A loop closure (cut joint): constrains frame B relative to frame A as joint `type` would, with
// the joint axis along both frames' z axes (planar: z is the plane normal). Rows (seed 003 eq. 4):
//   revolute: p_B = p_A, x_A.z_B = 0, y_A.z_B = 0        spherical: p_B = p_A
//   universal: p_B = p_A, x_A.y_B = 0 (rotation about x_A and y_B free)
//   prismatic: x_A.y_B = y_A.z_B = z_A.x_B = 0, (p_B-p_A).x_A = (p_B-p_A).y_A = 0
//   cylindrical: x_A.z_B = y_A.z_B = 0, (p_B-p_A).x_A = (p_B-p_A).y_A = 0
//   planar: z_A.x_B = z_A.y_B = 0, (p_B-p_A).z_A = 0
//   fixed: p_B = p_A, x_A.y_B = y_A.z_B = z_A.x_B = 0
//   planar_pin (cut joints only): (p_B-p_A).x_A = (p_B-p_A).y_A = 0: the cut of a planar loop of
//     revolute joints about z_A (a revolute cut repeats the plane's 3 rows, a spherical cut 1)
struct LoopClosureSpec {
  std::string name;
  JointType type = JointType::kRevolute;
  FrameIndex frame_a = -1;
  FrameIndex frame_b = -1;
};

// A driver prescribes one coordinate of a joint as a function of time, as a rheonomic constraint
// whose multiplier is minus the driving effort (torque or force; dae.h, "Sign of the multipliers"). Position drivers: q_k = f(t)
// (holonomic). Speed drivers: v_k = f(t) (a velocity constraint; the coordinate is its integral).
struct DriverSpec {
  std::string name;
  JointIndex joint = -1;
  int coordinate = 0;  // index within the joint's velocity coordinates
  enum class Mode { kPosition, kSpeed } mode = Mode::kSpeed;
  TimeFunction function;
};

// Force elements ---------------------------------------------------------------------------

// Force and torque on a frame: (force, torque) * scale(t), in world axes or the frame's axes; the
// force acts at the frame origin.
struct AppliedLoadSpec {
  std::string name;
  FrameIndex frame = -1;
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
  TimeFunction scale = TimeFunction::Constant(1.0);
  bool in_frame_axes = false;
};

// Generalized force on one joint coordinate (a motor torque or a load torque): f(t).
struct JointLoadSpec {
  std::string name;
  JointIndex joint = -1;
  int coordinate = 0;
  TimeFunction function;
};

// Point-to-point spring-damper between the origins of two frames: tension
// F = k (L - free_length) + c L-dot + preload, pulling the frames together when positive.
struct TranslationalSpringSpec {
  std::string name;
  FrameIndex frame_a = -1, frame_b = -1;
  double stiffness = 0, damping = 0, free_length = 0, preload = 0;
};

// Rotational spring-damper about the common z axis of two frames: torque on B
// T = -k (theta - theta0) - c theta-dot, theta the angle of B relative to A about z_A (wraps at
// +-pi; use a coordinate spring for multi-turn twist).
struct RotationalSpringSpec {
  std::string name;
  FrameIndex frame_a = -1, frame_b = -1;
  double stiffness = 0, damping = 0, angle0 = 0;
};

// Spring-damper on a joint coordinate (a torsional spring to ground on a revolute joint, seed 001
// k_jg): f = -k (q_k - q0) - c v_k.
struct CoordinateSpringSpec {
  std::string name;
  JointIndex joint = -1;
  int coordinate = 0;
  double stiffness = 0, damping = 0, q0 = 0;
};

// 6-DOF bushing between two frames (a bearing, seed 002 eq. 10): deflection of B relative to A in
// A's axes, d = (translation, rotation vector); wrench on B at its origin, in A's axes,
// w = -K d - D d-dot (K, D 6x6; diagonal bushings set the diagonals). A gets the opposite.
struct BushingSpec {
  std::string name;
  FrameIndex frame_a = -1, frame_b = -1;
  Mat6 stiffness = Mat6::Zero();
  Mat6 damping = Mat6::Zero();
};

// Rolling-element bearing between a housing (or pin) frame A and a shaft frame B whose common
// axis is z: radial and axial springs on B's displacement in A's axes, tilt springs on the angle
// between the axes (z_A x z_B), and free rotation about the axis however far it turns (a
// bushing's rotation vector would wrap at half a turn). A planet-pin bearing of seed 002 eq. 10.
struct BearingSpec {
  std::string name;
  FrameIndex frame_a = -1, frame_b = -1;
  double radial_stiffness = 0, axial_stiffness = 0, tilt_stiffness = 0;  // N/m, N/m, N m/rad
  double radial_damping = 0, axial_damping = 0, tilt_damping = 0;        // N s/m, N m s/rad
};

// Lumped gear mesh between two gears (the `lumped` rung of DESIGN.md; seed 001 eqs. 7-9 and
// 14-17, Lin & Parker 1999, seed 002 eqs. 7-9): a spring-damper along the line of action.
//
// Geometry, in the reference frame C (the carrier, or the world) that holds both gear centres:
// u points from gear a's centre to the pitch point P (towards b for an external pair, away from
// the ring's centre for an internal one), t = z x u, and the transverse lines of action through P
// are n_drive = cos(alpha_w) t + sin(alpha_w) u (the flank gear a drives with when turning +z) and
// n_coast = cos(alpha_w) t - sin(alpha_w) u. With the base helix angle beta_b the contact normals
// are n = cos(beta_b) n_t + sin(beta_b) z. Deflections (positive = compression), linear in small
// translations and tilts of the centres in C:
//   e = r_ba theta_a + sigma r_bb theta_b   (theta relative to C and to the initial configuration,
//                                            sigma = +1 external, -1 internal; wrapped to one
//                                            base pitch, so turns never accumulate)
//   delta_drive = cos(beta_b) (e + n_drive.dc) + sin(beta_b) dz,
//   delta_coast = -cos(beta_b) (e + n_coast.dc) - sin(beta_b) dz - cos(beta_b) backlash,
// with dc, dz the transverse and axial displacement of gear a's point at P relative to gear b's.
// Force F = k (delta - e_ste) + c delta-dot while in contact (never pulling), on gear b along +n
// (drive) or -n (coast) at P, the opposite on gear a. k is constant or read from a table over the
// mesh cycle (or over all teeth of one gear, for faults) at the mesh phase of gear a (or b);
// e_ste = sum_k A_k cos(2 pi k psi + phi_k) is the static transmission error (seed 001 eq. 14).
// Linear contact keeps one flank engaged for all deflections (the linear models of seed 001 and
// Lin & Parker); two-sided contact separates and hits the back flank across the backlash.
struct GearMeshSpec {
  std::string name;
  FrameIndex gear_a = -1, gear_b = -1;  // gear frames: origin at the centre, z along the axis
  FrameIndex reference = kWorldFrame;   // C: holds the gear centres; its z parallel to the axes
  int teeth_a = 0, teeth_b = 0;
  double base_radius_a = 0, base_radius_b = 0;  // m
  double working_pressure_angle = 0;            // rad, transverse
  double base_helix_angle = 0;                  // rad, signed by hand (+: axial force +z on b)
  bool internal_b = false;                      // gear b is an internal gear (a ring)
  enum class Contact { kTwoSided, kLinearDrive, kLinearCoast } contact = Contact::kTwoSided;
  double backlash = 0;                    // m, along the transverse line of action (two-sided)
  double stiffness = 0;                   // N/m, used when stiffness_table is empty
  std::vector<double> stiffness_table;    // N/m, uniform samples over table_cycles mesh cycles
  int table_cycles = 1;                   // 1, or the tooth count of the phase gear (per tooth)
  enum class PhaseGear { kA, kB } phase_gear = PhaseGear::kA;
  double phase = 0;                       // mesh phase at the initial configuration (cycles)
  double damping = 0;                     // N s/m, or:
  double damping_ratio = 0;               // c = 2 zeta sqrt(k_mean m_eq), m_eq from the inertias
  std::vector<double> ste_amplitudes;     // m, harmonics 1, 2, ... of the mesh frequency
  std::vector<double> ste_phases;         // rad
  // Static transmission error as a table (m, along the line of action), uniform samples over
  // ste_table_cycles mesh cycles of the phase gear, added to the harmonics above (e.g. the
  // no-load TE of a spalled tooth, models/mesh_stiffness.h Tvms::no_load_te_m).
  std::vector<double> ste_table_m;
  int ste_table_cycles = 1;
  // false: a published lumped model entered as printed, whose centre distance need not agree
  // with its base radii and pressure angle; forces then act at the lever points r_b / cos(alpha_w)
  // from each centre along u (which coincide when the geometry is consistent).
  bool check_centre_distance = true;
};

// Ideal gear mesh (the `kinematic` rung): the constraint delta_drive = 0 of the geometry above,
// one row whose multiplier is the tooth force along n_drive (on gear b).
struct GearConstraintSpec {
  std::string name;
  FrameIndex gear_a = -1, gear_b = -1, reference = kWorldFrame;
  int teeth_a = 0, teeth_b = 0;  // for the base pitch that the angles wrap to
  double base_radius_a = 0, base_radius_b = 0, working_pressure_angle = 0, base_helix_angle = 0;
  bool internal_b = false;
  bool check_centre_distance = true;
};

// Model ------------------------------------------------------------------------------------

// Line-of-action geometry of a gear mesh or gear constraint, in its reference frame C, taken at
// the initial configuration by Finalize().
struct MeshGeometry {
  Vec3 n_drive_C = Vec3::Zero(), n_coast_C = Vec3::Zero();  // transverse unit normals
  Vec3 r_a_C = Vec3::Zero(), r_b_C = Vec3::Zero();  // lever points from the centres of a, b:
                                                    // the pitch point P for consistent geometry
  Vec3 dc0_C = Vec3::Zero();             // centre of a - centre of b at the start
  Mat3 R_CA0 = Mat3::Identity(), R_CB0 = Mat3::Identity();  // gear orientations in C at the
                                         // start (angles are measured from them)
  double sigma = 1;                      // +1 external, -1 internal
  double cos_beta = 1, sin_beta = 0;
  // The contact normals in C with the helix: cos(beta_b) n_C + sin(beta_b) z (drive, coast).
  Vec3 n_drive_helix_C = Vec3::Zero(), n_coast_helix_C = Vec3::Zero();
  double k_spin_base = 0;                // cos(beta_b) (r_ba + sigma r_bb) (MeshState::k_spin_base)
  double base_pitch = 0;                 // m, transverse: 2 pi r_ba / z_a (0 if z unknown)
};

struct GearMesh {
  GearMeshSpec spec;
  MeshGeometry geometry;
  double k_mean = 0;   // N/m
  double c = 0;        // N s/m (resolved from the damping ratio if given)
  // Without tooth counts (1 and 1) the angles cannot be wrapped to a base pitch: the mesh then
  // holds for small rotations only (a published linear model), and a run stops past 1 rad.
  bool small_rotations_only = false;
  // Gear angles of a and b: indices into Model::gear_angles (ModelBuilder::Finalize).
  int angle_a = -1, angle_b = -1;
  // Cosines and sines of spec.ste_phases, one per harmonic (0 and 1 where no phase is given),
  // for EvaluateGearMeshAtAngles.
  std::vector<double> ste_phase_cos, ste_phase_sin;
};

// One joint coordinate of a gear angle read from the coordinates (GearAngle::terms).
struct GearAngleTerm {
  int q = -1;       // index into q of a joint's rotation coordinate
  double sign = 1;  // +1 on the gear's side of the tree, -1 on the reference's (times the sign
                    //   of the joint axis along z)
  double q0 = 0;    // the coordinate at the start (Model::q_initial)
};

// A gear's angle about its reference frame's z axis since the start, shared by the meshes of the
// same gear and reference (a planet's sun and ring meshes, a sun's meshes with every planet):
// CalcGearAngles evaluates each once per pipeline evaluation.
//
// Read from the coordinates (by_coordinates, decided by ModelBuilder::Finalize with
// FindGearAngleTerms): when the gear frame and the reference frame hang from a common body
// through joints and fixed offsets that all turn about that body's z axis (revolute and
// cylindrical joints about +-z, planar joints normal to +-z, prismatic and fixed joints; joint and
// frame offsets whose rotations keep z; no node frames), every rotation on both paths is one about
// z, they commute, and R_CG R_CG0^T = Rz(theta) with theta = sum_k sign_k (q_k - q0_k): no
// trigonometry, wrapped to [-pi, pi] as the general path's atan2. Otherwise the general path
// (GearSpinAngle: the relative rotation's atan2).
struct GearAngle {
  FrameIndex gear = -1, reference = -1;
  Mat3 R_CG0 = Mat3::Identity();  // the gear frame's orientation in the reference frame at the start
  bool by_coordinates = false;
  std::vector<GearAngleTerm> terms;  // by_coordinates: the coordinates the angle sums
};

struct GearConstraint {
  GearConstraintSpec spec;
  MeshGeometry geometry;
};

struct Body {
  std::string name;
  double mass = 0;            // kg
  Vec3 com_B = Vec3::Zero();  // centre of mass in body frame B, m (flexible: undeformed)
  Mat3 inertia_cm_B = Mat3::Zero();  // inertia about the centre of mass in B axes, kg m^2
  JointIndex parent_joint = -1;      // tree joint whose child this body is (-1 for the world)
  int flexible = -1;                 // index into Model::flexible_bodies, -1 for a rigid body
  // Set by Finalize: the body and every body above it are rigid, and every joint from the world
  // to it turns about z only (revolute about exactly +-z, or fixed) with fixed rotations (X_PF,
  // X_CM) whose z row and column are exactly (0, 0, +-1). Then B's z axis is world +-z for
  // every q, and the kinematics hold exact zeros: V_WB = (0, 0, w, vx, vy, 0) and A_WB =
  // (0, 0, alpha, ax, ay, az). CalcInverseDynamics skips the products with them.
  bool turns_about_z = false;
};

struct Frame {
  std::string name;
  BodyIndex body = kWorldBody;
  Transform X_BF;  // pose of the frame on its body (flexible body: undeformed)
  bool is_body_frame = false;  // X_BF is the identity (a body's own frame)
  // Frames on a flexible body's node follow the node: origin displaced by Phi_P q_f (plus the
  // node's small rotation Psi_P q_f times the offset from the node), axes turned by Psi_P q_f.
  int node = -1;  // index into the body's FlexibleBodyModes::nodes, -1 if not on a node
};

// A flexible body's place in the model (Finalize() fills the derived fields).
struct FlexibleBody {
  BodyIndex body = -1;
  std::shared_ptr<const FlexibleBodyModes> modes;
  FlexibleBodyOptions options;
  int nf = 0;              // modal coordinates in q and v (0 when frozen)
  int q_start = 0, v_start = 0;
  Eigen::MatrixXd mass;       // nf x nf: M_ff(k, l) = tr I5_kl
  Eigen::MatrixXd stiffness;  // nf x nf: K_ff
  Eigen::MatrixXd damping;    // nf x nf: resolved from modes.damping or the options
  // nf * nf axial vectors int rho Phi_m x Phi_l (index m * nf + l): the modal Coriolis terms.
  std::vector<Vec3> mode_cross;
  bool geometric_stiffening = false;
};

struct Joint {
  JointSpec spec;
  Transform X_MC;   // inverse of spec.X_CM (child frame from M)
  bool X_PF_is_identity = false, X_MC_is_identity = false;  // skip the products in kinematics
  // +1 or -1: a revolute joint whose axis is exactly +z or -z of F, posed by CalcFramePoses with
  // the rotation's zeros written out (kinematics.cpp RevoluteAboutZ); 0 for every other joint.
  int revolute_z = 0;
  int q_start = 0;  // offset in q
  int v_start = 0;  // offset in v
  int nq = 0, nv = 0;
  Vec3 axis = Vec3::UnitZ(), axis2 = Vec3::UnitX(), axis3 = Vec3::UnitY();  // unit, in F
};

struct Driver {
  DriverSpec spec;
  int v_index = 0;  // model-wide velocity index of the driven coordinate
  int q_index = 0;  // model-wide position index (position drivers)
};

// Constraint rows: each holonomic row has a position level Phi and a velocity row of G; velocity
// rows (speed drivers) only a row of G. Rows are ordered: loop closures, gear constraints,
// position drivers, speed drivers; holonomic rows come first, so Phi has the first n_holonomic
// rows of G.
//
// Only ModelBuilder makes a Model, and hands it out as std::shared_ptr<const Model>: a Model can
// be neither constructed nor copied elsewhere, so its data cannot be edited after Finalize() (a
// variant of a model is built anew from its description, never patched).
class Model {
 public:
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;
  Model(Model&&) = delete;
  Model& operator=(Model&&) = delete;

  // Sizes.
  int nq = 0, nv = 0;
  int nbodies = 0;         // including the world (body 0)
  int n_holonomic = 0;     // rows of Phi (loop closures + position drivers)
  int n_constraints = 0;   // rows of G (holonomic + speed drivers)

  std::vector<Body> bodies;        // index = BodyIndex
  std::vector<Frame> frames;       // index = FrameIndex; frame 0 is the world frame
  std::vector<Joint> joints;       // index = JointIndex (builder order)
  std::vector<JointIndex> tree_order;  // joints parent before child
  std::vector<LoopClosureSpec> loop_closures;
  std::vector<int> loop_row_start;  // first constraint row of each loop closure
  std::vector<int> loop_rows;       // number of rows of each loop closure
  std::vector<Driver> drivers;
  std::vector<int> driver_row;      // constraint row of each driver

  std::vector<AppliedLoadSpec> applied_loads;
  std::vector<JointLoadSpec> joint_loads;
  std::vector<int> joint_load_v_index;
  std::vector<TranslationalSpringSpec> translational_springs;
  std::vector<RotationalSpringSpec> rotational_springs;
  std::vector<CoordinateSpringSpec> coordinate_springs;
  std::vector<int> coordinate_spring_q_index, coordinate_spring_v_index;
  std::vector<BushingSpec> bushings;
  std::vector<BearingSpec> bearings;
  std::vector<GearMesh> gear_meshes;
  std::vector<GearAngle> gear_angles;  // distinct (gear, reference) pairs of gear_meshes
  bool gear_angles_by_coordinates = false;  // every gear angle is read from the coordinates
  std::vector<GearConstraint> gear_constraints;
  std::vector<int> gear_constraint_row;  // constraint row of each gear constraint (holonomic)
  std::vector<std::shared_ptr<const ExternalForceElement>> external_forces;
  std::vector<FlexibleBody> flexible_bodies;
  std::vector<Sensor> sensors;      // virtual sensors (sensor.h), in the order added
  int n_sensor_channels = 0;        // sum of the sensors' channels (Data::sensor_values)
  std::vector<int> sensor_elements; // external elements some sensor reads (indices, ascending)

  Vec3 gravity = Vec3::Zero();  // m/s^2, world axes
  Eigen::VectorXd q_initial;    // nq, from joint defaults (quaternions identity) and user values
  Eigen::VectorXd v_initial;    // nv

  // Velocity index -> joint (for coordinate names in output); -1 for modal coordinates.
  std::vector<JointIndex> joint_of_v;

  // Look-ups by name (throw std::out_of_range naming the missing name).
  BodyIndex body(const std::string& name) const;
  FrameIndex frame(const std::string& name) const;
  JointIndex joint(const std::string& name) const;
  int driver(const std::string& name) const;
  int sensor(const std::string& name) const;

  // True if any joint uses a quaternion (q-dot != v).
  bool has_quaternions = false;

 private:
  friend class ModelBuilder;
  Model() = default;
  std::unordered_map<std::string, BodyIndex> body_by_name_;
  std::unordered_map<std::string, FrameIndex> frame_by_name_;
  std::unordered_map<std::string, JointIndex> joint_by_name_;
  std::unordered_map<std::string, int> driver_by_name_;
  std::unordered_map<std::string, int> sensor_by_name_;
};

// Builds and validates a model. Every Add* validates its input and throws std::invalid_argument
// with a message naming the element and the offending value.
class ModelBuilder {
 public:
  ModelBuilder();

  // A rigid body. Its body frame is also registered as frame `name`. Requires mass > 0 and a
  // symmetric positive-definite central inertia satisfying the triangle inequality.
  BodyIndex AddBody(const std::string& name, double mass, const Vec3& com_B,
                    const Mat3& inertia_cm_B);
  // A flexible body (flexible_body.h): a body whose frame B is the reference interface of the
  // reduction, with the undeformed mass properties of `modes`, plus its modal coordinates
  // (initially zero; SetModalCoordinates changes them). Its body frame is frame `name`.
  BodyIndex AddFlexibleBody(const std::string& name, std::shared_ptr<const FlexibleBodyModes> modes,
                            const FlexibleBodyOptions& options = {});
  void SetModalCoordinates(BodyIndex body, const Eigen::VectorXd& q_f, const Eigen::VectorXd& v_f);
  // A named frame (marker) on a body.
  FrameIndex AddFrame(const std::string& name, BodyIndex body, const Transform& X_BF);
  // A frame on node `node` of a flexible body (by index into its modes' nodes), with pose X_BF
  // in the undeformed body (its origin usually at the node). It moves with the node.
  FrameIndex AddNodeFrame(const std::string& name, BodyIndex body, int node, const Transform& X_BF);
  // The index of the node with FE id (or interface master id) `id` on a flexible body.
  int FindNode(BodyIndex body, int id) const;
  FrameIndex body_frame(BodyIndex body) const { return body_frames_.at(body); }

  JointIndex AddJoint(const JointSpec& spec);
  // Initial joint coordinates (size nq of the joint; quaternions are normalized) and velocities.
  void SetJointPosition(JointIndex joint, const Eigen::VectorXd& q);
  void SetJointVelocity(JointIndex joint, const Eigen::VectorXd& v);

  void AddLoopClosure(const LoopClosureSpec& spec);
  int AddDriver(const DriverSpec& spec);

  void SetGravity(const Vec3& g) { gravity_ = g; }
  void AddAppliedLoad(const AppliedLoadSpec& spec);
  void AddJointLoad(const JointLoadSpec& spec);
  void AddTranslationalSpring(const TranslationalSpringSpec& spec);
  void AddRotationalSpring(const RotationalSpringSpec& spec);
  void AddCoordinateSpring(const CoordinateSpringSpec& spec);
  void AddBushing(const BushingSpec& spec);
  void AddBearing(const BearingSpec& spec);
  void AddGearMesh(const GearMeshSpec& spec);
  void AddGearConstraint(const GearConstraintSpec& spec);
  void AddExternalForce(std::shared_ptr<const ExternalForceElement> element);
  // A virtual sensor (sensor.h); returns its index. Validates the references (frame, joint and
  // coordinate, gear mesh, element and output), the axes and the kind's requirements; throws
  // std::invalid_argument naming the sensor and the offending value.
  int AddSensor(const SensorSpec& spec);

  int num_bodies() const { return static_cast<int>(model_->bodies.size()); }
  const Model& draft() const { return *model_; }

  // Checks the topology (every body has exactly one parent joint; no cycles), orders the tree,
  // assigns coordinates and constraint rows. The builder is consumed.
  std::shared_ptr<const Model> Finalize() &&;

 private:
  void CheckName(const std::string& kind, const std::string& name) const;
  void CheckFrame(const std::string& what, FrameIndex f) const;
  void CheckCoordinate(const std::string& what, JointIndex j, int coordinate) const;
  void FinalizeFlexibleBodies();  // modal coordinates and matrices (flexible_body.cpp)
  void FinalizeSensors();         // channels, units, initial positions (sensor_builder.cpp)
  void CheckGears(const std::string& what, FrameIndex gear_a, FrameIndex gear_b,
                  FrameIndex reference, int teeth_a, int teeth_b) const;

  std::unique_ptr<Model> model_;
  std::vector<FrameIndex> body_frames_;
  std::vector<Eigen::VectorXd> joint_q_, joint_v_;  // per joint, set values (may be empty)
  std::vector<Eigen::VectorXd> modal_q_, modal_v_;  // per flexible body (may be empty)
  Vec3 gravity_ = Vec3::Zero();
};

}  // namespace orrery

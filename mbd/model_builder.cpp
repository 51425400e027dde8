#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mbd/model.h"

#include "mbd/data.h"
#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"

namespace orrery {
namespace {

// Whether rotation R maps z to exactly +-z (its third row and column are exactly (0, 0, +-1)).
bool KeepsZExactly(const Mat3& R) {
  return R(0, 2) == 0 && R(1, 2) == 0 && R(2, 0) == 0 && R(2, 1) == 0 && std::abs(R(2, 2)) == 1;
}

// Body::turns_about_z, parents before children (tree order).
void MarkBodiesTurningAboutZ(Model& m) {
  for (const JointIndex j : m.tree_order) {
    const Joint& jt = m.joints[j];
    const bool parent_turns =
        jt.spec.parent == kWorldBody || m.bodies[jt.spec.parent].turns_about_z;
    const bool joint_turns = jt.revolute_z != 0 || jt.spec.type == JointType::kFixed;
    Body& body = m.bodies[jt.spec.child];
    body.turns_about_z = parent_turns && joint_turns && body.flexible < 0 &&
                         KeepsZExactly(jt.spec.X_PF.R) && KeepsZExactly(jt.X_MC.R);
  }
}

// Index of the gear angle (gear, reference) in model.gear_angles, added if new. Two meshes of
// the same gear and reference share one: the orientation at the start is the same configuration's.
int GearAngleIndex(Model& model, FrameIndex gear, FrameIndex reference, const Mat3& R_CG0) {
  for (size_t i = 0; i < model.gear_angles.size(); ++i)
    if (model.gear_angles[i].gear == gear && model.gear_angles[i].reference == reference) return int(i);
  model.gear_angles.push_back(GearAngle{gear, reference, R_CG0});
  return int(model.gear_angles.size()) - 1;
}

std::string Fmt(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

[[noreturn]] void Fail(const std::string& msg) { throw std::invalid_argument(msg); }

bool IsFiniteMatrix(const Eigen::MatrixXd& m) { return m.allFinite(); }

}  // namespace

template <class Map>
static auto LookUp(const Map& map, const std::string& kind, const std::string& name) {
  const auto it = map.find(name);
  if (it == map.end()) throw std::out_of_range("no " + kind + " named '" + name + "'");
  return it->second;
}

BodyIndex Model::body(const std::string& name) const { return LookUp(body_by_name_, "body", name); }
FrameIndex Model::frame(const std::string& name) const { return LookUp(frame_by_name_, "frame", name); }
JointIndex Model::joint(const std::string& name) const { return LookUp(joint_by_name_, "joint", name); }
int Model::driver(const std::string& name) const { return LookUp(driver_by_name_, "driver", name); }
int Model::sensor(const std::string& name) const { return LookUp(sensor_by_name_, "sensor", name); }

ModelBuilder::ModelBuilder() : model_(new Model()) {
  // Body 0 is the world, frame 0 its frame.
  model_->bodies.push_back(Body{"world", 0.0, Vec3::Zero(), Mat3::Zero(), -1});
  model_->body_by_name_["world"] = 0;
  model_->frames.push_back(Frame{"world", kWorldBody, Transform::Identity(), true});
  model_->frame_by_name_["world"] = 0;
  body_frames_.push_back(0);
}

void ModelBuilder::CheckName(const std::string& kind, const std::string& name) const {
  if (name.empty()) Fail(kind + " needs a name");
}

void ModelBuilder::CheckFrame(const std::string& what, FrameIndex f) const {
  if (f < 0 || f >= static_cast<int>(model_->frames.size()))
    Fail(what + ": frame index " + std::to_string(f) + " does not exist");
}

void ModelBuilder::CheckCoordinate(const std::string& what, JointIndex j, int coordinate) const {
  if (j < 0 || j >= static_cast<int>(model_->joints.size()))
    Fail(what + ": joint index " + std::to_string(j) + " does not exist");
  const Joint& joint = model_->joints[j];
  if (coordinate < 0 || coordinate >= JointNv(joint.spec.type))
    Fail(what + ": joint '" + joint.spec.name + "' (" + JointTypeName(joint.spec.type) +
         ") has no coordinate " + std::to_string(coordinate));
}

BodyIndex ModelBuilder::AddBody(const std::string& name, double mass, const Vec3& com_B,
                                const Mat3& I) {
  CheckName("body", name);
  if (model_->body_by_name_.count(name) || model_->frame_by_name_.count(name))
    Fail("body '" + name + "': name already used");
  if (!(mass > 0) || !std::isfinite(mass))
    Fail("body '" + name + "': mass must be positive, got " + std::to_string(mass));
  if (!com_B.allFinite()) Fail("body '" + name + "': centre of mass is not finite");
  if (!IsFiniteMatrix(I) || (I - I.transpose()).norm() > 1e-12 * (1 + I.norm()))
    Fail("body '" + name + "': inertia must be a finite symmetric matrix");
  // Principal moments: positive definite and triangle inequality (each <= sum of the others).
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
  const Vec3 d = eig.eigenvalues();
  if (!(d.minCoeff() > 0))
    Fail("body '" + name + "': inertia is not positive definite (principal moments " + Fmt(d) + ")");
  const double tol = 1e-9 * d.sum();
  if (d(0) + d(1) < d(2) - tol || d(0) + d(2) < d(1) - tol || d(1) + d(2) < d(0) - tol)
    Fail("body '" + name + "': principal moments " + Fmt(d) +
         " violate the triangle inequality (no real mass distribution has them)");
  const BodyIndex b = static_cast<BodyIndex>(model_->bodies.size());
  model_->bodies.push_back(Body{name, mass, com_B, I, -1});
  model_->body_by_name_[name] = b;
  const FrameIndex f = static_cast<FrameIndex>(model_->frames.size());
  model_->frames.push_back(Frame{name, b, Transform::Identity(), true});
  model_->frame_by_name_[name] = f;
  body_frames_.push_back(f);
  return b;
}

FrameIndex ModelBuilder::AddFrame(const std::string& name, BodyIndex body, const Transform& X_BF) {
  CheckName("frame", name);
  if (model_->frame_by_name_.count(name)) Fail("frame '" + name + "': name already used");
  if (body < 0 || body >= num_bodies())
    Fail("frame '" + name + "': body index " + std::to_string(body) + " does not exist");
  if (!X_BF.p.allFinite() || !X_BF.R.allFinite() ||
      (X_BF.R.transpose() * X_BF.R - Mat3::Identity()).norm() > 1e-9 || X_BF.R.determinant() < 0)
    Fail("frame '" + name + "': pose rotation is not a proper rotation matrix");
  const FrameIndex f = static_cast<FrameIndex>(model_->frames.size());
  model_->frames.push_back(Frame{name, body, X_BF, X_BF.IsIdentity()});
  model_->frame_by_name_[name] = f;
  return f;
}

JointIndex ModelBuilder::AddJoint(const JointSpec& spec) {
  CheckName("joint", spec.name);
  const std::string what = "joint '" + spec.name + "'";
  if (model_->joint_by_name_.count(spec.name)) Fail(what + ": name already used");
  if (spec.parent < 0 || spec.parent >= num_bodies())
    Fail(what + ": parent body index " + std::to_string(spec.parent) + " does not exist");
  if (spec.child <= 0 || spec.child >= num_bodies())
    Fail(what + ": child must be a body other than the world");
  if (spec.parent == spec.child) Fail(what + ": parent and child are the same body");
  if (model_->bodies[spec.child].parent_joint >= 0)
    Fail(what + ": body '" + model_->bodies[spec.child].name + "' already has parent joint '" +
         model_->joints[model_->bodies[spec.child].parent_joint].spec.name +
         "' (close loops with a loop closure)");
  Joint j;
  j.spec = spec;
  j.nq = JointNq(spec.type);
  j.nv = JointNv(spec.type);
  j.X_MC = spec.X_CM.Inverse();
  j.X_PF_is_identity = spec.X_PF.IsIdentity();
  j.X_MC_is_identity = j.X_MC.IsIdentity();
  const JointTypeInfo& info = JointInfo(spec.type);
  if (info.position == nullptr)
    Fail(what + ": a " + info.name + " is a cut joint only: close the loop with it under loop_closures");
  if (info.axes >= 1) {
    if (!spec.axis.allFinite() || spec.axis.norm() < 1e-12)
      Fail(what + ": axis " + Fmt(spec.axis) + " has zero length");
    j.axis = spec.axis.normalized();
  }
  if (info.axes >= 2) {
    if (!spec.axis2.allFinite() || spec.axis2.norm() < 1e-12)
      Fail(what + ": axis2 " + Fmt(spec.axis2) + " has zero length");
    Vec3 a2 = spec.axis2.normalized();
    if (std::abs(a2.dot(j.axis)) > 1e-6)
      Fail(what + ": axis2 " + Fmt(spec.axis2) + " must be perpendicular to axis " + Fmt(spec.axis));
    j.axis2 = a2;
    j.axis3 = j.axis.cross(a2);  // planar: in-plane y = n x x
  }
  if (spec.type == JointType::kRevolute && j.axis.x() == 0 && j.axis.y() == 0)
    j.revolute_z = j.axis.z() > 0 ? 1 : -1;  // normalized: exactly +-1
  const JointIndex index = static_cast<JointIndex>(model_->joints.size());
  model_->joints.push_back(j);
  model_->joint_by_name_[spec.name] = index;
  model_->bodies[spec.child].parent_joint = index;
  joint_q_.emplace_back();
  joint_v_.emplace_back();
  return index;
}

void ModelBuilder::SetJointPosition(JointIndex joint, const Eigen::VectorXd& q) {
  if (joint < 0 || joint >= static_cast<int>(model_->joints.size()))
    Fail("joint index " + std::to_string(joint) + " does not exist");
  const Joint& j = model_->joints[joint];
  if (q.size() != j.nq || !q.allFinite())
    Fail("joint '" + j.spec.name + "': initial position needs " + std::to_string(j.nq) +
         " finite values, got " + std::to_string(q.size()));
  joint_q_[joint] = q;
}

void ModelBuilder::SetJointVelocity(JointIndex joint, const Eigen::VectorXd& v) {
  if (joint < 0 || joint >= static_cast<int>(model_->joints.size()))
    Fail("joint index " + std::to_string(joint) + " does not exist");
  const Joint& j = model_->joints[joint];
  if (v.size() != j.nv || !v.allFinite())
    Fail("joint '" + j.spec.name + "': initial velocity needs " + std::to_string(j.nv) +
         " finite values, got " + std::to_string(v.size()));
  joint_v_[joint] = v;
}

void ModelBuilder::AddLoopClosure(const LoopClosureSpec& spec) {
  CheckName("loop closure", spec.name);
  const std::string what = "loop closure '" + spec.name + "'";
  CheckFrame(what, spec.frame_a);
  CheckFrame(what, spec.frame_b);
  if (JointInfo(spec.type).loop_rows == 0)
    Fail(what + ": a " + JointTypeName(spec.type) + " joint constrains nothing");
  if (model_->frames[spec.frame_a].body == model_->frames[spec.frame_b].body)
    Fail(what + ": both frames are on the same body");
  model_->loop_closures.push_back(spec);
}

int ModelBuilder::AddDriver(const DriverSpec& spec) {
  CheckName("driver", spec.name);
  const std::string what = "driver '" + spec.name + "'";
  if (model_->driver_by_name_.count(spec.name)) Fail(what + ": name already used");
  CheckCoordinate(what, spec.joint, spec.coordinate);
  const Joint& j = model_->joints[spec.joint];
  if (spec.mode == DriverSpec::Mode::kPosition &&
      JointInfo(j.spec.type).v_kind[spec.coordinate] == CoordinateKind::kQuaternion)
    Fail(what + ": a position driver cannot prescribe a rotation of a quaternion joint ('" +
         j.spec.name + "'); use a speed driver");
  for (const Driver& d : model_->drivers)
    if (d.spec.joint == spec.joint && d.spec.coordinate == spec.coordinate)
      Fail(what + ": coordinate already driven by '" + d.spec.name + "'");
  const int index = static_cast<int>(model_->drivers.size());
  model_->drivers.push_back(Driver{spec, 0, 0});
  model_->driver_by_name_[spec.name] = index;
  return index;
}

void ModelBuilder::AddAppliedLoad(const AppliedLoadSpec& spec) {
  CheckName("applied load", spec.name);
  CheckFrame("applied load '" + spec.name + "'", spec.frame);
  if (!spec.force.allFinite() || !spec.torque.allFinite())
    Fail("applied load '" + spec.name + "': force and torque must be finite");
  model_->applied_loads.push_back(spec);
}

void ModelBuilder::AddJointLoad(const JointLoadSpec& spec) {
  CheckName("joint load", spec.name);
  CheckCoordinate("joint load '" + spec.name + "'", spec.joint, spec.coordinate);
  model_->joint_loads.push_back(spec);
}

static void CheckSpring(const std::string& what, double k, double c) {
  if (!(k >= 0) || !std::isfinite(k)) Fail(what + ": stiffness must be >= 0, got " + std::to_string(k));
  if (!(c >= 0) || !std::isfinite(c)) Fail(what + ": damping must be >= 0, got " + std::to_string(c));
}

void ModelBuilder::AddTranslationalSpring(const TranslationalSpringSpec& spec) {
  CheckName("spring", spec.name);
  const std::string what = "translational spring '" + spec.name + "'";
  CheckFrame(what, spec.frame_a);
  CheckFrame(what, spec.frame_b);
  CheckSpring(what, spec.stiffness, spec.damping);
  if (!(spec.free_length >= 0)) Fail(what + ": free length must be >= 0");
  model_->translational_springs.push_back(spec);
}

void ModelBuilder::AddRotationalSpring(const RotationalSpringSpec& spec) {
  CheckName("spring", spec.name);
  const std::string what = "rotational spring '" + spec.name + "'";
  CheckFrame(what, spec.frame_a);
  CheckFrame(what, spec.frame_b);
  CheckSpring(what, spec.stiffness, spec.damping);
  model_->rotational_springs.push_back(spec);
}

void ModelBuilder::AddCoordinateSpring(const CoordinateSpringSpec& spec) {
  CheckName("spring", spec.name);
  const std::string what = "coordinate spring '" + spec.name + "'";
  CheckCoordinate(what, spec.joint, spec.coordinate);
  CheckSpring(what, spec.stiffness, spec.damping);
  const Joint& j = model_->joints[spec.joint];
  if (JointInfo(j.spec.type).v_kind[spec.coordinate] == CoordinateKind::kQuaternion)
    Fail(what + ": quaternion coordinates take a bushing, not a coordinate spring");
  model_->coordinate_springs.push_back(spec);
}

void ModelBuilder::AddBushing(const BushingSpec& spec) {
  CheckName("bushing", spec.name);
  const std::string what = "bushing '" + spec.name + "'";
  CheckFrame(what, spec.frame_a);
  CheckFrame(what, spec.frame_b);
  if (!spec.stiffness.allFinite() || !spec.damping.allFinite()) Fail(what + ": matrices must be finite");
  // Stiffness and damping must not generate energy: symmetric parts positive semi-definite.
  for (const auto& [label, m] : {std::pair<const char*, const Mat6*>{"stiffness", &spec.stiffness},
                                 {"damping", &spec.damping}}) {
    const Mat6 sym = 0.5 * (*m + m->transpose());
    const double lo = Eigen::SelfAdjointEigenSolver<Mat6>(sym).eigenvalues().minCoeff();
    if (lo < -1e-12 * (1 + sym.norm()))
      Fail(what + ": " + label + " matrix has a negative eigenvalue (" + std::to_string(lo) + ")");
  }
  model_->bushings.push_back(spec);
}

void ModelBuilder::AddBearing(const BearingSpec& spec) {
  CheckName("bearing", spec.name);
  const std::string what = "bearing '" + spec.name + "'";
  CheckFrame(what, spec.frame_a);
  CheckFrame(what, spec.frame_b);
  CheckSpring(what + " (radial)", spec.radial_stiffness, spec.radial_damping);
  CheckSpring(what + " (axial)", spec.axial_stiffness, spec.axial_damping);
  CheckSpring(what + " (tilt)", spec.tilt_stiffness, spec.tilt_damping);
  model_->bearings.push_back(spec);
}

void ModelBuilder::CheckGears(const std::string& what, FrameIndex gear_a, FrameIndex gear_b,
                              FrameIndex reference, int teeth_a, int teeth_b) const {
  CheckFrame(what, gear_a);
  CheckFrame(what, gear_b);
  CheckFrame(what, reference);
  if (model_->frames[gear_a].body == model_->frames[gear_b].body)
    Fail(what + ": both gears are on the same body");
  if (teeth_a < 1 || teeth_b < 1) Fail(what + ": tooth counts must be >= 1");
}

void ModelBuilder::AddGearMesh(const GearMeshSpec& spec) {
  CheckName("gear mesh", spec.name);
  const std::string what = "gear mesh '" + spec.name + "'";
  CheckGears(what, spec.gear_a, spec.gear_b, spec.reference, spec.teeth_a, spec.teeth_b);
  if (!(spec.backlash >= 0)) Fail(what + ": backlash must be >= 0, got " + std::to_string(spec.backlash));
  CheckSpring(what, spec.stiffness, spec.damping);
  if (!(spec.damping_ratio >= 0)) Fail(what + ": damping ratio must be >= 0");
  if (spec.damping > 0 && spec.damping_ratio > 0) Fail(what + ": give a damping coefficient or a ratio, not both");
  for (double k : spec.stiffness_table)
    if (!(k >= 0) || !std::isfinite(k)) Fail(what + ": stiffness table values must be >= 0");
  if (spec.stiffness_table.empty() && !(spec.stiffness > 0)) Fail(what + ": stiffness must be > 0");
  if (spec.table_cycles < 1) Fail(what + ": table_cycles must be >= 1");
  if (spec.ste_phases.size() > spec.ste_amplitudes.size())
    Fail(what + ": more transmission-error phases than amplitudes");
  for (double e : spec.ste_table_m)
    if (!std::isfinite(e)) Fail(what + ": transmission-error table values must be finite");
  if (spec.ste_table_cycles < 1) Fail(what + ": ste_table_cycles must be >= 1");
  GearMesh mesh;
  mesh.spec = spec;
  model_->gear_meshes.push_back(mesh);
}

void ModelBuilder::AddGearConstraint(const GearConstraintSpec& spec) {
  CheckName("gear constraint", spec.name);
  const std::string what = "gear constraint '" + spec.name + "'";
  CheckGears(what, spec.gear_a, spec.gear_b, spec.reference, spec.teeth_a, spec.teeth_b);
  GearConstraint c;
  c.spec = spec;
  model_->gear_constraints.push_back(c);
}

// Moment of inertia of a frame's body about the frame's z axis (infinite for the world).
static double InertiaAboutAxis(const Model& m, FrameIndex f) {
  const Frame& frame = m.frames[f];
  if (frame.body == kWorldBody) return std::numeric_limits<double>::infinity();
  const Body& b = m.bodies[frame.body];
  const Vec3 z = frame.X_BF.R.col(2);
  Vec3 r = b.com_B - frame.X_BF.p;
  r -= r.dot(z) * z;
  return z.dot(b.inertia_cm_B * z) + b.mass * r.squaredNorm();
}

std::shared_ptr<const Model> ModelBuilder::Finalize() && {
  Model& m = *model_;
  m.nbodies = static_cast<int>(m.bodies.size());
  m.gravity = gravity_;
  // Every body but the world needs a parent joint.
  for (BodyIndex b = 1; b < m.nbodies; ++b)
    if (m.bodies[b].parent_joint < 0)
      Fail("body '" + m.bodies[b].name +
           "' has no joint to a parent; give a floating body a free joint to the world");
  // Tree order: repeatedly take joints whose parent is placed (the world first). A joint never
  // placed sits on a cycle of tree joints.
  std::vector<char> placed(m.nbodies, 0);
  placed[kWorldBody] = 1;
  m.tree_order.clear();
  for (bool progress = true; progress;) {
    progress = false;
    for (JointIndex j = 0; j < static_cast<int>(m.joints.size()); ++j) {
      const Joint& jt = m.joints[j];
      if (!placed[jt.spec.child] && placed[jt.spec.parent]) {
        placed[jt.spec.child] = 1;
        m.tree_order.push_back(j);
        progress = true;
      }
    }
  }
  if (m.tree_order.size() != m.joints.size())
    for (const Joint& jt : m.joints)
      if (!placed[jt.spec.child])
        Fail("joint '" + jt.spec.name + "' is part of a cycle of tree joints not connected to the "
             "world; cut the loop with a loop closure");
  // Coordinates in tree order.
  m.nq = m.nv = 0;
  for (JointIndex j : m.tree_order) {
    Joint& jt = m.joints[j];
    jt.q_start = m.nq;
    jt.v_start = m.nv;
    m.nq += jt.nq;
    m.nv += jt.nv;
    if (JointInfo(jt.spec.type).quaternion >= 0) m.has_quaternions = true;
  }
  FinalizeFlexibleBodies();
  MarkBodiesTurningAboutZ(m);
  m.joint_of_v.assign(m.nv, -1);
  for (JointIndex j = 0; j < static_cast<int>(m.joints.size()); ++j)
    for (int k = 0; k < m.joints[j].nv; ++k) m.joint_of_v[m.joints[j].v_start + k] = j;
  // Initial state.
  m.q_initial = Eigen::VectorXd::Zero(m.nq);
  m.v_initial = Eigen::VectorXd::Zero(m.nv);
  for (JointIndex j = 0; j < static_cast<int>(m.joints.size()); ++j) {
    const Joint& jt = m.joints[j];
    const int quat = JointInfo(jt.spec.type).quaternion;
    if (quat >= 0) m.q_initial(jt.q_start + quat) = 1.0;  // identity rotation
    if (joint_q_[j].size()) {
      m.q_initial.segment(jt.q_start, jt.nq) = joint_q_[j];
      if (quat >= 0) {
        auto qs = m.q_initial.segment<4>(jt.q_start + quat);
        if (qs.norm() < 1e-12) Fail("joint '" + jt.spec.name + "': initial quaternion is zero");
        qs.normalize();
      }
    }
    if (joint_v_[j].size()) m.v_initial.segment(jt.v_start, jt.nv) = joint_v_[j];
  }
  for (size_t i = 0; i < m.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = m.flexible_bodies[i];
    if (modal_q_[i].size() && fb.nf > 0) {
      m.q_initial.segment(fb.q_start, fb.nf) = modal_q_[i].head(fb.nf);
      m.v_initial.segment(fb.v_start, fb.nf) = modal_v_[i].head(fb.nf);
    }
  }
  // Constraint rows: loop closures, gear constraints, position drivers (holonomic), then speed
  // drivers.
  int row = 0;
  m.loop_row_start.clear();
  m.loop_rows.clear();
  for (const LoopClosureSpec& lc : m.loop_closures) {
    m.loop_row_start.push_back(row);
    m.loop_rows.push_back(JointInfo(lc.type).loop_rows);
    row += m.loop_rows.back();
  }
  m.gear_constraint_row.clear();
  for (size_t k = 0; k < m.gear_constraints.size(); ++k) m.gear_constraint_row.push_back(row++);
  m.driver_row.assign(m.drivers.size(), -1);
  for (size_t d = 0; d < m.drivers.size(); ++d) {
    Driver& dr = m.drivers[d];
    const Joint& jt = m.joints[dr.spec.joint];
    dr.v_index = jt.v_start + dr.spec.coordinate;
    dr.q_index = jt.q_start + dr.spec.coordinate;
    if (dr.spec.mode == DriverSpec::Mode::kPosition) m.driver_row[d] = row++;
  }
  m.n_holonomic = row;
  for (size_t d = 0; d < m.drivers.size(); ++d)
    if (m.drivers[d].spec.mode == DriverSpec::Mode::kSpeed) m.driver_row[d] = row++;
  m.n_constraints = row;
  if (m.n_constraints > m.nv)
    Fail("the model has " + std::to_string(m.n_constraints) + " constraint rows but only " +
         std::to_string(m.nv) + " degrees of freedom: it is over-constrained");
  // Force-element indices.
  m.joint_load_v_index.clear();
  for (const JointLoadSpec& l : m.joint_loads)
    m.joint_load_v_index.push_back(m.joints[l.joint].v_start + l.coordinate);
  m.coordinate_spring_q_index.clear();
  m.coordinate_spring_v_index.clear();
  for (const CoordinateSpringSpec& s : m.coordinate_springs) {
    m.coordinate_spring_q_index.push_back(m.joints[s.joint].q_start + s.coordinate);
    m.coordinate_spring_v_index.push_back(m.joints[s.joint].v_start + s.coordinate);
  }
  // Gear meshes: line-of-action geometry at the initial configuration, resolved damping.
  if (!m.gear_meshes.empty() || !m.gear_constraints.empty()) {
    Data data(m);
    CalcPositionKinematics(m, m.q_initial, data);
    for (GearMesh& mesh : m.gear_meshes) {
      const GearMeshSpec& s = mesh.spec;
      const std::string what = "gear mesh '" + s.name + "'";
      mesh.geometry = ComputeMeshGeometry(what, data, s.gear_a, s.gear_b, s.reference, s.base_radius_a,
                                          s.base_radius_b, s.working_pressure_angle,
                                          s.base_helix_angle, s.internal_b, s.teeth_a,
                                          s.check_centre_distance);
      if (s.teeth_a > 1 && s.teeth_b > 1 &&
          std::abs(s.base_radius_b / s.base_radius_a - double(s.teeth_b) / s.teeth_a) >
              1e-6 * double(s.teeth_b) / s.teeth_a)
        Fail(what + ": base radius ratio " + std::to_string(s.base_radius_b / s.base_radius_a) +
             " differs from the tooth ratio " + std::to_string(double(s.teeth_b) / s.teeth_a));
      if (s.backlash >= mesh.geometry.base_pitch)
        Fail(what + ": backlash " + std::to_string(s.backlash) + " m is not below the base pitch " +
             std::to_string(mesh.geometry.base_pitch) + " m");
      mesh.small_rotations_only = s.teeth_a <= 1 || s.teeth_b <= 1;
      mesh.angle_a = GearAngleIndex(m, s.gear_a, s.reference, mesh.geometry.R_CA0);
      mesh.angle_b = GearAngleIndex(m, s.gear_b, s.reference, mesh.geometry.R_CB0);
      for (size_t k = 0; k < s.ste_amplitudes.size(); ++k) {
        const double phase = k < s.ste_phases.size() ? s.ste_phases[k] : 0.0;
        mesh.ste_phase_cos.push_back(std::cos(phase));
        mesh.ste_phase_sin.push_back(std::sin(phase));
      }
      mesh.k_mean = s.stiffness;
      if (!s.stiffness_table.empty()) {
        mesh.k_mean = 0;
        for (double k : s.stiffness_table) mesh.k_mean += k / s.stiffness_table.size();
      }
      mesh.c = s.damping;
      if (s.damping_ratio > 0) {
        const double inv_m = s.base_radius_a * s.base_radius_a / InertiaAboutAxis(m, s.gear_a) +
                             s.base_radius_b * s.base_radius_b / InertiaAboutAxis(m, s.gear_b);
        if (!(inv_m > 0)) Fail(what + ": a damping ratio needs at least one gear that can turn");
        mesh.c = 2 * s.damping_ratio * std::sqrt(mesh.k_mean / inv_m);
      }
    }
    // Gear angles read from the joint coordinates where the tree allows (GearAngle, model.h).
    m.gear_angles_by_coordinates = true;
    for (GearAngle& a : m.gear_angles) {
      a.by_coordinates = FindGearAngleTerms(m, a.gear, a.reference, &a.terms);
      m.gear_angles_by_coordinates = m.gear_angles_by_coordinates && a.by_coordinates;
    }
    for (GearConstraint& gc : m.gear_constraints) {
      const GearConstraintSpec& s = gc.spec;
      gc.geometry = ComputeMeshGeometry("gear constraint '" + s.name + "'", data, s.gear_a, s.gear_b,
                                        s.reference, s.base_radius_a, s.base_radius_b,
                                        s.working_pressure_angle, s.base_helix_angle, s.internal_b, s.teeth_a,
                                        s.check_centre_distance);
    }
  }
  FinalizeSensors();
  return std::shared_ptr<const Model>(std::move(model_));
}

}  // namespace orrery

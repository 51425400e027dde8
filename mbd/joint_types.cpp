#include "mbd/joint_types.h"

#include "mbd/model.h"

namespace orrery {
namespace {

using Kind = CoordinateKind;
using Term = LoopTerm;
constexpr int kX = 0, kY = 1, kZ = 2;

constexpr Term Point() { return {Term::Kind::kPoint, 0, 0}; }
constexpr Term Perpendicular(int axis_a, int axis_b) {
  return {Term::Kind::kPerpendicular, axis_a, axis_b};
}
constexpr Term Distance(int axis_a) { return {Term::Kind::kDistance, axis_a, 0}; }

// Spatial motion (angular w, linear v) as one 6-vector.
Vec6 Motion(const Vec3& w, const Vec3& v) {
  Vec6 m;
  m << w, v;
  return m;
}

// Unit quaternion (w, x, y, z) stored at q to a rotation matrix.
Mat3 QuatToRotation(const double* q) { return Quat(q[0], q[1], q[2], q[3]).toRotationMatrix(); }

// --- fixed: no coordinates; M stays on F -----------------------------------------------------
void FixedPosition(const Joint&, const double*, Transform& X_FM, Vec6*) {
  X_FM = Transform::Identity();
}

// --- revolute: angle about `axis` --------------------------------------------------------------
void RevolutePosition(const Joint& j, const double* q, Transform& X_FM, Vec6* S_F) {
  X_FM = Transform(AxisAngle(j.axis, q[0]), Vec3::Zero());
  S_F[0] = Motion(j.axis, Vec3::Zero());
}

// --- prismatic: slide along `axis` -------------------------------------------------------------
void PrismaticPosition(const Joint& j, const double* q, Transform& X_FM, Vec6* S_F) {
  X_FM = Transform(Mat3::Identity(), j.axis * q[0]);
  S_F[0] = Motion(Vec3::Zero(), j.axis);
}

// --- cylindrical: (angle, slide) about and along `axis` -----------------------------------------
void CylindricalPosition(const Joint& j, const double* q, Transform& X_FM, Vec6* S_F) {
  X_FM = Transform(AxisAngle(j.axis, q[0]), j.axis * q[1]);
  S_F[0] = Motion(j.axis, Vec3::Zero());
  S_F[1] = Motion(Vec3::Zero(), j.axis);
}

// --- universal: angle about `axis`, then about `axis2` turned by the first angle ---------------
void UniversalPosition(const Joint& j, const double* q, Transform& X_FM, Vec6* S_F) {
  const Mat3 R1 = AxisAngle(j.axis, q[0]);
  X_FM = Transform(R1 * AxisAngle(j.axis2, q[1]), Vec3::Zero());
  S_F[0] = Motion(j.axis, Vec3::Zero());
  S_F[1] = Motion(R1 * j.axis2, Vec3::Zero());
}

// The second axis turns with the first angle: d(R1 a2)/dt v2 = v1 v2 (a1 x R1 a2).
Vec6 UniversalVelocityProduct(const Joint& j, const double* q, const double* v) {
  const Vec3 a2 = AxisAngle(j.axis, q[0]) * j.axis2;
  return Motion(v[0] * v[1] * j.axis.cross(a2), Vec3::Zero());
}

// --- spherical: unit quaternion of R_FM; v = angular velocity in F -----------------------------
void SphericalPosition(const Joint&, const double* q, Transform& X_FM, Vec6* S_F) {
  X_FM = Transform(QuatToRotation(q), Vec3::Zero());
  for (int k = 0; k < 3; ++k) S_F[k] = Motion(Vec3::Unit(k), Vec3::Zero());
}

// --- planar: (x, y, angle) in the plane normal to `axis`, x along `axis2` ----------------------
// The rotation column moves F's origin point of M: its linear part is p x axis.
void PlanarPosition(const Joint& j, const double* q, Transform& X_FM, Vec6* S_F) {
  const Vec3 p = j.axis2 * q[0] + j.axis3 * q[1];
  X_FM = Transform(AxisAngle(j.axis, q[2]), p);
  S_F[0] = Motion(Vec3::Zero(), j.axis2);
  S_F[1] = Motion(Vec3::Zero(), j.axis3);
  S_F[2] = Motion(j.axis, p.cross(j.axis));
}

// d(p x axis)/dt v_angle = v_angle (p-dot x axis).
Vec6 PlanarVelocityProduct(const Joint& j, const double*, const double* v) {
  const Vec3 pdot = j.axis2 * v[0] + j.axis3 * v[1];
  return Motion(Vec3::Zero(), v[2] * pdot.cross(j.axis));
}

// --- free: (x, y, z, quaternion); v = (translational velocity in F, angular velocity in F) -----
void FreePosition(const Joint&, const double* q, Transform& X_FM, Vec6* S_F) {
  const Vec3 p(q[0], q[1], q[2]);
  X_FM = Transform(QuatToRotation(q + 3), p);
  for (int k = 0; k < 3; ++k) {
    S_F[k] = Motion(Vec3::Zero(), Vec3::Unit(k));
    S_F[3 + k] = Motion(Vec3::Unit(k), p.cross(Vec3::Unit(k)));
  }
}

// d(p x e_k)/dt w_k summed: p-dot x w.
Vec6 FreeVelocityProduct(const Joint&, const double*, const double* v) {
  const Vec3 pdot(v[0], v[1], v[2]), w(v[3], v[4], v[5]);
  return Motion(Vec3::Zero(), pdot.cross(w));
}

// Rows a list of loop terms makes.
constexpr int RowsOf(const JointTypeInfo& info) {
  int rows = 0;
  for (int k = 0; k < info.n_loop_terms; ++k)
    rows += info.loop_terms[k].kind == Term::Kind::kPoint ? 3 : 1;
  return rows;
}

constexpr JointTypeInfo WithRows(JointTypeInfo info) {
  info.loop_rows = RowsOf(info);
  return info;
}

constexpr Kind A = Kind::kAngle, L = Kind::kLength, Q = Kind::kQuaternion;

// The table, in enum order (one entry per type, laid out by hand).
// clang-format off
constexpr std::array<JointTypeInfo, 9> kJointTypes{{
    WithRows({.type = JointType::kFixed, .name = "fixed", .nq = 0, .nv = 0,
              .n_loop_terms = 4,
              .loop_terms = {Point(), Perpendicular(kX, kY), Perpendicular(kY, kZ),
                             Perpendicular(kZ, kX)},
              .position = FixedPosition}),
    WithRows({.type = JointType::kRevolute, .name = "revolute", .nq = 1, .nv = 1, .axes = 1,
              .q_kind = {A}, .v_kind = {A}, .q_names = {"angle"}, .v_names = {"angle"},
              .n_loop_terms = 3,
              .loop_terms = {Point(), Perpendicular(kX, kZ), Perpendicular(kY, kZ)},
              .position = RevolutePosition}),
    WithRows({.type = JointType::kPrismatic, .name = "prismatic", .nq = 1, .nv = 1, .axes = 1,
              .q_kind = {L}, .v_kind = {L}, .q_names = {"slide"}, .v_names = {"slide"},
              .n_loop_terms = 5,
              .loop_terms = {Perpendicular(kX, kY), Perpendicular(kY, kZ), Perpendicular(kZ, kX),
                             Distance(kX), Distance(kY)},
              .position = PrismaticPosition}),
    WithRows({.type = JointType::kCylindrical, .name = "cylindrical", .nq = 2, .nv = 2,
              .axes = 1, .q_kind = {A, L}, .v_kind = {A, L}, .q_names = {"angle", "slide"},
              .v_names = {"angle", "slide"}, .n_loop_terms = 4,
              .loop_terms = {Perpendicular(kX, kZ), Perpendicular(kY, kZ), Distance(kX),
                             Distance(kY)},
              .position = CylindricalPosition}),
    WithRows({.type = JointType::kUniversal, .name = "universal", .nq = 2, .nv = 2, .axes = 2,
              .q_kind = {A, A}, .v_kind = {A, A}, .q_names = {"angle1", "angle2"},
              .v_names = {"angle1", "angle2"}, .n_loop_terms = 2,
              .loop_terms = {Point(), Perpendicular(kX, kY)},
              .position = UniversalPosition, .velocity_product = UniversalVelocityProduct}),
    WithRows({.type = JointType::kSpherical, .name = "spherical", .nq = 4, .nv = 3,
              .quaternion = 0, .q_kind = {Q, Q, Q, Q}, .v_kind = {Q, Q, Q},
              .q_names = {"qw", "qx", "qy", "qz"}, .v_names = {"wx", "wy", "wz"},
              .n_loop_terms = 1, .loop_terms = {Point()}, .position = SphericalPosition}),
    WithRows({.type = JointType::kPlanar, .name = "planar", .nq = 3, .nv = 3, .axes = 2,
              .q_kind = {L, L, A}, .v_kind = {L, L, A}, .q_names = {"x", "y", "angle"},
              .v_names = {"x", "y", "angle"}, .n_loop_terms = 3,
              .loop_terms = {Perpendicular(kZ, kX), Perpendicular(kZ, kY), Distance(kZ)},
              .position = PlanarPosition, .velocity_product = PlanarVelocityProduct}),
    WithRows({.type = JointType::kFree, .name = "free", .nq = 7, .nv = 6, .quaternion = 3,
              .q_kind = {L, L, L, Q, Q, Q, Q}, .v_kind = {L, L, L, Q, Q, Q},
              .q_names = {"x", "y", "z", "qw", "qx", "qy", "qz"},
              .v_names = {"x", "y", "z", "wx", "wy", "wz"},
              .position = FreePosition, .velocity_product = FreeVelocityProduct}),
    // A pin in a plane, as a loop closure only: B's origin on A's z axis (two rows), everything
    // else free. It closes a planar loop of revolute joints with the two rows the plane leaves
    // (a revolute cut there has 5 rows of which 3 repeat the plane, a spherical cut 3 of which 1).
    WithRows({.type = JointType::kPlanarPin, .name = "planar_pin", .nq = 0, .nv = 0,
              .n_loop_terms = 2, .loop_terms = {Distance(kX), Distance(kY)}}),
}};
// clang-format on

// The table is indexed by the enum: each entry must sit at its own type's place.
constexpr bool TableInEnumOrder() {
  for (size_t k = 0; k < kJointTypes.size(); ++k)
    if (static_cast<size_t>(kJointTypes[k].type) != k) return false;
  return true;
}
static_assert(TableInEnumOrder(), "kJointTypes must list the joint types in enum order");

const char* UnitOf(CoordinateKind kind, bool rate) {
  switch (kind) {
    case Kind::kAngle: return rate ? "rad/s" : "rad";
    case Kind::kLength: return rate ? "m/s" : "m";
    case Kind::kQuaternion: return rate ? "rad/s" : "1";
  }
  return "1";
}

}  // namespace

const JointTypeInfo& JointInfo(JointType type) { return kJointTypes[static_cast<size_t>(type)]; }

std::span<const JointTypeInfo> AllJointTypes() { return kJointTypes; }

bool JointTypeFromName(std::string_view name, JointType* type) {
  for (const JointTypeInfo& info : kJointTypes)
    if (name == info.name) {
      *type = info.type;
      return true;
    }
  return false;
}

std::string JointCoordinateUnits(JointType type, bool rate) {
  const JointTypeInfo& info = JointInfo(type);
  const int n = rate ? info.nv : info.nq;
  const auto& kinds =
      rate ? std::span<const Kind>(info.v_kind) : std::span<const Kind>(info.q_kind);
  bool shared = true;
  for (int k = 1; k < n; ++k)
    shared = shared && UnitOf(kinds[k], rate) == std::string_view(UnitOf(kinds[0], rate));
  if (n == 0) return "1";
  if (shared) return UnitOf(kinds[0], rate);
  std::string units;
  for (int k = 0; k < n; ++k) units += std::string(k ? ", " : "") + UnitOf(kinds[k], rate);
  return units;
}

}  // namespace orrery

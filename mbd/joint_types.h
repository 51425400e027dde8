#pragma once
// Joint types: everything one kind of joint knows, in one table entry (Drake's mobilizer habit).
// Each entry holds the joint's sizes, where its unit quaternion sits, what each coordinate is
// (angle, length, quaternion: units in output and scene files), the rows it contributes as a
// loop closure, and its motion math: the joint transform X_FM(q), the motion subspace S_F(q) and
// the velocity-product term dS_F/dt v. Algorithms look a type up once per joint
// (`JointInfo(type)`) and call through the entry; adding a type means adding one entry in
// joint_types.cpp, not a case in every stage.
//
// Math (Featherstone, "Rigid Body Dynamics Algorithms", 2008, ch. 4; seed 003 eq. 3): the child's
// frame M moves relative to the parent's frame F by X_FM(q); its spatial velocity relative to F,
// about F's origin in F axes, is S_F(q) v (columns: angular over linear); its time derivative
// adds dS_F/dt v to the velocity-product acceleration. Quaternion blocks (spherical, free) have
// q-dot = N(q) v = 1/2 (0, w_F) x q (kinematics.h CalcQDot); their velocity variables are the
// angular velocity in F.
//
// Usage:
//   const JointTypeInfo& info = JointInfo(JointType::kPlanar);   // info.nq == 3, info.nv == 3
//   info.position(joint, q.data() + joint.q_start, X_FM, S_F);  // S_F: info.nv columns
#include <array>
#include <span>
#include <string>
#include <string_view>

#include "mbd/spatial.h"

namespace orrery {

struct Joint;

enum class JointType {
  kFixed,
  kRevolute,
  kPrismatic,
  kCylindrical,
  kUniversal,
  kSpherical,
  kPlanar,
  kFree,
  kPlanarPin  // a cut joint only (loop closures): no coordinates of its own
};

// What a coordinate is. For velocity coordinates kQuaternion marks a component of the angular
// velocity of a quaternion block (an angle rate with no integrable angle of its own).
enum class CoordinateKind : char { kAngle, kLength, kQuaternion };

// One term of a loop closure's rows, frames A and B with unit axes x, y, z (index 0, 1, 2):
//   kPoint: p_B - p_A = 0 (3 rows, world axes);  kPerpendicular: a_A . b_B = 0 (1 row);
//   kDistance: (p_B - p_A) . a_A = 0 (1 row).  Terms are emitted in table order.
struct LoopTerm {
  enum class Kind : char { kPoint, kPerpendicular, kDistance } kind = Kind::kPoint;
  int axis_a = 0, axis_b = 0;
};

// X_FM(q) and the nv columns of S_F(q) (motion subspace about F's origin, F axes). `q` points at
// the joint's first position coordinate; `S_F` holds at least nv entries.
using JointPositionFn = void (*)(const Joint& joint, const double* q, Transform& X_FM, Vec6* S_F);
// dS_F/dt v in F axes (angular over linear), from the joint's q and v.
using JointVelocityProductFn = Vec6 (*)(const Joint& joint, const double* q, const double* v);

struct JointTypeInfo {
  JointType type;
  const char* name;     // scene-file and output spelling ("revolute")
  int nq = 0, nv = 0;   // position and velocity coordinates
  int quaternion = -1;  // offset of the unit quaternion (w, x, y, z) in q and of its
                        //   angular velocity in v; -1 without one
  int axes = 0;         // 0: no axis; 1: `axis`; 2: `axis` and a perpendicular `axis2`
  std::array<CoordinateKind, 7> q_kind{};  // first nq entries
  std::array<CoordinateKind, 6> v_kind{};  // first nv entries
  std::array<const char*, 7> q_names{};    // column names of the q series in result files
  std::array<const char*, 6> v_names{};    // and of the v series
  // As a loop closure (LoopClosureSpec): its terms and the constraint rows they make.
  int n_loop_terms = 0;
  std::array<LoopTerm, 5> loop_terms{};
  int loop_rows = 0;
  JointPositionFn position = nullptr;  // nullptr: a cut-joint type only (no tree joint)
  JointVelocityProductFn velocity_product = nullptr;  // nullptr: S_F is constant in F
};

// The entry of a type (a table look-up).
const JointTypeInfo& JointInfo(JointType type);
// Every type, in enum order.
std::span<const JointTypeInfo> AllJointTypes();
// The type spelled `name` ("revolute"); false if no type is.
bool JointTypeFromName(std::string_view name, JointType* type);
// Units of the q (rate == false) or v series of a type: one unit when all coordinates share it
// ("rad"), else one per coordinate ("m, m, rad"); "1" without coordinates.
std::string JointCoordinateUnits(JointType type, bool rate);

inline const char* JointTypeName(JointType type) { return JointInfo(type).name; }
inline int JointNq(JointType type) { return JointInfo(type).nq; }  // position coordinates
inline int JointNv(JointType type) { return JointInfo(type).nv; }  // velocity coordinates

}  // namespace orrery

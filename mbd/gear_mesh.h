#pragma once
// Line-of-action kinematics of a gear mesh (GearMeshSpec, GearConstraintSpec in model.h): the
// geometry taken at the initial configuration, and the deflections at the current one.
#include <string>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Line-of-action geometry of a mesh in its reference frame from the frame poses in `data`
// (position kinematics at the initial configuration). Throws std::invalid_argument naming `what`
// if a gear axis is not parallel to the reference z axis or the centre distance disagrees with
// the base radii and working pressure angle.
MeshGeometry ComputeMeshGeometry(const std::string& what, const Data& data, FrameIndex gear_a,
                                 FrameIndex gear_b, FrameIndex reference, double base_radius_a,
                                 double base_radius_b, double working_pressure_angle,
                                 double base_helix_angle, bool internal_b, int teeth_a,
                                 bool check_centre_distance);

// Deflections of a mesh at the configuration in `data` (needs position kinematics; velocities
// need velocity kinematics).
struct MeshState {
  double e = 0;             // rotational transmission coordinate, wrapped to one base pitch (m)
  double delta_drive = 0;   // drive-flank compression (m)
  double delta_coast = 0;   // coast-flank compression (m), backlash included
  double theta_a = 0, theta_b = 0;  // gear angles relative to C since the start (rad)
  Vec3 p_a_W = Vec3::Zero(), p_b_W = Vec3::Zero();  // lever points on a and b (world): both the
                                                    // pitch point for consistent geometry
  Vec3 n_drive_W = Vec3::Zero(), n_coast_W = Vec3::Zero();  // contact normals (helix included)
  // Spin of the reference frame: the deflections use angles relative to it, so their rates have
  // the term -w_C.z * k_spin(n) with k_spin(n) = cos(beta_b) (r_ba + sigma r_bb) + z.((c_a - c_b) x n),
  // which vanishes for consistent geometry and undisplaced centres (the mesh's reaction moment
  // on the reference body).
  Vec3 z_W = Vec3::UnitZ();         // reference frame's z axis, world
  Vec3 dc_W = Vec3::Zero();         // centre of a minus centre of b, world
  double k_spin_base = 0;           // cos(beta_b) (r_ba + sigma r_bb)
  double KSpin(const Vec3& n_W) const { return k_spin_base + z_W.dot(dc_W.cross(n_W)); }
};
MeshState CalcMeshState(const MeshGeometry& g, const Data& data, FrameIndex gear_a,
                        FrameIndex gear_b, FrameIndex reference, double base_radius_a,
                        double base_radius_b, double backlash);
// The same with the gear angles given (theta_a, theta_b: GearSpinAngle of a and b, as
// CalcGearAngles leaves them in data.gear_angle).
MeshState CalcMeshState(const MeshGeometry& g, const Data& data, FrameIndex gear_a,
                        FrameIndex gear_b, FrameIndex reference, double base_radius_a,
                        double base_radius_b, double backlash, double theta_a, double theta_b);

// The rotational transmission coordinate e = r_ba theta_a + sigma r_bb theta_b wrapped to one
// base pitch around the middle of the backlash (MeshState::e), from the gear angles alone.
double MeshTransmissionCoordinate(const MeshGeometry& g, double base_radius_a, double base_radius_b,
                                  double backlash, double theta_a, double theta_b);

// Angle (rad) of gear frame `gear` about the z axis of frame `reference` since the start, when
// its orientation in the reference frame was R_CG0 (needs position kinematics in `data`): the
// general path, atan2 of the relative rotation, in [-pi, pi].
double GearSpinAngle(const Data& data, FrameIndex gear, FrameIndex reference, const Mat3& R_CG0);

// For ModelBuilder::Finalize (model with coordinates assigned and q_initial set): whether the
// angle of frame `gear` about frame `reference`'s z axis is a sum of joint coordinates
// (GearAngle::by_coordinates, model.h), and if so its terms. Joint axes and the z columns of the
// fixed rotations must be +-z within 1e-9 per component: a tilt eps moves the general path's
// angle by O(eps^2) only (the first-order terms of atan2(R_10, R_00) vanish for tilts about
// in-plane axes), so the two agree to rounding.
bool FindGearAngleTerms(const Model& model, FrameIndex gear, FrameIndex reference,
                        std::vector<GearAngleTerm>* terms);

// A by_coordinates gear angle from positions q (nq): sum_k sign_k (q_k - q0_k), wrapped to
// [-pi, pi] (an angle already within it is returned unchanged).
double GearAngleFromCoordinates(const GearAngle& angle, const double* q);

// Model::gear_angles entry `i` at the configuration in `data`: from data.q_normalized when it is
// by_coordinates, else GearSpinAngle (needs position kinematics).
double GearAngleAt(const Model& model, const Data& data, int i);

// data.gear_angle: every Model::gear_angles entry's angle (GearAngleAt), once per evaluation for
// all the meshes that share it (needs position kinematics). CalcForceElements calls it.
void CalcGearAngles(const Model& model, Data& data);

// Rate of the drive-flank compression for n_W = n_drive_W (of minus the coast-flank one for
// n_coast_W): velocity of gear a's material point at its lever point relative to gear b's at its
// own, along n_W, minus the reference frame's spin times s.KSpin(n_W).
double CalcMeshRate(const Model& model, const Data& data, FrameIndex gear_a, FrameIndex gear_b,
                    FrameIndex reference, const MeshState& s, const Vec3& n_W);

// Mesh stiffness at mesh phase psi (cycles) from the spec's table (or its constant).
double MeshStiffness(const GearMeshSpec& spec, double psi);

// Static transmission error at mesh phase psi (m): the table (periodic linear interpolation, as
// the stiffness table) plus the harmonics. Allocation-free.
double MeshTransmissionError(const GearMeshSpec& spec, double psi);

// Mesh phase (cycles) of the mesh's phase gear from the gear angles.
double MeshPhase(const GearMeshSpec& spec, const MeshGeometry& g, const MeshState& s);

// A lumped mesh's law (GearMeshSpec) at the configuration and velocities in `data` (needs
// position and velocity kinematics): the engaged flank, its compression and rate, the stiffness
// and static transmission error at the mesh phase, and the tooth force along the flank's normal
// (on gear b; zero with the teeth apart). CalcForceElements applies it; sensors read it.
// Throws std::runtime_error when a mesh without tooth counts has turned more than 1 rad.
struct MeshEvaluation {
  MeshState state;
  double psi = 0;     // mesh phase (cycles)
  double k = 0;       // stiffness at the phase (N/m)
  double ste = 0;     // static transmission error at the phase (m)
  int side = 0;       // +1 drive flank, -1 coast flank, 0 apart
  double delta = 0;   // compression of the engaged flank (m)
  double rate = 0;    // its rate (m/s)
  double force = 0;   // tooth force k (delta - ste) + c rate, >= 0 for two-sided contact (N)
};
MeshEvaluation EvaluateGearMesh(const Model& model, const GearMesh& mesh, const Data& data);
// The same with the gear angles taken from data.gear_angle (CalcGearAngles done at this
// configuration).
MeshEvaluation EvaluateGearMeshAtAngles(const Model& model, const GearMesh& mesh, const Data& data);

// Slopes of MeshStiffness and MeshTransmissionError in the mesh phase (N/m and m per cycle): the
// slope of the table's segment at psi (the tables are piecewise linear) plus the harmonics'.
double MeshStiffnessSlope(const GearMeshSpec& spec, double psi);
double MeshTransmissionErrorSlope(const GearMeshSpec& spec, double psi);

// Analytic tangents of every lumped mesh at the configuration and velocities in `data` (position
// and velocity kinematics and the body Jacobians data.J_WB, CalcBodyJacobians), added as in
// ExternalForceElement::AddTangents: K (nv x nv) += -dQ/d(dq), C (nv x nv) += -dQ/dv.
// Math: the engaged flank's compression rate is delta-dot = w v with the row
//   w = side (F_a^T J_a - F_b^T J_b - KSpin(n) [z; 0]^T J_C),  F_x = ForceAtPoint(p_x, n),
// J_x the spatial Jacobians of the mesh's frames (world origin), and the mesh's generalized force
// is Q = -f w^T with f = k(psi) (delta - ste(psi)) + c delta-dot, so
//   K += w^T (k w + (k'(psi) (delta - ste) - k ste'(psi)) w_psi),   C += c w^T w,
// w_psi = dpsi/d(dq) = (Z / 2 pi) [z; 0]^T (J_gear - J_C) for the phase gear (sign of the phase).
// The turning of n and of the lever points (terms of order f times the lever's change) is left
// out (they set Newton's convergence rate, not the solution); a two-sided mesh clamped at zero
// force or apart adds nothing. w and w_psi are scratch rows (nv), so that nothing allocates.
void AddGearMeshTangents(const Model& model, const Data& data, Eigen::Ref<Eigen::MatrixXd> K,
                         Eigen::Ref<Eigen::MatrixXd> C, Eigen::Ref<Eigen::VectorXd> w,
                         Eigen::Ref<Eigen::VectorXd> w_psi);

}  // namespace orrery

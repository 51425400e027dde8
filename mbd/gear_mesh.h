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
};
MeshState CalcMeshState(const MeshGeometry& g, const Data& data, FrameIndex gear_a,
                        FrameIndex gear_b, FrameIndex reference, double base_radius_a,
                        double base_radius_b, double backlash);

// Velocity of gear a's material point at its lever point relative to gear b's at its own, along
// `n_W`: the rate of the drive-flank compression for n_W = n_drive_W.
double CalcMeshRate(const Model& model, const Data& data, FrameIndex gear_a, FrameIndex gear_b,
                    const MeshState& s, const Vec3& n_W);

// Mesh stiffness at mesh phase psi (cycles) from the spec's table (or its constant).
double MeshStiffness(const GearMeshSpec& spec, double psi);

// Static transmission error at mesh phase psi (m).
double MeshTransmissionError(const GearMeshSpec& spec, double psi);

// Mesh phase (cycles) of the mesh's phase gear from the gear angles.
double MeshPhase(const GearMeshSpec& spec, const MeshGeometry& g, const MeshState& s);

}  // namespace orrery

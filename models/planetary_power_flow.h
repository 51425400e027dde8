#pragma once
// Static power flow of an ideal (lossless, rigid) planetary train in one gear range (seed 001
// section 2.2, eqs. 4-6), with equal load sharing among the n planets of a stage.
//
// Formulation. The rows G w = 0 of AssembleConstraints (meshes, connections, engaged clutches,
// engaged brakes) are velocity constraints; their multipliers lambda are the constraint loads and
// static equilibrium of every member and planet set about its own axis reads
//   Q_ext + G^T lambda = 0,                                              (virtual power)
// which is seed 001 eqs. 4a and 5a-5c written member by member: a mesh row Z_a w_a + Z_b w_b -
// (Z_a + Z_b) w_c puts the torque Z_a lambda on gear a, Z_b lambda on planet b and
// -(Z_a + Z_b) lambda on the carrier (pin force times pin radius). lambda of a mesh is a torque
// per tooth (N m), summed over the n branches; the torque on gear a is T_a = Z_a lambda and the
// tangential force per planet at the reference pitch circle is (seed 001 eq. 6)
//   F_t = |T_a| / (n r_a) = 2 |lambda| / (n m_t),
// the transverse force along the line of action F_bt = |T_a| / (n r_b,a) = F_t / cos(alpha_t) and
// the force normal to the flank F_n = F_bt / cos(beta_b), tan(beta_b) = tan(beta) cos(alpha_t).
// Q_ext is zero except at the ports (inputs and output); one port torque is given, the others are
// unknowns, so [G^T | e_ports] x = -e_known T_known is square (num_speeds unknowns) whenever the
// range is kinematically determinate. Equation 4b (power balance) then holds identically:
// sum Q_ext . w = -lambda^T G w = 0; it and the torque balance sum Q_ext + brake reactions = 0 are
// reported as residuals, checks of the solve.
//
// Usage:
//   PlanetaryPowerFlow p = CalcPlanetaryPowerFlow(*train, kin, train->inputs[0], 300.0);
//   double f = p.mesh_tangential_forces_n(train->MeshIndex("S1.sun-planet"));
#include <vector>

#include <Eigen/Core>

#include "models/planetary_kinematics.h"
#include "models/planetary_train.h"

namespace orrery::gears {

// Filled by CalcPlanetaryPowerFlow. Torques are about the train axis (members) or the planet axis
// (planet sets), positive in the positive sense of rotation, in N m.
struct PlanetaryPowerFlow {
  int range = -1;
  Eigen::VectorXd port_torques_n_m;         // (members) external torque at the ports, 0 elsewhere
  Eigen::VectorXd external_torques_n_m;     // (members) ports + brake reactions
  Eigen::VectorXd mesh_torques_n_m;         // (members) torque of the stage's meshes on the member
                                           //  (carrier: pin reactions); 0 = member unloaded
  Eigen::VectorXd connection_torques_n_m;   // (connections) torque applied to member_b (-a's)
  Eigen::VectorXd clutch_torques_n_m;       // (clutches) same; 0 when disengaged
  Eigen::VectorXd brake_torques_n_m;        // (brakes) torque of the ground on the member; 0 released
  Eigen::VectorXd mesh_loads_n_m;           // (meshes) lambda, torque per tooth, all branches
  Eigen::VectorXd mesh_gear_a_torques_n_m;  // (meshes) Z_a lambda, on gear a, all branches
  Eigen::VectorXd mesh_tangential_forces_n;      // (meshes) F_t per planet (eq. 6); NaN w/o form
  Eigen::VectorXd mesh_line_of_action_forces_n;  // (meshes) F_bt per planet; NaN without form
  Eigen::VectorXd mesh_normal_forces_n;          // (meshes) F_n per planet; NaN without form
  std::vector<bool> mesh_loaded;           // (meshes)
  std::vector<bool> member_loaded;         // (members) |mesh torque| above the tolerance
  std::vector<bool> stage_loaded;          // (stages) any mesh loaded; unloaded stages add zero
                                           //  modes to the dynamic model (seed 001 Table 3)
  double input_power_w = 0;                // sum over inputs of T w
  double output_power_w = 0;               // -T_out w_out
  double torque_residual_n_m = 0;           // |sum of external torques|
  double power_residual_w = 0;             // |sum over ports of T w|
  double load_tolerance_n_m = 0;            // threshold used for the *_loaded flags
};

// Given the torque on one port member (an input or the output), computes all the above for the
// range of `kinematics` (which must come from SolvePlanetaryKinematics on the same train).
// Throws std::invalid_argument if known_member is not a port, std::runtime_error if the torques
// are indeterminate (e.g. the output is held in that range).
PlanetaryPowerFlow CalcPlanetaryPowerFlow(const PlanetaryTrain& train,
                                          const PlanetaryKinematics& kinematics, int known_member,
                                          double known_torque_n_m);

}  // namespace orrery::gears

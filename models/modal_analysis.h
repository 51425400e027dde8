#pragma once
// Linear analysis of a planetary train model (train_dynamics.h) about its operating point: natural
// modes with their classes, stage participation and multiplicities (seed 001 section 2.4.2 and
// Table 3; Lin & Parker 1999 mode classes), and the steady forced response to the static
// transmission errors by modal summation with uniform modal damping (seed 001 Figs. 6-7).
//
// Operating point: the model at its initial configuration with zero speed; mesh contact linear on
// the loaded flank with the mean stiffness; no transmission error, no port loads. The carrier speed
// is ignored: no gyroscopic or centrifugal terms (seed 001 and Lin & Parker's stationary-carrier
// models). Speed drivers stay as constraints, so a speed-driven input removes the rigid-body mode;
// build with TrainModelOptions::Input::kTorque or kNone for seed 001's free train.
//
// Mode classes: rigid body (|w^2| within the eigenvalue tolerance of 0); planet (no central member
// moves: kinetic energy of every sun, ring, carrier below 1e-6 of the mode's); rotational (planar,
// spatial: central members do not translate; torsional: every other mode); translational (central
// members do not rotate); mixed otherwise. A stage takes part when its kinetic or strain energy
// share reaches `participation_threshold`.
// Eigenvalue tolerance (grouping of repeated modes and the zero test): the symmetric eigen solver's
// backward error is O(n eps lambda_max), and Linearize's central-difference K carries a rounding
// error of O(eps K_max) per entry, i.e. O(eps lambda_max) in the eigenvalues: an eigenvalue within
// safety * n * eps * lambda_max (safety 1e3) of 0 is a rigid-body mode. Modes are one group within
// that or within Linearize's relative accuracy (mbd/linearization.h SameEigenvalue: the central
// differences' eps / step + step^2 relative to the eigenvalue, times 10).
//
// Forced response (modal summation, seed 001 section 2.4.2): mesh m's transmission error
// e_m = sum_l A_l cos(2 pi l psi_m + phi_l) with psi_m = phase_m +- f_j t (the sign of gear a's
// speed relative to the carrier, f_j the stage mesh frequency) is the force k_m e_m J_m^T on the
// coordinates, J_m = d delta_m / dq the mesh's line-of-action vector (central differences of the
// mesh deflection). Each mode answers with H_i = 1 / (w_i^2 - W^2 + 2 i zeta w_i W); the dynamic
// mesh force is F_p = k_p (J_p q - e_p) (seed 001 eq. 18), summed over all stages and harmonics
// in time over a window, and reported peak to peak.
//
// Usage:
//   TrainModes modes = CalcTrainModes(tm);
//   ForcedResponse fr = CalcForcedResponse(tm, modes, {.input_speeds_rad_s = speeds});
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mbd/linearization.h"
#include "models/train_dynamics.h"

namespace orrery::gears {

enum class ModeClass { kRigidBody, kRotational, kTranslational, kPlanet, kMixed };
const char* ModeClassName(ModeClass c);

struct ModalOptions {
  double participation_threshold = 0.05;  // energy share for a stage to take part in a mode
};

struct TrainMode {
  double frequency_hz = 0;
  ModeClass mode_class = ModeClass::kRotational;
  int group = -1;                          // index into TrainModes::groups
  std::vector<double> stage_kinetic_share;  // (stages) sums to 1
  std::vector<double> stage_strain_share;   // (stages) sums to 1 (0 for rigid-body modes)
  std::vector<int> stages;                 // stages taking part
};

// Modes of (numerically) equal frequency.
struct ModeGroup {
  double frequency_hz = 0;
  int first_mode = 0, multiplicity = 1;
  ModeClass mode_class = ModeClass::kRotational;
};

// Filled by CalcTrainModes.
struct TrainModes {
  LinearModel linear;              // of the operating-point model (see above)
  Eigen::MatrixXd shapes;          // nv x nmodes: mass-normalized, ascending frequency
  std::vector<TrainMode> modes;    // (nmodes)
  std::vector<ModeGroup> groups;
  Eigen::MatrixXd mesh_directions; // n_meshes x nv: J_m = d delta_m / dq on the loaded flank
  Eigen::VectorXd mesh_stiffness;  // n_meshes: mean stiffness k_m (N/m)
  double eigenvalue_tolerance = 0; // (rad/s)^2
  int num_rigid_body_modes = 0;
};

// Throws std::runtime_error if the mass matrix is not positive definite.
TrainModes CalcTrainModes(const TrainModel& model, const ModalOptions& options = {});

// The options of the operating-point model of `model` (header): its own with every lumped mesh
// linear on its loaded flank at its mean stiffness (no table, no transmission error, no faults, no
// backlash) and no port loads (a torque input dropped, speed drivers kept).
TrainModelOptions OperatingPointOptions(const TrainModel& model);

struct ForcedResponseOptions {
  std::vector<double> input_speeds_rad_s;  // speeds of train.inputs[0]; others in proportion
  double modal_damping_ratio = 0.04;       // seed 001
  int samples_per_period = 64;             // per period of the highest excitation frequency
  double window_periods = 4;               // of the lowest stage mesh frequency (several stages)
};

// Filled by CalcForcedResponse; rows are speeds.
struct ForcedResponse {
  std::vector<double> input_speeds_rad_s;
  Eigen::MatrixXd stage_mesh_frequencies_hz;  // speeds x stages
  Eigen::MatrixXd mesh_force_p2p_n;           // speeds x meshes: k (J q - e), seed 001 eq. 18
  Eigen::MatrixXd mesh_deflection_p2p_m;      // speeds x meshes: J q, the motion along the line
  Eigen::MatrixXd member_angle_p2p_rad;       // speeds x members (seed 001 Fig. 7)
};

// Throws std::invalid_argument for non-positive options.
ForcedResponse CalcForcedResponse(const TrainModel& model, const TrainModes& modes,
                                  const ForcedResponseOptions& options);

}  // namespace orrery::gears

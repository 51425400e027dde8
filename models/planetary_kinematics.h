#pragma once
// Kinematics of an N-stage planetary train in one gear range (seed 001 section 2.1, eqs. 1-3).
//
// The speed vector w (PlanetaryTrain::num_speeds: members, then planet sets) solves A w = B, where
// A stacks
//   - one row per mesh (seed 001 eqs. 1a, 1b, 2a-2c; the Ravigneaux stage uses the same two forms
//     for its four meshes s1-a, a-b, s2-b, r-b):
//       external a-b on carrier c:   Z_a w_a + Z_b w_b - (Z_a + Z_b) w_c = 0
//       internal ring r - planet p:  Z_r w_r - Z_p w_p - (Z_r - Z_p) w_c = 0,
//   - w_i - w_j = 0 per connection and per engaged clutch,
//   - w_k = 0 per engaged brake,
//   - w_in = given, per input member.
// With one input this reproduces the Willis ratios, e.g. single-planet
//   (w_s - w_c) / (w_r - w_c) = -Z_r / Z_s,   double-planet  (w_s - w_c) / (w_r - w_c) = +Z_r / Z_s.
//
// Mesh (tooth-passing) frequency of a mesh a-b on carrier c (seed 001 eq. 3, in Hz):
//   f_m = Z_a |w_a - w_c| / (2 pi); all meshes of one stage share it (every row above makes
//   Z_a (w_a - w_c) = -+ Z_b (w_b - w_c) along the branch).
// Local tooth-fault frequencies (one damaged tooth meets a partner once per turn relative to the
// carrier; same formulas as Feng & Zuo 2012, "Vibration signal models for fault diagnosis of
// planetary gearboxes", J. Sound Vib. 331):
//   central gear j (sun or ring) met by n planets:   f_j = n f_m / Z_j = n |w_j - w_c| / (2 pi)
//   planet p with k meshes (k = 2 for a planet between sun and ring: one flank meets the sun, the
//   opposite flank the ring):                        f_p = k f_m / Z_p,
//   the per-flank value f_m / Z_p = |w_p - w_c| / (2 pi) is the planet's rotation relative to the
//   carrier.
//
// Usage:
//   PlanetaryKinematics k = SolvePlanetaryKinematics(*train, train->RangeIndex("1st"),
//                                                    Eigen::VectorXd::Constant(1, 100.0));
//   double w_out = k.speeds_rad_s(train->output);
#include <string>
#include <vector>

#include <Eigen/Core>

#include "models/planetary_train.h"

namespace orrery::gears {

enum class ConstraintKind { kMesh, kConnection, kClutch, kBrake, kInput };

// Constraint rows of a gear range without the input rows (filled by AssembleConstraints).
struct ConstraintRows {
  Eigen::MatrixXd G;                  // (rows x num_speeds), G w = 0
  std::vector<ConstraintKind> kind;   // (rows)
  std::vector<int> element;           // (rows) index into meshes/connections/clutches/brakes
  std::vector<std::string> label;     // (rows) e.g. "mesh S1.sun-planet", "brake B1 (S1.sun)"
};

// Rows in the order: meshes, connections, engaged clutches, engaged brakes.
// Throws std::out_of_range for a bad range index.
ConstraintRows AssembleConstraints(const PlanetaryTrain& train, int range);

// Determinacy of a range with the train's inputs (filled by AnalyzeRange).
struct RangeAnalysis {
  bool determinate = false;
  int rank = 0;                        // rank of A
  std::vector<int> free_speeds;        // speed indices that move with all inputs held
  std::vector<std::string> redundant;  // labels of rows that conflict or repeat others
  std::string message;                 // empty if determinate
};
RangeAnalysis AnalyzeRange(const PlanetaryTrain& train, int range);

// Filled by SolvePlanetaryKinematics.
struct PlanetaryKinematics {
  int range = -1;
  Eigen::VectorXd input_speeds_rad_s;            // (inputs) as given
  Eigen::VectorXd speeds_rad_s;                  // (num_speeds) members then planet sets, absolute
  Eigen::VectorXd planet_relative_speeds_rad_s;  // (planet_sets) w_p - w_c
  Eigen::VectorXd mesh_frequencies_hz;           // (meshes) seed 001 eq. 3
  Eigen::VectorXd stage_mesh_frequencies_hz;     // (stages) f_m of the stage
  Eigen::VectorXd gear_fault_frequencies_hz;     // (gears) local tooth fault, see above
  Eigen::MatrixXd A;                             // (num_speeds x num_speeds) assembled system
  Eigen::VectorXd B;                             // (num_speeds)
  double ratio = 0;  // w_input / w_output for one input; NaN for several inputs or w_output = 0
};

// Solves A w = B for the range. input_speeds_rad_s has one entry per train input (in AddInput
// order). Throws std::invalid_argument on a size mismatch or a bad range, std::runtime_error with
// AnalyzeRange's message if the range is not determinate.
PlanetaryKinematics SolvePlanetaryKinematics(const PlanetaryTrain& train, int range,
                                             const Eigen::VectorXd& input_speeds_rad_s);

}  // namespace orrery::gears

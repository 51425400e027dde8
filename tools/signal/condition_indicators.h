#pragma once
// Condition indicators of a gear: statistics of a time-synchronous average (TSA, one revolution
// of the member that carries the gear, S samples; time_synchronous_average.h) and of the signals
// left when its regular meshing components are taken out.
//
// Definitions (x: the TSA, N = S samples, x̄ its mean; Z: the gear's teeth, the order of its mesh
// frequency in the member's revolution; A_q: the amplitude of order q, single-sided, from the
// TSA's DFT, exact because every order is a bin):
//   RMS            sqrt( (1/N) sum x_i^2 )
//   peak           max |x_i|
//   crest factor   peak / RMS
//   kurtosis       N sum (x_i - x̄)^4 / ( sum (x_i - x̄)^2 )^2            (3 for Gaussian noise)
//   FM0            (max x - min x) / sum_{k>=1, kZ<=S/2} A_{kZ}
//                  peak-to-peak over the mesh harmonics (Stewart 1977)
//   FM4            kurtosis of the difference signal d (Stewart 1977)
//   NA4            N sum (r_i - r̄)^4 / [ (1/M) sum_{j=1}^{M} sum_i (r_ji - r̄_j)^2 ]^2
//                  of the residual signal r of the current run M, normalized by the residual
//                  variance averaged over runs 1..M of a trend (Zakrajsek, Townsend & Decker,
//                  "An analysis of gear fault detection methods as applied to pitting fatigue
//                  failure data", NASA TM-105950, 1993); with M = 1 it is the residual's kurtosis
// Sources: R. M. Stewart, "Some useful data analysis techniques for gearbox diagnostics", Report
// MHM/R/10/77, Machine Health Monitoring Group, Institute of Sound and Vibration Research,
// University of Southampton, 1977 (FM0, FM4); Zakrajsek et al. 1993 (NA4; its review of FM0, FM4).
//
// Regular meshing components, the orders removed (their DFT bins set to zero and the signal
// transformed back):
//   residual signal r:    the mean, the shaft orders 1 .. H (shaft frequency and its harmonics;
//                         H = shaft_harmonics, 2 by default: once- and twice-per-revolution
//                         components, unbalance and misalignment), the mesh harmonics kZ
//   difference signal d:  those and the first-order sidebands kZ ± 1
// Stewart and Zakrajsek name "the shaft frequency and harmonics" without a count; in a TSA every
// order is a shaft harmonic, so a count has to be chosen, and H is that choice.
//
// Usage:
//   ConditionIndicators c = CalcConditionIndicators(tsa.values, {.mesh_order = 14});
#include <span>
#include <vector>

namespace orrery::signal {

double Rms(std::span<const double> x);
double PeakAbs(std::span<const double> x);
double CrestFactor(std::span<const double> x);
// N sum (x - x̄)^4 / (sum (x - x̄)^2)^2; NaN for a constant record.
double Kurtosis(std::span<const double> x);

struct RegularComponents {
  int mesh_order = 0;       // Z >= 1, with Z + 1 <= S/2
  int shaft_harmonics = 2;  // H >= 0: shaft orders 1 .. H are regular
};

// The TSA with the regular components above removed. Throw std::invalid_argument when the TSA is
// too short for the mesh order (Z + 1 > S/2) or the mesh order is below 1.
std::vector<double> ResidualSignal(std::span<const double> tsa, const RegularComponents& regular);
std::vector<double> DifferenceSignal(std::span<const double> tsa, const RegularComponents& regular);

// (1/N) sum (r_i - r̄)^2 of the residual signal: a run's contribution to NA4's denominator.
double ResidualVariance(std::span<const double> tsa, const RegularComponents& regular);

// FM4 and NA4 are NaN when the difference (residual) signal's RMS is below 1e-10 of the TSA's:
// the TSA holds nothing but regular components, and a kurtosis of rounding errors means nothing.
double Fm0(std::span<const double> tsa, int mesh_order);
double Fm4(std::span<const double> tsa, const RegularComponents& regular);
// `earlier_residual_variances`: ResidualVariance of runs 1 .. M-1 of the trend (same S); empty
// for M = 1.
double Na4(std::span<const double> tsa, const RegularComponents& regular,
           std::span<const double> earlier_residual_variances = {});

struct ConditionIndicators {
  double rms = 0, peak = 0, crest_factor = 0, kurtosis = 0;  // of the TSA
  double fm0 = 0, fm4 = 0, na4 = 0;
  double residual_variance = 0;  // for the NA4 of later runs
};

ConditionIndicators CalcConditionIndicators(std::span<const double> tsa, const RegularComponents& regular,
                                            std::span<const double> earlier_residual_variances = {});

}  // namespace orrery::signal

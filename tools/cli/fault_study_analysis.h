#pragma once
// What `orrery fault-study` reads from its two result files (fault_study_command.h): the healthy
// run against the faulty run of one scene, on one recorded signal, with the kinematic lines the
// faulty file lists (/kinematics/lines, tools/cli/kinematic_lines_writer.h).
//
//   signal     options.signal (the command passes --signal, else the scene's first sensor), its
//              first column unless options.column names one; both records from t0
//              on (the start transient skipped), cut to one FastFftLength, Hann window;
//   mesh line  the first line of kind mesh (f_m), and the spectrum's largest peak within
//              2 bins + 1 % of it in the healthy run (mesh_frequency_found_hz, interpolated);
//   modulation the planet's rotation relative to the carrier (the line "f_p^H", or the first
//              "f_p^H ..." of a multi-stage train) when a planet is faulty, else the fault line of
//              the faulty gear ("f_fault S.sun"): a damaged tooth's sidebands sit at k f_m +- n f_mod
//              (DESIGN.md);
//   sidebands  for k = 1..3 and n = 1..3 on both sides: level of the line at k f_m + n f_mod in
//              each run, L = 20 log10(A / A_ref) dB with A = sqrt(2 P), P the line's power
//              (LinePower: the bins of the window's main lobe, so scalloping does not bias it),
//              A_ref = 1e-6 m/s^2 for accelerations (seed 000 eq. 27), else 1 in the signal's unit;
//   SER        SidebandEnergyRatio of each run (3 harmonics, 6 pairs), faulty over healthy;
//   indicators RMS, peak, crest factor and kurtosis of each record (condition_indicators.h);
//   mesh force the largest |force| over the record of every lumped mesh branch
//              (/gear_meshes/<b>/force) and contact branch (/external/<b>/line_of_action_force,
//              else normal_force), per run, with the branch and time;
//   stress     per flexible body with stress recovery (/flexible_bodies/<B>/von_mises_max), the
//              largest von Mises stress of the run with its time, node and position (body frame),
//              the position's radius and polar angle, and the nearest tooth (tooth k centred on
//              2 pi k / z in the gear frame) when options.gear_teeth names the body.
// Throws std::runtime_error naming file and dataset for what is missing or unreadable.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mbd/spatial.h"
#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/condition_indicators.h"
#include "tools/signal/kinematic_lines.h"
#include "tools/signal/signal_io.h"

namespace orrery::cli {

struct FaultStudyAnalysisOptions {
  std::string signal;  // dataset, e.g. "/sensors/ring/acceleration"
  std::string column;  // "": the first
  double t0_s = 0;     // records start here
  int harmonics = 3;   // mesh harmonics k whose sidebands are listed
  int sidebands = 3;   // n = 1..sidebands on each side
  std::map<std::string, int> gear_teeth;  // tooth count of each gear body ("S.planet1": 14)
  std::string fault_gear;  // train gear of the (first) fault: "S.planet", "S.sun"
  bool fault_on_planet = false;
};

struct SidebandLevel {
  double frequency_hz = 0;
  std::string label;      // "f_m + f_p^H", "2 f_m - 3 f_p^H" (LabelPeaks' form)
  int harmonic = 1, order = 1;  // k, signed n
  double healthy_db = 0, faulty_db = 0;
};

struct MeshForcePeak {
  double force_n = 0;   // largest |force| over the record
  std::string branch;   // "S.ring-planet#1"
  double time_s = 0;
};

struct StressPeak {
  std::string body;
  double stress_pa = 0, time_s = 0;
  long node = -1;
  Vec3 position_m = Vec3::Zero();  // in the body frame
  double radius_m = 0, angle_deg = 0;
  int tooth = -1;                  // nearest tooth, -1 when the body is no gear of the train
  double tooth_offset_deg = 0;     // angle from that tooth's centre line
};

struct FaultStudyRun {
  signal::RecordedSignal signal;
  signal::Spectrum spectrum;
  double ser = 0;
  signal::ConditionIndicators indicators;  // record statistics (FM0, FM4, NA4: NaN)
  MeshForcePeak mesh_force;
  std::vector<StressPeak> stress;
};

struct FaultStudyAnalysis {
  FaultStudyRun healthy, faulty;
  std::vector<signal::KinematicLine> lines;
  signal::KinematicLine mesh, modulation;
  double mesh_frequency_found_hz = 0;
  std::vector<SidebandLevel> sidebands;
  int harmonics = 3;          // options.harmonics
  double ser_ratio = 0;       // faulty over healthy (NaN when the healthy run has none)
  double db_reference = 1;    // A_ref
  std::string db_reference_text;  // "1e-6 m/s^2", "1 N"
};

FaultStudyAnalysis AnalyseFaultStudy(const std::string& healthy_h5, const std::string& faulty_h5,
                                     const FaultStudyAnalysisOptions& options);

}  // namespace orrery::cli

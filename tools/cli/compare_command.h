#pragma once
// `orrery compare HEALTHY.h5 FAULTY.h5 --signal PATH [--column C] [--t0 T] [--window W]
//                [--tsa MEMBER] [--mesh NAME] [--modulation NAME] [--json] [--png FILE]`
// A healthy and a faulty run of one scene side by side: the sideband energy ratio of each and
// their ratio, and the condition indicators (tools/signal).
//
// Steps: ReadSignal on both files (same dataset, column and t0; equal sample rates); the mesh
// line (the first of kind mesh, or --mesh NAME) and the modulation line (the first of kind fault,
// or --modulation NAME, any line) from the faulty file's /kinematics/lines; both records cut to
// the same FastFftLength and their amplitude spectra taken (Hann by default);
// SidebandEnergyRatio of each around the first three mesh harmonics with up to six sideband
// pairs at the modulation frequency (sideband_energy_ratio.h gives the exact definition);
//   sideband_energy_ratio = SER(faulty) / SER(healthy)
// (null in JSON, "inf" in text, when the healthy run has no sideband power).
// Indicators: without --tsa, RMS, peak, crest factor and kurtosis of each record (FM0, FM4, NA4
// are defined on a time-synchronous average and are null); with --tsa MEMBER (a joint name, e.g.
// S.planet1 whose angle /joints/S.planet1/q turns with the planet relative to the carrier, or an
// angle dataset), all seven on the TSA of each run over the member's revolutions (the same
// samples per revolution for both), the mesh order Z being f_m over the member's mean rotation
// frequency, which must be a whole number within 0.05; the faulty run's NA4 is normalized by the
// mean residual variance of the healthy and the faulty run (a trend of two runs,
// condition_indicators.h), the healthy run's by its own.
//
// JSON (--json), exactly these keys:
//   {"healthy", "faulty", "signal", "column", "unit", "window", "samples", "sample_rate_hz",
//    "resolution_hz", "mesh": {"name", "frequency_hz"}, "modulation": {"name", "frequency_hz"},
//    "sideband_energy_ratio", "ser": {"healthy", "faulty", "harmonics", "sidebands"},
//    "indicator_signal": "record" | "tsa",
//    "indicators": {"rms" | "peak" | "crest_factor" | "kurtosis" | "fm0" | "fm4" | "na4":
//                   {"healthy", "faulty"}},
//    "tsa": null | {"member", "samples_per_revolution", "revolutions_healthy",
//                   "revolutions_faulty", "mesh_order"}}
// --png FILE: both amplitude spectra overlaid, the mesh harmonics and sidebands marked
// (tools/plot/overlay_plot.py).
//
// Failures (a missing file, dataset or column, a record under 16 samples, differing sample
// rates, no kinematic lines or no mesh or modulation line in the faulty file, sidebands the
// record cannot resolve, a member whose revolutions hold no whole mesh order) print one line
// "orrery: error: <file>: <path>: reason" and return kExitFailure.
#include <optional>
#include <ostream>
#include <string>

namespace orrery::cli {

struct CompareArgs {
  std::string healthy, faulty;  // the two result files
  std::string signal;           // --signal: dataset path
  std::string column;           // --column
  std::optional<double> t0;     // --t0 (s)
  std::string window = "hann";  // --window
  std::string tsa_member;       // --tsa: "" for indicators of the raw records
  std::string mesh;             // --mesh: "" for the first mesh line
  std::string modulation;       // --modulation: "" for the first fault line
  bool json = false;
  std::string png;              // --png
};

int CompareCommand(const CompareArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

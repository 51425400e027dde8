#pragma once
// `orrery octave OUT.h5 --signal PATH [--column C] [--t0 T] [--reference A0] [--json] [--png FILE]`
// One-third-octave band levels of a recorded signal, L = 20 log10(a / a0) with a the band's RMS
// value and a0 = 1e-6 (m/s^2 for accelerations, seed 000 eq. 27) unless --reference says
// otherwise (tools/signal/third_octave.h: base-ten IEC 61260-1 bands, Hann-windowed periodogram
// integrated over each band).
//
// A signal whose unit is not m/s^2 keeps the 1e-6 reference unless told, with one warning line
// on `err` (the seed 000 reference is for accelerations).
// Text output: the record, then per band the nominal and exact mid-band frequency, the edges,
// the RMS and the level.
// JSON (--json): {"file", "signal", "column", "unit", "samples", "sample_rate_hz", "reference",
//   "bands": [{"nominal_hz", "exact_hz", "lower_hz", "upper_hz", "rms", "level_db"}]}
// --png FILE: the levels as bars (tools/plot/octave_plot.py).
// Failures print one line "orrery: error: <file>: <path>: reason" and return kExitFailure.
#include <optional>
#include <ostream>
#include <string>

namespace orrery::cli {

struct OctaveArgs {
  std::string path;          // OUT.h5
  std::string signal;        // --signal
  std::string column;        // --column
  std::optional<double> t0;  // --t0 (s)
  double reference = 1e-6;   // --reference
  bool reference_given = false;
  bool json = false;
  std::string png;           // --png
};

int OctaveCommand(const OctaveArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

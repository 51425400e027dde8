#pragma once
// `orrery plot OUT.h5 --signal PATH [--column C] [--t0 T] --png FILE`
// `orrery plot OUT.h5 --stress PATH --png FILE`
// Plots of recorded series: a signal over time (tools/plot/time_signal_plot.py, the values read
// here by ReadSignal and handed over), or the hot-spot von Mises stress of a flexible body over
// time, marked at its largest value with node and place (tools/plot/stress_plot.py, which reads
// PATH, e.g. /flexible_bodies/S.planet1/von_mises_max, and /time from the file with h5py).
// Exactly one of --signal and --stress. Failures print one line "orrery: error: ..." naming the
// file and dataset and return kExitFailure.
#include <optional>
#include <ostream>
#include <string>

namespace orrery::cli {

struct PlotArgs {
  std::string path;          // OUT.h5
  std::string signal;        // --signal
  std::string column;        // --column
  std::optional<double> t0;  // --t0 (s)
  std::string stress;        // --stress
  std::string png;           // --png (required)
};

int PlotCommand(const PlotArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

#include "tools/cli/plot_command.h"

#include <exception>
#include <limits>

#include "mbd/hdf5_reader.h"
#include "tools/cli/error_message.h"
#include "tools/cli/plot_script.h"
#include "tools/cli/signal_plots.h"
#include "tools/signal/signal_io.h"

namespace orrery::cli {
namespace {

using namespace orrery::signal;

void PlotSignal(const PlotArgs& args) {
  Hdf5Reader file(args.path);
  const RecordedSignal s = ReadSignal(file, args.signal, args.column, args.t0.value_or(-std::numeric_limits<double>::infinity()));
  PlotTimeSignal({.title = s.path + " [" + s.column_name + "] of " + s.file,
                  .x_label = "time (s)",
                  .y_label = s.column_name + (s.unit.empty() ? "" : " (" + s.unit + ")")},
                 s, args.png);
}

void PlotStress(const PlotArgs& args) {
  // Checked here so that the message has the same form as every other command's
  Hdf5Reader file(args.path);
  if (!file.IsDataset(args.stress)) throw std::runtime_error(args.path + ": " + args.stress + ": no such dataset");
  if (!file.IsDataset("/time")) throw std::runtime_error(args.path + ": /time: no such dataset (not a result file?)");
  PlotHotSpotStress(args.path, args.stress, args.png);
}

}  // namespace

int PlotCommand(const PlotArgs& args, std::ostream& out, std::ostream& err) {
  try {
    if (args.signal.empty() == args.stress.empty()) throw std::runtime_error("orrery plot needs exactly one of --signal and --stress");
    CheckPngPath(args.png);
    if (!args.signal.empty())
      PlotSignal(args);
    else
      PlotStress(args);
    out << "wrote " << args.png << "\n";
    return kExitSuccess;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli

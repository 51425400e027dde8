#include "tools/cli/octave_command.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>

#include "mbd/hdf5_reader.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"
#include "tools/cli/plot_script.h"
#include "tools/cli/signal_plots.h"
#include "tools/signal/signal_io.h"
#include "tools/signal/third_octave.h"

namespace orrery::cli {
namespace {

using namespace orrery::signal;

std::string Fmt(const char* format, double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

void WriteText(const RecordedSignal& s, const std::vector<OctaveBand>& bands, double reference, std::ostream& out) {
  out << "file         " << s.file << "\n";
  out << "signal       " << s.path << " [" << s.column_name << "]" << (s.unit.empty() ? "" : " (" + s.unit + ")") << ", "
      << s.values.size() << " samples at " << Fmt("%.6g", s.sample_rate_hz) << " Hz\n";
  out << "reference    " << Fmt("%g", reference) << (s.unit.empty() ? "" : " " + s.unit) << "\n\n";
  out << "  nominal_hz    lower_hz    upper_hz            rms   level_db\n";
  for (const OctaveBand& b : bands)
    out << Fmt("%12g", b.nominal_hz) << Fmt("%12.2f", b.lower_hz) << Fmt("%12.2f", b.upper_hz) << Fmt("%15.6g", b.rms)
        << Fmt("%11.2f", b.level_db) << "\n";
}

void WriteJson(const RecordedSignal& s, const std::vector<OctaveBand>& bands, double reference, std::ostream& out) {
  JsonWriter w(out);
  w.BeginObject();
  w.Key("file").String(s.file).Key("signal").String(s.path).Key("column").String(s.column_name).Key("unit").String(s.unit);
  w.Key("samples").Int(static_cast<long long>(s.values.size())).Key("sample_rate_hz").Number(s.sample_rate_hz);
  w.Key("reference").Number(reference).Key("bands").BeginArray();
  for (const OctaveBand& b : bands) {
    w.BeginObject().Key("nominal_hz").Number(b.nominal_hz).Key("exact_hz").Number(b.exact_hz);
    w.Key("lower_hz").Number(b.lower_hz).Key("upper_hz").Number(b.upper_hz).Key("rms").Number(b.rms);
    w.Key("level_db").Number(b.level_db).EndObject();
  }
  w.EndArray().EndObject();
}

void Plot(const RecordedSignal& s, const std::vector<OctaveBand>& bands, double reference, const std::string& png) {
  const PlotLabels labels{.title = "One-third-octave levels of " + s.path + " [" + s.column_name + "]",
                          .x_label = "one-third-octave band, nominal mid-band frequency (Hz)",
                          .y_label = "level (dB re " + Fmt("%g", reference) + (s.unit.empty() ? "" : " " + s.unit) + ")"};
  PlotOctaveBands(labels, bands, png);
}

}  // namespace

int OctaveCommand(const OctaveArgs& args, std::ostream& out, std::ostream& err) {
  try {
    if (!args.png.empty()) CheckPngPath(args.png);
    Hdf5Reader file(args.path);
    const RecordedSignal s =
        ReadSignal(file, args.signal, args.column, args.t0.value_or(-std::numeric_limits<double>::infinity()));
    if (!args.reference_given && s.unit != "m/s^2")
      err << "orrery: warning: " << s.file << ": " << s.path << ": unit '" << s.unit
          << "', not m/s^2: levels are against 1e-6 (seed 000's acceleration reference); set --reference\n";
    std::vector<OctaveBand> bands;
    try {
      bands = ThirdOctaveLevels(s.values, s.sample_rate_hz, {.reference = args.reference});
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(s.file + ": " + s.path + ": " + e.what());
    }
    if (!args.png.empty()) Plot(s, bands, args.reference, args.png);
    if (args.json)
      WriteJson(s, bands, args.reference, out);
    else
      WriteText(s, bands, args.reference, out);
    return kExitSuccess;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli

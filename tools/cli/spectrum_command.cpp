#include "tools/cli/spectrum_command.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <numbers>

#include "mbd/hdf5_reader.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"
#include "tools/cli/plot_script.h"
#include "tools/cli/signal_plots.h"
#include "tools/signal/fft.h"
#include "tools/signal/order_resample.h"
#include "tools/signal/peaks.h"
#include "tools/signal/signal_io.h"

namespace orrery::cli {
namespace {

using namespace orrery::signal;

// Everything the command computed
struct SpectrumResult {
  RecordedSignal signal;
  Spectrum spectrum;
  std::vector<Peak> peaks;
  std::vector<KinematicLine> lines;  // in the spectrum's x unit (Hz or orders)
  bool orders = false;
  std::string reference;             // --order's dataset
  int samples_per_revolution = 0;
  int revolutions = 0;
  double mean_reference_hz = 0;
};

std::string Fmt(const char* format, double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

SpectrumResult Compute(const SpectrumArgs& args, std::ostream& err) {
  Hdf5Reader file(args.path);
  SpectrumResult r;
  r.signal = ReadSignal(file, args.signal, args.column, args.t0.value_or(-std::numeric_limits<double>::infinity()));
  const WindowKind window = ParseWindowKind(args.window);
  const RecordedSignal& s = r.signal;
  double scale = 1.0;  // Hz per x unit

  if (args.order_member.empty()) {
    // Time spectrum of the first fast-length samples
    const int n = FastFftLength(static_cast<int>(s.values.size()));
    r.spectrum = AmplitudeSpectrum(std::span<const double>(s.values).first(n), s.sample_rate_hz, window);
  } else {
    // Order spectrum of the whole revolutions of the reference
    r.orders = true;
    r.reference = ReferenceAnglePath(args.order_member);
    const std::vector<double> angle = ReadReferenceAngle(file, args.order_member, s);
    int per_rev = 0;
    AngleDomainSignal a;
    try {
      per_rev = DefaultSamplesPerRevolution(angle);
      a = OrderResample(s.values, angle, per_rev);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(file.path() + ": " + r.reference + ": " + e.what());
    }
    r.samples_per_revolution = per_rev;
    r.revolutions = static_cast<int>(a.values.size() / per_rev);
    if (r.revolutions < 1)
      throw std::runtime_error(file.path() + ": " + r.reference + ": the record holds less than one revolution");
    const std::vector<double> rising = RisingAngle(angle);
    r.mean_reference_hz = (rising.back() - rising.front()) / (2 * std::numbers::pi) /
                          (s.time_s.back() - s.time_s.front());
    scale = r.mean_reference_hz;
    r.spectrum = AmplitudeSpectrum(std::span<const double>(a.values).first(static_cast<std::size_t>(r.revolutions) * per_rev),
                                   per_rev, window);
  }

  // Peaks, labelled from the file's kinematic lines (in the x unit)
  r.peaks = FindPeaks(r.spectrum, {.max_peaks = args.max_peaks});
  if (HasKinematicLines(file)) {
    r.lines = ReadKinematicLines(file);
    for (KinematicLine& line : r.lines) line.frequency_hz /= scale;
    LabelPeaks(r.peaks, r.lines, r.spectrum.resolution);
  } else {
    err << "orrery: warning: " << file.path() << ": /kinematics/lines: no kinematic lines, peaks are not labelled\n";
  }
  return r;
}

void WriteText(const SpectrumResult& r, std::ostream& out) {
  const RecordedSignal& s = r.signal;
  const std::string x = r.orders ? "order" : "frequency_hz";
  out << "file         " << s.file << "\n";
  out << "signal       " << s.path << " [" << s.column_name << "]" << (s.unit.empty() ? "" : " (" + s.unit + ")") << "\n";
  out << "record       " << r.spectrum.samples << " samples" << (r.orders ? " in angle" : "") << ", t = "
      << Fmt("%.6g", s.time_s.front()) << " .. " << Fmt("%.6g", s.time_s.back()) << " s, sample rate "
      << Fmt("%.6g", s.sample_rate_hz) << " Hz\n";
  if (r.orders)
    out << "reference    " << r.reference << ": " << r.revolutions << " revolutions at mean "
        << Fmt("%.6g", r.mean_reference_hz) << " Hz, " << r.samples_per_revolution << " samples per revolution\n";
  out << "resolution   " << Fmt("%.6g", r.spectrum.resolution) << (r.orders ? " orders" : " Hz") << ", window "
      << WindowName(r.spectrum.window) << "\n\n";
  out << (r.orders ? "     order" : "  frequency_hz") << "      amplitude  label\n";
  for (const Peak& p : r.peaks)
    out << Fmt(r.orders ? "%10.4f" : "%14.4f", p.frequency) << "  " << Fmt("%13.6g", p.amplitude) << "  " << p.label << "\n";
}

void WriteJson(const SpectrumResult& r, std::ostream& out) {
  const RecordedSignal& s = r.signal;
  const std::string x = r.orders ? "order" : "frequency_hz";
  JsonWriter w(out);
  w.BeginObject();
  w.Key("file").String(s.file).Key("signal").String(s.path).Key("column").String(s.column_name);
  w.Key("unit").String(s.unit).Key("window").String(WindowName(r.spectrum.window));
  w.Key("samples").Int(r.spectrum.samples).Key("sample_rate_hz").Number(s.sample_rate_hz);
  w.Key(r.orders ? "resolution_orders" : "resolution_hz").Number(r.spectrum.resolution);
  if (r.orders) {
    w.Key("reference").String(r.reference).Key("samples_per_revolution").Int(r.samples_per_revolution);
    w.Key("revolutions").Int(r.revolutions).Key("mean_reference_frequency_hz").Number(r.mean_reference_hz);
  }
  w.Key(x).BeginArray();
  for (double f : r.spectrum.frequency) w.Number(f);
  w.EndArray().Key("amplitude").BeginArray();
  for (double a : r.spectrum.amplitude) w.Number(a);
  w.EndArray().Key("peaks").BeginArray();
  for (const Peak& p : r.peaks)
    w.BeginObject().Key(x).Number(p.frequency).Key("amplitude").Number(p.amplitude).Key("label").String(p.label).EndObject();
  w.EndArray().EndObject();
}

void Plot(const SpectrumResult& r, const std::string& png) {
  const RecordedSignal& s = r.signal;
  const PlotLabels labels{
      .title = (r.orders ? "Order spectrum of " : "Amplitude spectrum of ") + s.path + " [" + s.column_name + "]",
      .x_label = r.orders ? "order of " + r.reference : "frequency (Hz)",
      .y_label = "amplitude" + (s.unit.empty() ? std::string() : " (" + s.unit + ")") + ", " +
                 std::string(WindowName(r.spectrum.window)) + " window"};
  PlotSpectrum(labels, r.spectrum, r.peaks, r.lines, png);
}

}  // namespace

int SpectrumCommand(const SpectrumArgs& args, std::ostream& out, std::ostream& err) {
  try {
    if (!args.png.empty()) CheckPngPath(args.png);
    const SpectrumResult r = Compute(args, err);
    if (!args.png.empty()) Plot(r, args.png);
    if (args.json)
      WriteJson(r, out);
    else
      WriteText(r, out);
    return kExitSuccess;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli

#include "tools/cli/compare_command.h"

#include <algorithm>
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
#include "tools/signal/condition_indicators.h"
#include "tools/signal/fft.h"
#include "tools/signal/sideband_energy_ratio.h"
#include "tools/signal/signal_io.h"
#include "tools/signal/time_synchronous_average.h"

namespace orrery::cli {
namespace {

using namespace orrery::signal;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One run's record, spectrum, SER and indicators
struct Run {
  RecordedSignal signal;
  Spectrum spectrum;
  SidebandEnergy ser;
  ConditionIndicators indicators;
  int revolutions = 0;
};

struct Comparison {
  Run healthy, faulty;
  KinematicLine mesh, modulation;
  double ser_ratio = kNaN;
  bool tsa = false;
  std::string member;
  int samples_per_revolution = 0, mesh_order = 0;
};

std::string Fmt(const char* format, double x) {
  if (std::isnan(x)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

// The mesh and modulation lines from the faulty file
void ReadLines(const Hdf5Reader& file, const CompareArgs& args, Comparison& c) {
  const std::vector<KinematicLine> lines = ReadKinematicLines(file);
  const std::optional<KinematicLine> mesh = FindLine(lines, LineKind::kMesh, args.mesh);
  if (!mesh)
    throw std::runtime_error(file.path() + ": /kinematics/lines: no mesh line" + (args.mesh.empty() ? "" : " named '" + args.mesh + "'"));
  c.mesh = *mesh;
  if (args.modulation.empty()) {
    const std::optional<KinematicLine> fault = FindLine(lines, LineKind::kFault);
    if (!fault)
      throw std::runtime_error(file.path() + ": /kinematics/lines: no fault line (a faulty run's file lists its fault "
                               "frequency; name another line with --modulation)");
    c.modulation = *fault;
    return;
  }
  for (const KinematicLine& line : lines)
    if (line.name == args.modulation) {
      c.modulation = line;
      return;
    }
  throw std::runtime_error(file.path() + ": /kinematics/lines: no line named '" + args.modulation + "'");
}

// Indicators on the TSA over the member's revolutions
void TsaIndicators(const Hdf5Reader& h, const Hdf5Reader& f, const CompareArgs& args, Comparison& c) {
  c.tsa = true;
  c.member = ReferenceAnglePath(args.tsa_member);
  const std::vector<double> angle_h = ReadReferenceAngle(h, args.tsa_member, c.healthy.signal);
  const std::vector<double> angle_f = ReadReferenceAngle(f, args.tsa_member, c.faulty.signal);
  SynchronousAverage tsa_h, tsa_f;
  try {
    c.samples_per_revolution = std::max(DefaultSamplesPerRevolution(angle_h), DefaultSamplesPerRevolution(angle_f));
    tsa_h = TimeSynchronousAverage(c.healthy.signal.values, angle_h, c.samples_per_revolution);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(h.path() + ": " + c.member + ": " + e.what());
  }
  try {
    tsa_f = TimeSynchronousAverage(c.faulty.signal.values, angle_f, c.samples_per_revolution);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(f.path() + ": " + c.member + ": " + e.what());
  }
  // Mesh order: f_m over the member's mean rotation frequency, a whole number
  const std::vector<double> rising = RisingAngle(angle_f);
  const double member_hz = (rising.back() - rising.front()) / (2 * std::numbers::pi) /
                           (c.faulty.signal.time_s.back() - c.faulty.signal.time_s.front());
  const double order = c.mesh.frequency_hz / member_hz;
  c.mesh_order = static_cast<int>(std::lround(order));
  if (c.mesh_order < 1 || std::abs(order - c.mesh_order) > 0.05)
    throw std::runtime_error(f.path() + ": " + c.member + ": the mesh frequency " + c.mesh.name + " is " + Fmt("%.4g", order) +
                             " orders of the member (mean " + Fmt("%.6g", member_hz) +
                             " Hz), not a whole number: the TSA needs the member that carries the gear");
  const RegularComponents regular{.mesh_order = c.mesh_order};
  try {
    c.healthy.indicators = CalcConditionIndicators(tsa_h.values, regular);
    const double baseline[] = {c.healthy.indicators.residual_variance};
    c.faulty.indicators = CalcConditionIndicators(tsa_f.values, regular, baseline);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(f.path() + ": " + c.member + ": " + e.what());
  }
  c.healthy.revolutions = tsa_h.revolutions;
  c.faulty.revolutions = tsa_f.revolutions;
}

// Statistics of the raw record; the TSA-based indicators stay undefined
ConditionIndicators RecordIndicators(const std::vector<double>& x) {
  ConditionIndicators i;
  i.rms = Rms(x);
  i.peak = PeakAbs(x);
  i.crest_factor = CrestFactor(x);
  i.kurtosis = Kurtosis(x);
  i.fm0 = i.fm4 = i.na4 = kNaN;
  return i;
}

Comparison Compute(const CompareArgs& args) {
  Hdf5Reader h(args.healthy), f(args.faulty);
  Comparison c;
  const double t0 = args.t0.value_or(-std::numeric_limits<double>::infinity());
  c.healthy.signal = ReadSignal(h, args.signal, args.column, t0);
  c.faulty.signal = ReadSignal(f, args.signal, args.column, t0);
  const double fs = c.healthy.signal.sample_rate_hz;
  if (std::abs(c.faulty.signal.sample_rate_hz - fs) > 1e-6 * fs)
    throw std::runtime_error(f.path() + ": /time: sample rate " + Fmt("%.9g", c.faulty.signal.sample_rate_hz) + " Hz, " +
                             h.path() + " has " + Fmt("%.9g", fs) + " Hz");
  ReadLines(f, args, c);

  // Spectra of equal length, SER of each
  const WindowKind window = ParseWindowKind(args.window);
  const int n = FastFftLength(static_cast<int>(std::min(c.healthy.signal.values.size(), c.faulty.signal.values.size())));
  for (Run* run : {&c.healthy, &c.faulty}) {
    run->spectrum = AmplitudeSpectrum(std::span<const double>(run->signal.values).first(n), fs, window);
    try {
      run->ser = SidebandEnergyRatio(run->spectrum, c.mesh.frequency_hz, c.modulation.frequency_hz);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(run->signal.file + ": " + run->signal.path + ": " + e.what());
    }
  }
  c.ser_ratio = c.healthy.ser.ratio > 0 ? c.faulty.ser.ratio / c.healthy.ser.ratio : kNaN;

  // Indicators
  if (args.tsa_member.empty()) {
    c.healthy.indicators = RecordIndicators(c.healthy.signal.values);
    c.faulty.indicators = RecordIndicators(c.faulty.signal.values);
  } else {
    TsaIndicators(h, f, args, c);
  }
  return c;
}

// The indicators in output order
std::vector<std::pair<const char*, double ConditionIndicators::*>> IndicatorFields() {
  return {{"rms", &ConditionIndicators::rms},
          {"peak", &ConditionIndicators::peak},
          {"crest_factor", &ConditionIndicators::crest_factor},
          {"kurtosis", &ConditionIndicators::kurtosis},
          {"fm0", &ConditionIndicators::fm0},
          {"fm4", &ConditionIndicators::fm4},
          {"na4", &ConditionIndicators::na4}};
}

void WriteText(const Comparison& c, std::ostream& out) {
  const RecordedSignal& s = c.faulty.signal;
  out << "healthy      " << c.healthy.signal.file << "\n";
  out << "faulty       " << s.file << "\n";
  out << "signal       " << s.path << " [" << s.column_name << "]" << (s.unit.empty() ? "" : " (" + s.unit + ")") << ", "
      << c.faulty.spectrum.samples << " samples at " << Fmt("%.6g", s.sample_rate_hz) << " Hz, resolution "
      << Fmt("%.4g", c.faulty.spectrum.resolution) << " Hz, window " << WindowName(c.faulty.spectrum.window) << "\n";
  out << "mesh         " << c.mesh.name << " = " << Fmt("%.6g", c.mesh.frequency_hz) << " Hz, modulation "
      << c.modulation.name << " = " << Fmt("%.6g", c.modulation.frequency_hz) << " Hz\n\n";
  out << "sideband energy ratio (" << c.faulty.ser.harmonics << " mesh harmonics, " << c.faulty.ser.sidebands
      << " sideband pairs)\n";
  out << "  healthy          " << Fmt("%.6g", c.healthy.ser.ratio) << "\n";
  out << "  faulty           " << Fmt("%.6g", c.faulty.ser.ratio) << "\n";
  out << "  faulty/healthy   " << (std::isnan(c.ser_ratio) ? std::string("inf") : Fmt("%.6g", c.ser_ratio) + " (" +
                                     Fmt("%+.1f", 10 * std::log10(c.ser_ratio)) + " dB)") << "\n\n";
  if (c.tsa)
    out << "indicators of the TSA over " << c.member << " (" << c.healthy.revolutions << " and " << c.faulty.revolutions
        << " revolutions, " << c.samples_per_revolution << " samples per revolution, mesh order " << c.mesh_order << ")\n";
  else
    out << "indicators of the records (FM0, FM4, NA4 need a time-synchronous average: --tsa MEMBER)\n";
  out << "  name                healthy         faulty\n";
  for (const auto& [name, field] : IndicatorFields())
    out << "  " << name << std::string(14 - std::string(name).size(), ' ') << Fmt("%15.6g", c.healthy.indicators.*field)
        << Fmt("%15.6g", c.faulty.indicators.*field) << "\n";
}

void WriteJson(const Comparison& c, std::ostream& out) {
  const RecordedSignal& s = c.faulty.signal;
  JsonWriter w(out);
  w.BeginObject();
  w.Key("healthy").String(c.healthy.signal.file).Key("faulty").String(s.file);
  w.Key("signal").String(s.path).Key("column").String(s.column_name).Key("unit").String(s.unit);
  w.Key("window").String(WindowName(c.faulty.spectrum.window)).Key("samples").Int(c.faulty.spectrum.samples);
  w.Key("sample_rate_hz").Number(s.sample_rate_hz).Key("resolution_hz").Number(c.faulty.spectrum.resolution);
  w.Key("mesh").BeginObject().Key("name").String(c.mesh.name).Key("frequency_hz").Number(c.mesh.frequency_hz).EndObject();
  w.Key("modulation").BeginObject().Key("name").String(c.modulation.name).Key("frequency_hz").Number(c.modulation.frequency_hz).EndObject();
  w.Key("sideband_energy_ratio").Number(c.ser_ratio);
  w.Key("ser").BeginObject().Key("healthy").Number(c.healthy.ser.ratio).Key("faulty").Number(c.faulty.ser.ratio);
  w.Key("harmonics").Int(c.faulty.ser.harmonics).Key("sidebands").Int(c.faulty.ser.sidebands).EndObject();
  w.Key("indicator_signal").String(c.tsa ? "tsa" : "record");
  w.Key("indicators").BeginObject();
  for (const auto& [name, field] : IndicatorFields())
    w.Key(name).BeginObject().Key("healthy").Number(c.healthy.indicators.*field).Key("faulty").Number(c.faulty.indicators.*field).EndObject();
  w.EndObject().Key("tsa");
  if (c.tsa) {
    w.BeginObject().Key("member").String(c.member).Key("samples_per_revolution").Int(c.samples_per_revolution);
    w.Key("revolutions_healthy").Int(c.healthy.revolutions).Key("revolutions_faulty").Int(c.faulty.revolutions);
    w.Key("mesh_order").Int(c.mesh_order).EndObject();
  } else {
    w.Null();
  }
  w.EndObject();
}

void Plot(const Comparison& c, const std::string& png) {
  const RecordedSignal& s = c.faulty.signal;
  const PlotLabels labels{.title = "Healthy and faulty: " + s.path + " [" + s.column_name + "]",
                          .x_label = "frequency (Hz)",
                          .y_label = "amplitude" + (s.unit.empty() ? std::string() : " (" + s.unit + ")") + ", " +
                                     std::string(WindowName(c.faulty.spectrum.window)) + " window"};
  const SerSummary ser{.healthy = c.healthy.ser.ratio, .faulty = c.faulty.ser.ratio, .ratio = c.ser_ratio,
                       .harmonics = c.faulty.ser.harmonics, .sidebands = c.faulty.ser.sidebands};
  PlotOverlay(labels, c.healthy.spectrum, c.faulty.spectrum, c.mesh, c.modulation, ser, png);
}

}  // namespace

int CompareCommand(const CompareArgs& args, std::ostream& out, std::ostream& err) {
  try {
    if (!args.png.empty()) CheckPngPath(args.png);
    const Comparison c = Compute(args);
    if (!args.png.empty()) Plot(c, args.png);
    if (args.json)
      WriteJson(c, out);
    else
      WriteText(c, out);
    return kExitSuccess;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli

#include "tools/study/output_extraction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/condition_indicators.h"
#include "tools/signal/fft.h"
#include "tools/signal/kinematic_lines.h"
#include "tools/signal/peaks.h"
#include "tools/signal/sideband_energy_ratio.h"
#include "tools/signal/signal_io.h"
#include "tools/signal/time_synchronous_average.h"

namespace orrery::study {
namespace {

using namespace orrery::signal;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

[[noreturn]] void Fail(const Hdf5Reader& file, const std::string& object,
                       const std::string& reason) {
  throw std::runtime_error(file.path() + ": " + object + ": " + reason);
}

// The unit of column c: the "unit" attribute, or its c-th entry when it lists one per column
std::string ColumnUnit(const Hdf5Reader& file, const std::string& path, int column, int count) {
  if (!file.HasAttribute(path, "unit")) return "";
  const std::string unit = file.ReadStringAttribute(path, "unit");
  const std::vector<std::string> units = SplitAttributeList(unit);
  return count > 1 && static_cast<int>(units.size()) == count
             ? units[static_cast<std::size_t>(column)]
             : unit;
}

// The window's start (s): from_s, or from_fraction of the way through the recorded time
double WindowStart(const StudyOutput& o, const std::vector<double>& time) {
  if (o.from_fraction < 0 || time.empty()) return o.from_s;
  return time.front() + o.from_fraction * (time.back() - time.front());
}

// The column's values at the rows whose time lies in the window (any sampling)
std::vector<double> WindowValues(const Hdf5Reader& file, const StudyOutput& o, int forced_column,
                                 std::string* unit) {
  if (!file.IsDataset(o.dataset)) Fail(file, o.dataset, "no such dataset");
  if (!file.IsDataset("/time")) Fail(file, "/time", "no such dataset (not a result file?)");
  const Eigen::MatrixXd data = file.ReadMatrix(o.dataset);
  const std::vector<double> time = file.ReadVector("/time");
  if (data.rows() != static_cast<Eigen::Index>(time.size()))
    Fail(file, o.dataset,
         std::to_string(data.rows()) + " rows, /time has " + std::to_string(time.size()));
  const int cols = static_cast<int>(data.cols());
  const int c = forced_column >= 0 ? forced_column : DatasetColumn(file, o.dataset, o.column, cols);
  if (c >= cols) Fail(file, o.dataset, "no column " + std::to_string(c));
  *unit = ColumnUnit(file, o.dataset, c, cols);
  std::vector<double> x;
  const double from_s = WindowStart(o, time);
  for (std::size_t i = 0; i < time.size(); ++i)
    if (time[i] >= from_s && time[i] <= o.to_s)
      x.push_back(data(static_cast<Eigen::Index>(i), c));
  if (x.empty()) {
    std::ostringstream msg;
    msg << "no rows in the window [" << from_s << ", " << o.to_s << "] s";
    if (!time.empty())
      msg << " (the run recorded " << time.front() << " to " << time.back() << " s)";
    Fail(file, o.dataset, msg.str());
  }
  return x;
}

double Statistic(StudyOutputKind kind, const std::vector<double>& x) {
  const bool any_nan = std::any_of(x.begin(), x.end(), [](double v) { return std::isnan(v); });
  if (any_nan && kind != StudyOutputKind::kFinal) return kNaN;
  double r = 0;
  switch (kind) {
    case StudyOutputKind::kPeak:
      for (double v : x) r = std::max(r, std::abs(v));
      return r;
    case StudyOutputKind::kRms:
      for (double v : x) r += v * v;
      return std::sqrt(r / static_cast<double>(x.size()));
    case StudyOutputKind::kMean:
      for (double v : x) r += v;
      return r / static_cast<double>(x.size());
    case StudyOutputKind::kMin: return *std::min_element(x.begin(), x.end());
    case StudyOutputKind::kMax:
    case StudyOutputKind::kMaxStress: return *std::max_element(x.begin(), x.end());
    case StudyOutputKind::kFinal: return x.back();
    default: return kNaN;
  }
}

// The record from `from` to `to`, uniformly sampled
RecordedSignal Record(const Hdf5Reader& file, const StudyOutput& o) {
  const double from_s = o.from_fraction < 0 ? o.from_s : WindowStart(o, file.ReadVector("/time"));
  RecordedSignal s = ReadSignal(file, o.dataset, o.column, from_s);
  const auto end = std::upper_bound(s.time_s.begin(), s.time_s.end(), o.to_s);
  const auto n = static_cast<std::size_t>(end - s.time_s.begin());
  if (n < static_cast<std::size_t>(kMinSignalSamples))
    Fail(file, o.dataset,
         "record too short: " + std::to_string(n) + " samples in the window (need at least " +
             std::to_string(kMinSignalSamples) + ")");
  s.time_s.resize(n);
  s.values.resize(n);
  return s;
}

Spectrum RecordSpectrum(const RecordedSignal& s, const std::string& window) {
  const int n = FastFftLength(static_cast<int>(s.values.size()));
  return AmplitudeSpectrum(std::span<const double>(s.values).first(static_cast<std::size_t>(n)),
                           s.sample_rate_hz, ParseWindowKind(window));
}

// A frequency given by name (a kinematic line of the file) or in Hz
double Frequency(const Hdf5Reader& file, const std::string& name, double hz) {
  if (name.empty()) return hz;
  for (const KinematicLine& line : ReadKinematicLines(file))
    if (line.name == name) return line.frequency_hz;
  Fail(file, "/kinematics/lines", "no line named '" + name + "'");
}

// The amplitude of the line at f (see the header)
double LineAmplitude(const Hdf5Reader& file, const StudyOutput& o, const Spectrum& s, double f) {
  const int last = static_cast<int>(s.amplitude.size()) - 1;
  const double k0 = f / s.resolution;
  if (!(f > 0) || k0 > last)
    Fail(file, o.dataset,
         "frequency " + std::to_string(f) + " Hz is not inside (0, " +
             std::to_string(s.frequency.back()) + "] Hz, the record's band");
  const int half = MainLobeHalfWidthBins(s.window);
  const int lo = std::max(1, static_cast<int>(std::ceil(k0 - half)));
  const int hi = std::min(last, static_cast<int>(std::floor(k0 + half)));
  int best = std::clamp(static_cast<int>(std::lround(k0)), lo, std::max(lo, hi));
  for (int k = lo; k <= hi; ++k)
    if (s.amplitude[static_cast<std::size_t>(k)] > s.amplitude[static_cast<std::size_t>(best)])
      best = k;
  const auto& a = s.amplitude;
  const auto b = static_cast<std::size_t>(best);
  const bool local_max = best > 0 && best < last && a[b] > a[b - 1] && a[b] >= a[b + 1];
  return local_max ? InterpolatePeak(s, best).amplitude : a[b];
}

double Amplitude(const Hdf5Reader& file, const StudyOutput& o, std::string* unit) {
  const RecordedSignal s = Record(file, o);
  *unit = s.unit;
  double f = o.harmonic * Frequency(file, o.line, o.frequency_hz);
  if (o.sideband != 0) f += o.sideband * Frequency(file, o.modulation, o.modulation_hz);
  return LineAmplitude(file, o, RecordSpectrum(s, o.window), f);
}

double SidebandRatio(const Hdf5Reader& file, const StudyOutput& o, std::string* unit) {
  const RecordedSignal s = Record(file, o);
  unit->assign(1, '1');  // dimensionless
  const double mesh = Frequency(file, o.mesh, o.mesh_hz);
  const double modulation = Frequency(file, o.modulation, o.modulation_hz);
  try {
    return SidebandEnergyRatio(RecordSpectrum(s, o.window), mesh, modulation,
                               {.harmonics = o.harmonics, .sidebands = o.sidebands})
        .ratio;
  } catch (const std::invalid_argument& e) {
    Fail(file, o.dataset, e.what());
  }
}

// The mesh order of a TSA: given, or f_mesh over the member's mean rotation frequency
int MeshOrder(const Hdf5Reader& file, const StudyOutput& o, const RecordedSignal& s,
              const std::vector<double>& angle) {
  if (o.mesh_order > 0) return o.mesh_order;
  const double mesh = Frequency(file, o.mesh, o.mesh_hz);
  const std::vector<double> rising = RisingAngle(angle);
  const double member_hz = (rising.back() - rising.front()) / (2 * std::numbers::pi) /
                           (s.time_s.back() - s.time_s.front());
  const double order = mesh / member_hz;
  const int z = static_cast<int>(std::lround(order));
  if (z < 1 || std::abs(order - z) > 0.05)
    Fail(file, ReferenceAnglePath(o.tsa),
         "the mesh frequency is " + std::to_string(order) +
             " orders of the member, not a whole number: the TSA needs the member that carries the "
             "gear");
  return z;
}

double Indicator(const Hdf5Reader& file, const StudyOutput& o, std::string* unit) {
  const RecordedSignal s = Record(file, o);
  const bool dimensionless = o.indicator != "rms" && o.indicator != "peak";
  *unit = dimensionless ? "1" : s.unit;
  ConditionIndicators c;
  if (o.tsa.empty()) {
    c.rms = Rms(s.values);
    c.peak = PeakAbs(s.values);
    c.crest_factor = CrestFactor(s.values);
    c.kurtosis = Kurtosis(s.values);
  } else {
    try {
      const std::vector<double> angle = ReadReferenceAngle(file, o.tsa, s);
      const int per_rev = o.samples_per_revolution > 0 ? o.samples_per_revolution
                                                       : DefaultSamplesPerRevolution(angle);
      const SynchronousAverage tsa = TimeSynchronousAverage(s.values, angle, per_rev);
      c = CalcConditionIndicators(tsa.values, {.mesh_order = MeshOrder(file, o, s, angle)});
    } catch (const std::invalid_argument& e) {
      Fail(file, ReferenceAnglePath(o.tsa), e.what());
    }
  }
  if (o.indicator == "rms") return c.rms;
  if (o.indicator == "peak") return c.peak;
  if (o.indicator == "crest_factor") return c.crest_factor;
  if (o.indicator == "kurtosis") return c.kurtosis;
  if (o.indicator == "fm0") return c.fm0;
  if (o.indicator == "fm4") return c.fm4;
  return c.na4;
}

}  // namespace

double ExtractOutput(const Hdf5Reader& file, const StudyOutput& o, std::string* unit) {
  switch (o.kind) {
    case StudyOutputKind::kAmplitude: return Amplitude(file, o, unit);
    case StudyOutputKind::kSidebandEnergyRatio: return SidebandRatio(file, o, unit);
    case StudyOutputKind::kIndicator: return Indicator(file, o, unit);
    case StudyOutputKind::kMaxStress: {
      const double v = Statistic(o.kind, WindowValues(file, o, 0, unit));
      *unit = "Pa";
      return v;
    }
    default: return Statistic(o.kind, WindowValues(file, o, -1, unit));
  }
}

ExtractedOutputs ExtractOutputs(const std::string& path, const std::vector<StudyOutput>& outputs) {
  ExtractedOutputs x;
  x.values.assign(outputs.size(), kNaN);
  x.units.assign(outputs.size(), "");
  if (outputs.empty()) return x;
  std::optional<Hdf5Reader> file;
  try {
    file.emplace(path);
  } catch (const std::exception& e) {
    x.error = std::string("outputs: ") + e.what();
    return x;
  }
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    try {
      x.values[i] = ExtractOutput(*file, outputs[i], &x.units[i]);
    } catch (const std::exception& e) {
      if (x.error.empty()) x.error = "output '" + outputs[i].name + "': " + e.what();
    }
  }
  return x;
}

}  // namespace orrery::study

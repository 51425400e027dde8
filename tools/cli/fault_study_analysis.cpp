#include "tools/cli/fault_study_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <stdexcept>

#include "mbd/hdf5_reader.h"
#include "tools/signal/fft.h"
#include "tools/signal/peaks.h"
#include "tools/signal/sideband_energy_ratio.h"
#include "tools/signal/window.h"

namespace orrery::cli {
namespace {

using namespace orrery::signal;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The modulation of a damaged tooth's sidebands: f_p^H for a faulty planet, else the gear's fault line
KinematicLine ModulationLine(const std::vector<KinematicLine>& lines, const FaultStudyAnalysisOptions& o,
                             const std::string& file) {
  for (const KinematicLine& line : lines) {
    if (o.fault_on_planet && (line.name == "f_p^H" || line.name.rfind("f_p^H ", 0) == 0)) return line;
    if (!o.fault_on_planet && line.name == "f_fault " + o.fault_gear) return line;
  }
  throw std::runtime_error(file + ": /kinematics/lines: no " +
                           (o.fault_on_planet ? std::string("f_p^H line") : "line f_fault " + o.fault_gear));
}

// The interpolated peak nearest f in the spectrum, within 2 bins + 1 % of f
double FoundLine(const Spectrum& s, double f) {
  const double tolerance = 2 * s.resolution + 0.01 * f;
  int best = -1;
  for (int k = 1; k + 1 < static_cast<int>(s.amplitude.size()); ++k) {
    if (std::abs(s.frequency[k] - f) > tolerance) continue;
    if (s.amplitude[k] < s.amplitude[k - 1] || s.amplitude[k] < s.amplitude[k + 1]) continue;
    if (best < 0 || s.amplitude[k] > s.amplitude[best]) best = k;
  }
  return best < 0 ? kNaN : InterpolatePeak(s, best).frequency;
}

ConditionIndicators RecordIndicators(const std::vector<double>& x) {
  ConditionIndicators i;
  i.rms = Rms(x);
  i.peak = PeakAbs(x);
  i.crest_factor = CrestFactor(x);
  i.kurtosis = Kurtosis(x);
  i.fm0 = i.fm4 = i.na4 = kNaN;
  return i;
}

// The largest |force| of every lumped and contact branch from t0 on
MeshForcePeak PeakMeshForce(const Hdf5Reader& r, double t0) {
  MeshForcePeak peak;
  const Eigen::MatrixXd t = r.ReadMatrix("/time");
  auto scan = [&](const std::string& branch, const std::string& dataset) {
    const Eigen::MatrixXd f = r.ReadMatrix(dataset);
    for (Eigen::Index i = 0; i < std::min(f.rows(), t.rows()); ++i)
      if (t(i, 0) >= t0 && std::abs(f(i, 0)) > peak.force_n) peak = {std::abs(f(i, 0)), branch, t(i, 0)};
  };
  if (r.Exists("/gear_meshes"))
    for (const std::string& b : r.ListGroup("/gear_meshes")) scan(b, "/gear_meshes/" + b + "/force");
  if (r.Exists("/external"))
    for (const std::string& b : r.ListGroup("/external")) {
      const std::string g = "/external/" + b + "/";
      if (r.Exists(g + "line_of_action_force")) scan(b, g + "line_of_action_force");
      else if (r.Exists(g + "normal_force")) scan(b, g + "normal_force");
    }
  return peak;
}

// The largest von Mises stress of each flexible body with stress recovery, from t0 on
std::vector<StressPeak> PeakStresses(const Hdf5Reader& r, double t0, const std::map<std::string, int>& teeth) {
  std::vector<StressPeak> peaks;
  if (!r.Exists("/flexible_bodies")) return peaks;
  const Eigen::MatrixXd t = r.ReadMatrix("/time");
  for (const std::string& body : r.ListGroup("/flexible_bodies")) {
    const std::string path = "/flexible_bodies/" + body + "/von_mises_max";
    if (!r.Exists(path)) continue;
    const Eigen::MatrixXd vm = r.ReadMatrix(path);
    Eigen::Index row = -1;
    for (Eigen::Index i = 0; i < std::min(vm.rows(), t.rows()); ++i)
      if (t(i, 0) >= t0 && (row < 0 || vm(i, 0) > vm(row, 0))) row = i;
    if (row < 0) continue;
    StressPeak p{.body = body, .stress_pa = vm(row, 0), .time_s = t(row, 0), .node = std::lround(vm(row, 1)),
                 .position_m = Vec3(vm(row, 2), vm(row, 3), vm(row, 4))};
    p.radius_m = std::hypot(p.position_m.x(), p.position_m.y());
    const double angle = std::atan2(p.position_m.y(), p.position_m.x());
    p.angle_deg = angle * 180 / std::numbers::pi;
    if (const auto z = teeth.find(body); z != teeth.end() && z->second > 0) {
      const double pitch = 2 * std::numbers::pi / z->second;
      const long k = std::lround(angle / pitch);
      p.tooth = static_cast<int>(((k % z->second) + z->second) % z->second);
      p.tooth_offset_deg = (angle - k * pitch) * 180 / std::numbers::pi;
    }
    peaks.push_back(p);
  }
  return peaks;
}

// "f_m", "2 f_m", plus the sideband term
std::string SidebandLabel(const KinematicLine& mesh, const KinematicLine& mod, int k, int n) {
  std::string label = (k == 1 ? "" : std::to_string(k) + " ") + mesh.name;
  label += n > 0 ? " + " : " - ";
  if (std::abs(n) != 1) label += std::to_string(std::abs(n)) + " ";
  return label + mod.name;
}

double Db(double amplitude, double reference) {
  return amplitude > 0 ? 20 * std::log10(amplitude / reference) : -std::numeric_limits<double>::infinity();
}

// One run: record, spectrum on n samples, SER, indicators, peaks
void AnalyseRun(const Hdf5Reader& r, const FaultStudyAnalysisOptions& o, FaultStudyRun& run) {
  run.signal = ReadSignal(r, o.signal, o.column, o.t0_s);
  run.indicators = RecordIndicators(run.signal.values);
  run.mesh_force = PeakMeshForce(r, o.t0_s);
  run.stress = PeakStresses(r, o.t0_s, o.gear_teeth);
}

}  // namespace

FaultStudyAnalysis AnalyseFaultStudy(const std::string& healthy_h5, const std::string& faulty_h5,
                                     const FaultStudyAnalysisOptions& o) {
  const Hdf5Reader h(healthy_h5), f(faulty_h5);
  FaultStudyAnalysis a;
  AnalyseRun(h, o, a.healthy);
  AnalyseRun(f, o, a.faulty);
  const double fs = a.healthy.signal.sample_rate_hz;
  if (std::abs(a.faulty.signal.sample_rate_hz - fs) > 1e-6 * fs)
    throw std::runtime_error(faulty_h5 + ": /time: sample rate differs from " + healthy_h5 + "'s");

  // Kinematic lines of the faulty file: the mesh line and the modulation
  a.lines = ReadKinematicLines(f);
  const std::optional<KinematicLine> mesh = FindLine(a.lines, LineKind::kMesh);
  if (!mesh) throw std::runtime_error(faulty_h5 + ": /kinematics/lines: no mesh line");
  a.mesh = *mesh;
  a.modulation = ModulationLine(a.lines, o, faulty_h5);

  // Spectra of equal length (Hann), the mesh line found, SER of each
  const int n = FastFftLength(static_cast<int>(std::min(a.healthy.signal.values.size(), a.faulty.signal.values.size())));
  for (FaultStudyRun* run : {&a.healthy, &a.faulty}) {
    run->spectrum = AmplitudeSpectrum(std::span<const double>(run->signal.values).first(n), fs, WindowKind::kHann);
    try {
      run->ser = SidebandEnergyRatio(run->spectrum, a.mesh.frequency_hz, a.modulation.frequency_hz).ratio;
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(run->signal.Describe() + ": " + e.what());
    }
  }
  a.ser_ratio = a.healthy.ser > 0 ? a.faulty.ser / a.healthy.ser : kNaN;
  a.mesh_frequency_found_hz = FoundLine(a.healthy.spectrum, a.mesh.frequency_hz);

  // Sideband levels, k f_m +- n f_mod
  const bool acceleration = a.faulty.signal.unit == "m/s^2";
  a.db_reference = acceleration ? 1e-6 : 1.0;
  a.db_reference_text = acceleration ? "1e-6 m/s^2" : "1 " + (a.faulty.signal.unit.empty() ? std::string("(unit)") : a.faulty.signal.unit);
  const double nyquist = fs / 2;
  a.harmonics = o.harmonics;
  for (int k = 1; k <= o.harmonics; ++k)
    for (int m = -o.sidebands; m <= o.sidebands; ++m) {
      const double freq = k * a.mesh.frequency_hz + m * a.modulation.frequency_hz;
      if (m == 0 || freq <= 0 || freq >= 0.8 * nyquist) continue;
      SidebandLevel s{.frequency_hz = freq, .label = SidebandLabel(a.mesh, a.modulation, k, m), .harmonic = k, .order = m};
      s.healthy_db = Db(std::sqrt(2 * LinePower(a.healthy.spectrum, freq)), a.db_reference);
      s.faulty_db = Db(std::sqrt(2 * LinePower(a.faulty.spectrum, freq)), a.db_reference);
      a.sidebands.push_back(s);
    }
  return a;
}

}  // namespace orrery::cli

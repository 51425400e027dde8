#include "tools/cli/fault_study_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "import/scene.h"
#include "mbd/result_file.h"
#include "tools/cli/error_message.h"
#include "tools/cli/fault_study_analysis.h"
#include "tools/cli/forked_run.h"
#include "tools/cli/interrupt.h"
#include "tools/cli/json_writer.h"
#include "tools/cli/kinematic_lines_writer.h"
#include "tools/cli/progress_bar.h"
#include "tools/cli/run_command.h"
#include "tools/cli/signal_plots.h"
#include "tools/signal/peaks.h"

namespace orrery::cli {
namespace {

namespace fs = std::filesystem;
using namespace orrery::signal;

const char* const kResultNames[] = {"healthy.h5", "faulty.h5", "summary.json", "summary.md"};

std::string Fmt(const char* format, double x) {
  if (!std::isfinite(x)) return std::isnan(x) ? "-" : (x > 0 ? "inf" : "-inf");
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

// DIR made; its earlier results refused unless --force
void PrepareFolder(const FaultStudyArgs& args) {
  if (args.output_dir.empty()) throw std::invalid_argument("fault-study: give the output folder with -o DIR");
  std::error_code ec;
  if (fs::exists(args.output_dir, ec) && !fs::is_directory(args.output_dir, ec))
    throw std::invalid_argument(args.output_dir + ": exists and is not a folder");
  for (const char* name : kResultNames)
    if (fs::exists(fs::path(args.output_dir) / name, ec) && !args.force)
      throw std::invalid_argument(args.output_dir + ": holds the results of a fault study (" + name +
                                  "); pass --force to replace them, or name another folder with -o");
  fs::create_directories(args.output_dir, ec);
  if (ec) throw std::invalid_argument(args.output_dir + ": cannot make the folder: " + ec.message());
}

// The scene as written and its healthy twin; both must be gear trains and the first faulty
struct StudyScenes {
  Scene faulty, healthy;
};

void CheckFaultyScene(const Scene& faulty, const std::string& path) {
  if (faulty.kind != SceneKind::kGearTrain || faulty.gear_train->options.tooth_faults.empty())
    throw std::invalid_argument(path + ": declares no tooth faults; a fault study runs a gear-train scene "
                                "with its faults against the same scene without them");
}

StudyScenes LoadScenes(const FaultStudyArgs& args) {
  RunArgs run{.scene_path = args.scene_path, .end_time = args.end_time.value_or(kFaultStudyEndTime),
              .overrides = args.overrides};
  const std::vector<std::string> overrides = SceneOverrides(run);
  if (!fs::exists(args.scene_path)) throw std::invalid_argument("scene file " + args.scene_path + ": no such file");
  Scene faulty = LoadScene(args.scene_path, overrides, {.make_reduced_bodies = true});
  CheckFaultyScene(faulty, args.scene_path);
  Scene healthy = LoadScene(args.scene_path, overrides, {.make_reduced_bodies = true, .without_faults = true});
  return {std::move(faulty), std::move(healthy)};
}

// --signal, else the scene's first sensor
std::string StudySignal(const FaultStudyArgs& args, const Scene& scene) {
  if (!args.signal.empty()) return args.signal;
  if (scene.model->sensors.empty())
    throw std::invalid_argument(args.scene_path + ": has no sensors; add a `sensors:` list (the first is analysed) "
                                "or name a dataset with --signal");
  const Sensor& s = scene.model->sensors.front();
  return "/sensors/" + s.spec.name + "/" + s.quantity;
}

// Body name -> tooth count of every gear of the train
std::map<std::string, int> GearTeeth(const Scene& scene) {
  std::map<std::string, int> teeth;
  const gears::PlanetaryTrain& train = *scene.gear_train->train;
  for (const gears::TrainGear& g : train.gears) {
    if (g.planet_set < 0) {
      teeth[train.members[g.member].name] = g.teeth;
      continue;
    }
    const gears::PlanetSet& ps = train.planet_sets[g.planet_set];
    for (size_t i = 0; i < ps.angles_rad.size(); ++i) teeth[ps.name + std::to_string(i + 1)] = g.teeth;
  }
  return teeth;
}

// The work of one run in its child: DIR/<name> written, progress reported
ChildWork RunWork(const Scene& scene, const std::string& path) {
  return [&scene, path](const ProgressFn& progress) {
    SimulationOptions options = scene.simulation;
    options.interrupt = InterruptFlag();
    std::optional<ResultFile> result = ResultFile::Create(path);
    WriteKinematicLines(scene, *result);
    SimulationReport report = Simulate(*scene.model, options, &*result, progress);
    result->Close();
    return report;
  };
}

// Both runs at once, one child process each (forked_run.h), under one progress bar; a failed run
// is reported with its reason (the other stopped), an interrupt with where both runs stopped
struct RunTimes {
  double healthy_wall_s = 0, faulty_wall_s = 0, healthy_cpu_s = 0, faulty_cpu_s = 0;
};

RunTimes RunBoth(const Scene& healthy, const Scene& faulty, const fs::path& dir, ProgressBar& bar) {
  const std::string paths[2] = {(dir / "healthy.h5").string(), (dir / "faulty.h5").string()};
  const char* const names[2] = {"healthy", "faulty"};
  for (const Scene* s : {&healthy, &faulty}) CheckSimulationSettings(*s->model, s->simulation);
  const std::vector<ChildOutcome> r =
      RunForked({{RunWork(healthy, paths[0]), healthy.simulation.end_time},
                 {RunWork(faulty, paths[1]), faulty.simulation.end_time}},
                [&](const SimulationProgress& p) { bar.Update(p); });
  for (int i = 0; i < 2; ++i)
    if (r[i].status == ChildOutcome::Status::kFailed)
      throw std::runtime_error(std::string(names[i]) + " run failed: " + r[i].reason +
                               (fs::is_regular_file(paths[i]) ? " (" + paths[i] + " keeps its rows)" : "") +
                               (r[1 - i].status == ChildOutcome::Status::kStopped
                                                         ? std::string("; the ") + names[1 - i] + " run was stopped"
                                                         : ""));
  for (int i = 0; i < 2; ++i)
    if (r[i].status == ChildOutcome::Status::kInterrupted)
      throw SimulationInterrupted(r[i].signal, r[i].last.t);
  return {.healthy_wall_s = r[0].last.wall_s, .faulty_wall_s = r[1].last.wall_s, .healthy_cpu_s = r[0].cpu_time_s,
          .faulty_cpu_s = r[1].cpu_time_s};
}

void WriteStress(JsonWriter& w, const std::vector<StressPeak>& peaks) {
  if (peaks.empty()) {
    w.Null();
    return;
  }
  const StressPeak* p = &peaks.front();
  for (const StressPeak& q : peaks)
    if (q.stress_pa > p->stress_pa) p = &q;
  w.BeginObject().Key("value").Number(p->stress_pa).Key("body").String(p->body).Key("time_s").Number(p->time_s);
  w.Key("node").Int(p->node).Key("position_m").BeginArray();
  for (int k = 0; k < 3; ++k) w.Number(p->position_m(k));
  w.EndArray().Key("radius_m").Number(p->radius_m).Key("angle_deg").Number(p->angle_deg);
  w.Key("tooth");
  if (p->tooth >= 0) w.Int(p->tooth);
  else w.Null();
  w.Key("tooth_offset_deg").Number(p->tooth >= 0 ? p->tooth_offset_deg : NAN).EndObject();
}

// What the study chose, in words (summary.json "settings.why", summary.md)
std::string WhyText(const FaultStudyAnalysis& a, double end_time, double t0) {
  const double record = a.faulty.spectrum.samples / a.faulty.signal.sample_rate_hz;
  return "simulated " + Fmt("%.3g", end_time) + " s, analysed from t0 = " + Fmt("%.3g", t0) + " s (start transient skipped): " +
         Fmt("%.4g", record) + " s record, resolution " + Fmt("%.3g", a.faulty.spectrum.resolution) +
         " Hz; the sideband energy ratio needs lines " + a.modulation.name + " = " + Fmt("%.4g", a.modulation.frequency_hz) +
         " Hz apart to lie more than 4 Hann bins apart (T > " + Fmt("%.3g", 4 / a.modulation.frequency_hz) + " s)";
}

struct StudyTimes {
  double healthy_wall_s = 0, faulty_wall_s = 0, total_wall_s = 0, end_time_s = 0, t0_s = 0;
  double healthy_cpu_s = 0, faulty_cpu_s = 0;  // CPU time of each run's process
};

void WriteSummaryJson(const FaultStudyArgs& args, const FaultStudyAnalysis& a, const StudyTimes& t, std::ostream& out) {
  JsonWriter w(out);
  const RecordedSignal& s = a.faulty.signal;
  w.BeginObject().Key("scene").String(args.scene_path).Key("folder").String(args.output_dir);
  w.Key("settings").BeginObject().Key("end_time_s").Number(t.end_time_s).Key("t0_s").Number(t.t0_s);
  w.Key("why").String(WhyText(a, t.end_time_s, t.t0_s)).EndObject();
  w.Key("signal").String(s.path).Key("column").String(s.column_name).Key("unit").String(s.unit);
  w.Key("sample_rate_hz").Number(s.sample_rate_hz).Key("samples").Int(a.faulty.spectrum.samples);
  w.Key("resolution_hz").Number(a.faulty.spectrum.resolution).Key("window").String("hann");
  w.Key("mesh_frequency_hz").Number(a.mesh.frequency_hz).Key("mesh_frequency_found_hz").Number(a.mesh_frequency_found_hz);
  w.Key("modulation").BeginObject().Key("name").String(a.modulation.name).Key("frequency_hz").Number(a.modulation.frequency_hz).EndObject();
  w.Key("db_reference").String(a.db_reference_text).Key("sidebands").BeginArray();
  for (const SidebandLevel& sb : a.sidebands)
    w.BeginObject().Key("frequency_hz").Number(sb.frequency_hz).Key("label").String(sb.label).Key("healthy_db")
        .Number(sb.healthy_db).Key("faulty_db").Number(sb.faulty_db).EndObject();
  w.EndArray().Key("sideband_energy_ratio").Number(a.ser_ratio);
  w.Key("ser").BeginObject().Key("healthy").Number(a.healthy.ser).Key("faulty").Number(a.faulty.ser).EndObject();
  w.Key("indicators").BeginObject();
  const std::pair<const char*, double ConditionIndicators::*> fields[] = {
      {"rms", &ConditionIndicators::rms}, {"peak", &ConditionIndicators::peak},
      {"crest_factor", &ConditionIndicators::crest_factor}, {"kurtosis", &ConditionIndicators::kurtosis}};
  for (const auto& [name, field] : fields)
    w.Key(name).BeginObject().Key("healthy").Number(a.healthy.indicators.*field).Key("faulty").Number(a.faulty.indicators.*field).EndObject();
  w.EndObject().Key("peak_mesh_force_n").BeginObject();
  for (const auto& [name, run] : {std::pair{"healthy", &a.healthy}, std::pair{"faulty", &a.faulty}})
    w.Key(name).BeginObject().Key("value").Number(run->mesh_force.force_n).Key("branch").String(run->mesh_force.branch)
        .Key("time_s").Number(run->mesh_force.time_s).EndObject();
  w.EndObject().Key("max_von_mises_pa");
  if (a.faulty.stress.empty()) {
    w.Null();
  } else {
    w.BeginObject().Key("healthy");
    WriteStress(w, a.healthy.stress);
    w.Key("faulty");
    WriteStress(w, a.faulty.stress);
    w.EndObject();
  }
  w.Key("wall_time_s").BeginObject().Key("healthy").Number(t.healthy_wall_s).Key("faulty").Number(t.faulty_wall_s)
      .Key("total").Number(t.total_wall_s).EndObject();
  w.Key("cpu_time_s").BeginObject().Key("healthy").Number(t.healthy_cpu_s).Key("faulty").Number(t.faulty_cpu_s).EndObject();
  w.EndObject();
  out << "\n";
}

void WriteSummaryMd(const FaultStudyArgs& args, const FaultStudyAnalysis& a, const StudyTimes& t, std::ostream& out) {
  const RecordedSignal& s = a.faulty.signal;
  out << "# Fault study: " << args.scene_path << "\n\n";
  out << "Healthy twin (the scene's tooth faults removed) against the scene as written; `healthy.h5`, `faulty.h5`.\n"
      << WhyText(a, t.end_time_s, t.t0_s) << ".\n\n";
  out << "- signal: `" << s.path << "` [" << s.column_name << "] (" << s.unit << "), " << a.faulty.spectrum.samples
      << " samples at " << Fmt("%.6g", s.sample_rate_hz) << " Hz, Hann window\n";
  out << "- mesh frequency: " << Fmt("%.2f", a.mesh.frequency_hz) << " Hz kinematic, " << Fmt("%.2f", a.mesh_frequency_found_hz)
      << " Hz found (healthy spectrum)\n";
  out << "- modulation: " << a.modulation.name << " = " << Fmt("%.2f", a.modulation.frequency_hz) << " Hz\n";
  out << "- sideband energy ratio (3 mesh harmonics): healthy " << Fmt("%.4g", a.healthy.ser) << ", faulty "
      << Fmt("%.4g", a.faulty.ser) << ", faulty/healthy " << Fmt("%.3g", a.ser_ratio) << " ("
      << Fmt("%+.1f", 10 * std::log10(a.ser_ratio)) << " dB)\n";
  out << "- peak mesh force: healthy " << Fmt("%.5g", a.healthy.mesh_force.force_n) << " N (" << a.healthy.mesh_force.branch
      << "), faulty " << Fmt("%.5g", a.faulty.mesh_force.force_n) << " N (" << a.faulty.mesh_force.branch << ", t = "
      << Fmt("%.4g", a.faulty.mesh_force.time_s) << " s)\n";
  for (const StressPeak& p : a.faulty.stress)
    out << "- max von Mises (faulty) " << p.body << ": " << Fmt("%.4g", p.stress_pa * 1e-6) << " MPa at t = "
        << Fmt("%.4g", p.time_s) << " s, node " << p.node << ", r = " << Fmt("%.2f", p.radius_m * 1e3) << " mm, "
        << Fmt("%.1f", p.angle_deg) << " deg" << (p.tooth >= 0 ? ", tooth " + std::to_string(p.tooth) + " (" +
                                                     Fmt("%+.1f", p.tooth_offset_deg) + " deg from its centre line)" : "") << "\n";
  for (const StressPeak& p : a.healthy.stress)
    out << "- max von Mises (healthy) " << p.body << ": " << Fmt("%.4g", p.stress_pa * 1e-6) << " MPa\n";
  out << "\n| sideband | frequency (Hz) | healthy (dB re " << a.db_reference_text << ") | faulty (dB) | growth (dB) |\n"
      << "|---|---|---|---|---|\n";
  for (const SidebandLevel& sb : a.sidebands)
    out << "| " << sb.label << " | " << Fmt("%.2f", sb.frequency_hz) << " | " << Fmt("%.1f", sb.healthy_db) << " | "
        << Fmt("%.1f", sb.faulty_db) << " | " << Fmt("%+.1f", sb.faulty_db - sb.healthy_db) << " |\n";
  out << "\n| indicator | healthy | faulty |\n|---|---|---|\n";
  out << "| RMS | " << Fmt("%.4g", a.healthy.indicators.rms) << " | " << Fmt("%.4g", a.faulty.indicators.rms) << " |\n";
  out << "| peak | " << Fmt("%.4g", a.healthy.indicators.peak) << " | " << Fmt("%.4g", a.faulty.indicators.peak) << " |\n";
  out << "| crest factor | " << Fmt("%.4g", a.healthy.indicators.crest_factor) << " | "
      << Fmt("%.4g", a.faulty.indicators.crest_factor) << " |\n";
  out << "| kurtosis | " << Fmt("%.4g", a.healthy.indicators.kurtosis) << " | " << Fmt("%.4g", a.faulty.indicators.kurtosis)
      << " |\n";
  out << "\nwall time: healthy " << FormatDuration(t.healthy_wall_s) << ", faulty " << FormatDuration(t.faulty_wall_s)
      << " (run at once, one process each), study " << FormatDuration(t.total_wall_s) << "; CPU time: healthy "
      << FormatDuration(t.healthy_cpu_s) << ", faulty " << FormatDuration(t.faulty_cpu_s) << "\n";
}

// The PNG files
void DrawPlots(const FaultStudyArgs& args, const FaultStudyAnalysis& a) {
  const fs::path dir(args.output_dir);
  const RecordedSignal& s = a.faulty.signal;
  const std::string unit = s.unit.empty() ? "" : " (" + s.unit + ")";
  const PlotLabels overlay{.title = "Healthy and faulty: " + s.path + " [" + s.column_name + "]",
                           .x_label = "frequency (Hz)", .y_label = "amplitude" + unit + ", Hann window"};
  const SerSummary ser{.healthy = a.healthy.ser, .faulty = a.faulty.ser, .ratio = a.ser_ratio};
  PlotOverlay(overlay, a.healthy.spectrum, a.faulty.spectrum, a.mesh, a.modulation, ser, (dir / "overlay.png").string());
  // Each spectrum up to the mesh harmonics the summary lists, its peaks labelled as the summary's
  // sidebands are (k f_m +- n f_mod: the mesh line and the modulation only, so that a planet
  // fault's 2 f_p^H does not read as another line's multiple)
  const std::vector<KinematicLine> study_lines{a.mesh, a.modulation};
  const double top_hz = (a.harmonics + 0.5) * a.mesh.frequency_hz;
  for (const auto& [name, run] : {std::pair{"healthy", &a.healthy}, std::pair{"faulty", &a.faulty}}) {
    std::vector<Peak> peaks = FindPeaks(run->spectrum, {.max_peaks = 1000});
    std::erase_if(peaks, [&](const Peak& p) { return p.frequency > top_hz; });
    if (peaks.size() > 12) peaks.resize(12);  // the largest, labelled
    LabelPeaks(peaks, study_lines, 1.5 * run->spectrum.resolution);
    PlotSpectrum({.title = std::string(name) + " run: " + s.path + " [" + s.column_name + "]",
                  .x_label = "frequency (Hz)", .y_label = "amplitude" + unit},
                 run->spectrum, peaks, study_lines, (dir / (std::string(name) + "_spectrum.png")).string());
  }
  PlotTimeSignal({.title = "faulty run: " + s.path + " [" + s.column_name + "]", .x_label = "time (s)",
                  .y_label = s.column_name + unit},
                 s, (dir / "faulty_signal.png").string());
  for (const StressPeak& p : a.faulty.stress)
    PlotHotSpotStress((dir / "faulty.h5").string(), "/flexible_bodies/" + p.body + "/von_mises_max",
                      (dir / ("stress_" + p.body + ".png")).string(), "faulty run: largest von Mises stress of " + p.body);
}

}  // namespace

int RunFaultStudy(const Scene& faulty, const Scene& healthy, const FaultStudyArgs& args, std::ostream& out,
                  std::ostream& err) {
  const ProgressBar::Style style = args.quiet ? ProgressBar::Style::kNone
                                   : args.err_is_terminal ? ProgressBar::Style::kBar
                                                          : ProgressBar::Style::kLines;
  ProgressBar bar(err, style);
  const auto start = std::chrono::steady_clock::now();
  try {
    // The folder, the signal, the fault
    CheckFaultyScene(faulty, args.scene_path);
    PrepareFolder(args);
    const fs::path dir(args.output_dir);
    FaultStudyAnalysisOptions options{.signal = StudySignal(args, faulty), .t0_s = args.t0.value_or(kFaultStudyT0),
                                      .gear_teeth = GearTeeth(faulty)};
    const gears::TrainToothFault& fault = faulty.gear_train->options.tooth_faults.front();
    options.fault_gear = fault.gear;
    for (const gears::TrainGear& g : faulty.gear_train->train->gears)
      if (g.name == fault.gear) options.fault_on_planet = g.planet_set >= 0;
    StudyTimes times{.end_time_s = faulty.simulation.end_time, .t0_s = options.t0_s};
    if (!(options.t0_s < times.end_time_s))
      throw std::invalid_argument("--t0 " + Fmt("%g", options.t0_s) + " s: must lie before the end time " +
                                  Fmt("%g", times.end_time_s) + " s");

    // The two runs at once, under one progress bar
    InterruptGuard guard;
    const RunTimes run_times = RunBoth(healthy, faulty, dir, bar);
    times.healthy_wall_s = run_times.healthy_wall_s;
    times.faulty_wall_s = run_times.faulty_wall_s;
    times.healthy_cpu_s = run_times.healthy_cpu_s;
    times.faulty_cpu_s = run_times.faulty_cpu_s;
    bar.Finish();

    // Analysis, plots, summaries
    const FaultStudyAnalysis a = AnalyseFaultStudy((dir / "healthy.h5").string(), (dir / "faulty.h5").string(), options);
    if (args.plots) DrawPlots(args, a);
    times.total_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ofstream json(dir / "summary.json"), md(dir / "summary.md");
    WriteSummaryJson(args, a, times, json);
    WriteSummaryMd(args, a, times, md);
    if (!json || !md) throw std::runtime_error(args.output_dir + ": could not write summary.json / summary.md");
    std::ostringstream text;
    WriteSummaryMd(args, a, times, text);
    out << text.str() << std::flush;
    return kExitSuccess;
  } catch (const SimulationInterrupted& e) {
    bar.Abandon();
    ReportError(err, e.what());
    return kExitSignalBase + e.signal();
  } catch (const std::exception& e) {
    bar.Abandon();
    ReportError(err, e.what());
    return kExitFailure;
  }
}

int FaultStudyCommand(const FaultStudyArgs& args, std::ostream& out, std::ostream& err) {
  std::optional<StudyScenes> scenes;
  try {
    scenes = LoadScenes(args);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  return RunFaultStudy(scenes->faulty, scenes->healthy, args, out, err);
}

}  // namespace orrery::cli

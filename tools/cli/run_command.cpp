#include "tools/cli/run_command.h"

#include <charconv>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <system_error>

#include "import/scene.h"
#include "mbd/file_checks.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/xdmf_writer.h"
#include "tools/cli/kinematic_lines_writer.h"
#include "tools/cli/error_message.h"
#include "tools/cli/interrupt.h"
#include "tools/cli/progress_bar.h"

namespace orrery::cli {
namespace {

// Shortest text that reads back as the same double ("0.2", not "0.20000000000000001")
std::string ShortestText(double value) {
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(value);
}

// One "label   value" line of the summary
void SummaryLine(std::ostream& out, const char* label, const std::string& value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%-20s", label);
  out << buffer << value << '\n';
}

std::string Number(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

// Flexible bodies: the largest von Mises stress of the run and where, and the XDMF file that
// animates the recorded surfaces (written beside the result file).
void PrintFlexibleBodies(std::ostream& out, const Model& model, const std::string& output_path) {
  bool surfaces = false;
  for (const FlexibleBody& fb : model.flexible_bodies) {
    surfaces = surfaces || fb.options.record_surface;
    const std::string name = model.bodies[fb.body].name;
    const std::string path = "/flexible_bodies/" + name + "/von_mises_max";
    try {
      const Hdf5Reader r(output_path);
      if (!r.Exists(path)) continue;
      const Eigen::MatrixXd vm = r.ReadMatrix(path);
      if (vm.rows() == 0) continue;
      Eigen::Index row;
      vm.col(0).maxCoeff(&row);
      const std::string where = "t = " + Number("%.4g", r.ReadMatrix("/time")(row, 0)) + " s, node " +
                                Number("%.0f", vm(row, 1)) + " at (" + Number("%.4g", vm(row, 2)) + ", " +
                                Number("%.4g", vm(row, 3)) + ", " + Number("%.4g", vm(row, 4)) + ") m";
      SummaryLine(out, "max von Mises", name + ": " + Number("%.4g MPa", vm(row, 0) * 1e-6) + ", " + where);
    } catch (const std::exception& e) {
      SummaryLine(out, "max von Mises", name + ": not read: " + e.what());
    }
  }
  if (!surfaces) return;
  try {
    SummaryLine(out, "animation", WriteSurfaceXdmf(output_path).string() + " (ParaView)");
  } catch (const std::exception& e) {
    SummaryLine(out, "animation", std::string("not written: ") + e.what());
  }
}

// The run's health: "ok" with its numbers, or one line per warning.
void PrintHealth(std::ostream& out, const SimulationReport& report) {
  std::string numbers = "energy balance " + Number("%.2g", report.energy_residual_relative) + " of its scale";
  if (report.energy_quadrature_relative > 0.01)
    numbers += Number(" (rows resolve it to %.2g)", report.energy_quadrature_relative);
  if (report.omega_max_h >= 0) {
    numbers += ", omega_max h " + Number("%.3g", report.omega_max_h);
    if (report.omega_max_h > 3.14159 && report.rho_infinity <= 0.99)
      numbers += Number(" (stiffest mode not resolved, damped: rho_inf %.2g)", report.rho_infinity);
  }
  if (report.health.empty()) {
    SummaryLine(out, "health", "ok (" + numbers + ")");
    return;
  }
  SummaryLine(out, "health", std::to_string(report.health.size()) + " warning" +
                                 (report.health.size() > 1 ? "s" : "") + " (" + numbers + "; /health in the file)");
  for (const HealthWarning& w : report.health) {
    std::string line = Number("t = %.6g s: ", w.t) + w.element + ": " + w.cause;
    if (w.count > 1) line += " (" + std::to_string(w.count) + " times, worst " + Number("%.3g", w.worst_value) +
                             Number(" at t = %.6g s)", w.worst_t);
    SummaryLine(out, "warning", line);
  }
}

// What the result file holds, read back from the disk: "the file holds N rows (t = a to b s)".
std::string RowsInFile(const std::string& path) {
  try {
    const Hdf5Reader r(path);
    if (!r.Exists("/time")) return "the file " + path + " holds no rows";
    const Eigen::MatrixXd t = r.ReadMatrix("/time");
    if (t.rows() == 0) return "the file " + path + " holds no rows";
    return path + " holds " + std::to_string(t.rows()) + " rows (t = " + Number("%g", t(0, 0)) + " to " +
           Number("%g", t(t.rows() - 1, 0)) + " s)";
  } catch (const std::exception& e) {
    return std::string("the file cannot be read back: ") + e.what();
  }
}

// "" when the result file may be written at `output`, else why not: it must not be the scene or
// a file the scene reads (same file by device and inode, however the paths are spelt).
std::string InputClash(const std::string& output, const std::string& scene_path, const std::vector<std::string>& inputs) {
  if (SameFile(output, scene_path)) return "result file " + output + " is the scene file " + scene_path;
  for (const std::string& input : inputs)
    if (SameFile(output, input)) return "result file " + output + " is " + input + ", which the scene reads";
  return "";
}

void PrintSummary(std::ostream& out, const std::string& output_path, const SimulationReport& report) {
  const IntegratorStats& s = report.stats;
  const double simulated_s = report.final_state.t;
  SummaryLine(out, "result file", output_path);
  SummaryLine(out, "rows written", std::to_string(report.output_rows));
  SummaryLine(out, "simulated time", Number("%g s", simulated_s));
  SummaryLine(out, "wall time", Number("%.3g s", report.wall_s));
  SummaryLine(out, "wall per sim. s",
              simulated_s > 0 ? Number("%.3g s", report.wall_s / simulated_s) : std::string("-"));
  SummaryLine(out, "integrator", report.integrator);
  SummaryLine(out, "steps", std::to_string(s.steps));
  SummaryLine(out, "residual evals", std::to_string(s.residual_evaluations));
  SummaryLine(out, "jacobian evals", std::to_string(s.jacobian_evaluations));
  SummaryLine(out, "newton failures", std::to_string(s.newton_failures));
  if (s.newton_backtracks > 0) SummaryLine(out, "newton backtracks", std::to_string(s.newton_backtracks));
  SummaryLine(out, "error-test fails", std::to_string(s.error_test_failures));
  SummaryLine(out, "max |Phi|", Number("%.3g", s.max_abs_phi));
  SummaryLine(out, "max |Phi-dot|", Number("%.3g", s.max_abs_phidot));
  PrintHealth(out, report);
  out << std::flush;
}

// The run's place in a study: /study attributes from "key=value" (numbers where they read as one)
void WriteStudyAttributes(ResultFile& result, const std::vector<std::string>& attributes) {
  for (const std::string& a : attributes) {
    const std::size_t eq = a.find('=');
    if (eq == std::string::npos || eq == 0) throw std::invalid_argument("--study-attribute " + a + ": expected KEY=VALUE");
    const std::string key = a.substr(0, eq), value = a.substr(eq + 1);
    long long integer = 0;
    double number = 0;
    const char* end = value.data() + value.size();
    if (!value.empty() && std::from_chars(value.data(), end, integer).ptr == end)
      result.SetAttribute("/study", key, static_cast<std::int64_t>(integer));
    else if (!value.empty() && std::from_chars(value.data(), end, number).ptr == end)
      result.SetAttribute("/study", key, number);
    else
      result.SetAttribute("/study", key, value);
  }
}

ProgressBar::Style ProgressStyle(const RunArgs& args) {
  if (args.quiet) return ProgressBar::Style::kNone;
  return args.err_is_terminal ? ProgressBar::Style::kBar : ProgressBar::Style::kLines;
}

}  // namespace

std::vector<std::string> SceneOverrides(const RunArgs& args) {
  std::vector<std::string> overrides = args.overrides;
  if (args.end_time) overrides.push_back("solver.end_time=" + ShortestText(*args.end_time));
  if (!args.integrator.empty()) overrides.push_back("solver.integrator=" + args.integrator);
  if (args.threads) overrides.push_back("solver.threads=" + std::to_string(*args.threads));
  return overrides;
}

int RunCommand(const RunArgs& args, std::ostream& out, std::ostream& err) {
  // Load the scene (a missing file gets a plain message before the parser sees it); `run` may
  // make a missing reduced body from its reduce input
  std::error_code ec;
  if (!std::filesystem::exists(args.scene_path, ec)) {
    ReportError(err, "scene file " + args.scene_path + ": no such file");
    return kExitFailure;
  }
  std::optional<Scene> scene;
  try {
    scene = LoadScene(args.scene_path, SceneOverrides(args), {.make_reduced_bodies = true});
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }

  // Settings of the run; refused ones (absurd times, an oversized file) before any file is touched
  SimulationOptions options = scene->simulation;
  options.interrupt = InterruptFlag();
  options.health.strict = args.strict;
  if (args.max_output_gb) options.max_output_bytes = *args.max_output_gb * 1e9;
  const std::string output_path = args.output_path.empty() ? scene->output_path : args.output_path;
  try {
    CheckSimulationSettings(*scene->model, options);
    if (const std::string clash = InputClash(output_path, args.scene_path, scene->input_files); !clash.empty())
      throw std::invalid_argument(clash + "; name another result file with -o");
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }

  // Create the result file
  std::optional<ResultFile> result;
  try {
    result = ResultFile::Create(output_path);
    WriteStudyAttributes(*result, args.study_attributes);
    WriteKinematicLines(*scene, *result);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }

  // Simulate, drawing progress; a signal stops it within one integrator step
  ProgressBar bar(err, ProgressStyle(args));
  SimulationReport report;
  try {
    InterruptGuard guard;
    report = Simulate(*scene->model, options, &*result, [&](const SimulationProgress& p) {
      bar.Update(p);
      if (args.observer) args.observer(p);
    });
    bar.Finish();
  } catch (const SimulationInterrupted& e) {
    // Simulate flushed the rows; close the file before saying what it holds
    bar.Abandon();
    result.reset();
    ReportError(err, std::string(e.what()) + "; " + RowsInFile(output_path));
    return kExitSignalBase + e.signal();
  } catch (const std::exception& e) {
    // Failures (solver, health check, full disk): the file keeps the rows written until then
    bar.Abandon();
    result.reset();
    const bool stopped = dynamic_cast<const RunHealthError*>(&e) || dynamic_cast<const ResultFileFullError*>(&e);
    ReportError(err, std::string(stopped ? "run stopped: " : "simulation failed: ") + e.what() + "; " +
                         RowsInFile(output_path));
    return kExitFailure;
  }

  // Close the file (the last chance for the disk to refuse), then summarize
  try {
    result->Close();
  } catch (const std::exception& e) {
    ReportError(err, std::string(e.what()) + "; " + RowsInFile(output_path));
    return kExitFailure;
  }
  PrintSummary(out, output_path, report);
  PrintFlexibleBodies(out, *scene->model, output_path);
  return kExitSuccess;
}

}  // namespace orrery::cli

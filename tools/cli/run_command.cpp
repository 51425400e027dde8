#include "tools/cli/run_command.h"

#include <charconv>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <system_error>

#include "import/scene.h"
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
  out << std::flush;
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
  return overrides;
}

int RunCommand(const RunArgs& args, std::ostream& out, std::ostream& err) {
  // Load the scene (a missing file gets a plain message before the parser sees it)
  std::error_code ec;
  if (!std::filesystem::exists(args.scene_path, ec)) {
    ReportError(err, "scene file " + args.scene_path + ": no such file");
    return kExitFailure;
  }
  std::optional<Scene> scene;
  try {
    scene = LoadScene(args.scene_path, SceneOverrides(args));
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }

  // Create the result file
  const std::string output_path = args.output_path.empty() ? scene->output_path : args.output_path;
  std::optional<ResultFile> result;
  try {
    result = ResultFile::Create(output_path);
    WriteKinematicLines(*scene, *result);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }

  // Simulate, drawing progress and polling for Ctrl-C after every output row
  ProgressBar bar(err, ProgressStyle(args));
  long rows = 1;  // Simulate records the initial state before the first callback
  SimulationReport report;
  try {
    InterruptGuard guard;
    report = Simulate(*scene->model, scene->simulation, &*result, [&](const SimulationProgress& p) {
      ++rows;
      bar.Update(p);
      if (args.observer) args.observer(p);
      if (const int signal = PendingInterrupt()) throw Interrupted(signal, p.t);
    });
    bar.Finish();
  } catch (const Interrupted& e) {
    // Simulate flushed the rows; close the file before saying so
    bar.Abandon();
    result.reset();
    ReportError(err, std::string(e.what()) + "; " + std::to_string(rows) + " rows saved in " + output_path);
    return kExitSignalBase + e.signal();
  } catch (const std::exception& e) {
    bar.Abandon();
    result.reset();
    ReportError(err, std::string("simulation failed: ") + e.what() + " (rows until then are in " + output_path + ")");
    return kExitFailure;
  }

  // Close the file (the last chance for the disk to refuse), then summarize
  try {
    result->Close();
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  PrintSummary(out, output_path, report);
  PrintFlexibleBodies(out, *scene->model, output_path);
  return kExitSuccess;
}

}  // namespace orrery::cli

// The `orrery` command-line program: CLI11 parsing only; the commands live in the orrery_tools
// library (run_command.h, inspect_command.h).
//
//   orrery run SCENE [-o OUT.h5] [--end-time T] [--set key=value ...] [--integrator NAME] [--quiet]
//              [--strict] [--max-output-gb GB]
//   orrery inspect OUT.h5
//   orrery kinematics SCENE [--json] [--range NAME] [--set key=value ...]
//   orrery modes SCENE [--json] [--set key=value ...]
//   orrery fe-modes MESH.inp --E PA --nu NU --rho KG_M3 [--fix NODESET ...] --modes N [--json]
//   orrery reduce INPUT.yaml -o BODY.h5 [--json]
//   orrery reduce MESH.inp -o BODY.h5 --interface NODESET[:rbe2|rbe3] ... [--E PA --nu NU --rho KG_M3]
//                 [--modes N] [--cutoff-hz F] [--json]
//   orrery mesh-stiffness SCENE --mesh NAME [--load N] [--points K] [--json] [--set key=value ...]
//                         [--flexible [--fe-level L]]
//   orrery --version
//
// Exit codes: 0 success, 1 runtime failure, 2 bad usage, 128 + signal when interrupted.
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "tools/cli/error_message.h"
#include "tools/cli/fe_modes_command.h"
#include "tools/cli/inspect_command.h"
#include "tools/cli/kinematics_command.h"
#include "tools/cli/mesh_stiffness_command.h"
#include "tools/cli/modes_command.h"
#include "tools/cli/reduce_command.h"
#include "tools/cli/run_command.h"

namespace {

using namespace orrery::cli;

// A finite number > 0, with a message naming what it is (CLI11's PositiveNumber prints the
// whole range of double when it fails).
CLI::Validator PositiveNumber(const std::string& what, const std::string& label) {
  return CLI::Validator(
      [what](std::string& text) -> std::string {
        std::size_t used = 0;
        double value = 0;
        try {
          value = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != text.size() || used == 0 || !(value > 0) || !std::isfinite(value))
          return "must be " + what + " > 0, got '" + text + "'";
        return "";
      },
      label);
}
const CLI::Validator kPositiveSeconds = PositiveNumber("a number of seconds", "SECONDS > 0");
const CLI::Validator kPositiveValue = PositiveNumber("a number", "VALUE > 0");

int Main(int argc, char** argv) {
  CLI::App app{"Orrery: multibody dynamics engine", "orrery"};
  app.set_version_flag("--version", std::string("orrery ") + ORRERY_VERSION);
  app.require_subcommand(1);

  // orrery run
  RunArgs run_args;
  double end_time = 0;
  CLI::App* run = app.add_subcommand("run", "Simulate a scene file and write a result file");
  run->add_option("scene", run_args.scene_path, "Scene file (YAML)")->required();
  run->add_option("-o,--output", run_args.output_path, "Result file (default: the scene's output file)");
  CLI::Option* end_time_option =
      run->add_option("--end-time", end_time, "End time in s (overrides solver.end_time)")
          ->check(kPositiveSeconds);
  run->add_option("--set", run_args.overrides, "Scene override key.path=value (repeatable)")
      ->allow_extra_args(false);
  run->add_option("--integrator", run_args.integrator, "Integrator (overrides solver.integrator)")
      ->check(CLI::IsMember({"ida", "generalized_alpha"}));
  run->add_flag("-q,--quiet", run_args.quiet, "No progress output");
  run->add_flag("--strict", run_args.strict, "Stop at the first health warning (run_health.h)");
  double max_output_gb = 0;
  CLI::Option* max_output_option =
      run->add_option("--max-output-gb", max_output_gb,
                      "Largest result file the run may write, estimated before it starts (GB, default 10)")
          ->check(kPositiveValue);

  // orrery inspect
  InspectArgs inspect_args;
  CLI::App* inspect = app.add_subcommand("inspect", "List the groups, datasets and attributes of a result file");
  inspect->add_option("file", inspect_args.path, "Result file (HDF5)")->required();

  // orrery kinematics
  KinematicsArgs kinematics_args;
  CLI::App* kinematics = app.add_subcommand(
      "kinematics", "Speeds, torques, mesh frequencies, forces and stiffnesses of a gear scene");
  kinematics->add_option("scene", kinematics_args.scene_path, "Scene file (YAML)")->required();
  kinematics->add_flag("--json", kinematics_args.json, "Write JSON to stdout");
  kinematics->add_option("--range", kinematics_args.range, "Gear range (default: the scene's range:)");
  kinematics->add_option("--set", kinematics_args.overrides, "Scene override key.path=value (repeatable)")
      ->allow_extra_args(false);

  // orrery modes
  ModesArgs modes_args;
  CLI::App* modes = app.add_subcommand("modes", "Natural frequencies with mode classes and multiplicities");
  modes->add_option("scene", modes_args.scene_path, "Scene file (YAML)")->required();
  modes->add_flag("--json", modes_args.json, "Write JSON to stdout");
  modes->add_option("--set", modes_args.overrides, "Scene override key.path=value (repeatable)")
      ->allow_extra_args(false);

  // orrery fe-modes
  FeModesArgs fe_args;
  CLI::App* fe_modes = app.add_subcommand("fe-modes", "Natural frequencies of an FE mesh (.inp)");
  fe_modes->add_option("mesh", fe_args.mesh_path, "Mesh file (Abaqus/CalculiX .inp)")->required();
  fe_modes->add_option("--E", fe_args.youngs_modulus_pa, "Young's modulus (Pa)")->check(kPositiveValue);
  fe_modes->add_option("--nu", fe_args.poissons_ratio, "Poisson's ratio")->check(CLI::Range(-1.0, 0.5));
  fe_modes->add_option("--rho", fe_args.density_kg_m3, "Density (kg/m^3)")->check(kPositiveValue);
  fe_modes->add_option("--fix", fe_args.fixed_node_sets, "Node set held fixed (repeatable)")->allow_extra_args(false);
  fe_modes->add_option("--modes", fe_args.num_modes, "Number of modes")->required()->check(CLI::Range(1, 100000));
  fe_modes->add_flag("--json", fe_args.json, "Write JSON to stdout");

  // orrery reduce
  ReduceArgs reduce_args;
  CLI::App* reduce = app.add_subcommand("reduce", "Reduce an FE body (Craig-Bampton) and write a reduced-body file");
  reduce->add_option("input", reduce_args.input_path, "Reduce input (YAML: generated gear) or mesh file (.inp)")
      ->required();
  reduce->add_option("-o,--output", reduce_args.output_path, "Reduced-body file (HDF5)")->required();
  reduce->add_flag("--json", reduce_args.json, "Write JSON to stdout");
  reduce->add_option("--interface", reduce_args.interfaces,
                     "Interface node set of a mesh input, NODESET[:rbe2|rbe3] (repeatable; the first is the body frame's)")
      ->allow_extra_args(false);
  reduce->add_option("--E", reduce_args.youngs_modulus_pa, "Young's modulus of a mesh input (Pa)")->check(kPositiveValue);
  reduce->add_option("--nu", reduce_args.poissons_ratio, "Poisson's ratio of a mesh input")->check(CLI::Range(-1.0, 0.5));
  reduce->add_option("--rho", reduce_args.density_kg_m3, "Density of a mesh input (kg/m^3)")->check(kPositiveValue);
  reduce->add_option("--modes", reduce_args.num_modes, "Fixed-interface modes kept, mesh input (default 20)")
      ->check(CLI::Range(0, 100000));
  reduce->add_option("--cutoff-hz", reduce_args.cutoff_hz, "Keep fixed-interface modes up to this frequency, mesh input")
      ->check(kPositiveValue);

  // orrery mesh-stiffness
  MeshStiffnessArgs ms_args;
  CLI::App* mesh_stiffness = app.add_subcommand(
      "mesh-stiffness", "Quasi-static mesh stiffness and transmission error of a gear mesh with tooth contact");
  mesh_stiffness->add_option("scene", ms_args.scene_path, "Scene file (YAML, gear_train)")->required();
  mesh_stiffness->add_option("--mesh", ms_args.mesh, "Train mesh, e.g. S1.sun-planet")->required();
  mesh_stiffness->add_option("--load", ms_args.load_n, "Force along the line of action (N, default 1000)")
      ->check(kPositiveValue);
  mesh_stiffness->add_option("--points", ms_args.points, "Roll angles per mesh period (default 40)")
      ->check(CLI::Range(1, 100000));
  mesh_stiffness->add_option("--set", ms_args.overrides, "Scene override key.path=value (repeatable)")
      ->allow_extra_args(false);
  mesh_stiffness->add_flag("--json", ms_args.json, "Write JSON to stdout");
  mesh_stiffness->add_flag("--flexible", ms_args.flexible,
                           "FE-reduced (flexible) gears with Hertzian contact compliance");
  mesh_stiffness->add_option("--fe-level", ms_args.fe_level,
                             "With --flexible: FE mesh refinement factor (default 1, coarse)")
      ->check(CLI::Range(1, 8));

  // Parse: help and version go to stdout, any other problem is one line on stderr
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    // Before a command, a stray argument is the problem (a misspelt command or option)
    std::string reason = e.what();
    const std::vector<std::string> stray = app.remaining();
    if (app.get_subcommands().empty() && !stray.empty() && !stray.front().empty())
      reason = stray.front().front() == '-' ? "unknown option '" + stray.front() + "'"
                                            : "unknown command '" + stray.front() + "' (expected run, inspect, kinematics, modes, fe-modes, reduce or mesh-stiffness)";
    ReportError(std::cerr, reason + "; see orrery --help");
    return kExitUsage;
  }

  // Dispatch
  if (run->parsed()) {
    if (end_time_option->count() > 0) run_args.end_time = end_time;
    if (max_output_option->count() > 0) run_args.max_output_gb = max_output_gb;
    run_args.err_is_terminal = isatty(STDERR_FILENO) == 1;
    return RunCommand(run_args, std::cout, std::cerr);
  }
  if (kinematics->parsed()) return KinematicsCommand(kinematics_args, std::cout, std::cerr);
  if (modes->parsed()) return ModesCommand(modes_args, std::cout, std::cerr);
  if (fe_modes->parsed()) return FeModesCommand(fe_args, std::cout, std::cerr);
  if (reduce->parsed()) return ReduceCommand(reduce_args, std::cout, std::cerr);
  if (mesh_stiffness->parsed()) return MeshStiffnessCommand(ms_args, std::cout, std::cerr);
  return InspectCommand(inspect_args, std::cout, std::cerr);
}

}  // namespace

int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) makes a write fail with EFBIG instead of killing the process
  // with SIGXFSZ: the result file then says what it holds (result_file.cpp)
  std::signal(SIGXFSZ, SIG_IGN);
  // Last line of defence: nothing escapes as a stack trace or an abort
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    ReportError(std::cerr, e.what());
  } catch (...) {
    ReportError(std::cerr, "unknown error");
  }
  return kExitFailure;
}

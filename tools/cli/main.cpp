// The `orrery` command-line program: CLI11 parsing only; the commands live in the orrery_tools
// library (run_command.h, inspect_command.h).
//
//   orrery run SCENE [-o OUT.h5] [--end-time T] [--set key=value ...] [--integrator NAME]
//              [--threads N] [--quiet]
//              [--strict] [--max-output-gb GB]
//   orrery inspect OUT.h5
//   orrery kinematics SCENE [--json] [--range NAME] [--set key=value ...]
//   orrery modes SCENE [--json] [--set key=value ...]
//   orrery fe-modes MESH.inp --E PA --nu NU --rho KG_M3 [--fix NODESET ...] --modes N [--json]
//   orrery reduce INPUT.yaml -o BODY.h5 [--json]
//   orrery reduce PART -o BODY.h5 --interface NODESET|bore[:rbe2|rbe3] ... [--E PA --nu NU --rho KG_M3]
//                 [--modes N] [--cutoff-hz F] [--unit U] [--element tet10|tet4] [--curved] [--mesh-size H]
//                 [--mesh-min-size H] [--curvature N] [--mass M.mtx --dofs TABLE] [--mesh MESH] [--json]
//                 (PART: .inp, .msh, STEP/IGES, a surface mesh, CalculiX job.sti or Matrix Market K.mtx)
//   orrery mesh-info FILE [--unit m|cm|mm|in] [--density KG_M3] [--no-self-intersections] [--json]
//   orrery mesh-stiffness SCENE --mesh NAME[#k] [--load N] [--points K] [--json] [--set key=value ...]
//                         [--fault KEY=VALUE,... ...]
//                         [--flexible [--fe-level L]]
//   orrery spectrum OUT.h5 --signal PATH [--column C] [--window hann|flattop|rect] [--order MEMBER]
//                   [--t0 T] [--peaks N] [--json] [--png FILE]
//   orrery compare HEALTHY.h5 FAULTY.h5 --signal PATH [--column C] [--t0 T] [--window W] [--tsa MEMBER]
//                  [--mesh NAME] [--modulation NAME] [--json] [--png FILE]
//   orrery octave OUT.h5 --signal PATH [--column C] [--t0 T] [--reference A0] [--json] [--png FILE]
//   orrery plot OUT.h5 (--signal PATH [--column C] [--t0 T] | --stress PATH) --png FILE
//   orrery study STUDY.yaml [-o DIR] [-j N] [--retry-failed] [--mpi] [--dry-run] [--quiet]
//   mpirun -n N orrery study STUDY.yaml ...
//   orrery advise --study DIR [--study DIR ...] --output NAME --error BOUND [--absolute]
//                 [--cost cpu|wall|memory] [--reference [STUDY:]RUN] [--json]
//   orrery fault-study SCENE -o DIR [--end-time T] [--t0 T0] [--signal PATH] [--set k=v] [--force] [--no-plots] [--quiet]
//   orrery --version
//
// Exit codes: 0 success, 1 runtime failure, 2 bad usage, 128 + signal when interrupted.
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <exception>
#include <optional>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "tools/cli/compare_command.h"
#include "tools/cli/fault_study_command.h"
#include "tools/cli/error_message.h"
#include "tools/cli/fe_modes_command.h"
#include "tools/cli/inspect_command.h"
#include "tools/cli/kinematics_command.h"
#include "tools/cli/mesh_info_command.h"
#include "tools/cli/mesh_stiffness_command.h"
#include "tools/cli/modes_command.h"
#include "tools/cli/octave_command.h"
#include "tools/cli/plot_command.h"
#include "tools/cli/reduce_command.h"
#include "tools/cli/run_command.h"
#include "tools/cli/spectrum_command.h"
#include "tools/cli/study_command.h"
#include "tools/cli/advise_command.h"
#include "tools/study/run_process.h"

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

// The signal-analysis commands (spectrum, compare, octave, plot): arguments, options, dispatch.
struct SignalCommands {
  SpectrumArgs spectrum_args;
  CompareArgs compare_args;
  OctaveArgs octave_args;
  PlotArgs plot_args;
  double spectrum_t0 = 0, compare_t0 = 0, octave_t0 = 0, plot_t0 = 0;
  CLI::App *spectrum = nullptr, *compare = nullptr, *octave = nullptr, *plot = nullptr;
  CLI::Option *spectrum_t0_option = nullptr, *compare_t0_option = nullptr, *octave_t0_option = nullptr;
  CLI::Option *plot_t0_option = nullptr, *reference_option = nullptr;

  void Add(CLI::App& app) {
    AddSpectrum(app);
    AddCompare(app);
    AddOctave(app);
    AddPlot(app);
  }

  void AddSpectrum(CLI::App& app) {
    spectrum = app.add_subcommand("spectrum", "Amplitude spectrum of a recorded signal, peaks labelled with kinematic lines");
    spectrum->add_option("file", spectrum_args.path, "Result file (HDF5)")->required();
    spectrum->add_option("--signal", spectrum_args.signal, "Dataset, e.g. /bodies/S.planet1/angular_acceleration")->required();
    spectrum->add_option("--column", spectrum_args.column, "Column: 0-based index or name (default: the first)");
    spectrum->add_option("--window", spectrum_args.window, "Window (default hann)")->check(CLI::IsMember({"hann", "flattop", "rect"}));
    spectrum->add_option("--order", spectrum_args.order_member, "Order spectrum over the angle of this joint (or angle dataset)");
    spectrum_t0_option = spectrum->add_option("--t0", spectrum_t0, "Start of the record (s)");
    spectrum->add_option("--peaks", spectrum_args.max_peaks, "Largest peaks listed (default 20)")->check(CLI::Range(0, 100000));
    spectrum->add_flag("--json", spectrum_args.json, "Write JSON to stdout");
    spectrum->add_option("--png", spectrum_args.png, "Also draw the spectrum into this PNG file");
  }

  void AddCompare(CLI::App& app) {
    compare = app.add_subcommand("compare", "Healthy against faulty run: sideband energy ratio and condition indicators");
    compare->add_option("healthy", compare_args.healthy, "Result file of the healthy run")->required();
    compare->add_option("faulty", compare_args.faulty, "Result file of the faulty run")->required();
    compare->add_option("--signal", compare_args.signal, "Dataset, e.g. /bodies/S.planet1/angular_acceleration")->required();
    compare->add_option("--column", compare_args.column, "Column: 0-based index or name (default: the first)");
    compare_t0_option = compare->add_option("--t0", compare_t0, "Start of the records (s)");
    compare->add_option("--window", compare_args.window, "Window (default hann)")->check(CLI::IsMember({"hann", "flattop", "rect"}));
    compare->add_option("--tsa", compare_args.tsa_member, "Indicators on the TSA over this joint's (or angle dataset's) revolutions");
    compare->add_option("--mesh", compare_args.mesh, "Mesh line (default: the first of kind mesh)");
    compare->add_option("--modulation", compare_args.modulation, "Sideband line (default: the first of kind fault)");
    compare->add_flag("--json", compare_args.json, "Write JSON to stdout");
    compare->add_option("--png", compare_args.png, "Also draw both spectra into this PNG file");
  }

  void AddOctave(CLI::App& app) {
    octave = app.add_subcommand("octave", "One-third-octave band levels of a recorded signal");
    octave->add_option("file", octave_args.path, "Result file (HDF5)")->required();
    octave->add_option("--signal", octave_args.signal, "Dataset, e.g. /bodies/S.ring/linear_acceleration")->required();
    octave->add_option("--column", octave_args.column, "Column: 0-based index or name (default: the first)");
    octave_t0_option = octave->add_option("--t0", octave_t0, "Start of the record (s)");
    reference_option =
        octave->add_option("--reference", octave_args.reference, "Reference value a0 (default 1e-6, m/s^2)")->check(kPositiveValue);
    octave->add_flag("--json", octave_args.json, "Write JSON to stdout");
    octave->add_option("--png", octave_args.png, "Also draw the levels into this PNG file");
  }

  void AddPlot(CLI::App& app) {
    plot = app.add_subcommand("plot", "Plot a recorded signal or a flexible body's hot-spot stress over time");
    plot->add_option("file", plot_args.path, "Result file (HDF5)")->required();
    plot->add_option("--signal", plot_args.signal, "Dataset to plot over time");
    plot->add_option("--column", plot_args.column, "Column of --signal: 0-based index or name");
    plot_t0_option = plot->add_option("--t0", plot_t0, "Start of the record (s)");
    plot->add_option("--stress", plot_args.stress, "Hot-spot stress dataset, e.g. /flexible_bodies/S.planet1/von_mises_max");
    plot->add_option("--png", plot_args.png, "PNG file to write")->required();
  }

  // The exit code of the command that was parsed, if it is one of these
  std::optional<int> Dispatch() {
    if (spectrum->parsed()) {
      if (spectrum_t0_option->count() > 0) spectrum_args.t0 = spectrum_t0;
      return SpectrumCommand(spectrum_args, std::cout, std::cerr);
    }
    if (compare->parsed()) {
      if (compare_t0_option->count() > 0) compare_args.t0 = compare_t0;
      return CompareCommand(compare_args, std::cout, std::cerr);
    }
    if (octave->parsed()) {
      if (octave_t0_option->count() > 0) octave_args.t0 = octave_t0;
      octave_args.reference_given = reference_option->count() > 0;
      return OctaveCommand(octave_args, std::cout, std::cerr);
    }
    if (plot->parsed()) {
      if (plot_t0_option->count() > 0) plot_args.t0 = plot_t0;
      return PlotCommand(plot_args, std::cout, std::cerr);
    }
    return std::nullopt;
  }
};

// orrery study: arguments, options, dispatch.
struct StudyCli {
  StudyArgs args;
  CLI::App* study = nullptr;

  void Add(CLI::App& app) {
    study = app.add_subcommand("study", "Run a parameter study: many runs of a scene, outputs collected in an index");
    study->add_option("file", args.study_path, "Study file (YAML)")->required();
    study->add_option("-o,--output", args.folder, "Study folder (default: the file's folder:, else results/studies/NAME)");
    study->add_option("-j,--jobs", args.jobs, "Runs at a time on this machine, or per MPI rank (default: the cores)")
        ->check(CLI::Range(1, 100000));
    study->add_flag("--retry-failed", args.retry_failed, "Run the failed runs of an earlier start again");
    study->add_flag("--mpi", args.mpi, "Use MPI without a launcher (found automatically under mpirun or srun)");
    study->add_flag("--dry-run", args.dry_run, "Check the study and list its runs without running them");
    study->add_flag("-q,--quiet", args.quiet, "No progress output");
  }

  std::optional<int> Dispatch() {
    if (!study->parsed()) return std::nullopt;
    args.err_is_terminal = isatty(STDERR_FILENO) == 1;
    return StudyCommand(args, std::cout, std::cerr);
  }
};

// orrery advise: arguments, options, dispatch.
struct AdviseCli {
  AdviseArgs args;
  CLI::App* advise = nullptr;

  void Add(CLI::App& app) {
    advise = app.add_subcommand("advise", "The cheapest measured setting of a study that meets an error bound on an output");
    advise->add_option("--study", args.studies, "Study folder or its index.h5 (repeatable: the runs of all are compared)")->required();
    advise->add_option("--output", args.output, "Output of the study (a column of its index)")->required();
    advise->add_option("--error", args.error, "Error bound against the reference: a fraction (0.01) or percentage (1%), or with --absolute in the output's unit")->required();
    advise->add_flag("--absolute", args.absolute, "The bound is in the output's unit");
    advise->add_option("--cost", args.cost, "Cost to minimize: cpu (user + system time, default), wall, memory");
    advise->add_option("--reference", args.reference, "The reference run, RUN or STUDY:RUN (default: the last run of the last study)");
    advise->add_flag("--json", args.json, "Write JSON to stdout");
  }

  std::optional<int> Dispatch() {
    if (!advise->parsed()) return std::nullopt;
    return AdviseCommand(args, std::cout, std::cerr);
  }
};

// The simulation commands (run, inspect, kinematics, modes, fault-study): arguments, options,
// dispatch.
struct SimulationCommands {
  RunArgs run_args;
  InspectArgs inspect_args;
  KinematicsArgs kinematics_args;
  ModesArgs modes_args;
  FaultStudyArgs fs_args;
  double end_time = 0, max_output_gb = 0, fs_end_time = 0, fs_t0 = 0;
  CLI::App *run = nullptr, *inspect = nullptr, *kinematics = nullptr, *modes = nullptr, *fault_study = nullptr;
  CLI::Option *end_time_option = nullptr, *max_output_option = nullptr, *fs_end_option = nullptr,
              *fs_t0_option = nullptr;

  void Add(CLI::App& app) {
    AddRun(app);
    AddInspect(app);
    AddKinematics(app);
    AddModes(app);
    AddFaultStudy(app);
  }

  void AddRun(CLI::App& app) {
    run = app.add_subcommand("run", "Simulate a scene file and write a result file");
    run->add_option("scene", run_args.scene_path, "Scene file (YAML)")->required();
    run->add_option("-o,--output", run_args.output_path, "Result file (default: the scene's output file)");
    end_time_option =
        run->add_option("--end-time", end_time, "End time in s (overrides solver.end_time)")
            ->check(kPositiveSeconds);
    run->add_option("--set", run_args.overrides, "Scene override key.path=value (repeatable)")
        ->allow_extra_args(false);
    run->add_option("--integrator", run_args.integrator, "Integrator (overrides solver.integrator)")
        ->check(CLI::IsMember({"ida", "generalized_alpha"}));
    run->add_option("--threads", run_args.threads,
                    "Threads for the tooth contacts of one step (overrides solver.threads; "
                    "default OMP_NUM_THREADS, else 1)")
        ->check(CLI::Range(1, 4096));
    run->add_flag("-q,--quiet", run_args.quiet, "No progress output");
    run->add_option("--study-attribute", run_args.study_attributes, "")  // set by `orrery study`
        ->allow_extra_args(false)
        ->group("");
    run->add_flag("--strict", run_args.strict, "Stop at the first health warning (run_health.h)");
    max_output_option =
        run->add_option("--max-output-gb", max_output_gb,
                        "Largest result file the run may write, estimated before it starts (GB, default 10)")
            ->check(kPositiveValue);
  }

  void AddInspect(CLI::App& app) {
    inspect = app.add_subcommand("inspect", "List the groups, datasets and attributes of a result file");
    inspect->add_option("file", inspect_args.path, "Result file (HDF5)")->required();
  }

  void AddKinematics(CLI::App& app) {
    kinematics = app.add_subcommand(
        "kinematics", "Speeds, torques, mesh frequencies, forces and stiffnesses of a gear scene");
    kinematics->add_option("scene", kinematics_args.scene_path, "Scene file (YAML)")->required();
    kinematics->add_flag("--json", kinematics_args.json, "Write JSON to stdout");
    kinematics->add_option("--range", kinematics_args.range, "Gear range (default: the scene's range:)");
    kinematics->add_option("--set", kinematics_args.overrides, "Scene override key.path=value (repeatable)")
        ->allow_extra_args(false);
  }

  void AddModes(CLI::App& app) {
    modes = app.add_subcommand("modes", "Natural frequencies with mode classes and multiplicities");
    modes->add_option("scene", modes_args.scene_path, "Scene file (YAML)")->required();
    modes->add_flag("--json", modes_args.json, "Write JSON to stdout");
    modes->add_option("--set", modes_args.overrides, "Scene override key.path=value (repeatable)")
        ->allow_extra_args(false);
  }

  void AddFaultStudy(CLI::App& app) {
    fault_study = app.add_subcommand(
        "fault-study", "Run a faulty gear scene and its healthy twin; spectra, sidebands, indicators, plots, summary");
    fault_study->add_option("scene", fs_args.scene_path, "Scene file (YAML, gear_train with tooth faults)")->required();
    fault_study->add_option("-o,--output", fs_args.output_dir, "Study folder")->required();
    fs_end_option =
        fault_study->add_option("--end-time", fs_end_time, "Simulated time of each run in s (default 0.30)")
            ->check(kPositiveSeconds);
    fs_t0_option =
        fault_study->add_option("--t0", fs_t0, "Start of the analysed records in s (default 0.03)")->check(CLI::NonNegativeNumber);
    fault_study->add_option("--signal", fs_args.signal, "Dataset to analyse (default: the scene's first sensor)");
    fault_study->add_option("--set", fs_args.overrides, "Scene override key.path=value (repeatable)")->allow_extra_args(false);
    fault_study->add_flag("--force", fs_args.force, "Replace the folder's earlier results");
    fault_study->add_flag("--no-plots{false}", fs_args.plots, "Skip the PNG plots");
    fault_study->add_flag("-q,--quiet", fs_args.quiet, "No progress output");
  }

  // The exit code of the command that was parsed, if it is one of these
  std::optional<int> Dispatch() {
    if (run->parsed()) {
      if (end_time_option->count() > 0) run_args.end_time = end_time;
      if (max_output_option->count() > 0) run_args.max_output_gb = max_output_gb;
      run_args.err_is_terminal = isatty(STDERR_FILENO) == 1;
      return RunCommand(run_args, std::cout, std::cerr);
    }
    if (kinematics->parsed()) return KinematicsCommand(kinematics_args, std::cout, std::cerr);
    if (modes->parsed()) return ModesCommand(modes_args, std::cout, std::cerr);
    if (fault_study->parsed()) {
      if (fs_end_option->count() > 0) fs_args.end_time = fs_end_time;
      if (fs_t0_option->count() > 0) fs_args.t0 = fs_t0;
      fs_args.err_is_terminal = isatty(STDERR_FILENO) == 1;
      return FaultStudyCommand(fs_args, std::cout, std::cerr);
    }
    if (inspect->parsed()) return InspectCommand(inspect_args, std::cout, std::cerr);
    return std::nullopt;
  }
};

// The body and mesh commands (fe-modes, reduce, mesh-info, mesh-stiffness): arguments, options,
// dispatch.
struct BodyCommands {
  FeModesArgs fe_args;
  ReduceArgs reduce_args;
  MeshInfoArgs info_args;
  MeshStiffnessArgs ms_args;
  CLI::App *fe_modes = nullptr, *reduce = nullptr, *mesh_info = nullptr, *mesh_stiffness = nullptr;

  void Add(CLI::App& app) {
    AddFeModes(app);
    AddReduce(app);
    AddMeshInfo(app);
    AddMeshStiffness(app);
  }

  void AddFeModes(CLI::App& app) {
    fe_modes = app.add_subcommand("fe-modes", "Natural frequencies of an FE mesh (.inp)");
    fe_modes->add_option("mesh", fe_args.mesh_path, "Mesh file (Abaqus/CalculiX .inp)")->required();
    fe_modes->add_option("--E", fe_args.youngs_modulus_pa, "Young's modulus (Pa)")->check(kPositiveValue);
    fe_modes->add_option("--nu", fe_args.poissons_ratio, "Poisson's ratio")->check(CLI::Range(-1.0, 0.5));
    fe_modes->add_option("--rho", fe_args.density_kg_m3, "Density (kg/m^3)")->check(kPositiveValue);
    fe_modes->add_option("--fix", fe_args.fixed_node_sets, "Node set held fixed (repeatable)")->allow_extra_args(false);
    fe_modes->add_option("--modes", fe_args.num_modes, "Number of modes")->required()->check(CLI::Range(1, 100000));
    fe_modes->add_flag("--json", fe_args.json, "Write JSON to stdout");
  }

  void AddReduce(CLI::App& app) {
    reduce = app.add_subcommand("reduce", "Reduce an FE body (Craig-Bampton) and write a reduced-body file");
    reduce->add_option("input", reduce_args.input_path,
                       "Reduce input (YAML: generated gear), or a part: mesh (.inp, .msh), STEP/IGES, surface mesh, "
                       "CalculiX job.sti or Matrix Market K.mtx")
        ->required();
    reduce->add_option("-o,--output", reduce_args.output_path, "Reduced-body file (HDF5)")->required();
    reduce->add_flag("--json", reduce_args.json, "Write JSON to stdout");
    reduce->add_option("--interface", reduce_args.interfaces,
                       "Interface of a part, NODESET or bore, optionally :rbe2|:rbe3 (repeatable; the first is the body frame's)")
        ->allow_extra_args(false);
    reduce->add_option("--E", reduce_args.youngs_modulus_pa, "Young's modulus of a part (Pa)")->check(kPositiveValue);
    reduce->add_option("--nu", reduce_args.poissons_ratio, "Poisson's ratio of a part")->check(CLI::Range(-1.0, 0.5));
    reduce->add_option("--rho,--density", reduce_args.density_kg_m3, "Density of a part (kg/m^3)")->check(kPositiveValue);
    reduce->add_option("--modes", reduce_args.num_modes, "Fixed-interface modes kept, part input (default 20)")
        ->check(CLI::Range(0, 100000));
    reduce->add_option("--cutoff-hz", reduce_args.cutoff_hz, "Keep fixed-interface modes up to this frequency, part input")
        ->check(kPositiveValue);
    reduce->add_option("--unit", reduce_args.unit, "Length unit of a surface mesh or .msh part (m, cm, mm, in; default m)");
    reduce->add_option("--element", reduce_args.element, "Elements gmsh makes of a CAD or surface part (tet10, tet4)");
    reduce->add_flag("--curved", reduce_args.curved, "CAD part: tet10 midside nodes on the geometry");
    reduce->add_option("--mesh-size", reduce_args.mesh_size_m, "Largest element size gmsh makes (m)")->check(kPositiveValue);
    reduce->add_option("--mesh-min-size", reduce_args.mesh_min_size_m, "Smallest element size gmsh makes (m)")
        ->check(kPositiveValue);
    reduce->add_option("--curvature", reduce_args.curvature_elements, "gmsh elements per 2 pi of curvature")
        ->check(CLI::Range(1, 1000));
    reduce->add_option("--mass", reduce_args.mass_matrix, "Mass matrix (Matrix Market) of a K.mtx input");
    reduce->add_option("--dofs", reduce_args.dof_table, "DOF table (NODE DIR per row) of a K.mtx input");
    reduce->add_option("--mesh", reduce_args.mesh_file, "Mesh (.inp, .msh) with the nodes of FE matrices");
  }

  void AddMeshInfo(CLI::App& app) {
    mesh_info = app.add_subcommand(
        "mesh-info", "Read a mesh or CAD file: checks (watertight, manifold, orientation) and mass properties");
    mesh_info->add_option("file", info_args.path, "STL, OBJ, STEP/IGES, .msh, .inp, PLY, glTF, 3MF, ...")->required();
    mesh_info->add_option("--unit", info_args.unit, "Length unit of the file (m, cm, mm, in; default m)");
    mesh_info->add_option("--density", info_args.density_kg_m3, "Density (kg/m^3): mass and inertia")
        ->check(kPositiveValue);
    mesh_info->add_flag("--no-self-intersections{false}", info_args.self_intersections, "Skip the self-intersection test");
    mesh_info->add_flag("--json", info_args.json, "Write JSON to stdout");
  }

  void AddMeshStiffness(CLI::App& app) {
    mesh_stiffness = app.add_subcommand(
        "mesh-stiffness", "Quasi-static mesh stiffness and transmission error of a gear mesh with tooth contact");
    mesh_stiffness->add_option("scene", ms_args.scene_path, "Scene file (YAML, gear_train)")->required();
    mesh_stiffness->add_option("--mesh", ms_args.mesh, "Train mesh, e.g. S1.sun-planet")->required();
    mesh_stiffness->add_option("--load", ms_args.load_n, "Force along the line of action (N, default 1000)")
        ->check(kPositiveValue);
    mesh_stiffness->add_option("--points", ms_args.points, "Roll angles per mesh period (default 40)")
        ->check(CLI::Range(1, 100000));
    mesh_stiffness->add_option("--set", ms_args.overrides, "Scene override key.path=value (repeatable)")
        ->allow_extra_args(false);
    mesh_stiffness->add_option("--fault", ms_args.faults,
                               "Tooth fault KEY=VALUE,... as in dynamics.faults (repeatable; adds to the scene's)")
        ->allow_extra_args(false);
    mesh_stiffness->add_flag("--json", ms_args.json, "Write JSON to stdout");
    mesh_stiffness->add_flag("--flexible", ms_args.flexible,
                             "FE-reduced (flexible) gears with Hertzian contact compliance");
    mesh_stiffness->add_option("--fe-level", ms_args.fe_level,
                               "With --flexible: FE mesh refinement factor (default 1, coarse)")
        ->check(CLI::Range(1, 8));
  }

  std::optional<int> Dispatch() {
    if (fe_modes->parsed()) return FeModesCommand(fe_args, std::cout, std::cerr);
    if (reduce->parsed()) return ReduceCommand(reduce_args, std::cout, std::cerr);
    if (mesh_info->parsed()) return MeshInfoCommand(info_args, std::cout, std::cerr);
    if (mesh_stiffness->parsed()) return MeshStiffnessCommand(ms_args, std::cout, std::cerr);
    return std::nullopt;
  }
};

int Main(int argc, char** argv) {
  CLI::App app{"Orrery: multibody dynamics engine", "orrery"};
  app.set_version_flag("--version", std::string("orrery ") + ORRERY_VERSION);
  app.require_subcommand(1);
  SimulationCommands simulation;
  simulation.Add(app);
  BodyCommands bodies;
  bodies.Add(app);
  SignalCommands signal_commands;
  signal_commands.Add(app);
  StudyCli study;
  study.Add(app);
  AdviseCli advise;
  advise.Add(app);

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
                                            : "unknown command '" + stray.front() + "' (expected run, inspect, kinematics, modes, fe-modes, reduce, mesh-info, mesh-stiffness, spectrum, compare, octave, plot, study, advise or fault-study)";
    ReportError(std::cerr, reason + "; see orrery --help");
    return kExitUsage;
  }

  // Dispatch
  if (const std::optional<int> code = simulation.Dispatch()) return *code;
  if (const std::optional<int> code = bodies.Dispatch()) return *code;
  if (const std::optional<int> code = signal_commands.Dispatch()) return *code;
  if (const std::optional<int> code = study.Dispatch()) return *code;
  if (const std::optional<int> code = advise.Dispatch()) return *code;
  ReportError(std::cerr, "no command; see orrery --help");
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  // A run started by `orrery study` dies with the study
  orrery::study::PrepareStudyChild();
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

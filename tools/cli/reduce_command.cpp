#include "tools/cli/reduce_command.h"

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include "flex/craig_bampton.h"
#include "flex/blas_kernels.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_modes.h"
#include "flex/flexible_body_modes.h"
#include "flex/inp_file.h"
#include "flex/reduced_body_file.h"
#include "import/length_unit.h"
#include "import/part_reduction.h"
#include "import/reduce_input.h"
#include "models/gear_fe_mesh.h"
#include "models/gear_geometry.h"
#include "mbd/file_checks.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {
namespace {

constexpr const char* kFullModelBoundary =
    "reference interface master clamped (RBE2/RBE3 constraints of every interface applied, other masters free)";

// Seconds since `start`.
double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string Num(double x, const char* format = "%g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

// What the command reduces: the mesh with its material, the interfaces (first: reference unless
// stated), the options and a description of the source.
struct Job {
  flex::FeMesh mesh;
  std::vector<flex::FeInterface> interfaces;
  std::vector<std::string> interface_sets;  // node set of each interface
  flex::CraigBamptonOptions cb_options;
  flex::FlexibleBodyModesOptions outputs;
  std::string source;
  std::string faults;                 // provenance fault text ("" for a mesh file: unknown)
  std::vector<std::string> notes;     // .inp keywords ignored, meshing notes
  std::vector<std::string> warnings;  // e.g. the millimetre warning of a surface mesh
  std::optional<flex::FeSystem> system;  // external FE matrices (else assembled)
  std::string matrices_digest;           // external FE matrices: their files' hash
};

// A generated gear from a reduce input file.
Job GearJob(const std::string& path) {
  GearReduction g = PrepareGearReduction(LoadReduceInput(path));
  Job job;
  job.mesh = std::move(g.mesh);
  job.interfaces = std::move(g.interfaces);
  job.interface_sets = std::move(g.interface_sets);
  job.cb_options = g.cb_options;
  job.outputs = std::move(g.outputs);
  job.source = std::move(g.source);
  job.faults = std::move(g.faults);
  return job;
}

// A part (mesh, CAD, surface or FE matrices) with interfaces and material from the command line.
Job PartJob(const ReduceArgs& args) {
  const int given = args.youngs_modulus_pa.has_value() + args.poissons_ratio.has_value() + args.density_kg_m3.has_value();
  if (given != 0 && given != 3) throw std::runtime_error("give all of --E, --nu and --rho (--density), or none");
  PartReductionInput in{.input = args.input_path,
                        .interfaces = args.interfaces,
                        .modes = args.num_modes.value_or(20),
                        .cutoff_hz = args.cutoff_hz.value_or(0),
                        .mass_matrix = args.mass_matrix,
                        .dof_table = args.dof_table,
                        .mesh_file = args.mesh_file};
  if (!args.unit.empty()) {
    in.unit = ParseLengthUnit(args.unit);
    if (!in.unit) throw std::runtime_error("--unit " + args.unit + ": expected " + kLengthUnitChoices);
  }
  if (given == 3)
    in.material = flex::IsotropicMaterial{.name = "CLI", .youngs_modulus_pa = *args.youngs_modulus_pa,
                                          .poissons_ratio = *args.poissons_ratio,
                                          .density_kg_m3 = *args.density_kg_m3};
  if (!args.element.empty() && args.element != "tet10" && args.element != "tet4")
    throw std::runtime_error("--element " + args.element + ": expected tet10 or tet4");
  in.meshing.order = args.element == "tet4" ? 1 : 2;
  in.meshing.curved = args.curved;
  in.meshing.max_size_m = args.mesh_size_m.value_or(0);
  in.meshing.min_size_m = args.mesh_min_size_m.value_or(0);
  in.meshing.curvature_elements = args.curvature_elements.value_or(0);
  PartReduction p = PreparePartReduction(in);
  Job job;
  job.mesh = std::move(p.mesh);
  job.interfaces = std::move(p.interfaces);
  job.interface_sets = std::move(p.interface_sets);
  job.cb_options = p.cb_options;
  job.outputs = std::move(p.outputs);
  job.source = std::move(p.source);
  job.notes = std::move(p.notes);
  job.warnings = std::move(p.warnings);
  job.system = std::move(p.system);
  job.matrices_digest = std::move(p.matrices_digest);
  return job;
}

// Lowest `n` modes of the FE model with every interface's constraint applied and the reference
// master clamped (the model the Craig-Bampton basis approximates).
flex::FeModes FullModel(const Job& job, const flex::FeSystem& system, int n) {
  const flex::InterfaceTransform t = flex::MakeInterfaceTransform(job.mesh, job.interfaces);
  flex::FeSystem q;
  q.K = flex::InterfaceCoordinatesMatrix(t, system.K);
  q.M = flex::InterfaceCoordinatesMatrix(t, system.M);
  std::vector<int> fixed(6);
  std::iota(fixed.begin(), fixed.end(), 6 * job.cb_options.reference_interface);
  return flex::CalcFeModes(q, fixed, {.num_modes = n, .tolerance = job.cb_options.tolerance});
}

const char* KindName(flex::InterfaceKind k) { return k == flex::InterfaceKind::kRbe2 ? "rbe2" : "rbe3"; }

}  // namespace

int ReduceCommand(const ReduceArgs& args, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!std::filesystem::exists(args.input_path, ec)) {
    ReportError(err, "input file " + args.input_path + ": no such file");
    return kExitFailure;
  }
  if (SameFile(args.output_path, args.input_path)) {
    ReportError(err, "reduced-body file " + args.output_path + " is the input " + args.input_path +
                         "; name another file with -o");
    return kExitFailure;
  }
  std::string extension = std::filesystem::path(args.input_path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool yaml = extension == ".yaml" || extension == ".yml";
  if (yaml && (args.youngs_modulus_pa || args.poissons_ratio || args.density_kg_m3 || !args.interfaces.empty() ||
               args.num_modes || args.cutoff_hz || !args.unit.empty() || args.mesh_size_m || args.mesh_min_size_m ||
               args.curvature_elements || !args.element.empty() || args.curved || !args.mass_matrix.empty() ||
               !args.dof_table.empty() || !args.mesh_file.empty())) {
    ReportError(err, "--E, --nu, --rho, --interface, --modes, --cutoff-hz, --unit, meshing and matrix options go with a "
                     "part input (mesh, CAD or matrices); " + args.input_path + " states them itself");
    return kExitFailure;
  }
  Job job;
  flex::ReducedBody body;
  flex::CraigBamptonModel cb;
  flex::FeModes full;
  double t_mesh = 0, t_assembly = 0, t_reduction = 0, t_modes = 0, t_full = 0, t_write = 0;
  long long dofs = 0;
  try {
    // Mesh, material, interfaces
    auto start = std::chrono::steady_clock::now();
    job = yaml ? GearJob(args.input_path) : PartJob(args);
    t_mesh = Since(start);
    for (const std::string& w : job.warnings) err << "orrery: warning: " << w << "\n";
    // The factorization's BLAS kernels: one note when OpenBLAS runs its generic ones
    if (const std::string advice = flex::BlasKernelAdvice(); !advice.empty()) err << "orrery: note: " << advice << "\n";
    // Assembly (or the given matrices), reduction and what the engine needs
    Reduction reduction =
        job.system ? ReduceAssembledBody(job.mesh, std::move(*job.system), job.interfaces, job.cb_options, job.outputs,
                                         job.source, job.faults)
                   : ReduceBody(job.mesh, job.interfaces, job.cb_options, job.outputs, job.source, job.faults);
    if (!job.matrices_digest.empty())
      reduction.body.provenance.mesh_hash =
          flex::Fnv1a64Hex(reduction.body.provenance.mesh_hash + "+" + job.matrices_digest);
    dofs = reduction.system.K.rows();
    t_assembly = reduction.assembly_s;
    t_reduction = reduction.reduction_s;
    t_modes = reduction.modes_s;
    cb = reduction.cb;
    body = std::move(reduction.body);
    ValidateFlexibleBodyModes(std::filesystem::path(args.output_path).stem().string(), body.modes);
    // The full model under the same boundary condition, as many modes as the reduction keeps
    start = std::chrono::steady_clock::now();
    if (cb.num_elastic > 0) full = FullModel(job, reduction.system, cb.num_elastic);
    t_full = Since(start);
    // The file, read back and checked against what was written
    start = std::chrono::steady_clock::now();
    body.full_frequencies_hz = full.frequencies_hz;
    body.full_model_boundary = kFullModelBoundary;
    flex::WriteReducedBody(args.output_path, body);
    flex::ReadReducedBody(args.output_path, &body.provenance);
    t_write = Since(start);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }

  const std::vector<double> reduced(cb.frequencies_hz.begin() + cb.num_rigid, cb.frequencies_hz.end());
  const flex::FeMesh& mesh = job.mesh;
  const flex::ReducedBodyProvenance& p = body.provenance;
  if (args.json) {
    JsonWriter w(out);
    w.BeginObject().Key("input").String(args.input_path).Key("output").String(args.output_path);
    w.Key("source").String(job.source).Key("nodes").Int(mesh.num_nodes()).Key("elements").Int(mesh.num_elements());
    w.Key("dofs").Int(dofs).Key("element_type").String(p.element_type);
    w.Key("material").BeginObject().Key("name").String(p.material.name).Key("E").Number(p.material.youngs_modulus_pa);
    w.Key("nu").Number(p.material.poissons_ratio).Key("rho").Number(p.material.density_kg_m3).EndObject();
    w.Key("interfaces").BeginArray();
    for (std::size_t i = 0; i < body.interfaces.size(); ++i) {
      const flex::ReducedInterface& f = body.interfaces[i];
      w.BeginObject().Key("name").String(f.name).Key("node_set").String(job.interface_sets[i]);
      w.Key("kind").String(KindName(f.kind)).Key("slave_nodes").Int(static_cast<long long>(f.slave_node_ids.size()));
      w.Key("master_position_m").BeginArray();
      for (int k = 0; k < 3; ++k) w.Number(f.master_position_m[k]);
      w.EndArray().EndObject();
    }
    w.EndArray().Key("reference_interface").String(body.interfaces[body.reference_interface].name);
    w.Key("modes_kept").Int(static_cast<long long>(cb.fixed_interface_eigenvalues.size()));
    w.Key("cutoff_reached").Bool(cb.cutoff_reached);
    w.Key("reduced_coordinates").Int(cb.K.rows()).Key("elastic_modes").Int(cb.num_elastic);
    w.Key("exported_nodes").Int(static_cast<long long>(body.modes.nodes.size()));
    w.Key("surface_triangles").Int(static_cast<long long>(body.modes.surface_triangles.size()));
    w.Key("stress_modes").Bool(job.outputs.stress_modes).Key("geometric_stiffness").Bool(job.outputs.geometric_stiffness);
    w.Key("full_model_boundary").String(kFullModelBoundary);
    w.Key("full_frequencies_hz").BeginArray();
    for (double f : full.frequencies_hz) w.Number(f);
    w.EndArray().Key("reduced_frequencies_hz").BeginArray();
    for (double f : reduced) w.Number(f);
    w.EndArray().Key("mesh_hash").String(p.mesh_hash).Key("options_hash").String(p.options_hash);
    w.Key("timings_s").BeginObject().Key("mesh").Number(t_mesh).Key("assembly").Number(t_assembly);
    w.Key("reduction").Number(t_reduction).Key("modes").Number(t_modes).Key("full_model").Number(t_full);
    w.Key("write").Number(t_write).EndObject();
    w.Key("notes").BeginArray();
    for (const std::string& n : job.notes) w.String(n);
    w.EndArray().EndObject();
    return kExitSuccess;
  }
  // Text: summary, then the frequency table
  out << job.source << "\n"
      << "mesh: " << mesh.num_nodes() << " nodes, " << mesh.num_elements() << " " << p.element_type << " elements, "
      << dofs << " DOFs; material " << p.material.name << " (E " << Num(p.material.youngs_modulus_pa) << " Pa, nu "
      << Num(p.material.poissons_ratio) << ", rho " << Num(p.material.density_kg_m3) << " kg/m^3)\n";
  for (std::size_t i = 0; i < body.interfaces.size(); ++i) {
    const flex::ReducedInterface& f = body.interfaces[i];
    out << "interface " << f.name << ": " << KindName(f.kind) << " over " << job.interface_sets[i] << " ("
        << f.slave_node_ids.size() << " nodes)" << (static_cast<int>(i) == body.reference_interface ? ", body frame" : "")
        << "\n";
  }
  out << "reduced: " << cb.K.rows() << " coordinates (6 rigid, " << cb.num_elastic << " elastic: "
      << cb.fixed_interface_eigenvalues.size() << " fixed-interface modes"
      << (cb.cutoff_reached ? ", cutoff reached" : "") << "), " << body.modes.nodes.size() << " exported nodes, "
      << body.modes.surface_triangles.size() << " surface triangles" << (job.outputs.stress_modes ? ", stress modes" : "")
      << (job.outputs.geometric_stiffness ? ", geometric stiffness" : "") << "\n"
      << "time: mesh " << Num(t_mesh, "%.2f") << " s, assembly " << Num(t_assembly, "%.2f") << " s, reduction "
      << Num(t_reduction, "%.2f") << " s, modes " << Num(t_modes, "%.2f") << " s, full model " << Num(t_full, "%.2f")
      << " s, write " << Num(t_write, "%.2f") << " s\n"
      << "wrote " << args.output_path << "\n"
      << "full model: " << kFullModelBoundary << "\n";
  char line[96];
  std::snprintf(line, sizeof line, "%4s  %16s  %16s  %10s\n", "mode", "full (Hz)", "reduced (Hz)", "diff (%)");
  out << line;
  for (std::size_t i = 0; i < reduced.size(); ++i) {
    const double f = i < full.frequencies_hz.size() ? full.frequencies_hz[i] : NAN;
    std::snprintf(line, sizeof line, "%4zu  %16.6f  %16.6f  %10.4f\n", i + 1, f, reduced[i], 100 * (reduced[i] - f) / f);
    out << line;
  }
  return kExitSuccess;
}

}  // namespace orrery::cli

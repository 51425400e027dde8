#include "tools/cli/reduce_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_modes.h"
#include "flex/flexible_body_modes.h"
#include "flex/inp_file.h"
#include "flex/reduced_body_file.h"
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
  std::vector<std::string> notes;  // .inp keywords ignored
};

// An interface over a node set; `where` prefixes the error of an unknown set.
flex::FeInterface Interface(const flex::FeMesh& mesh, const std::string& name, const std::string& node_set,
                            flex::InterfaceKind kind, const std::string& where) {
  try {
    flex::FeInterface i = flex::MakeInterface(mesh, node_set, kind);
    i.name = name;
    return i;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
}

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
  return job;
}

// A mesh file with interfaces and material from the command line.
Job InpJob(const ReduceArgs& args) {
  Job job;
  const int given = args.youngs_modulus_pa.has_value() + args.poissons_ratio.has_value() + args.density_kg_m3.has_value();
  if (given != 0 && given != 3) throw std::runtime_error("give all of --E, --nu and --rho (or none, to use the mesh file's materials)");
  if (args.interfaces.empty())
    throw std::runtime_error("a mesh input needs --interface NODESET[:rbe2|rbe3] (the first is the body frame's)");
  flex::InpReadResult read = flex::ReadInp(args.input_path);
  job.mesh = std::move(read.mesh);
  job.notes = std::move(read.notes);
  if (given == 3) {
    job.mesh.AssignMaterialToAll({.name = "CLI", .youngs_modulus_pa = *args.youngs_modulus_pa,
                                  .poissons_ratio = *args.poissons_ratio, .density_kg_m3 = *args.density_kg_m3});
  } else if (job.mesh.materials().empty()) {
    throw std::runtime_error(args.input_path + " has no *MATERIAL / *SOLID SECTION: give --E, --nu and --rho");
  }
  for (const std::string& spec : args.interfaces) {
    // NODESET or NODESET:KIND
    const std::size_t colon = spec.rfind(':');
    const std::string set = spec.substr(0, colon);
    const std::string kind = colon == std::string::npos ? "rbe2" : spec.substr(colon + 1);
    if (set.empty() || (kind != "rbe2" && kind != "rbe3"))
      throw std::runtime_error("--interface " + spec + ": expected NODESET, NODESET:rbe2 or NODESET:rbe3");
    job.interfaces.push_back(Interface(job.mesh, flex::UpperName(set), set,
                                       kind == "rbe3" ? flex::InterfaceKind::kRbe3 : flex::InterfaceKind::kRbe2,
                                       "--interface " + spec));
    job.interface_sets.push_back(set);
  }
  job.cb_options = {.num_modes = args.num_modes.value_or(20), .cutoff_hz = args.cutoff_hz.value_or(0)};
  job.outputs = {.stress_modes = true, .geometric_stiffness = true};
  job.source = "mesh file " + args.input_path;
  return job;
}

// Lowest `n` modes of the FE model with every interface's constraint applied and the reference
// master clamped (the model the Craig-Bampton basis approximates).
flex::FeModes FullModel(const Job& job, const flex::FeSystem& system, int n) {
  const flex::InterfaceTransform t = flex::MakeInterfaceTransform(job.mesh, job.interfaces);
  flex::FeSystem q;
  q.K = t.T.transpose() * system.K * t.T;
  q.M = t.T.transpose() * system.M * t.T;
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
  const std::string extension = std::filesystem::path(args.input_path).extension().string();
  const bool inp = extension == ".inp" || extension == ".INP";
  if (!inp && (args.youngs_modulus_pa || args.poissons_ratio || args.density_kg_m3 || !args.interfaces.empty() ||
               args.num_modes || args.cutoff_hz)) {
    ReportError(err, "--E, --nu, --rho, --interface, --modes and --cutoff-hz go with a mesh (.inp) input; " +
                         args.input_path + " states them itself");
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
    job = inp ? InpJob(args) : GearJob(args.input_path);
    t_mesh = Since(start);
    // Assembly, reduction and what the engine needs
    Reduction reduction = ReduceBody(job.mesh, job.interfaces, job.cb_options, job.outputs, job.source);
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

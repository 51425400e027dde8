#include "tools/cli/fe_modes_command.h"

#include <cstdio>
#include <exception>
#include <filesystem>

#include "flex/blas_kernels.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"
#include "flex/inp_file.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {

int FeModesCommand(const FeModesArgs& args, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!std::filesystem::exists(args.mesh_path, ec)) {
    ReportError(err, "mesh file " + args.mesh_path + ": no such file");
    return kExitFailure;
  }
  const int given = args.youngs_modulus_pa.has_value() + args.poissons_ratio.has_value() + args.density_kg_m3.has_value();
  if (given != 0 && given != 3) {
    ReportError(err, "give all of --E, --nu and --rho (or none, to use the mesh file's materials)");
    return kExitFailure;
  }
  flex::InpReadResult read;
  flex::FeModes modes;
  try {
    read = flex::ReadInp(args.mesh_path);
    flex::FeMesh& mesh = read.mesh;
    if (given == 3) {
      mesh.AssignMaterialToAll({.name = "CLI", .youngs_modulus_pa = *args.youngs_modulus_pa,
                                .poissons_ratio = *args.poissons_ratio, .density_kg_m3 = *args.density_kg_m3});
    } else if (mesh.materials().empty()) {
      throw std::runtime_error(args.mesh_path + " has no *MATERIAL / *SOLID SECTION: give --E, --nu and --rho");
    }
    // Fixed DOFs: every DOF of the named node sets
    std::vector<int> fixed_nodes;
    for (const std::string& set : args.fixed_node_sets) {
      const std::vector<int>& nodes = mesh.NodeSet(set);
      fixed_nodes.insert(fixed_nodes.end(), nodes.begin(), nodes.end());
    }
    // The factorization's BLAS kernels: one note when OpenBLAS runs its generic ones
    if (const std::string advice = flex::BlasKernelAdvice(); !advice.empty()) err << "orrery: note: " << advice << "\n";
    // The system goes to the solver, which releases K and M once the free-DOF matrices are made
    modes = flex::CalcFeModes(flex::AssembleFeSystem(mesh), flex::NodeDofs(fixed_nodes), {.num_modes = args.num_modes});
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  const flex::FeMesh& mesh = read.mesh;
  if (args.json) {
    JsonWriter w(out);
    w.BeginObject().Key("mesh").String(args.mesh_path).Key("nodes").Int(mesh.num_nodes());
    w.Key("elements").Int(mesh.num_elements()).Key("dofs").Int(static_cast<long long>(modes.free_dofs.size()));
    w.Key("fixed_node_sets").BeginArray();
    for (const std::string& s : args.fixed_node_sets) w.String(s);
    w.EndArray().Key("rigid_body_modes").Int(modes.num_rigid_body_modes).Key("frequencies_hz").BeginArray();
    for (double f : modes.frequencies_hz) w.Number(f);
    w.EndArray().Key("notes").BeginArray();
    for (const std::string& n : read.notes) w.String(n);
    w.EndArray().EndObject();
    return kExitSuccess;
  }
  out << "mesh " << args.mesh_path << ": " << mesh.num_nodes() << " nodes, " << mesh.num_elements() << " elements, "
      << modes.free_dofs.size() << " free DOFs, " << modes.num_rigid_body_modes << " rigid-body modes\n";
  char line[64];
  std::snprintf(line, sizeof line, "%4s  %16s\n", "mode", "frequency (Hz)");
  out << line;
  for (std::size_t i = 0; i < modes.frequencies_hz.size(); ++i) {
    std::snprintf(line, sizeof line, "%4zu  %16.6f\n", i + 1, modes.frequencies_hz[i]);
    out << line;
  }
  return kExitSuccess;
}

}  // namespace orrery::cli

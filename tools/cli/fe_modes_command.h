#pragma once
// `orrery fe-modes MESH.inp --E <Pa> --nu <-> --rho <kg/m^3> [--fix NODESET ...] --modes N [--json]`:
// natural frequencies of a linear elastic FE mesh (flex/): the mesh is read from an Abaqus /
// CalculiX .inp file (flex/inp_file.h), the material (E, nu, rho) is assigned to every element
// (without --E/--nu/--rho the file's *MATERIAL / *SOLID SECTION data are used, all three or
// none), the DOFs of the --fix node sets are held at zero, and the lowest N modes are computed
// by shift-invert Lanczos (flex/fe_modes.h). Rigid-body modes of an unsupported mesh are 0 Hz.
//
// Text: a summary line, then "mode  frequency (Hz)" per mode. JSON (--json):
//   {"mesh", "nodes", "elements", "dofs" (free), "fixed_node_sets": [...],
//    "rigid_body_modes", "frequencies_hz": [N values ascending, rigid-body modes as 0],
//    "notes": [ignored .inp keywords]}
// Failures (unreadable mesh, unknown node set, bad material, inverted element, too many modes)
// print one line "orrery: error: <reason>" and return kExitFailure.
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace orrery::cli {

struct FeModesArgs {
  std::string mesh_path;
  std::optional<double> youngs_modulus_pa, poissons_ratio, density_kg_m3;
  std::vector<std::string> fixed_node_sets;
  int num_modes = 10;
  bool json = false;
};

int FeModesCommand(const FeModesArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

#pragma once
// `orrery reduce INPUT -o BODY.h5 [--json]`: reduce a finite-element body once and store it as a
// reduced-body file (flex/reduced_body_file.h, layout in docs/reduced_bodies.md) for the scenes
// that use it.
//
// INPUT is either
//   - a reduce input file (YAML, import/reduce_input.h): a generated gear (models/gear_fe_mesh.h),
//     its material, interfaces, number of modes and outputs; or
//   - a mesh MESH.inp (flex/inp_file.h) with --interface NODESET[:rbe2|rbe3] (repeatable; the
//     first is the reference, the body frame's interface), --modes N [--cutoff-hz F] and the
//     material by --E/--nu/--rho (all three, or none to use the file's).
// Steps: mesh, assembly, Craig-Bampton reduction (flex/craig_bampton.h), the engine's modes and
// invariants (flex/flexible_body_modes.h, with stress modes and geometric stiffness unless
// switched off), the full FE model's frequencies under the same boundary condition (the
// reference interface's master clamped, every interface's RBE2/RBE3 constraint applied, the
// other masters free: the model the reduction approximates, so every reduced frequency is a
// Rayleigh-Ritz upper bound of the matching full one), then the file, which is read back and
// checked before the command reports success.
//
// Text: a summary (mesh, interfaces, sizes, timings) and a table "mode, full (Hz), reduced (Hz),
// difference (%)". JSON (--json):
//   {"input", "output", "source", "nodes", "elements", "dofs", "element_type", "material",
//    "interfaces": [{"name", "node_set", "kind", "slave_nodes", "master_position_m"}],
//    "reference_interface", "modes_kept", "cutoff_reached", "reduced_coordinates", "elastic_modes",
//    "exported_nodes", "surface_triangles", "stress_modes", "geometric_stiffness",
//    "full_model_boundary", "full_frequencies_hz", "reduced_frequencies_hz" (elastic, ascending),
//    "mesh_hash", "options_hash", "timings_s": {"mesh", "assembly", "reduction", "modes",
//    "full_model", "write"}}
// Failures (unreadable or invalid input, unknown node set, bad material, failed reduction) print
// one line "orrery: error: <reason>" naming the file and key where there is one, and return
// kExitFailure.
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace orrery::cli {

struct ReduceArgs {
  std::string input_path;
  std::string output_path;
  bool json = false;
  // For a .inp input only:
  std::optional<double> youngs_modulus_pa, poissons_ratio, density_kg_m3;
  std::vector<std::string> interfaces;  // "NODESET" or "NODESET:rbe2" / "NODESET:rbe3"
  std::optional<int> num_modes;         // default 20
  std::optional<double> cutoff_hz;
};

int ReduceCommand(const ReduceArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

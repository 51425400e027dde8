#pragma once
// `orrery reduce INPUT -o BODY.h5 [--json]`: reduce a finite-element body once and store it as a
// reduced-body file (flex/reduced_body_file.h, layout in docs/reduced_bodies.md) for the scenes
// that use it.
//
// INPUT is chosen by its extension:
//   - .yaml / .yml: a reduce input file (import/reduce_input.h): a generated gear
//     (models/gear_fe_mesh.h), its material, interfaces, number of modes and outputs;
//   - anything else is a part (import/part_reduction.h), with --interface SPEC[:rbe2|rbe3]
//     (repeatable; the first is the reference, the body frame's interface; SPEC a node set, or
//     `bore`), --modes N [--cutoff-hz F]:
//       a volume mesh MESH.inp / MESH.msh, material by --E/--nu/--rho (all three, or for .inp none
//         to use the file's; --density is --rho); .msh coordinates in --unit (default m);
//       a STEP/IGES solid (its own unit) or a watertight surface mesh (STL, OBJ, PLY, glTF, 3MF,
//         ...; --unit, default m), tetrahedralized by gmsh (import/gmsh_mesher.h) with
//         --element tet10|tet4 (default tet10, straight-sided; --curved: on the CAD geometry),
//         --mesh-size H and --mesh-min-size H (m), --curvature N (elements per 2 pi of
//         curvature), then --E/--nu/--rho;
//       a user's FE matrices: CalculiX job.sti (with job.mas, job.dof and the mesh job.inp beside
//         it, or --mesh) or a Matrix Market stiffness K.mtx with --mass M.mtx, --dofs TABLE and
//         --mesh MESH (import/fe_matrices.h).
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
  // For part inputs only (not .yaml):
  std::optional<double> youngs_modulus_pa, poissons_ratio, density_kg_m3;
  std::vector<std::string> interfaces;  // "SPEC" or "SPEC:rbe2" / "SPEC:rbe3"
  std::optional<int> num_modes;         // default 20
  std::optional<double> cutoff_hz;
  std::string unit;                     // "" or m, cm, mm, in
  std::optional<double> mesh_size_m, mesh_min_size_m;
  std::optional<int> curvature_elements;
  std::string element;                  // "" (tet10), "tet10", "tet4"
  bool curved = false;                  // CAD tet10 with midside nodes on the geometry
  std::string mass_matrix, dof_table, mesh_file;
};

int ReduceCommand(const ReduceArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

#pragma once
// What `orrery reduce` needs to reduce a part that is not a generated gear: a volume mesh from a
// file (.msh, .inp, a STEP/IGES solid or a watertight surface mesh tetrahedralized by gmsh,
// volume_mesh.h) with a material, or a user's own FE matrices (CalculiX MATRIXSTORAGE or Matrix
// Market, fe_matrices.h); its interfaces; the reduction options. The result feeds ReduceBody
// (reduce_input.h), whose reduced body carries the provenance of this input.
//
// Interfaces ("SPEC[:rbe2|rbe3]", the first is the body frame's):
//   NODESET   a node set of the mesh: an .inp *NSET, a .msh physical group, FACE<k> for face k
//             of a STEP solid (gmsh_mesher.h), SOLID;
//   bore      the bore of a gear-like part: the nodes on the boundary surface whose distance r
//             from the z axis through the solid's centroid is at most 1.02 r_min, r_min the smallest
//             such distance of a corner node (corners lie on the surface; midside nodes of straight
//             edges on chords inside the bore are selected with them). The centroid axis is the gear axis for a
//             gear in its own frame (gear_geometry.h). Its master (the body frame's origin when
//             it is the first interface) is the solid's centroid: on the axis and mid-face for a
//             gear, not the slave nodes' centroid, which an unstructured mesh's uneven node density
//             moves off the axis. Refused when it selects fewer than 3 nodes or nodes that span
//             less than half the turn.
// Provenance: the mesh hash is that of the FE mesh (meshing with gmsh is deterministic:
// one thread, fixed options); for external matrices it also covers the matrix files' bytes.
//
// Errors: std::runtime_error naming the input, the option or the interface.
//
// Usage:
//   PartReduction job = PreparePartReduction({.input = "planet.step", .material = steel,
//                                             .interfaces = {"bore"}, .modes = 20});
//   Reduction r = ReduceBody(job.mesh, job.system, job.interfaces, job.cb_options, job.outputs,
//                            job.source);
#include <optional>
#include <string>
#include <vector>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_mesh.h"
#include "flex/flexible_body_modes.h"
#include "import/gmsh_mesher.h"
#include "import/length_unit.h"

namespace orrery {

struct PartReductionInput {
  std::string input;                                  // mesh, CAD, surface or matrix file
  std::optional<LengthUnit> unit;                     // .msh and surface inputs
  std::optional<flex::IsotropicMaterial> material;    // required but for .inp / matrices
  std::vector<std::string> interfaces;                // "SPEC[:rbe2|rbe3]", at least one
  int modes = 20;
  double cutoff_hz = 0;
  GmshMeshOptions meshing;                            // CAD / surface inputs
  // External matrices: input is the stiffness (job.sti, or a Matrix Market .mtx)
  std::string mass_matrix;   // .mtx: required; .sti: default job.mas
  std::string dof_table;     // .mtx: required; .sti: default job.dof
  std::string mesh_file;     // node positions and sets: .sti: default job.inp; .mtx: required
};

struct PartReduction {
  flex::FeMesh mesh;
  std::optional<flex::FeSystem> system;  // external matrices (else assembled from the mesh)
  std::vector<flex::FeInterface> interfaces;
  std::vector<std::string> interface_sets;   // what each interface was selected by
  flex::CraigBamptonOptions cb_options;
  flex::FlexibleBodyModesOptions outputs;
  std::string source;
  std::string matrices_digest;               // external matrices: FNV-1a 64 of their files
  std::vector<std::string> notes, warnings;
};

// True for inputs PreparePartReduction handles (not the YAML gear inputs of reduce_input.h).
bool IsPartReductionInput(const std::string& path);

PartReduction PreparePartReduction(const PartReductionInput& input);

// An interface from "SPEC[:rbe2|rbe3]" (above) on `mesh`; its name is the node set's (upper
// case) or "BORE". Throws std::runtime_error "--interface SPEC: reason".
flex::FeInterface SelectInterface(const flex::FeMesh& mesh, const std::string& spec);

}  // namespace orrery

#pragma once
// `orrery mesh-stiffness SCENE --mesh NAME --flexible [--load N] [--points K] [--json]`: the
// quasi-static mesh sweep of mesh_stiffness_command.h with both gears FLEXIBLE
// (models/flexible_gear_mesh.h SweepFlexibleGearMesh): each gear meshed with hex20 elements,
// held at its bore (radius: the lumped models' blank, TrainMeshTvmsOptions), reduced to the
// static attachment modes of the loaded flanks through the mesh zone; analytic flanks embedded in
// the FE faces carry the contact; the penalty is the Hertzian line-contact stiffness of the
// lumped TVMS (Yang & Lin 1987), so that bending, shear and the fillet foundation come from the FE
// model only.
// Default mesh (what a CI run affords, about 10 s for seed 001's 34/18 pair): flank 4, tooth 3,
// fillet 2, root layer 2, rim 2 hex20 elements, one across the face width; --fe-level L multiplies
// every count by L (L = 2: about 8 times the nodes, minutes and several GB).
//
// Text: one line per roll angle (TE, stiffness, contact points, teeth in contact, the number the
// unloaded path of contact predicts, contact pattern on gear 1) and a summary: mean stiffness,
// single- and double-zone means, ISO 6336 c' b and c_gamma_alpha b, TVMS mean / min / max.
// JSON (--json): the rigid command's keys, plus "predicted_pairs", "single_zone_stiffness_n_per_m",
// "double_zone_stiffness_n_per_m", "tvms_min_n_per_m", "tvms_max_n_per_m",
// "hertz_stiffness_n_per_m", "modes_gear1", "modes_gear2", "fe_nodes_gear1", "fe_nodes_gear2",
// "reduce_seconds", "sweep_seconds".
#include <ostream>

#include "tools/cli/mesh_stiffness_command.h"

namespace orrery::cli {

// args.flexible is implied; args.fe_level (>= 1) scales the default mesh.
int FlexibleMeshStiffnessCommand(const MeshStiffnessArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli

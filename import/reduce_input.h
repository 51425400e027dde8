#pragma once
// Input files of `orrery reduce` (YAML): what to mesh, with which material, which interfaces,
// how many modes and which outputs. Read with the scene rules (docs/scene_format.md: strict keys
// with suggestions, plain numbers, errors "FILE:LINE: KEY: reason" as SceneError); described in
// docs/reduced_bodies.md.
//
//   gear: {teeth: 23, module_mm: 2, pressure_angle_deg: 20, helix_angle_deg: 0, hand: right,
//          face_width_mm: 20, profile_shift: 0, bore_diameter_mm: 20}
//   mesh: {element: hex20, flank_divisions: 4, fillet_divisions: 2, tooth_divisions: 2,
//          root_layer_divisions: 1, rim_divisions: 2, face_divisions: 2}
//   material: {name: steel, E: 210e9, nu: 0.3, rho: 7850}          # Pa, -, kg/m^3
//   interfaces:
//     - {name: bore, node_set: BORE, kind: rbe2}
//   reduction: {modes: 20, cutoff_hz: 0, reference: bore, inertial_load_modes: false}
//   outputs: {stress_modes: true, geometric_stiffness: true, export_node_sets: [TOOTH0_FLANK_PLUS]}
//   fault: {kind: broken_tooth, tooth: 0, height_fraction: 0.5}     # or a list (optional)
//
// fault: tooth faults of the gear (import/tooth_fault_reader.h: the fields of
// models/tooth_fault.h), checked against the gear; breaks and cracks change the mesh
// (models/gear_fe_mesh.h), and every fault is recorded in the body's provenance
// (ReducedBodyProvenance::faults), so that a body reduced healthy is never taken for a faulty one.
//
// Lengths take a unit suffix (module, module_mm; face_width, face_width_mm; bore_diameter,
// bore_diameter_mm), angles are in degrees (_deg) or radians (no suffix). The gear is checked by
// constructing it (models/gear_geometry.h); node set names are checked when the mesh exists, so
// every interface keeps the place of its node_set key (`node_set_at`) for that message.
//
// Usage:
//   ReduceInput in = LoadReduceInput("planet.yaml");
//   gears::Gear gear(in.gear);
//   flex::FeMesh mesh = gears::MakeGearFeMesh(gear, in.mesh);
#include <span>
#include <string>
#include <vector>

#include "flex/craig_bampton.h"
#include "flex/fe_interface.h"
#include "flex/fe_mesh.h"
#include "flex/flexible_body_modes.h"
#include "flex/reduced_body_file.h"
#include "models/gear_fe_mesh.h"
#include "models/gear_geometry.h"

namespace orrery {

struct ReduceInput {
  std::string file;           // the input file (as given)
  gears::GearSpec gear;       // gear: (validated)
  gears::GearFeMeshSpec mesh; // mesh: and material: (bore radius from gear.bore_diameter)

  struct Interface {
    std::string name;         // unique
    std::string node_set;     // a node set of the generated mesh
    bool rbe3 = false;        // kind: rbe2 (default) | rbe3
    std::string node_set_at;  // "FILE:LINE: interfaces[NAME].node_set", for errors
  };
  std::vector<Interface> interfaces;  // at least one

  int modes = 20;             // reduction.modes: fixed-interface normal modes (>= 0)
  bool inertial_load_modes = false;  // reduction.inertial_load_modes (CraigBamptonOptions)
  double cutoff_hz = 0;       // reduction.cutoff_hz (>= 0; 0: none)
  int reference_interface = 0;  // reduction.reference (an interface name; default the first)
  bool stress_modes = true;         // outputs.stress_modes
  bool geometric_stiffness = true;  // outputs.geometric_stiffness
  std::vector<std::string> export_node_sets;  // outputs.export_node_sets
};

// Throws SceneError (import/scene.h) "FILE:LINE: KEY: reason" for a missing or unknown key, a
// wrong type or a value out of range, "FILE: cannot open ..." for an unreadable file.
ReduceInput LoadReduceInput(const std::string& path);
// The same from text; `file` names it in messages.
ReduceInput ParseReduceInput(const std::string& text, const std::string& file);

// What reducing a generated gear takes: its mesh (material assigned), the interfaces over their
// node sets, the reduction options, the outputs and a description of the source. Shared by
// `orrery reduce` and by scenes that check a reduced-body file against its input (the expected
// provenance is MakeReducedBodyProvenance of these).
struct GearReduction {
  flex::FeMesh mesh;
  std::vector<flex::FeInterface> interfaces;
  std::vector<std::string> interface_sets;  // node set of each interface
  flex::CraigBamptonOptions cb_options;
  flex::FlexibleBodyModesOptions outputs;
  std::string source;
  std::string faults;  // DescribeGearFaults of the mesh's faults ("none" for a healthy gear)
};
// Throws std::runtime_error "FILE: KEY: reason" when the mesh cannot be generated or an
// interface's or output's node set does not exist.
GearReduction PrepareGearReduction(const ReduceInput& input);

// Assembles and reduces a mesh with its interfaces: the reduced body with its provenance,
// Craig-Bampton K, M and frequencies and the interfaces, plus the assembled system, the reduction
// and the time of each stage. The full model's frequencies are left empty (`orrery reduce` adds
// them; a scene that makes a missing body file on the fly does not need them).
struct Reduction {
  flex::FeSystem system;
  flex::CraigBamptonModel cb;
  flex::ReducedBody body;
  double assembly_s = 0, reduction_s = 0, modes_s = 0;  // wall time of each stage
};
// `faults`: the provenance's fault text (DescribeGearFaults; "" unknown, e.g. a mesh file).
Reduction ReduceBody(const flex::FeMesh& mesh, std::span<const flex::FeInterface> interfaces,
                     const flex::CraigBamptonOptions& cb_options, const flex::FlexibleBodyModesOptions& outputs,
                     const std::string& source, const std::string& faults = "");
// The same for a system assembled elsewhere (external FE matrices, import/fe_matrices.h): `system`
// is used as given (assembly_s = 0).
Reduction ReduceAssembledBody(const flex::FeMesh& mesh, flex::FeSystem system,
                              std::span<const flex::FeInterface> interfaces, const flex::CraigBamptonOptions& cb_options,
                              const flex::FlexibleBodyModesOptions& outputs, const std::string& source,
                              const std::string& faults = "");

// The faults of a gear as provenance text: "none", or DescribeToothFault of each joined by "; ".
std::string DescribeGearFaults(const std::vector<gears::ToothFaultSpec>& faults);

}  // namespace orrery

#pragma once
// Reduced-body files: a Craig-Bampton reduction (craig_bampton.h) and everything the engine needs
// from it (mbd/flexible_body.h FlexibleBodyModes), stored once as HDF5 and reused across runs.
// The layout is described in docs/reduced_bodies.md; doubles are stored as IEEE 64-bit values and
// read back bit for bit, so WriteReducedBody then ReadReducedBody returns an equal ReducedBody.
//
// Staleness: the file carries its provenance (ReducedBodyProvenance): hashes of the mesh and of
// the reduction options, the element type, the material, the modes kept and the engine version.
// A scene that uses the file computes the provenance it expects from its own mesh and options
// (MakeReducedBodyProvenance) and CheckReducedBodyMatches rejects a file that was reduced from
// something else, with the reasons ("mesh hash differs: file was reduced from ..., the scene's
// mesh is ..."; "modes kept 20, the scene asks 30").
//
// Hashes are FNV-1a 64 (Fowler, Noll, Vo; http://www.isthe.com/chongo/tech/comp/fnv/) over a
// canonical byte stream: node ids and positions, element ids, types and node indices, the
// material of every element (name, E, nu, rho) and the node sets, all in mesh order, doubles by
// their IEEE bit patterns. FNV-1a detects changes; it is not meant to resist forgery.
//
// Usage:
//   ReducedBody body{.modes = MakeFlexibleBodyModes(...), .K = cb.K, .M = cb.M, ...};
//   body.provenance = MakeReducedBodyProvenance(mesh, cb_options, interfaces, outputs, "gear z=23");
//   WriteReducedBody("planet.h5", body);
//   ReducedBody again = ReadReducedBody("planet.h5");                 // format and sizes checked
//   ReducedBody checked = ReadReducedBody("planet.h5", &expected);    // and provenance matched
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "flex/craig_bampton.h"
#include "flex/fe_interface.h"
#include "flex/fe_mesh.h"
#include "flex/flexible_body_modes.h"
#include "mbd/flexible_body.h"

namespace orrery::flex {

// "orrery reduced body" files of this format version are read; others are rejected.
inline constexpr int kReducedBodyFormatVersion = 1;

// Where a reduced body came from. Fields left at their defaults ("" / -1 / material E = 0) are
// "not known" and are not compared by CheckReducedBodyMatches.
struct ReducedBodyProvenance {
  std::string source;          // what was reduced: "gear z=23 m_n=2 mm ..." or the mesh file path
  std::string mesh_hash;       // "fnv1a64:<16 hex digits>" of the mesh (HashFeMesh)
  std::string options_hash;    // "fnv1a64:<16 hex digits>" of the reduction (HashReductionOptions)
  std::string element_type;    // CalculiX names of the element types, "C3D20" or "C3D8+C3D20"
  IsotropicMaterial material;  // the mesh's material ("MIXED" name, zeros if several)
  int modes_kept = -1;         // fixed-interface normal modes kept
  std::string engine_version;  // ORRERY_VERSION of the writer (recorded, not compared)
  // The damage the reduced geometry carries, as text ("none" for a healthy gear; a gear's tooth
  // faults as import/reduce_input.h DescribeGearFaults writes them), so that a body reduced
  // healthy is never used where a faulty one is asked for (and the reverse); "" unknown (files
  // written before this field, mesh-file reductions).
  std::string faults;
};

// An interface as stored: enough to rebuild the FeInterface on the same mesh and to attach
// joints to its master.
struct ReducedInterface {
  std::string name;
  InterfaceKind kind = InterfaceKind::kRbe2;
  Eigen::Vector3d master_position_m = Eigen::Vector3d::Zero();  // in B
  std::vector<int> slave_node_ids;  // FE node ids (not indices)
  std::vector<double> weights;      // per slave node (1 where the interface gave none)
};

// The content of a reduced-body file.
struct ReducedBody {
  FlexibleBodyModes modes;                   // what the engine needs (flexible_body.h)
  Eigen::MatrixXd K;                         // (nr x nr) Craig-Bampton reduced stiffness, N/m
  Eigen::MatrixXd M;                         // (nr x nr) Craig-Bampton reduced mass, kg
  std::vector<double> reduced_frequencies_hz;  // (nr) CraigBamptonModel::frequencies_hz, 6 rigid zeros first
  std::vector<double> full_frequencies_hz;     // the FE model under `full_model_boundary`, ascending
  std::string full_model_boundary;             // e.g. "reference interface master clamped"
  std::vector<ReducedInterface> interfaces;
  int reference_interface = 0;               // index into `interfaces`: the body frame's interface
  ReducedBodyProvenance provenance;
};

// Thrown by CheckReducedBodyMatches (and ReadReducedBody with an expected provenance).
class StaleReducedBodyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "fnv1a64:<16 lower-case hex digits>" of `bytes`.
std::string Fnv1a64Hex(std::string_view bytes);
// The mesh hash (header): nodes, elements, element materials, node and element sets.
std::string HashFeMesh(const FeMesh& mesh);
// The hash of the reduction: CB options, interfaces (name, kind, slave node indices, weights,
// master position) and what MakeFlexibleBodyModes was asked to export.
std::string HashReductionOptions(const CraigBamptonOptions& options, std::span<const FeInterface> interfaces,
                                 const FlexibleBodyModesOptions& outputs);
// The provenance of reducing `mesh` with these settings (engine version = this build's).
ReducedBodyProvenance MakeReducedBodyProvenance(const FeMesh& mesh, const CraigBamptonOptions& options,
                                                std::span<const FeInterface> interfaces,
                                                const FlexibleBodyModesOptions& outputs, std::string source,
                                                std::string faults = "");
// An interface as stored (master position: the given one or the slave centroid).
ReducedInterface DescribeInterface(const FeMesh& mesh, const FeInterface& interface);

// Writes (truncates) `path`. Throws std::invalid_argument naming the field when the body is
// inconsistent (sizes of modes, K and M, interfaces, reference index), std::runtime_error naming
// the path when the file cannot be written.
void WriteReducedBody(const std::string& path, const ReducedBody& body);

// Reads a reduced-body file and checks its format, every size and index against the others, and
// that every number is finite (node positions, mode shapes, stress modes, matrices: a NaN or inf
// would flow silently into every result). With `expected`, also CheckReducedBodyMatches. Throws
// std::runtime_error naming the file and the dataset or attribute ("body.h5: /modes/stiffness:
// expected 4 x 4, found 4 x 5"; "body.h5: /modes/nodes/positions: value nan at row 3, column 0 is
// not finite"; "body.h5: not an orrery reduced body file (no attribute format on /)"),
// StaleReducedBodyError for a provenance mismatch.
ReducedBody ReadReducedBody(const std::string& path, const ReducedBodyProvenance* expected = nullptr);

// Compares the known fields of `expected` with the file's provenance; throws
// StaleReducedBodyError listing every difference, prefixed by `file_path` when given.
void CheckReducedBodyMatches(const ReducedBodyProvenance& file, const ReducedBodyProvenance& expected,
                             const std::string& file_path = "");

}  // namespace orrery::flex

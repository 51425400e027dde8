#pragma once
// External FE matrices: the stiffness and mass of a user's own FE model (their mesh, materials,
// bolt holes), exported by their solver, so that the engine's Craig-Bampton code
// (flex/craig_bampton.h) reduces it. File formats, so they live in import/; what they become is
// flex's FeSystem over a flex::FeMesh.
//
// CalculiX (ccx 2.20, *STEP / *FREQUENCY, SOLVER=MATRIXSTORAGE; documented in the CalculiX
// User's Manual, *FREQUENCY): ccx writes
//   job.sti, job.mas   one entry per line "row column value", 1-based, upper triangle
//                      (row <= column), 14 significant digits;
//   job.dof            one line per row/column: "node.direction" (direction 1-3 for solids).
// The DOFs of nodes held by a *BOUNDARY are not in the matrices; export the free model.
// Matrix Market (NIST, "The Matrix Market Exchange Formats", Boisvert, Pozo, Remington 1996):
//   "%%MatrixMarket matrix coordinate real|integer general|symmetric" then '%' comments, the size
//   line "rows columns entries" and the entries "i j value" (1-based; duplicates are summed;
//   symmetric: one triangle, mirrored), or "array real general|symmetric" (column-major values,
//   symmetric: the lower triangle by columns). Pattern, complex, skew and Hermitian matrices
//   are refused. A general matrix must be symmetric to 1e-9 of its largest entry.
// DOF tables (for Matrix Market): one line per row, "NODE DIR" or "NODE.DIR", DIR one of
//   1 2 3 / x y z; '#' and '%' start comments.
//
// Into the engine (ToFeModel): the nodes of a mesh file (.inp or .msh: positions, node sets, and
// elements if there are any, for surface triangles and stress modes) restricted to the nodes the
// DOF table lists; every such node must have all three translational DOFs, every element only
// such nodes; the matrices are reordered to the FE numbering (node index i owns DOFs 3 i + 0..2,
// flex/fe_assembly.h).
//
// Errors (std::runtime_error, "FILE[:LINE]: reason"): a malformed line, an index outside the
// size, matrices of different sizes, a DOF table whose length is not the matrix size, a DOF
// beyond 3 (shell / beam rotations), a node of the table missing from the mesh, a node with only
// some of its DOFs, an element on a node without DOFs, a non-symmetric matrix, non-finite values.
// Header counts are checked against the bytes left before anything is sized by them.
//
// Usage:
//   FeMatrices m = ReadCalculixMatrices("job");           // job.sti, job.mas, job.dof
//   ExternalFeModel fe = ToFeModel(m, flex::ReadInp("job.inp").mesh, "job.inp");
//   flex::ReduceCraigBampton(fe.mesh, fe.system, interfaces, options);
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/SparseCore>

#include "flex/fe_assembly.h"
#include "flex/fe_mesh.h"
#include "import/bounded_file.h"

namespace orrery {

struct DofEntry {
  int node_id = 0;
  int direction = 0;  // 1, 2, 3 (x, y, z)
};

struct FeMatrices {
  Eigen::SparseMatrix<double> K;   // (n x n) symmetric, both triangles stored
  Eigen::SparseMatrix<double> M;   // (n x n)
  std::vector<DofEntry> dofs;      // (n) the node and direction of each row
  std::string source;              // "CalculiX matrices job.sti, job.mas, job.dof"
  std::string digest;              // FNV-1a 64 of the files' bytes (provenance)
};

// A symmetric matrix from a Matrix Market file (`bytes`, named `source`).
Eigen::SparseMatrix<double> ParseMatrixMarket(std::string_view bytes, const std::string& source);
Eigen::SparseMatrix<double> ReadMatrixMarket(const std::filesystem::path& path,
                                             std::uintmax_t max_bytes = kDefaultMaxInputBytes);

// A CalculiX .sti / .mas file: `size` rows and columns (from the .dof file).
Eigen::SparseMatrix<double> ParseCalculixMatrix(std::string_view bytes, int size, const std::string& source);
// A DOF table (CalculiX .dof or the table above).
std::vector<DofEntry> ParseDofTable(std::string_view bytes, const std::string& source);

// `job` with or without extension: job.sti, job.mas and job.dof.
FeMatrices ReadCalculixMatrices(const std::filesystem::path& job, std::uintmax_t max_bytes = kDefaultMaxInputBytes);
// Matrix Market stiffness and mass with a DOF table.
FeMatrices ReadMatrixMarketPair(const std::filesystem::path& stiffness, const std::filesystem::path& mass,
                                const std::filesystem::path& dof_table,
                                std::uintmax_t max_bytes = kDefaultMaxInputBytes);

struct ExternalFeModel {
  flex::FeMesh mesh;        // the nodes of the DOF table (mesh order), their elements and sets
  flex::FeSystem system;    // K, M in the FE numbering; volume and mass from the mass matrix
  std::vector<std::string> notes;
};

// Throws std::runtime_error naming `mesh_source` or the matrices' source (see above).
ExternalFeModel ToFeModel(const FeMatrices& matrices, const flex::FeMesh& mesh, const std::string& mesh_source);

}  // namespace orrery

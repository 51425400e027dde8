#pragma once
// Abaqus / CalculiX input files (.inp): read a mesh, write a mesh with its materials and an
// eigenfrequency step.
//
// Reader (ReadInp / ParseInp). Keywords and parameters are case-insensitive; "**" starts a
// comment line; a data line ending in a comma continues on the next line.
//   *NODE [, NSET=name]                 id, x, y, z
//   *ELEMENT, TYPE=C3D4|C3D10|C3D8|C3D20 [, ELSET=name]
//                                       id, node ids (CalculiX order, fe_mesh.h), over as many
//                                       lines as needed
//   *NSET, NSET=name [, GENERATE]       node ids or node set names; GENERATE: first, last[, step]
//   *ELSET, ELSET=name [, GENERATE]     element ids or element set names; GENERATE as above
//   *MATERIAL, NAME=name                then *ELASTIC [, TYPE=ISO] (E, nu) and *DENSITY (rho)
//   *SOLID SECTION, ELSET=name, MATERIAL=name
// Every other keyword (and its data lines) is skipped with a note "file:line: *KEYWORD ignored";
// *INCLUDE is an error (the mesh would be incomplete). Elements and sets may refer to nodes and
// elements defined later in the file. Errors are std::runtime_error "file:line: *KEYWORD: reason".
//
// Writer (WriteInp): *HEADING, *NODE, *ELEMENT blocks (one per run of equal types; C3D20 on two
// lines, at most 16 entries per line), *NSET / *ELSET for every set, *MATERIAL / *ELASTIC /
// *DENSITY per material, *SOLID SECTION per assignment, *BOUNDARY (DOFs 1-3) for the fixed node
// sets, and *STEP / *FREQUENCY with the number of eigenfrequencies (CalculiX writes them to the
// .dat file). Numbers are written with 17 significant digits, so a read-back mesh is identical.
//
// Usage:
//   InpReadResult r = ReadInp("gear.inp");            // r.mesh, r.notes
//   WriteInpFile("job.inp", r.mesh, {.fixed_node_sets = {"BORE"}, .num_frequencies = 20});
#include <filesystem>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "flex/fe_mesh.h"

namespace orrery::flex {

struct InpReadResult {
  FeMesh mesh;
  std::vector<std::string> notes;  // ignored keywords, "file:line: *KEYWORD ignored"
};

// Throws std::runtime_error (file:line: *KEYWORD: reason) on malformed input, and for an
// unreadable file or one that is not a regular file (a device such as /dev/zero).
InpReadResult ReadInp(const std::filesystem::path& path);
// `source_name` stands for the file in messages.
InpReadResult ParseInp(std::istream& in, const std::string& source_name);

struct InpWriteOptions {
  std::string heading = "Orrery FE mesh";
  std::vector<std::string> fixed_node_sets;  // *BOUNDARY set, 1, 3
  int num_frequencies = 0;                   // > 0: *STEP / *FREQUENCY / *END STEP
};

// Throws std::invalid_argument for an unknown fixed node set.
void WriteInp(std::ostream& out, const FeMesh& mesh, const InpWriteOptions& options = {});
// Throws std::runtime_error if the file cannot be written.
void WriteInpFile(const std::filesystem::path& path, const FeMesh& mesh, const InpWriteOptions& options = {});

}  // namespace orrery::flex

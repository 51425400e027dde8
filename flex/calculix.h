#pragma once
// CalculiX (ccx) as an external oracle for FE modes: find the program, run a *FREQUENCY job on a
// mesh written by WriteInp, and read the eigenvalues from its .dat file.
//
// The .dat file of a *FREQUENCY step holds a table after the line "E I G E N V A L U E   O U T P U T":
//   MODE NO, EIGENVALUE (rad/time)^2, FREQUENCY real part (rad/time), (cycles/time), imaginary part
// ReadCalculixEigenvalues returns the EIGENVALUE column (7 significant digits in ccx 2.20).
//
// Usage:
//   if (auto ccx = FindCalculix()) {
//     std::vector<double> w2 = RunCalculixFrequency(*ccx, mesh, {"XMIN"}, 20, work_dir);
//   }
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "flex/fe_mesh.h"

namespace orrery::flex {

// The CalculiX program on PATH: "ccx", else the first "ccx_<version>" found; nullopt if none.
std::optional<std::filesystem::path> FindCalculix();

// The eigenvalues w^2 ((rad/s)^2) of the first frequency step in a .dat file, in mode order.
// Throws std::runtime_error if the file cannot be read or holds no eigenvalue table.
std::vector<double> ReadCalculixEigenvalues(const std::filesystem::path& dat_file);

// Writes `work_dir`/orrery_modes.inp (mesh with its materials, *BOUNDARY on `fixed_node_sets`,
// *FREQUENCY with `num_modes`), runs `ccx -i orrery_modes` there and returns the eigenvalues.
// Throws std::runtime_error (with the tail of ccx's output) if ccx fails.
std::vector<double> RunCalculixFrequency(const std::filesystem::path& ccx, const FeMesh& mesh,
                                         const std::vector<std::string>& fixed_node_sets, int num_modes,
                                         const std::filesystem::path& work_dir);

}  // namespace orrery::flex

#pragma once
// Tooth faults in `orrery mesh-stiffness` (mesh_stiffness_command.h): the scene's
// `dynamics.faults` and `--fault KEY=VALUE,...` entries on the swept pair's gears, and the
// comparison of a faulty sweep with its healthy twin and with the lumped TVMS (docs/faults.md,
// "Cross-level consistency": the same definitions as tests/models/tooth_fault_levels_test.cpp).
//   - Faults: those on gear 1 or gear 2 of the mesh (planets: the branch of `--mesh NAME#k`,
//     default 1), gear-frame tooth indices as everywhere.
//   - Range: the first fault's tooth engagement (the TVMS's pair of that tooth, eps_alpha mesh
//     periods, models/mesh_stiffness.h TvmsSweepFrame) with a quarter pitch on either side.
//   - Ratio r = k_faulty / k_healthy at each roll angle, for the sweep's level and for the TVMS
//     (secant F / delta at the load, 400 samples per period, the train's blanks and material);
//     drop zone: r below 1 - half the largest drop (a crack, which acts over the whole
//     engagement: r < 0.995); mean drop: the mean of 1 - r over the TVMS's zone.
//   - A spall: the TVMS rows of both spall models (Hertz contact: what FE contact shows; lost
//     slices: what rigid contact shows).
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "models/gear_contact.h"
#include "models/mesh_stiffness.h"

namespace orrery {
struct GearTrainScene;
}

namespace orrery::cli {

struct MeshFaults {
  std::vector<gears::ToothFaultSpec> gear1, gear2;  // gear-frame teeth
  std::vector<std::string> names;                   // "S1.planet#1 tooth 17 broken_tooth", ...
  bool empty() const { return gear1.empty() && gear2.empty(); }
};

// mesh_name: "S1.sun-planet" or "S1.sun-planet#2"; fills the train mesh index and branch (0-based).
// Throws std::runtime_error for an unknown mesh or a branch out of range; SceneError for a bad
// --fault.
MeshFaults SelectMeshFaults(const GearTrainScene& gt, const std::string& mesh_name,
                            const std::vector<std::string>& cli_faults, int* mesh, int* branch);

gears::MeshSweepRange FaultEngagement(const gears::GearPair& pair, const MeshFaults& faults);

// One level's comparison with the TVMS (header).
struct FaultDrop {
  std::string level;
  double first_rad = 0, last_rad = 0;  // the level's drop zone (NaN: none)
  double mean_drop = 0, tvms_mean_drop = 0;
};
FaultDrop CompareFaultDrop(const std::string& level, const std::vector<double>& angles,
                           const std::vector<double>& healthy, const std::vector<double>& faulty,
                           const std::vector<double>& tvms_healthy, const std::vector<double>& tvms_faulty,
                           bool engagement);

// TVMS secant stiffness F / delta (N/m) at sweep angles, with the faults.
std::vector<double> TvmsSecantAt(const gears::GearPair& pair, gears::TvmsOptions options, const MeshFaults& faults,
                                 const std::vector<double>& angles, double load_n);

// The whole fault report of one level: sweeps `sweep(faults)` (the level's stiffness at the
// range's `points` angles, empty faults: healthy) healthy and faulty, the TVMS at the same angles,
// and writes one line per angle and the table rows (text) or the JSON keys "faults",
// "roll_angle_rad", "healthy_stiffness_n_per_m", "faulty_stiffness_n_per_m",
// "tvms_healthy_n_per_m", "tvms_faulty_n_per_m" and "levels" [{level, drop_zone_start_rad,
// drop_zone_end_rad, mean_drop, tvms_mean_drop}].
class JsonWriter;
void WriteFaultReport(const std::string& level, const gears::GearPair& pair, const gears::TvmsOptions& tvms_options,
                      const MeshFaults& faults, double load_n, const gears::MeshSweepRange& range, int points,
                      const std::function<std::vector<double>(const MeshFaults&)>& sweep, JsonWriter* json,
                      std::ostream& out);

// The `orrery mesh-stiffness --fault` output of one level: its head (scene, mesh, load; the text
// head names the level's `surfaces`), then WriteFaultReport over the first fault's engagement, as
// one JSON object (json) or text.
struct FaultSweepHead {
  std::string scene, mesh, surfaces;
  double load_n = 0;
  int points = 0;
  bool json = false;
};
void WriteFaultSweep(const FaultSweepHead& head, const std::string& level, const gears::GearPair& pair,
                     const gears::TvmsOptions& tvms_options, const MeshFaults& faults,
                     const std::function<std::vector<double>(const MeshFaults&, const gears::MeshSweepRange&)>& sweep,
                     std::ostream& out);

}  // namespace orrery::cli

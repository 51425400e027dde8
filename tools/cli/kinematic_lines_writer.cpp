#include "tools/cli/kinematic_lines_writer.h"

#include <string>
#include <vector>

#include "models/train_frequencies.h"

namespace orrery::cli {

void WriteKinematicLines(const Scene& scene, ResultFile& out) {
  if (scene.kind != SceneKind::kGearTrain) return;
  const GearTrainScene& g = *scene.gear_train;
  const Eigen::VectorXd speeds = Eigen::Map<const Eigen::VectorXd>(g.input_speeds_rad_s.data(),
                                                                   static_cast<Eigen::Index>(g.input_speeds_rad_s.size()));
  const gears::PlanetaryKinematics k = gears::SolvePlanetaryKinematics(*g.train, g.range, speeds);
  std::vector<std::string> names, kinds;
  std::vector<double> hz;
  for (const gears::TrainFrequency& f : gears::CalcTrainFrequencies(*g.train, k)) {
    names.push_back(f.name);
    hz.push_back(f.frequency_hz);
    kinds.push_back(f.kind);
  }
  if (names.empty()) return;
  out.WriteStrings("/kinematics/lines/name", names);
  out.WriteVector("/kinematics/lines/frequency_hz", hz, "Hz");
  out.WriteStrings("/kinematics/lines/kind", kinds);
}

}  // namespace orrery::cli

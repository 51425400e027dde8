// Seed 003's planetary stage with tooth contact on every mesh, as a C++ scene: the model of
// models/scenes/seed003_contact_healthy.yaml (sun 22, planet 14, ring 50, three planets, module
// 4 mm, 22.5 deg, 40 mm face width; the ring driven at 80.6 rad/s and the sun at -10 rad/s, 6000
// N m on the carrier), each sun-planet and ring-planet branch a ContactElement on the gears' own
// tooth surfaces (models/train_contact.h). The scene is a GearTrainDescription, the plain data
// the YAML reader fills too (models/train_description.h). Runs 20 ms, then prints each branch's mean
// line-of-action force over the last 10 ms against the power flow's, and its transmission error
// and mesh stiffness. Writes contact_planetary_stage.h5.
//
//   build/bin/example_contact_planetary_stage
#include <cmath>
#include <cstdio>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/planetary_scenes.h"
#include "models/train_description.h"

using namespace orrery;
using namespace orrery::gears;

int main() {
  // Seed 003's stage (models/planetary_scenes.h), with the sun at -10 rad/s (case 1) as
  // seed003_contact_healthy.yaml has it.
  GearTrainDescription d = MakeSeed003StageDescription(-10);
  TrainModelOptions& o = d.options;
  // Tooth contact on every mesh: 40 involute intervals per flank, 20 um backlash, the penalty
  // calibrated to ISO 6336 c' b at the branches' static force along the line of action.
  o.mesh_model = MeshModel::kContact;
  o.contact.gear.involute_intervals = 40;
  o.contact.gear.hunt_crossley_s_per_m = 0.5;
  o.contact.gear.margin_m = 100e-6;
  o.contact.gear.calibration_load_n = 15000;
  o.contact.normal_backlash_m = 20e-6;
  const GearTrainAssembly stage = AssembleGearTrain(d);
  const int sun_mesh = stage.train->MeshIndex("S.sun-planet");
  const PlanetaryPowerFlow& flow = stage.model.power_flow;

  SimulationOptions sim;
  sim.end_time = 0.02;
  sim.output_interval = 1e-4;
  sim.integrator.kind = IntegratorKind::kGeneralizedAlpha;
  sim.integrator.step = 5e-6;
  sim.integrator.rho_inf = 0.5;
  sim.scene_name = "seed 003 stage with tooth contact (C++ example)";
  {
    ResultFile out = ResultFile::Create("contact_planetary_stage.h5");
    const SimulationReport r = Simulate(*stage.model.model, sim, &out);
    out.Close();
    std::printf("simulated %.3f s in %.2f s wall (%ld steps, %ld Newton failures)\n", sim.end_time,
                r.wall_s, r.stats.steps, r.stats.newton_failures);
  }

  // Mean over the last 10 ms of every branch.
  const Hdf5Reader result("contact_planetary_stage.h5");
  const Eigen::VectorXd time = result.ReadMatrix("/time").col(0);
  auto mean = [&](const std::string& element, const char* output) {
    const Eigen::VectorXd x = result.ReadMatrix("/external/" + element + "/" + output).col(0);
    double sum = 0;
    int n = 0;
    for (Eigen::Index i = 0; i < x.size(); ++i)
      if (time(i) >= 0.01) sum += x(i), ++n;
    return sum / n;
  };
  std::printf("power flow: %.0f N along the line of action per branch\n",
              flow.mesh_line_of_action_forces_n(sun_mesh));
  for (const TrainContactMesh& m : stage.model.contacts)
    std::printf("%-16s force %8.0f N  TE %6.2f um  mesh stiffness %6.0f N/um\n", m.name.c_str(),
                std::abs(mean(m.name, "line_of_action_force")),
                mean(m.name, "transmission_error") * 1e6, mean(m.name, "mesh_stiffness") * 1e-6);
  std::printf("wrote contact_planetary_stage.h5\n");
  return 0;
}

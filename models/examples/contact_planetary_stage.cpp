// Seed 003's planetary stage with tooth contact on every mesh, as a C++ scene: the model of
// models/scenes/seed003_contact_stage.yaml (sun 22, planet 14, ring 50, three planets, module
// 4 mm, 22.5 deg, 40 mm face width; the ring driven at 80.6 rad/s and the sun at 10 rad/s, 6000
// N m on the carrier), each sun-planet and ring-planet branch a ContactElement on the gears' own
// tooth surfaces (contact/train_contact.h). Runs 20 ms, then prints each branch's mean
// line-of-action force over the last 10 ms against the power flow's, and its transmission error
// and mesh stiffness. Writes contact_planetary_stage.h5.
//
//   build/bin/example_contact_planetary_stage
#include <cmath>
#include <cstdio>

#include "contact/train_contact.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/planetary_kinematics.h"
#include "models/planetary_power_flow.h"
#include "models/planetary_train.h"

using namespace orrery;
using namespace orrery::gears;

int main() {
  const double pi = 3.14159265358979323846;
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {22}, .planet = {14}, .ring = {50}, .num_planets = 3,
                          .tooth_form = ToothForm{.normal_module_m = 4e-3,
                                                  .normal_pressure_angle_rad = 22.5 * pi / 180}});
  b.AddRange("steer", {});
  b.AddInput("S.ring");
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  const std::shared_ptr<const PlanetaryTrain> train = std::move(b).Finalize();
  const int range = train->RangeIndex("steer");

  // Speeds on both inputs; the carrier's 6000 N m through the power flow.
  const std::vector<double> speeds = {80.6, 10.0};
  const PlanetaryKinematics kin = SolvePlanetaryKinematics(*train, range, Eigen::Map<const Eigen::VectorXd>(speeds.data(), 2));
  const PlanetaryPowerFlow flow = CalcPlanetaryPowerFlow(*train, kin, train->output, -6000.0);
  TrainModelOptions o;
  o.face_width_m = 0.04;
  o.input = TrainModelOptions::Input::kSpeed;
  o.input_speeds_rad_s = speeds;
  o.input_torque_Nm = flow.port_torques_Nm(train->inputs[0]);

  // Tooth contact: 40 involute intervals per flank, 20 um backlash, the penalty calibrated to
  // ISO 6336 c' b at the branches' static force along the line of action.
  const int sun_mesh = train->MeshIndex("S.sun-planet");
  contact::TrainContactOptions c;
  c.gear.involute_intervals = 40;
  c.gear.hunt_crossley_s_per_m = 0.5;
  c.gear.margin_m = 100e-6;
  c.gear.calibration_load_n = flow.mesh_line_of_action_forces_N(sun_mesh);
  c.normal_backlash_m = 20e-6;
  const contact::TrainContactModel stage = contact::BuildTrainContactModel(*train, range, o, c);

  SimulationOptions sim;
  sim.end_time = 0.02;
  sim.output_interval = 1e-4;
  sim.integrator.kind = IntegratorKind::kGeneralizedAlpha;
  sim.integrator.step = 5e-6;
  sim.integrator.rho_inf = 0.5;
  sim.scene_name = "seed 003 stage with tooth contact (C++ example)";
  {
    ResultFile out = ResultFile::Create("contact_planetary_stage.h5");
    const SimulationReport r = Simulate(*stage.train_model.model, sim, &out);
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
              flow.mesh_line_of_action_forces_N(sun_mesh));
  for (const contact::TrainContactMesh& m : stage.contacts)
    std::printf("%-16s force %8.0f N  TE %6.2f um  mesh stiffness %6.0f N/um\n", m.name.c_str(),
                std::abs(mean(m.name, "line_of_action_force")),
                mean(m.name, "transmission_error") * 1e6, mean(m.name, "mesh_stiffness") * 1e-6);
  std::printf("wrote contact_planetary_stage.h5\n");
  return 0;
}

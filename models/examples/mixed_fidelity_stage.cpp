// Seed 003's planetary stage with its fidelity chosen per mesh and per body, as a C++ scene: the
// model of models/scenes/seed003_mixed_fidelity.yaml. Planet 1 is an FE gear (hex20, reduced by
// Craig-Bampton to 24 modes on its bore) meshing by tooth contact with the sun and the ring;
// planets 2 and 3 are rigid on lumped meshes with the potential-energy TVMS. The ring is driven
// at +80.6 rad/s and the sun at -10 rad/s (seed 003 case 1), 6000 N m on the carrier. Runs 20 ms
// and prints each branch's mean force over the last 10 ms against the power flow's.
// Writes mixed_fidelity_stage.h5.
//
//   build/bin/example_mixed_fidelity_stage
#include <cmath>
#include <cstdio>
#include <memory>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/gear_fe_mesh.h"
#include "models/planetary_scenes.h"
#include "models/train_description.h"

using namespace orrery;
using namespace orrery::gears;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Seed 003's planet as models/bodies/seed003_planet.yaml makes it: 14 teeth, m_n 4 mm, 22.5 deg,
// 40 mm face, bore 22.4 mm held by an RBE2 (the body frame), hex20, 24 fixed-interface modes.
std::shared_ptr<const FlexibleBodyModes> ReducePlanet() {
  const Gear planet({.teeth = 14, .normal_module_m = 4e-3, .normal_pressure_angle_rad = 22.5 * kPi / 180,
                     .hand = HelixHand::kLeft, .face_width_m = 0.04});
  const flex::FeMesh mesh = MakeGearFeMesh(
      planet, {.bore_radius_m = 11.2e-3, .type = flex::ElementType::kHex20, .flank_divisions = 4,
               .fillet_divisions = 2, .tooth_divisions = 2, .root_layer_divisions = 1, .rim_divisions = 2,
               .face_divisions = 2,
               .material = {.name = "STEEL", .youngs_modulus_pa = 206e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850}});
  const flex::FeSystem system = flex::AssembleFeSystem(mesh);
  std::vector<flex::FeInterface> interfaces = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
  interfaces[0].name = "bore";
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, system, interfaces, {.num_modes = 24});
  return std::make_shared<FlexibleBodyModes>(flex::MakeFlexibleBodyModes(mesh, system, cb, interfaces));
}

}  // namespace

int main() {
  // Seed 003's stage (models/planetary_scenes.h): ring +80.6 rad/s, sun -10 rad/s, 6000 N m.
  GearTrainDescription d = MakeSeed003StageDescription(-10);
  TrainModelOptions& o = d.options;
  // Fidelity: lumped TVMS meshes by default, tooth contact on planet 1's two branches, planet 1
  // flexible.
  o.mesh_model = MeshModel::kLumped;
  o.mesh_stiffness_source = MeshStiffnessSource::kTvms;
  o.mesh_models["S.sun-planet#1"] = MeshModel::kContact;
  o.mesh_models["S.ring-planet#1"] = MeshModel::kContact;
  TrainFlexibleBody& planet = o.flexible_bodies["S.planet1"];
  planet.modes = ReducePlanet();
  planet.options.damping_ratios = {0.02};
  // Tooth contact of the contact branches.
  o.contact.normal_backlash_m = 20e-6;
  o.contact.gear.involute_intervals = 40;
  o.contact.gear.calibration_load_n = 15000;
  o.contact.gear.hunt_crossley_s_per_m = 0.5;
  o.contact.gear.margin_m = 100e-6;
  const GearTrainAssembly stage = AssembleGearTrain(d);
  for (const TrainMeshBranch& b : stage.model.branches)
    std::printf("%s#%d: %s\n", stage.train->meshes[b.train_mesh].name.c_str(), b.branch + 1, MeshModelName(b.model));

  SimulationOptions sim;
  sim.end_time = 0.02;
  sim.output_interval = 1e-4;
  sim.integrator.kind = IntegratorKind::kGeneralizedAlpha;
  sim.integrator.step = 5e-6;
  sim.integrator.rho_inf = 0.5;
  sim.integrator.max_step_halvings = 8;
  sim.integrator.matrix_refresh_rate = 0.1;
  sim.scene_name = "seed 003 stage, mixed fidelity (C++ example)";
  {
    ResultFile out = ResultFile::Create("mixed_fidelity_stage.h5");
    const SimulationReport r = Simulate(*stage.model.model, sim, &out);
    out.Close();
    std::printf("simulated %.3f s in %.2f s wall (%ld steps)\n", sim.end_time, r.wall_s, r.stats.steps);
  }

  // Means over the last 10 ms: contact branches' line-of-action force, lumped branches' force.
  const Hdf5Reader result("mixed_fidelity_stage.h5");
  const Eigen::VectorXd time = result.ReadMatrix("/time").col(0);
  auto mean = [&](const std::string& dataset) {
    const Eigen::VectorXd x = result.ReadMatrix(dataset).col(0);
    double sum = 0;
    int n = 0;
    for (Eigen::Index i = 0; i < x.size(); ++i)
      if (time(i) >= 0.01) sum += std::abs(x(i)), ++n;
    return sum / n;
  };
  const int sun_mesh = stage.train->MeshIndex("S.sun-planet");
  std::printf("power flow: %.0f N along the line of action per sun-planet branch\n",
              stage.model.power_flow.mesh_line_of_action_forces_n(sun_mesh));
  for (const TrainContactMesh& m : stage.model.contacts)
    std::printf("%-16s contact  %8.0f N\n", m.name.c_str(), mean("/external/" + m.name + "/line_of_action_force"));
  for (const GearMesh& m : stage.model.model->gear_meshes)
    std::printf("%-16s lumped   %8.0f N\n", m.spec.name.c_str(), mean("/gear_meshes/" + m.spec.name + "/force"));
  std::printf("wrote mixed_fidelity_stage.h5\n");
  return 0;
}

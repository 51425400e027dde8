// A flexible planet written as a C++ scene: seed 002's stage with planet 1 generated as an FE
// gear, reduced by Craig-Bampton and attached to its carrier pin, the others rigid. The lumped
// meshes act on an RBE3 over the planet's root circle. Writes flexible_planet.h5 (modal
// coordinates, von Mises hot spot, deformed surface) and flexible_planet.xdmf for ParaView.
//
//   build/bin/example_flexible_planet
#include <cstdio>
#include <memory>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "mbd/xdmf_writer.h"
#include "models/gear_fe_mesh.h"
#include "models/seed_models.h"
#include "models/train_dynamics.h"

using namespace orrery;
using namespace orrery::gears;

int main() {
  const auto train = Seed002ShiftedStage();
  TrainModelOptions options = Seed002DynamicsOptions(TimeFunction::Constant(20 * 2 * M_PI / 60));

  // The planet: the gear of the sun-planet pair with 34 teeth, a hex8 mesh with a bore.
  const GearPair pair = MakeTrainGearPair(*train, train->MeshIndex("S.sun-planet"), options);
  const Gear& planet = pair.gear2().spec().teeth == 34 ? pair.gear2() : pair.gear1();
  flex::FeMesh mesh = MakeGearFeMesh(planet, {.bore_radius_m = 0.12, .type = flex::ElementType::kHex8,
                                              .flank_divisions = 3, .fillet_divisions = 2, .tooth_divisions = 2,
                                              .root_layer_divisions = 1, .rim_divisions = 3, .face_divisions = 3});
  const flex::FeSystem system = flex::AssembleFeSystem(mesh);

  // Interfaces: the bore (RBE2) is the body frame on the pin; the root circle (RBE3) takes the
  // mesh loads. 12 fixed-interface modes, stress modes for the von Mises output.
  std::vector<flex::FeInterface> interfaces = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2),
                                               flex::MakeInterface(mesh, "ROOT", flex::InterfaceKind::kRbe3)};
  interfaces[0].name = "bore";
  interfaces[1].name = "rim";
  const flex::CraigBamptonModel cb = flex::ReduceCraigBampton(mesh, system, interfaces, {.num_modes = 12});
  auto modes = std::make_shared<FlexibleBodyModes>(
      flex::MakeFlexibleBodyModes(mesh, system, cb, interfaces, {.stress_modes = true}));
  std::printf("planet: %d FE DOF, %.1f kg, reduced to %d modal coordinates (%.0f .. %.0f Hz)\n",
              3 * mesh.num_nodes(), system.mass_kg, modes->nf, modes->frequencies_hz.front(),
              modes->frequencies_hz.back());

  // Attach it and build the stage.
  TrainFlexibleBody& flexible = options.flexible_bodies["S.planet1"];
  flexible.modes = modes;
  flexible.options.damping_ratios = {0.02};
  flexible.options.record_surface = true;
  flexible.mesh_interface = "rim";
  const TrainModel stage = BuildTrainModel(*train, 0, options);
  const State start = SolveTrainStaticState(stage, State::Initial(*stage.model));

  SimulationOptions sim;
  sim.end_time = 0.05;
  sim.output_interval = 1e-3;
  sim.integrator.kind = IntegratorKind::kGeneralizedAlpha;
  sim.integrator.step = 1e-4;
  sim.integrator.rho_inf = 0.8;
  sim.scene_name = "seed 002 stage with a flexible planet (C++ example)";
  {
    ResultFile out = ResultFile::Create("flexible_planet.h5");
    const SimulationReport r = Simulate(*stage.model, sim, &out, {}, &start);
    out.Close();
    std::printf("simulated %.3f s in %.2f s wall (%ld steps)\n", sim.end_time, r.wall_s, r.stats.steps);
  }
  WriteSurfaceXdmf("flexible_planet.h5");
  const Hdf5Reader result("flexible_planet.h5");
  const Eigen::MatrixXd vm = result.ReadMatrix("/flexible_bodies/S.planet1/von_mises_max");
  Eigen::Index row;
  vm.col(0).maxCoeff(&row);
  std::printf("largest von Mises stress %.3f MPa at node %.0f, (%.3f, %.3f, %.3f) m in the planet frame\n",
              vm(row, 0) * 1e-6, vm(row, 1), vm(row, 2), vm(row, 3), vm(row, 4));
  std::printf("wrote flexible_planet.h5 and flexible_planet.xdmf\n");
  return 0;
}

// A spur gear pair with a broken pinion tooth, as a C++ scene: the lumped mesh takes its
// stiffness from the potential-energy method over a whole pinion revolution, with tooth 0 of the
// pinion missing half its height. Runs healthy and faulty pairs at constant speed under load and
// prints the transmission error (mesh deflection) range; the faulty run dips once per pinion
// revolution. Writes pair_healthy.h5 and pair_broken.h5.
//
//   build/bin/example_broken_tooth_pair
#include <cstdio>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/gear_pair_model.h"

using namespace orrery;
using namespace orrery::gears;

int main() {
  GearSpec pinion, wheel;
  pinion.teeth = 20, wheel.teeth = 40;
  pinion.normal_module_m = wheel.normal_module_m = 3e-3;
  pinion.face_width_m = wheel.face_width_m = 25e-3;
  const GearPair pair{Gear(pinion), Gear(wheel)};

  for (const bool broken : {false, true}) {
    GearPairModelOptions o;
    o.bore_radius1_m = 8e-3;
    o.bore_radius2_m = 15e-3;
    o.input_speed = TimeFunction::Constant(150.0);  // rad/s: 477 Hz mesh frequency
    o.initial_speed1 = 150.0;
    o.load_torque = TimeFunction::SmoothStep(0, 0.01, 0, 100.0);  // N m against the wheel
    if (broken)
      o.faults.emplace_back(1, ToothFaultSpec{.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0,
                                              .height_fraction = 0.5});
    const GearPairModel m = BuildGearPairModel(pair, o);

    SimulationOptions sim;
    sim.end_time = 0.2;  // about 5 pinion revolutions
    sim.output_interval = 2e-5;
    sim.scene_name = broken ? "gear pair, broken pinion tooth" : "gear pair, healthy";
    const char* path = broken ? "pair_broken.h5" : "pair_healthy.h5";
    ResultFile out = ResultFile::Create(path);
    const SimulationReport r = Simulate(*m.model, sim, &out);
    out.Close();

    const Hdf5Reader in(path);
    const Eigen::MatrixXd delta = in.ReadMatrix("/gear_meshes/mesh/deflection");
    const Eigen::VectorXd late = delta.col(0).tail(delta.rows() / 2);  // after the load step
    std::printf("%-8s mean stiffness %.3e N/m (%s), TE %.3f .. %.3f um; %ld steps, %.2f s wall -> %s\n",
                broken ? "broken" : "healthy", m.mesh_stiffness_mean_n_per_m,
                m.tvms ? "TVMS" : "constant", 1e6 * late.minCoeff(), 1e6 * late.maxCoeff(),
                r.stats.steps, r.wall_s, path);
  }
  return 0;
}

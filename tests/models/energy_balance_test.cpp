// Energy balance of a time-domain run of a lumped planetary stage: the work put in by the input
// driver and the load equals the change of kinetic and elastic energy plus the energy the mesh
// and bearing dampers took out. Each term comes from the result file (/power, /energy),
// integrated independently of the integrator (Simpson's rule on the recorded rows).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/lumped_planetary.h"

namespace orrery {
namespace {

// Composite Simpson integral of uniformly sampled y (odd number of samples).
double Simpson(const Eigen::VectorXd& y, double h) {
  const int n = static_cast<int>(y.size());
  double s = y(0) + y(n - 1);
  for (int i = 1; i < n - 1; ++i) s += (i % 2 ? 4 : 2) * y(i);
  return s * h / 3;
}

TEST(EnergyBalance, InputWorkEqualsOutputWorkPlusDissipationPlusStoredEnergy) {
  for (const auto dofs : {LumpedStageParams::Dofs::kTorsional, LumpedStageParams::Dofs::kPlanar}) {
    // A consistent stage: module 2 mm, 20 deg, 20/30/80 teeth, 3 planets, steel-like members.
    const double m = 2e-3, alpha = 20 * 3.14159265358979323846 / 180;
    LumpedStageParams p = LinParker1999Example(3);
    p.dofs = dofs;
    p.check_centre_distance = true;
    p.sun.teeth = 20, p.planet.teeth = 30, p.ring.teeth = 80;
    p.sun.radius = 0.5 * m * 20 * std::cos(alpha);
    p.planet.radius = 0.5 * m * 30 * std::cos(alpha);
    p.ring.radius = 0.5 * m * 80 * std::cos(alpha);
    p.carrier.radius = 0.5 * m * (20 + 30);
    p.sun.inertia = 2e-4, p.planet.inertia = 5e-4, p.ring.inertia = 2e-2, p.carrier.inertia = 1e-2;
    p.pressure_angle_sun = p.pressure_angle_ring = alpha;
    p.mesh_damping_ratio = 0.05;
    p.sun.bearing_damping = p.ring.bearing_damping = p.carrier.bearing_damping = 2e3;
    p.planet.bearing_damping = 2e3;
    p.lines_of_action_on_carrier = true;
    const int rot = dofs == LumpedStageParams::Dofs::kTorsional ? 0 : 2;  // rotation coordinate
    const LumpedStage stage = BuildLumpedStage(p, [rot](ModelBuilder& b, const LumpedStage& st) {
      // Sun run up smoothly to 100 rad/s; the carrier carries a load torque.
      b.AddDriver({.name = "motor", .joint = st.sun, .coordinate = rot,
                   .mode = DriverSpec::Mode::kSpeed, .function = TimeFunction::SmoothStep(0, 0.05, 0, 100)});
      b.AddJointLoad({.name = "load", .joint = st.carrier, .coordinate = rot,
                      .function = TimeFunction::Ramp(0.02, 0.0202, 0, -40)});  // a sharp step: rings
    });
    const std::string path = ::testing::TempDir() + "/energy_balance.h5";
    {
      ResultFile out = ResultFile::Create(path);
      SimulationOptions o;
      o.end_time = 0.1;
      o.output_interval = 2e-5;  // Simpson error ~ h^4 f'''' well below the tolerance below
      o.integrator.rtol = 1e-9;
      o.integrator.atol = 1e-12;
      Simulate(*stage.model, o, &out);
    }
    const Hdf5Reader in(path);
    const Eigen::MatrixXd power = in.ReadMatrix("/power"), energy = in.ReadMatrix("/energy");
    const double h = 2e-5;
    const double w_applied = Simpson(power.col(0), h), w_driver = Simpson(power.col(1), h);
    const double w_dissipated = Simpson(power.col(2), h);
    const Eigen::VectorXd e = energy.rowwise().sum();
    const double stored = e(e.size() - 1) - e(0);
    const double in_out = w_driver + w_applied;
    std::printf("[energy balance %s] driver %.6f J, load %.6f J, dissipated %.6f J, stored %.6f J, "
                "residual %.3e J\n", dofs == LumpedStageParams::Dofs::kTorsional ? "torsional" : "planar",
                w_driver, w_applied, w_dissipated, stored, in_out - w_dissipated - stored);
    EXPECT_GT(w_driver, 0);
    EXPECT_LT(w_applied, 0);
    EXPECT_GT(w_dissipated, 0);
    // Tolerance: the integrator's relative error (rtol = 1e-9, global error a few rtol) on
    // energies of the size of the driver work, and the quadrature error of the power rows (far
    // smaller at this sampling); well below the dissipated energy, so a missing damper shows.
    EXPECT_NEAR(in_out, w_dissipated + stored, 10 * 1e-9 * std::abs(w_driver));
    EXPECT_GT(w_dissipated, 10 * 10 * 1e-9 * std::abs(w_driver));
    std::filesystem::remove(path);
  }
}

}  // namespace
}  // namespace orrery

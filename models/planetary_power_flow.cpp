#include "models/planetary_power_flow.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

namespace orrery::gears {
namespace {

// Relative size below which a torque counts as zero (rounding of an O(1e2) system).
constexpr double kLoadRelativeTolerance = 1e-9;

}  // namespace

PlanetaryPowerFlow CalcPlanetaryPowerFlow(const PlanetaryTrain& train,
                                          const PlanetaryKinematics& kinematics, int known_member,
                                          double known_torque_n_m) {
  const int n = train.num_speeds();
  const int nm = train.num_members();
  if (kinematics.speeds_rad_s.size() != n)
    throw std::invalid_argument("CalcPlanetaryPowerFlow: kinematics of another train");
  // Ports: the inputs, then the output; one of them carries the known torque.
  std::vector<int> ports = train.inputs;
  ports.push_back(train.output);
  if (std::find(ports.begin(), ports.end(), known_member) == ports.end())
    throw std::invalid_argument("CalcPlanetaryPowerFlow: member " +
                                (known_member >= 0 && known_member < nm
                                     ? "'" + train.members[known_member].name + "'"
                                     : std::to_string(known_member)) +
                                " is neither an input nor the output");
  std::vector<int> unknown_ports;
  for (int p : ports)
    if (p != known_member) unknown_ports.push_back(p);

  // Equilibrium Q_ext + G^T lambda = 0 with unknowns x = [lambda; unknown port torques].
  const ConstraintRows c = AssembleConstraints(train, kinematics.range);
  const int nc = static_cast<int>(c.G.rows());
  const int nu = nc + static_cast<int>(unknown_ports.size());
  if (nu != n)
    throw std::runtime_error("gear range '" + train.ranges[kinematics.range].name +
                             "': " + std::to_string(nu) + " unknown loads for " +
                             std::to_string(n) + " equilibrium equations");
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, nu);
  M.leftCols(nc) = c.G.transpose();
  for (size_t j = 0; j < unknown_ports.size(); ++j) M(unknown_ports[j], nc + j) = 1.0;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  rhs(known_member) = -known_torque_n_m;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
  lu.setThreshold(1e-10);
  if (lu.rank() < n)
    throw std::runtime_error("gear range '" + train.ranges[kinematics.range].name +
                             "': torques are indeterminate (is the output '" +
                             train.members[train.output].name + "' held in this range?)");
  const Eigen::VectorXd x = lu.solve(rhs);
  const Eigen::VectorXd lambda = x.head(nc);

  PlanetaryPowerFlow p;
  p.range = kinematics.range;
  // Port torques and brake reactions.
  p.port_torques_n_m = Eigen::VectorXd::Zero(nm);
  p.port_torques_n_m(known_member) = known_torque_n_m;
  for (size_t j = 0; j < unknown_ports.size(); ++j) p.port_torques_n_m(unknown_ports[j]) = x(nc + j);
  p.external_torques_n_m = p.port_torques_n_m;
  p.connection_torques_n_m = Eigen::VectorXd::Zero(train.connections.size());
  p.clutch_torques_n_m = Eigen::VectorXd::Zero(train.clutches.size());
  p.brake_torques_n_m = Eigen::VectorXd::Zero(train.brakes.size());
  p.mesh_loads_n_m = Eigen::VectorXd::Zero(train.meshes.size());
  p.mesh_torques_n_m = Eigen::VectorXd::Zero(nm);
  for (int r = 0; r < nc; ++r) {
    const int e = c.element[r];
    switch (c.kind[r]) {
      case ConstraintKind::kMesh:
        p.mesh_loads_n_m(e) = lambda(r);
        p.mesh_torques_n_m += c.G.row(r).head(nm).transpose() * lambda(r);
        break;
      // Row w_a - w_b: torque lambda on a, -lambda on b.
      case ConstraintKind::kConnection: p.connection_torques_n_m(e) = -lambda(r); break;
      case ConstraintKind::kClutch: p.clutch_torques_n_m(e) = -lambda(r); break;
      case ConstraintKind::kBrake:
        p.brake_torques_n_m(e) = lambda(r);
        p.external_torques_n_m(train.brakes[e].member) += lambda(r);
        break;
      case ConstraintKind::kInput: break;
    }
  }
  // Mesh torques on gear a and forces per planet (seed 001 eq. 6).
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const int nmesh = static_cast<int>(train.meshes.size());
  p.mesh_gear_a_torques_n_m.resize(nmesh);
  p.mesh_tangential_forces_n = Eigen::VectorXd::Constant(nmesh, nan);
  p.mesh_line_of_action_forces_n = Eigen::VectorXd::Constant(nmesh, nan);
  p.mesh_normal_forces_n = Eigen::VectorXd::Constant(nmesh, nan);
  for (int m = 0; m < nmesh; ++m) {
    const TrainGear& a = train.gears[train.meshes[m].gear_a];
    const double planets = train.stages[train.meshes[m].stage].num_planets;
    const double ta = a.teeth * p.mesh_loads_n_m(m);
    p.mesh_gear_a_torques_n_m(m) = ta;
    if (!a.has_tooth_form) continue;
    const double ft = std::abs(ta) / (planets * a.pitch_radius_m);
    const double fbt = std::abs(ta) / (planets * a.base_radius_m);
    const double beta_b =
        std::atan(std::tan(a.tooth_form.helix_angle_rad) * std::cos(a.transverse_pressure_angle_rad));
    p.mesh_tangential_forces_n(m) = ft;
    p.mesh_line_of_action_forces_n(m) = fbt;
    p.mesh_normal_forces_n(m) = fbt / std::cos(beta_b);
  }
  // Loaded flags against a tolerance relative to the largest external torque.
  p.load_tolerance_n_m = kLoadRelativeTolerance * p.external_torques_n_m.cwiseAbs().maxCoeff();
  p.mesh_loaded.assign(nmesh, false);
  p.stage_loaded.assign(train.stages.size(), false);
  p.member_loaded.assign(nm, false);
  for (int m = 0; m < nmesh; ++m) {
    p.mesh_loaded[m] = std::abs(p.mesh_gear_a_torques_n_m(m)) > p.load_tolerance_n_m;
    if (p.mesh_loaded[m]) p.stage_loaded[train.meshes[m].stage] = true;
  }
  for (int i = 0; i < nm; ++i)
    p.member_loaded[i] = std::abs(p.mesh_torques_n_m(i)) > p.load_tolerance_n_m;
  // Balance checks (seed 001 eqs. 4a, 4b for the whole train).
  const Eigen::VectorXd& w = kinematics.speeds_rad_s;
  for (int in : train.inputs) p.input_power_w += p.port_torques_n_m(in) * w(in);
  p.output_power_w = -p.port_torques_n_m(train.output) * w(train.output);
  p.torque_residual_n_m = std::abs(p.external_torques_n_m.sum());
  p.power_residual_w = std::abs(p.port_torques_n_m.dot(w.head(nm)));
  return p;
}

}  // namespace orrery::gears

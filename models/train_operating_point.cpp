// Stage 1 of BuildTrainModel: the operating point. Kinematics at the input speeds of t = 0 and at
// unit input speed (the directions of the mesh phases and loads), the input torque (given, or
// from a torque on the output port through the power flow), and the power flow at that torque
// (the loaded flanks and the port loads).
#include "models/train_assembly.h"

namespace orrery::gears {

void ResolveOperatingPoint(TrainAssembly& a) {
  const PlanetaryTrain& train = a.train;
  const TrainModelOptions& o = a.o;
  const int num_inputs = static_cast<int>(train.inputs.size());
  // Input speeds at t = 0.
  a.speeds = Eigen::VectorXd::Zero(num_inputs);
  for (int i = 0; i < static_cast<int>(o.input_speeds_rad_s.size()); ++i) a.speeds(i) = o.input_speeds_rad_s[i];
  for (int i = 0; i < static_cast<int>(o.input_speed_functions.size()); ++i)
    a.speeds(i) = o.input_speed_functions[i].Value(0.0);
  a.tm.kinematics = SolvePlanetaryKinematics(train, a.range, a.speeds);
  // Unit kinematics: inputs scaled so that the first turns at 1 rad/s.
  Eigen::VectorXd unit = Eigen::VectorXd::Ones(num_inputs);
  if (a.speeds.cwiseAbs().maxCoeff() > 0) {
    if (a.speeds(0) == 0) FailTrain("the first input's speed is 0 while others are not: cannot scale");
    unit = a.speeds / a.speeds(0);
  }
  a.tm.unit_kinematics = SolvePlanetaryKinematics(train, a.range, unit);
  // The input torque: given, or the one that puts the output port torque on the output at the
  // operating speeds (zero speeds count as 1 rad/s: only the ratios matter).
  double input_torque = o.input_torque_n_m;
  if (o.output_port_torque_n_m) {
    Eigen::VectorXd w = Eigen::VectorXd::Ones(num_inputs);
    for (int i = 0; i < num_inputs; ++i) {
      const double s = o.operating_speeds_rad_s.empty() ? a.speeds(i) : o.operating_speeds_rad_s[i];
      if (s != 0) w(i) = s;
    }
    const PlanetaryKinematics k = SolvePlanetaryKinematics(train, a.range, w);
    const PlanetaryPowerFlow p = CalcPlanetaryPowerFlow(train, k, train.output, *o.output_port_torque_n_m);
    input_torque = p.port_torques_n_m(train.inputs[0]);
  }
  a.tm.input_torque_n_m = input_torque;
  // Power flow: the loaded flanks (from 1 N m if no torque is given) and the port torques.
  const double t_flow = input_torque != 0 ? input_torque : 1.0;
  a.tm.power_flow = CalcPlanetaryPowerFlow(train, a.tm.unit_kinematics, train.inputs[0], t_flow);
  a.load_scale = input_torque != 0 ? 1.0 : 0.0;
}

}  // namespace orrery::gears

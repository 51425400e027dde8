// Stages 6 and 7 of BuildTrainModel: what joins the members (connections and engaged clutches as
// stiff torsional springs between them, engaged brakes as torsional springs to ground; seed 001
// section 3) and what drives the train (speed drivers on the inputs or the input torque, the
// other ports' power-flow torques as loads).
#include "models/train_assembly.h"

namespace orrery::gears {

void AddCouplings(TrainAssembly& a) {
  const PlanetaryTrain& train = a.train;
  auto coupling = [&](const std::string& name, const Coupling& c, double k) {
    a.b.AddRotationalSpring({.name = name, .frame_a = a.b.body_frame(a.tm.member_bodies[c.member_a]),
                             .frame_b = a.b.body_frame(a.tm.member_bodies[c.member_b]), .stiffness = k});
  };
  for (const Coupling& c : train.connections) coupling(c.name, c, a.o.connection_stiffness_n_m_per_rad);
  const GearRange& gr = train.ranges[a.range];
  for (int ci : gr.clutches) coupling(train.clutches[ci].name, train.clutches[ci], a.o.clutch_stiffness_n_m_per_rad);
  for (int bi : gr.brakes) {
    const Brake& br = train.brakes[bi];
    const TrainMemberOverride& ov = a.Override(train.members[br.member].name);
    AddTrainGroundSpring(a, br.name, br.member, ov.brake_stiffness_n_m_per_rad.value_or(a.o.brake_stiffness_n_m_per_rad));
  }
}

void AddDrives(TrainAssembly& a) {
  const PlanetaryTrain& train = a.train;
  const TrainModelOptions& o = a.o;
  const int num_inputs = static_cast<int>(train.inputs.size());
  for (int i = 0; i < num_inputs; ++i) {
    const int member = train.inputs[i];
    const JointIndex j = a.tm.member_joints[member];
    const std::string& name = train.members[member].name;
    if (o.input == TrainModelOptions::Input::kSpeed) {
      a.b.AddDriver({.name = "drive_" + name, .joint = j, .coordinate = a.rot, .mode = DriverSpec::Mode::kSpeed,
                     .function = o.input_speed_functions.empty() ? TimeFunction::Constant(a.speeds(i))
                                                                 : o.input_speed_functions[i]});
    } else if (o.input == TrainModelOptions::Input::kTorque && i == 0) {
      a.b.AddJointLoad({.name = "torque_" + name, .joint = j, .coordinate = a.rot,
                        .function = TimeFunction::Constant(a.tm.input_torque_n_m)});
    } else if (o.port_loads && a.load_scale != 0 && i > 0) {
      a.b.AddJointLoad({.name = "torque_" + name, .joint = j, .coordinate = a.rot,
                        .function = TimeFunction::Constant(a.tm.power_flow.port_torques_n_m(member))});
    }
  }
  const JointIndex out = a.tm.member_joints[train.output];
  const std::string load = "load_" + train.members[train.output].name;
  if (o.output_torque_n_m)
    a.b.AddJointLoad({.name = load, .joint = out, .coordinate = a.rot, .function = *o.output_torque_n_m});
  else if (o.port_loads && a.load_scale != 0)
    a.b.AddJointLoad({.name = load, .joint = out, .coordinate = a.rot,
                      .function = TimeFunction::Constant(a.tm.power_flow.port_torques_n_m(train.output))});
}

}  // namespace orrery::gears

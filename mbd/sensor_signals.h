#pragma once
// The readings of every sensor of a model (sensor.h) at one instant: the stage a data-acquisition
// system's front end would be. Sampling and filtering are in sensor_sampler.h.
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Fills data.sensor_values (model.n_sensor_channels) at (t, q, v, vdot): runs the pose and
// velocity kinematics (CalcFramePoses, or the whole CalcPositionKinematics when an external
// element is read; CalcVelocityKinematics), the acceleration pass (CalcAccelerationKinematics)
// when an accelerometer or angular accelerometer needs it, the law of each lumped mesh a sensor
// reads and the Apply() of each external element a sensor reads (its forces go to data.f_ext and
// are not used). The point kinematics of frame sensors are those of sensor.h. Allocation-free.
// Throws what the mesh law or an element throws.
void CalcSensorSignals(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& v,
                       const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data);

}  // namespace orrery

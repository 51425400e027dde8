#include "mbd/evaluate.h"

#include "mbd/constraints.h"
#include "mbd/dynamics.h"
#include "mbd/force_elements.h"
#include "mbd/kinematics.h"

namespace orrery {

void EvaluateDynamics(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& v,
                      const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data) {
  CalcPositionKinematics(model, q, data);
  CalcVelocityKinematics(model, v, data);
  CalcForceElements(model, t, v, data);
  CalcConstraints(model, t, data);
  CalcInverseDynamics(model, vdot, data);
}

}  // namespace orrery

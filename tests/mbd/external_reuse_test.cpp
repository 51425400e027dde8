// CalcExternalForces (mbd/force_elements.h) adds the stored results of an external element with
// analytic tangents again, instead of computing them, when its workspace holds the very state of
// the evaluation (Data::tangent_elements_*), and computes them at any other state: after a change
// of t, q or v in the last bit, after evaluations that skipped it (DaeSystem::Tangents'
// differences) at other states and back, after a warm start and after AddTangents. The element
// below counts its computations; the oracle for the numbers is the same evaluation with the
// results computed again (==).
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/external_force.h"
#include "mbd/force_elements.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery {
namespace {

struct SpringWorkspace final : ExternalForceWorkspace {
  Vec6 f = Vec6::Zero();
  int computations = 0;
};

// A torsional spring-damper to the world on a body turning about z: torque -k theta - c omega.
class TorsionSpring final : public ExternalForceElement {
 public:
  explicit TorsionSpring(BodyIndex body) : body_(body) {}
  const std::string& name() const override { return name_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model&) const override {
    return std::make_unique<SpringWorkspace>();
  }
  void Apply(const Model& model, double t, Data& data, ExternalForceWorkspace& ws) const override {
    Compute(model, t, data, ws);
    AddTo(model, ws, data);
  }
  bool SplitsApply() const override { return true; }
  void Compute(const Model&, double t, const Data& data,
               ExternalForceWorkspace& workspace) const override {
    auto& ws = static_cast<SpringWorkspace&>(workspace);
    const Mat3& R = data.X_WB[body_].R;
    const double theta = std::atan2(R(1, 0), R(0, 0)), omega = data.V_WB[body_](2);
    ws.f << 0, 0, -k_ * theta - c_ * omega + std::sin(t), 0, 0, 0;
    ++ws.computations;
  }
  void AddTo(const Model&, const ExternalForceWorkspace& workspace, Data& data) const override {
    data.f_ext[body_] += static_cast<const SpringWorkspace&>(workspace).f;
  }
  bool HasTangents() const override { return true; }
  void AddTangents(const Model& model, const Data&, ExternalForceWorkspace&,
                   Eigen::Ref<Eigen::MatrixXd> K, Eigen::Ref<Eigen::MatrixXd> C) const override {
    const int k = model.joints[model.bodies[body_].parent_joint].v_start;
    K(k, k) += k_;
    C(k, k) += c_;
  }
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  void GetOutputs(const ExternalForceWorkspace&, double*) const override {}

 private:
  BodyIndex body_;
  double k_ = 40, c_ = 0.3;
  std::string name_ = "torsion";
  std::vector<OutputDescription> outputs_;
};

std::shared_ptr<const Model> SpringModel() {
  ModelBuilder b;
  const BodyIndex body = b.AddBody("rotor", 2.0, Vec3(0.1, 0, 0), 0.05 * Mat3::Identity());
  const JointIndex j = b.AddJoint(
      {.name = "pin", .type = JointType::kRevolute, .parent = kWorldBody, .child = body});
  b.SetJointPosition(j, Eigen::VectorXd::Constant(1, 0.3));
  b.SetJointVelocity(j, Eigen::VectorXd::Constant(1, 2.0));
  b.SetGravity(Vec3(0, -9.81, 0));
  b.AddExternalForce(std::make_shared<TorsionSpring>(body));
  return std::move(b).Finalize();
}

int Computations(const Data& data) {
  return static_cast<const SpringWorkspace&>(*data.external[0]).computations;
}

TEST(ExternalReuse, ResultsAddedAgainOnlyAtTheSameState) {
  const std::shared_ptr<const Model> model = SpringModel();
  const Model& m = *model;
  for (const int threads : {1, 2}) {
    Data data(m), fresh(m);
    data.threads = fresh.threads = threads;
    const State s = State::Initial(m);
    const Eigen::VectorXd vdot = Eigen::VectorXd::Constant(1, 0.7);
    EvaluateDynamics(m, 0.1, s.q, s.v, vdot, data);
    EXPECT_EQ(Computations(data), 1);
    EvaluateDynamics(m, 0.1, s.q, s.v, vdot, data);  // the same state: added again
    EXPECT_EQ(Computations(data), 1);
    EvaluateDynamics(m, 0.1, s.q, s.v, vdot, fresh);
    EXPECT_EQ(data.tau_id, fresh.tau_id);
    EXPECT_EQ(data.f_ext[1], fresh.f_ext[1]);

    // One ulp of v, of q, of t: computed.
    Eigen::VectorXd v1 = s.v, q1 = s.q;
    v1(0) = std::nextafter(v1(0), 10.0);
    EvaluateDynamics(m, 0.1, s.q, v1, vdot, data);
    EXPECT_EQ(Computations(data), 2);
    q1(0) = std::nextafter(q1(0), 10.0);
    EvaluateDynamics(m, 0.1, q1, v1, vdot, data);
    EXPECT_EQ(Computations(data), 3);
    EvaluateDynamics(m, std::nextafter(0.1, 1.0), q1, v1, vdot, data);
    EXPECT_EQ(Computations(data), 4);

    // Evaluations that skip it (the differences) leave its state; back there it is added again.
    data.skip_elements_with_tangents = true;
    EvaluateDynamics(m, 0.1, s.q, s.v, vdot, data);
    EXPECT_EQ(Computations(data), 4);
    data.skip_elements_with_tangents = false;
    EvaluateDynamics(m, std::nextafter(0.1, 1.0), q1, v1, vdot, data);
    EXPECT_EQ(Computations(data), 4);

    // A warm start into data: computed at its next evaluation, even at the same state.
    WarmStartExternalWorkspaces(m, fresh, data);
    EvaluateDynamics(m, std::nextafter(0.1, 1.0), q1, v1, vdot, data);
    EXPECT_EQ(Computations(data), 5);
  }
}

TEST(ExternalReuse, TangentsAtTheIterateOfTheLastResidual) {
  const std::shared_ptr<const Model> model = SpringModel();
  const Model& m = *model;
  DaeSystem reusing(m), computing(m);
  Eigen::VectorXd y(reusing.size()), yp(reusing.size()), r(reusing.size());
  reusing.ConsistentInitial(State::Initial(m), y, yp);
  const int nq = m.nq, nv = m.nv;
  const auto q = y.segment(0, nq), v = y.segment(nq, nv), vdot = yp.segment(nq, nv);
  const auto lambda = y.segment(nq + nv, 0);
  Eigen::MatrixXd Kq(nv, nv), Cv(nv, nv), Kq2(nv, nv), Cv2(nv, nv);
  // reusing: a residual at the state, then the tangents there (their last pass adds the
  // element's results again); computing: a residual elsewhere first.
  reusing.Residual(0.2, y, yp, r);
  const int before = Computations(reusing.data());
  reusing.Tangents(0.2, q, v, vdot, lambda, Kq, Cv);
  EXPECT_EQ(Computations(reusing.data()), before);
  Eigen::VectorXd y_other = y;
  y_other(nq) += 1.0;
  computing.Residual(0.2, y_other, yp, r);
  const int before2 = Computations(computing.data());
  computing.Tangents(0.2, q, v, vdot, lambda, Kq2, Cv2);
  EXPECT_EQ(Computations(computing.data()), before2 + 1);
  EXPECT_EQ(Kq, Kq2);
  EXPECT_EQ(Cv, Cv2);
  EXPECT_EQ(reusing.data().tau_id, computing.data().tau_id);
  EXPECT_EQ(reusing.data().f_ext[1], computing.data().f_ext[1]);
  // After AddTangents the workspace is not trusted: the next residual at the state computes.
  reusing.Residual(0.2, y, yp, r);
  EXPECT_EQ(Computations(reusing.data()), before + 1);
}

}  // namespace
}  // namespace orrery

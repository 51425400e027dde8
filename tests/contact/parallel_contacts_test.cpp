// Tooth contacts evaluated on several threads (mbd/force_elements.h, CalcExternalForces): the
// elements compute into their own workspaces in parallel and their results are added in element
// order on one thread, so a run with 2 threads writes the same numbers to the last bit as a run
// with 1 (the oracle: the serial run, compared bit for bit). Also: an element's exception on a
// worker thread reaches the caller.
#include <gtest/gtest.h>

#include <atomic>

#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "contact/contact_element.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "mbd/state.h"
#include "models/gear_contact.h"
#include "tests/contact/two_mesh_model.h"

namespace orrery::contact {
namespace {

using test_scenes::TwoMeshModel;

bool BitEqual(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  return x.size() == y.size() &&
         std::memcmp(x.data(), y.data(), sizeof(double) * static_cast<size_t>(x.size())) == 0;
}

TEST(ParallelContacts, EvaluationsBitIdenticalForOneAndTwoThreads) {
  const std::shared_ptr<const Model> model = TwoMeshModel();
  const Model& m = *model;
  Data serial(m), parallel(m);
  parallel.threads = 2;
  State s = State::Initial(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(m.nv);
  int pressed = 0;
  for (int k = 0; k < 40; ++k) {
    // The pinion turned through half a mesh period against the gears, pressing both flanks.
    s.q(0) = 2e-3 * k + 4e-6 / 0.0135;
    s.v.setConstant(0.5 * std::sin(0.3 * k));
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, serial);
    EvaluateDynamics(m, 0.0, s.q, s.v, vdot, parallel);
    ASSERT_TRUE(BitEqual(serial.tau_id, parallel.tau_id)) << "evaluation " << k;
    for (int b = 0; b < m.nbodies; ++b)
      ASSERT_TRUE(serial.f_ext[b] == parallel.f_ext[b]) << "evaluation " << k << ", body " << b;
    ASSERT_EQ(serial.potential_energy, parallel.potential_energy);
    ASSERT_EQ(serial.power_dissipated, parallel.power_dissipated);
    pressed += static_cast<const ContactWorkspace&>(*serial.external[0]).normal_force > 0 &&
               static_cast<const ContactWorkspace&>(*serial.external[1]).normal_force > 0;
  }
  // Both meshes carried load in most of the evaluations (the comparison is not of zeros).
  EXPECT_GT(pressed, 20);
}

// A run through several mesh periods with generalized-alpha (the pinion thrown against both
// gears; analytic contact tangents, Newton iterations, halved steps when contact comes on): the
// final state is the same to the last bit, and so is every step (the same counts).
TEST(ParallelContacts, RunBitIdenticalForOneAndTwoThreads) {
  const std::shared_ptr<const Model> model = TwoMeshModel();
  SimulationOptions o;
  o.end_time = 0.01;
  o.output_interval = 1e-3;
  o.integrator.kind = IntegratorKind::kGeneralizedAlpha;
  o.integrator.step = 2e-5;
  o.integrator.rho_inf = 0.5;
  o.integrator.max_step_halvings = 6;
  State start = State::Initial(*model);
  start.v(0) = 20;  // rad/s: the pinion runs into both gears
  auto run = [&](int threads) {
    o.integrator.threads = threads;
    ResultFile out = ResultFile::CreateInMemory("parallel contacts " + std::to_string(threads));
    return Simulate(*model, o, &out, {}, &start);
  };
  const SimulationReport one = run(1);
  const SimulationReport two = run(2);
  EXPECT_TRUE(BitEqual(one.final_state.q, two.final_state.q));
  EXPECT_TRUE(BitEqual(one.final_state.v, two.final_state.v));
  EXPECT_EQ(one.stats.steps, two.stats.steps);
  EXPECT_EQ(one.stats.residual_evaluations, two.stats.residual_evaluations);
  EXPECT_EQ(one.stats.newton_iterations, two.stats.newton_iterations);
  // The gears were thrown: they turn (the comparison is not of a state at rest).
  EXPECT_GT(std::abs(one.final_state.v(1)), 0.1);
  EXPECT_GT(std::abs(one.final_state.v(2)), 0.1);
}

// Two elements whose Compute() throws at their first call only: the exception thrown on a worker
// thread is rethrown by the evaluation, and the next evaluation, where nothing throws, does not
// throw the other element's stale one.
TEST(ParallelContacts, WorkerExceptionReachesTheCaller) {
  class Throwing final : public ExternalForceElement {
   public:
    const std::string& name() const override { return name_; }
    std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model&) const override {
      return std::make_unique<ExternalForceWorkspace>();
    }
    void Apply(const Model& m, double t, Data& d, ExternalForceWorkspace& w) const override {
      Compute(m, t, d, w);
    }
    bool SplitsApply() const override { return true; }
    void Compute(const Model&, double, const Data&, ExternalForceWorkspace&) const override {
      if (calls_.fetch_add(1) == 0) throw std::runtime_error(name_ + " failed");
    }
    bool HasTangents() const override { return false; }
    void AddTangents(const Model&, const Data&, ExternalForceWorkspace&, Eigen::Ref<Eigen::MatrixXd>,
                     Eigen::Ref<Eigen::MatrixXd>) const override {}
    const std::vector<OutputDescription>& outputs() const override { return outputs_; }
    void GetOutputs(const ExternalForceWorkspace&, double*) const override {}

    explicit Throwing(std::string name) : name_(std::move(name)) {}
   private:
    std::string name_;
    std::vector<OutputDescription> outputs_;
    mutable std::atomic<int> calls_{0};
  };
  ModelBuilder b;
  const BodyIndex body = b.AddBody("body", 1.0, Vec3::Zero(), Mat3::Identity());
  JointSpec j;
  j.name = "slider", j.type = JointType::kPrismatic, j.parent = kWorldBody, j.child = body;
  b.AddJoint(j);
  b.AddExternalForce(std::make_shared<Throwing>("throwing1"));
  b.AddExternalForce(std::make_shared<Throwing>("throwing2"));
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  Data data(*model);
  data.threads = 2;
  const State s = State::Initial(*model);
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(model->nv);
  try {
    EvaluateDynamics(*model, 0.0, s.q, s.v, vdot, data);
    ADD_FAILURE() << "no exception from the failing elements";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "throwing1 failed");  // the first in element order
  }
  EXPECT_NO_THROW(EvaluateDynamics(*model, 0.0, s.q, s.v, vdot, data));
}

}  // namespace
}  // namespace orrery::contact

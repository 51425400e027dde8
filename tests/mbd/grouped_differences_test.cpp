// DaeSystem::Tangents with grouped differences (mbd/dae.h set_grouped_differences) against the
// one-column-per-evaluation differences on a spatial planetary stage as seed 002 builds it
// (tests/common/spatial_stage.h: sun, ring and carrier on free joints on the world with
// bearings, two planets on free joints on the carrier with pin bearings, lumped meshes with
// analytic tangents, a speed driver on the carrier). The meshes are the only elements between the
// three subtrees and are not differenced, so a column's differenced rows lie in its own subtree: Kq
// and Cv must be the one-column differences' to the last bit (a wrong class, a missed coupling or a
// row taken from the wrong evaluation shows as a difference of the size of the entries).
#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "mbd/dae.h"
#include "mbd/data.h"
#include "mbd/kinematics.h"
#include "mbd/model.h"
#include "mbd/state.h"
#include "tests/common/spatial_stage.h"

namespace orrery {
namespace {

// A state off equilibrium: every coordinate moved (micrometres and milliradians on the bearings'
// and meshes' scale, turns of the free rotations), velocities of all sizes.
State Moved(const Model& m) {
  State s = State::Initial(m);
  s.t = 0.37;
  for (int k = 0; k < m.nv; ++k) {
    Eigen::VectorXd dv = Eigen::VectorXd::Zero(m.nv);
    dv(k) =
        (k % 6 < 3 ? 1e-5 : 1e-3) * std::sin(1.3 * k + 0.4) + (k % 6 == 5 ? 2.0 + 0.1 * k : 0.0);
    IntegratePositions(m, dv, s.q);
    s.v(k) = (k % 6 < 3 ? 1e-3 : 0.2) * std::cos(0.7 * k) + (k % 6 == 5 ? 5.0 : 0.0);
  }
  return s;
}

void ExpectGroupedAsOneColumnEach(const Model& m, int groups) {
  DaeSystem grouped(m), single(m);
  single.set_grouped_differences(false);
  EXPECT_EQ(grouped.difference_groups(), groups);
  const State s = Moved(m);
  const Eigen::VectorXd vdot = Eigen::VectorXd::LinSpaced(m.nv, -3.0, 4.0);
  const Eigen::VectorXd lambda = Eigen::VectorXd::Constant(m.n_constraints, 12.5);
  Eigen::MatrixXd Kq_g(m.nv + m.n_constraints, m.nv), Cv_g(m.nv, m.nv);
  Eigen::MatrixXd Kq_s(m.nv + m.n_constraints, m.nv), Cv_s(m.nv, m.nv);
  grouped.Tangents(s.t, s.q, s.v, vdot, lambda, Kq_g, Cv_g);
  single.Tangents(s.t, s.q, s.v, vdot, lambda, Kq_s, Cv_s);
  ASSERT_GT(Kq_s.cwiseAbs().maxCoeff(), 1e5);  // the bearings' and meshes' stiffness is in it
  for (int c = 0; c < m.nv; ++c) {
    for (int r = 0; r < m.nv + m.n_constraints; ++r)
      EXPECT_EQ(Kq_g(r, c), Kq_s(r, c)) << "Kq " << r << ", " << c;
    for (int r = 0; r < m.nv; ++r) EXPECT_EQ(Cv_g(r, c), Cv_s(r, c)) << "Cv " << r << ", " << c;
  }
  // Data is left at the base point alike
  EXPECT_EQ(grouped.data().tau_id, single.data().tau_id);
}

TEST(GroupedDifferences, TangentsAsOneColumnPerEvaluation) {
  const std::shared_ptr<const Model> model = test_support::SpatialStage(false);
  // Sun 6, ring 6, carrier with two planets 18 coordinates: 18 evaluations for 30 columns
  ExpectGroupedAsOneColumnEach(*model, 18);
}

TEST(GroupedDifferences, ASpringBetweenSubtreesJoinsThem) {
  const std::shared_ptr<const Model> model = test_support::SpatialStage(true);
  // Sun and ring in one class (12 coordinates), the carrier's 18: still 18 groups, and the
  // sun's and ring's columns no longer share an evaluation
  ExpectGroupedAsOneColumnEach(*model, 18);
}

}  // namespace
}  // namespace orrery

// Tracked gaps (tracked_gaps.h) against the candidate-pair gaps (signed_gap.h over a fresh
// search at every pose, itself checked against a brute force in candidate_pairs_test.cpp):
// whole spur gears with tooth rings rolled through two mesh periods in small steps with a
// Newton-like wobble, jumps and a reversal, so that tooth pairs join and leave the tracked set,
// nodes sleep and wake, walk and are seeded.
#include "contact/tracked_gaps.h"

#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "contact/gear_contact.h"
#include "models/gear_geometry.h"

namespace orrery::contact {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Poses {
  Transform X_W1, X_W2;
};

class TrackedGapsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    g1_ = std::make_unique<gears::Gear>(
        gears::GearSpec{.teeth = 19, .normal_module_m = 2e-3, .face_width_m = 0.01});
    g2_ = std::make_unique<gears::Gear>(
        gears::GearSpec{.teeth = 27, .normal_module_m = 2e-3, .face_width_m = 0.01});
    a_ = gears::GearPair(*g1_, *g2_).center_distance_m();
    GearContactOptions o;
    o.involute_intervals = 16;
    o.margin_m = 30e-6;
    o.slack_m = 100e-6;
    s1_ = MakeGearContactSurface(*g1_, o, {}, Transform());
    s2_ = MakeGearContactSurface(*g2_, o, {}, Transform());
  }

  // Gear 1 at roll angle theta, gear 2 at its kinematic angle; gear 1 advanced by `ahead` along
  // the line of action (m) into the zero-backlash mesh, and gear 2 shifted off its centre.
  Poses At(double theta, double ahead, const Vec3& shift = Vec3::Zero()) const {
    const double th1 = theta + ahead / g1_->base_radius_m();
    const double th2 = kPi + kPi / 27 - theta * 19.0 / 27;
    return {Transform(AxisAngle(Vec3::UnitZ(), th1), Vec3::Zero()),
            Transform(AxisAngle(Vec3::UnitZ(), th2), Vec3(a_, 0, 0) + shift)};
  }

  std::unique_ptr<gears::Gear> g1_, g2_;
  double a_ = 0;
  std::shared_ptr<const ContactSurface> s1_, s2_;
};

// The candidate-pair gaps of one pass at these poses (slack 0 searches every time).
std::vector<NodeGap> OracleGaps(const ContactSurface& nodes, const Transform& X_WN,
                                const ContactSurface& faces, const Transform& X_WF,
                                bool nodes_are_a, const std::vector<TrianglePair>& pairs,
                                double d) {
  GapScratch scratch(nodes);
  std::vector<NodeGap> gaps;
  ComputeNodeGaps(nodes, X_WN, faces, X_WF, pairs, nodes_are_a, d, &scratch, &gaps);
  return gaps;
}

TEST_F(TrackedGapsTest, EqualTheCandidatePairGapsWhileRolling) {
  TrackedGaps tracked(*s1_, *s2_);
  CandidateSearch search(*s1_, *s2_);
  const double d = tracked.search_distance_m();
  std::vector<NodeGap> gaps_a, gaps_b;
  gaps_a.reserve(s1_->num_vertices());
  gaps_b.reserve(s2_->num_vertices());
  std::vector<TrianglePair> pairs;
  pairs.reserve(search.suggested_capacity());

  // Two mesh periods forward in 400 steps, the approach oscillating between 5 and 25 um, with a
  // wobble (a Newton iterate) at every step; then jumps, a reversal and a shifted centre.
  std::vector<Poses> poses;
  const double period = 2 * kPi / 19;
  for (int k = 0; k <= 400; ++k) {
    const double theta = 2 * period * k / 400;
    const double ahead = 15e-6 + 10e-6 * std::sin(0.07 * k);
    poses.push_back(At(theta, ahead));
    poses.push_back(At(theta + 1e-5, ahead - 2e-6));
  }
  for (double theta : {0.9 * period, 0.3 * period, 1.7 * period, 0.0})
    poses.push_back(At(theta, 20e-6));
  for (int k = 0; k <= 40; ++k)
    poses.push_back(At(-0.5 * period * k / 40, 12e-6, Vec3(-8e-6, 15e-6, 0)));

  int compared = 0, penetrating = 0, face_ties = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    const Poses& p = poses[k];
    tracked.Update(p.X_W1, p.X_W2, &gaps_a, &gaps_b);
    search.UpdateBroadPhase(p.X_W1, p.X_W2);
    search.FindPairs(&pairs);
    for (int dir = 0; dir < 2; ++dir) {
      const std::vector<NodeGap>& got = dir == 0 ? gaps_a : gaps_b;
      const std::vector<NodeGap> want =
          dir == 0 ? OracleGaps(*s1_, p.X_W1, *s2_, p.X_W2, true, pairs, d)
                   : OracleGaps(*s2_, p.X_W2, *s1_, p.X_W1, false, pairs, d);
      std::map<int, const NodeGap*> by_node;
      for (const NodeGap& g : want) by_node[g.node] = &g;
      // Every listed node has the oracle's gap and face.
      for (const NodeGap& g : got) {
        auto it = by_node.find(g.node);
        ASSERT_NE(it, by_node.end()) << "pose " << k << " dir " << dir << " node " << g.node;
        EXPECT_NEAR(g.gap, it->second->gap, 1e-15) << "pose " << k << " node " << g.node;
        // The face may differ only on a tie: copies of a vertex where two teeth meet.
        if (g.face != it->second->face) ++face_ties;
        EXPECT_EQ(g.on_surface, it->second->on_surface);
        ++compared;
      }
      // Every node in contact is listed.
      std::map<int, const NodeGap*> listed;
      for (const NodeGap& g : got) listed[g.node] = &g;
      for (const NodeGap& g : want) {
        if (!(g.gap < 0 && g.on_surface)) continue;
        EXPECT_TRUE(listed.count(g.node)) << "pose " << k << " dir " << dir << " node " << g.node
                                          << " gap " << g.gap;
        penetrating += g.gap < 0 && g.on_surface;
      }
    }
  }
  EXPECT_GT(compared, 10000);
  EXPECT_LT(face_ties, compared / 1000);
  EXPECT_GT(penetrating, 5000);
  const TrackedGapStats& s = tracked.stats();
  // The walk and the seeding both ran, pairs came and went, and most nodes slept.
  EXPECT_GT(s.walk_steps, 100);
  EXPECT_GT(s.seeds, 100);
  EXPECT_GT(s.pair_changes, 10);
  const long tracked_nodes_per_update = s.node_evaluations / s.updates;
  EXPECT_LT(tracked_nodes_per_update, s1_->num_vertices() / 5);
  std::printf("tracked: %ld updates, %.1f nodes evaluated per update (of %d + %d), %.2f seeds "
              "per update, %ld walk steps, %ld pair changes\n",
              s.updates, static_cast<double>(s.node_evaluations) / s.updates,
              s1_->num_vertices(), s2_->num_vertices(),
              static_cast<double>(s.seeds) / s.updates, s.walk_steps, s.pair_changes);
}

}  // namespace
}  // namespace orrery::contact

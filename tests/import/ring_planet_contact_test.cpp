// Seed 003's rigid ring-planet contact (models/scenes/seed003_contact_healthy.yaml) stays on the
// line of action over a mesh cycle. Rigid involute flanks push along the common tangent of the
// base circles; a tip touching a fillet or root pushes elsewhere (almost radially).
//
// Oracle: the line of action from the pair's closed-form geometry (gear_geometry.h GearPair:
// r_b1, r_b2, centre distance a, cos(alpha_wt) = (r_b2 - r_b1) / a): its unit direction t in the
// world for branch 1's planet centre. The branch's resultant force F on the planet (the contact
// element's own force, without velocities, at the scene's kinematic configuration, ring turned to load a flank) against
// the sum N of its normal forces: |F . t| = N exactly when every contact normal is along t.
//
// The interference this catches (docs/faults.md): at the centred kinematic position (each flank
// 10 um from its mate) each ring tip passes the planet's fillet 23 um away (exact geometry), but
// the fillet surface, sampled at 6 even intervals of the rack angle, had a chord 52 um into the
// tooth space: every ring-planet branch touched there, 3.8 kN with 14.5 um penetration and 22 N
// along the line of action, once per mesh cycle.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "contact/contact_element.h"
#include "import/scene.h"
#include "mbd/data.h"
#include "mbd/evaluate.h"
#include "models/train_contact.h"
#include "models/train_dynamics.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

// The ring-planet#1 contact of the scene at the kinematic configuration of time t, ring turned
// further by phi (rad): the normal force sum and the resultant force on the planet along the line
// of action (N).
class RingPlanetBranch {
 public:
  explicit RingPlanetBranch(const Scene& s) : scene_(s), data_(*s.model) {
    const GearTrainScene& g = *s.gear_train;
    const int mesh = g.train->MeshIndex("S.ring-planet");
    for (const gears::TrainContactMesh& c : g.model->contacts)
      if (c.train_mesh == mesh && c.branch == 0) contact_ = c;
    element_ = dynamic_cast<const contact::ContactElement*>(s.model->external_forces.at(contact_.external_force).get());
    ring_q_ = s.model->joints[g.model->member_joints[g.train->MemberIndex("S.ring")]].q_start;
    pair_ = std::make_unique<gears::GearPair>(gears::MakeTrainGearPair(*g.train, mesh, g.options));
    if (element_) ws_ = std::make_unique<contact::ContactWorkspace>(*element_->spec().surface_a, *element_->spec().surface_b);
  }
  const gears::GearPair& pair() const { return *pair_; }
  bool ok() const { return element_ != nullptr; }

  struct Forces {
    double normal_n = 0, along_line_n = 0;
  };
  Forces operator()(double t, double phi) {
    const Model& m = *scene_.model;
    Eigen::VectorXd q = m.q_initial + t * m.v_initial;
    q(ring_q_) += phi;
    EvaluateDynamics(m, t, q, m.v_initial, Eigen::VectorXd::Zero(m.nv), data_);
    // Body 1 is the planet, body 2 the ring (train_contact.h); the ring's axis is the world z
    // axis through its body origin.
    const Vec3 c1 = data_.X_WB[contact_.body1].p, c2 = data_.X_WB[contact_.body2].p;
    // The element's forces at these poses without velocities (quasi-static: no Hunt-Crossley
    // damping).
    Vec6 f1, f2;
    double e = 0, p = 0;
    element_->UpdateGaps(data_.X_WB[contact_.body1], data_.X_WB[contact_.body2], *ws_);
    element_->CalcForces(Vec6::Zero(), Vec6::Zero(), *ws_, &f1, &f2, &e, &p);
    // Line of action: t perpendicular to e, e the line of centres u turned by +-alpha_wt (the
    // flank that carries F decides the sign; |F . t| is the same for both tangents' mirror).
    const Vec3 d = c1 - c2;
    const gears::Vec2 u = gears::Vec2(d.x(), d.y()).normalized();
    const gears::Vec2 force(f1(3), f1(4));
    const double aw = pair_->working_pressure_angle_rad();
    double best = 0;
    for (double sign : {-1.0, 1.0}) {
      const double c = std::cos(sign * aw), s = std::sin(sign * aw);
      const gears::Vec2 e_dir(c * u.x() - s * u.y(), s * u.x() + c * u.y());
      best = std::max(best, std::abs(force.dot(gears::Vec2(-e_dir.y(), e_dir.x()))));
    }
    return {ws_->normal_force, best};
  }

 private:
  const Scene& scene_;
  Data data_;
  gears::TrainContactMesh contact_;
  const contact::ContactElement* element_ = nullptr;
  int ring_q_ = -1;
  std::unique_ptr<gears::GearPair> pair_;
  std::unique_ptr<contact::ContactWorkspace> ws_;
};

TEST(RingPlanetContact, Seed003ContactStaysOnTheLineOfActionOverAMeshCycle) {
  const fs::path path = fs::path(ORRERY_SOURCE_DIR) / "models" / "scenes" / "seed003_contact_healthy.yaml";
  const Scene scene = LoadScene(path.string());
  RingPlanetBranch branch(scene);
  ASSERT_TRUE(branch.ok());
  const GearTrainScene& g = *scene.gear_train;
  const double f_m = g.model->kinematics.stage_mesh_frequencies_hz(0);
  const double r_b2 = branch.pair().gear2().base_radius_m();
  const double backlash_m = 20e-6;  // the scene's normal backlash (spur: normal = transverse)

  // 48 instants over one mesh cycle, each: unloaded (centred: no contact at all), and the ring
  // turned to close the backlash and press one flank by 2 um (the geometry itself) and by the
  // penalty's calibration deflection (15 kN, the scene's operating load: tip corners then reach
  // the mating flank beyond the path of contact, as rigid teeth under load do).
  const int n = 48;
  const auto& cal = g.model->contacts.front().calibration;
  double worst_free = 0, worst_light = 1, worst_full = 1, mean_full = 0, min_n = 1e300, max_n = 0;
  for (int i = 0; i < n; ++i) {
    const double t = i / (n * f_m);
    worst_free = std::max(worst_free, branch(t, 0).normal_n);
    // The loaded flank: whichever sign of the turn closes first.
    double sign = 1;
    if (branch(t, (0.5 * backlash_m + 2e-6) / r_b2).normal_n <= 0) sign = -1;
    const RingPlanetBranch::Forces light = branch(t, sign * (0.5 * backlash_m + 2e-6) / r_b2);
    const RingPlanetBranch::Forces full = branch(t, sign * (0.5 * backlash_m + cal.reference_deflection_m) / r_b2);
    ASSERT_GT(light.normal_n, 0) << "t " << t;
    ASSERT_GT(full.normal_n, 0) << "t " << t;
    worst_light = std::min(worst_light, light.along_line_n / light.normal_n);
    worst_full = std::min(worst_full, full.along_line_n / full.normal_n);
    mean_full += full.along_line_n / full.normal_n / n;
    min_n = std::min(min_n, full.normal_n);
    max_n = std::max(max_n, full.normal_n);
  }
  std::printf("unloaded: largest normal force %.3g N; 2 um: along the line of action >= %.4f N; "
              "%.1f um (%.0f .. %.0f N): >= %.4f N, mean %.4f N (per N of normal force)\n",
              worst_free, worst_light, cal.reference_deflection_m * 1e6, min_n, max_n, worst_full, mean_full);
  EXPECT_EQ(worst_free, 0);
  // Faceting (40 involute intervals, fillets within 1 um) is all that may turn the light load.
  EXPECT_GT(worst_light, 0.99);
  // Under full load the tip corners' extended contact turns a few per cent of the force.
  EXPECT_GT(worst_full, 0.95);
  EXPECT_GT(mean_full, 0.99);
}

}  // namespace
}  // namespace orrery

// One tooth fault at three levels (docs/faults.md): the quasi-static mesh stiffness over the
// faulty tooth's engagement from the lumped potential-energy TVMS (models/mesh_stiffness.h), from
// rigid tooth contact (SweepGearMesh) and from flexible FE tooth contact (SweepFlexibleGearMesh),
// on seed 001's sun-planet pair (sun 34 = gear 1 driving, planet 18 = gear 2; m_n 1.5 mm,
// 21.3 deg, b 30 mm, standard addenda, bores 0.4 r; 1429 N: seed 001 Tables 1 and 2). The fault
// sits on the planet's tooth 17 (gear frame), which meets the sun's tooth 0 (TvmsSweepFrame).
// Healthy and faulty sweeps at the same roll angles give the ratio r = k_faulty / k_healthy of
// each level. Oracles (no level is the reference of another):
//   - where: each level's drop zone is the TVMS's, up to one sweep point at each end of the zone
//     (the levels see a zone boundary between two sweep points; the flexible level's load
//     lengthens contact by about one step: flexible_gear_mesh.h). The zone: r below 1 - half of
//     that level's largest drop for a broken tooth and a spall (their drop is concentrated where
//     the lost part would mesh); for a crack, which softens the tooth over its whole engagement
//     (by a constant factor at the rigid level, by one that fades towards the tooth's root in the
//     TVMS), the engagement itself: r below 0.995;
//   - how much: in the TVMS's zone each level's mean drop 1 - r equals the TVMS's within the
//     level's healthy disagreement with the TVMS, sigma = the peak-to-peak of k_level / k_TVMS
//     over the healthy sweep relative to its mean (the levels' different double/single-pair
//     contrast: the rigid penalty's force grows as delta^(3/2), so losing a share of the contact
//     lowers its secant stiffness by less than the linear TVMS's: gear_contact.h).
// A spall is compared with the TVMS model of the same physics: the rigid level with the
// lost-slice model (its penalty lumps the whole pair into the contact), the flexible level with
// the Hertz-contact model (its teeth stay one body across the width): mesh_stiffness.h.
// The table of docs/faults.md is printed. Broken tooth, load path: where the lost tip would mesh
// the broken tooth's partner touches nothing at both contact levels, its neighbour carries alone
// (the rigid dynamic run of broken_tooth_test.cpp, quasi-statically and for flexible gears).
// Spall, light load: the rigid contact on the spalled
// tooth leaves the spall's axial band exactly over its roll range (within the contact strip).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "contact/contact_element.h"
#include "models/flexible_gear_mesh.h"
#include "models/gear_contact.h"
#include "models/mesh_stiffness.h"

namespace orrery::gears {

using namespace orrery::contact;
namespace {

using gears::ToothFaultSpec;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;
constexpr double kLoad = 1429;
constexpr int kPlanetTooth = 17;

gears::GearPair Seed001SunPlanet() {
  gears::GearSpec sun{.teeth = 34, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kDeg,
                      .face_width_m = 0.03};
  gears::GearSpec planet = sun;
  planet.teeth = 18;
  return {gears::Gear(sun), gears::Gear(planet)};
}

// The faults of the study (planet tooth 17, loaded = plus flank).
ToothFaultSpec Fault(const gears::GearPair& pair, const std::string& kind) {
  if (kind == "broken_tooth")  // the tip quarter: lost while the tooth shares the load near its tip
    return {.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = kPlanetTooth, .height_fraction = 0.25};
  if (kind == "root_crack")
    return {.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = kPlanetTooth, .crack_depth_m = 0.8e-3,
            .crack_angle_rad = 45 * kDeg};
  // Spall: the middle third of the face over the middle of the planet's single-pair zone.
  const double g = pair.line_of_action_length_m(), s0 = pair.contact_start_m(), s1 = pair.contact_end_m();
  const double mid = 0.5 * (s0 + s1), half = 0.08 * (s1 - s0);
  return {.kind = ToothFaultSpec::Kind::kSpall, .tooth = kPlanetTooth, .flank = ToothFaultSpec::Flank::kPlus,
          .roll_start_m = g - (mid + half), .roll_end_m = g - (mid - half), .axial_start_m = 0.01,
          .axial_end_m = 0.02, .depth_m = 20e-6};
}

// The sweep range: the tooth pair's engagement (TVMS frame [0, eps_alpha p)) with a quarter pitch
// on either side, in the sweep frame.
MeshSweepRange Engagement(const gears::GearPair& pair) {
  const double p = 2 * kPi / pair.gear1().teeth();
  const double offset = gears::MakeTvmsSweepFrame(pair).theta_offset_rad;
  return {.start_rad = -offset - 0.25 * p, .span_rad = (pair.transverse_contact_ratio() + 0.5) * p};
}

// TVMS secant stiffness F / delta at the sweep angles.
std::vector<double> TvmsAt(const gears::GearPair& pair, const std::vector<ToothFaultSpec>& planet_faults,
                           const std::vector<double>& angles,
                           gears::TvmsOptions::SpallModel model = gears::TvmsOptions::SpallModel::kHertzContact) {
  gears::TvmsOptions o{.bore_radius1_m = 0.4 * pair.gear1().reference_radius_m(),
                       .rim_radius2_m = 0.4 * pair.gear2().reference_radius_m(), .samples_per_period = 400,
                       .load_n = kLoad, .spall_model = model};
  o.faults = gears::TvmsFaultsInSweepFrame(pair, {}, planet_faults);
  const gears::Tvms t = gears::CalcTvms(pair, o);
  const double offset = gears::MakeTvmsSweepFrame(pair).theta_offset_rad;
  std::vector<double> k;
  for (double a : angles) k.push_back(kLoad / gears::InterpolateTvms(t, t.loaded_te_m, a + offset));
  return k;
}

struct Level {
  std::string name;
  std::vector<double> healthy;                 // N/m at the angles
  std::vector<std::vector<double>> faulty;     // per fault
};

// Peak-to-peak of a / b relative to its mean.
double ShapeSpread(const std::vector<double>& a, const std::vector<double>& b) {
  double mean = 0, lo = 1e300, hi = -1e300;
  for (size_t i = 0; i < a.size(); ++i) {
    mean += a[i] / b[i] / a.size();
    lo = std::min(lo, a[i] / b[i]);
    hi = std::max(hi, a[i] / b[i]);
  }
  return (hi - lo) / mean;
}

// The drop zone of ratios r (header): below 1 - half the largest drop, or (engagement) 0.995.
std::vector<bool> DropZone(const std::vector<double>& r, bool engagement = false) {
  double max_drop = 0;
  for (double v : r) max_drop = std::max(max_drop, 1 - v);
  std::vector<bool> zone;
  for (double v : r) zone.push_back(v < (engagement ? 0.995 : 1 - 0.5 * max_drop));
  return zone;
}

TEST(ToothFaultLevels, Seed001SunPlanetTable) {
  const gears::GearPair pair = Seed001SunPlanet();
  const std::vector<std::string> kinds = {"broken_tooth", "root_crack", "spall"};
  const MeshSweepRange range = Engagement(pair);
  constexpr int kPoints = 14;
  std::vector<double> angles;
  for (int i = 0; i < kPoints; ++i) angles.push_back(range.start_rad + range.span_rad * i / kPoints);
  const double step = range.span_rad / kPoints;

  Level tvms{"lumped TVMS"}, rigid{"rigid contact"}, flexible{"flexible FE contact"};
  tvms.healthy = TvmsAt(pair, {}, angles);
  for (const std::string& k : kinds) tvms.faulty.push_back(TvmsAt(pair, {Fault(pair, k)}, angles));
  const std::vector<double> tvms_slices = TvmsAt(pair, {Fault(pair, "spall")}, angles,
                                                 gears::TvmsOptions::SpallModel::kSlices);

  // Rigid: penalty calibrated at the load, cracks through the per-tooth factor.
  GearContactOptions ro;
  ro.calibration_load_n = kLoad;
  ro.rim_radius1_m = 0.4 * pair.gear1().reference_radius_m();
  ro.rim_radius2_m = 0.4 * pair.gear2().reference_radius_m();
  std::vector<MeshSweepPoint> rigid_broken, flexible_broken;  // for the load path below
  auto rigid_k = [&](const std::vector<ToothFaultSpec>& faults) {
    GearContactOptions o = ro;
    o.faults2 = faults;
    std::vector<double> k;
    const MeshSweep s = SweepGearMesh(pair, o, kLoad, kPoints, range);
    for (const MeshSweepPoint& p : s.points) k.push_back(p.stiffness_n_per_m);
    if (!faults.empty() && faults[0].kind == ToothFaultSpec::Kind::kBrokenTooth) rigid_broken = s.points;
    return k;
  };
  rigid.healthy = rigid_k({});
  for (const std::string& k : kinds) rigid.faulty.push_back(rigid_k({Fault(pair, k)}));

  // Flexible: the default (CI) hex20 meshes.
  auto flexible_k = [&](const std::vector<ToothFaultSpec>& faults) {
    FlexibleGearMeshOptions o;
    o.faults2 = faults;
    const FlexibleMeshSweep s = SweepFlexibleGearMesh(pair, o, kLoad, kPoints, range);
    EXPECT_EQ(s.inflation_exceeded, 0);
    std::vector<double> k;
    for (const MeshSweepPoint& p : s.points) k.push_back(p.stiffness_n_per_m);
    if (!faults.empty() && faults[0].kind == ToothFaultSpec::Kind::kBrokenTooth) flexible_broken = s.points;
    return k;
  };
  flexible.healthy = flexible_k({});
  for (const std::string& k : kinds) flexible.faulty.push_back(flexible_k({Fault(pair, k)}));

  // The sweeps, and the table.
  std::printf("roll(deg)  TVMS healthy/broken/crack/spall(Hertz)/spall(slices)   rigid h/b/c/s   flexible h/b/c/s  (N/um)\n");
  for (int i = 0; i < kPoints; ++i) {
    std::printf("%7.3f", angles[i] / kDeg);
    for (const Level* l : {&tvms, &rigid, &flexible}) {
      std::printf("  %5.0f", l->healthy[i] * 1e-6);
      for (const auto& f : l->faulty) std::printf(" %5.0f", f[i] * 1e-6);
      if (l == &tvms) std::printf(" %5.0f", tvms_slices[i] * 1e-6);
    }
    std::printf("\n");
  }
  std::printf("| fault | level | healthy mean (N/um) | healthy spread vs TVMS | drop zone (deg) | mean drop | TVMS drop | diff |\n");
  for (size_t f = 0; f < kinds.size(); ++f) {
    for (const Level* l : {&tvms, &rigid, &flexible}) {
      // The TVMS reference: for a spall, the model of the same physics (header).
      const std::vector<double>& ref = kinds[f] == "spall" && l == &rigid ? tvms_slices : tvms.faulty[f];
      std::vector<double> rt(kPoints), rl(kPoints);
      for (int i = 0; i < kPoints; ++i) {
        rt[i] = ref[i] / tvms.healthy[i];
        rl[i] = l->faulty[f][i] / l->healthy[i];
      }
      const bool engagement = kinds[f] == "root_crack";
      const std::vector<bool> zt = DropZone(rt, engagement), zl = DropZone(rl, engagement);
      const double sigma = l == &tvms ? 0.0 : ShapeSpread(l->healthy, tvms.healthy);
      double mean = 0, tvms_mean = 0, first = 1e9, last = -1e9;
      int n = 0, mismatch_low = 0, mismatch_high = 0;
      for (int i = 0; i < kPoints; ++i) {
        if (zl[i]) first = std::min(first, angles[i]), last = std::max(last, angles[i]);
        if (zt[i]) {
          mean += 1 - rl[i];
          tvms_mean += 1 - rt[i];
          ++n;
        }
        if (zt[i] != zl[i]) (angles[i] < 0.5 * (angles.front() + angles.back()) ? mismatch_low : mismatch_high)++;
      }
      ASSERT_GT(n, 0) << kinds[f];
      mean /= n;
      tvms_mean /= n;
      double healthy_mean = 0;
      for (double k : l->healthy) healthy_mean += k / kPoints;
      const std::string name = l->name + (kinds[f] == "spall" && l == &tvms ? " (Hertz contact)" : "");
      std::printf("| %s | %s | %.0f | %.1f %% | %.2f .. %.2f | %.1f %% | %.1f %% | %+.1f %% |\n", kinds[f].c_str(),
                  name.c_str(), healthy_mean * 1e-6, 100 * sigma, first / kDeg, last / kDeg, 100 * mean,
                  100 * tvms_mean, 100 * (mean - tvms_mean));
      // Where: at most one sweep point off at each end of the zone.
      EXPECT_LE(mismatch_low, 1) << kinds[f] << " " << l->name;
      EXPECT_LE(mismatch_high, 1) << kinds[f] << " " << l->name;
      // How much: within the level's healthy disagreement with the TVMS.
      EXPECT_LE(std::abs(mean - tvms_mean), sigma + 1e-12) << kinds[f] << " " << l->name << " step " << step;
    }
  }
  // Broken tooth, load path: where the lost tip would mesh (the TVMS's zone, but its last point:
  // there the loaded contact reaches down to the fracture's edge, one step early as in "where")
  // the sun's tooth 0, partner of the broken planet tooth, touches nothing; its neighbour carries
  // alone.
  {
    std::vector<double> r;
    for (int i = 0; i < kPoints; ++i) r.push_back(tvms.faulty[0][i] / tvms.healthy[i]);
    const std::vector<bool> zone = DropZone(r);
    int checked = 0;
    for (const std::vector<MeshSweepPoint>* pts : {&rigid_broken, &flexible_broken})
      for (int i = 0; i + 1 < kPoints; ++i) {
        if (!zone[i] || !zone[i + 1]) continue;
        const MeshSweepPoint& p = (*pts)[i];
        EXPECT_EQ(p.teeth_in_contact, 1) << "roll " << angles[i] / kDeg << " deg";
        for (int t : p.teeth) EXPECT_NE(t, 0) << "roll " << angles[i] / kDeg << " deg";
        ++checked;
      }
    EXPECT_GE(checked, 4);
    std::printf("broken tooth: %d sweep points of the rigid and flexible runs with the partner out of contact\n",
                checked);
  }
  // The spall under the lost-slice model, for the table.
  double slice_drop = 0;
  int n = 0;
  const std::vector<bool> zs = [&] {
    std::vector<double> r;
    for (int i = 0; i < kPoints; ++i) r.push_back(tvms_slices[i] / tvms.healthy[i]);
    return DropZone(r);
  }();
  for (int i = 0; i < kPoints; ++i)
    if (zs[i]) slice_drop += 1 - tvms_slices[i] / tvms.healthy[i], ++n;
  std::printf("| spall | lumped TVMS (lost slices) | | | | %.1f %% | | |\n", 100 * slice_drop / n);
}

TEST(ToothFaultLevels, SpallLosesRigidContactExactlyOverItsRollRange) {
  // Light load: the contact strip (Hertz half width sqrt(2 rho delta)) is a few micrometres wide.
  const gears::GearPair pair = Seed001SunPlanet();
  const ToothFaultSpec spall = Fault(pair, "spall");
  GearContactOptions o;
  o.faults2 = {spall};
  const double load = 50;
  const MeshSweepRange range = Engagement(pair);
  const MeshSweep sweep = SweepGearMesh(pair, o, load, 40, range);
  const ContactElement element(MakeGearContactSpec("spall", pair, 1, 2, o));
  ContactWorkspace ws(*element.spec().surface_a, *element.spec().surface_b);
  const gears::Gear& planet = pair.gear2();
  const double z1 = pair.gear1().teeth(), z2 = planet.teeth(), rb1 = pair.gear1().base_radius_m();
  int inside = 0, outside = 0;
  for (const MeshSweepPoint& p : sweep.points) {
    // Pose of the sweep's solution (gear_contact.h frames).
    const double theta2 = kPi + kPi / z2 - z1 / z2 * p.roll_angle_rad;
    const Transform X_W1(AxisAngle(Vec3::UnitZ(), p.roll_angle_rad + p.transmission_error_m / rb1), Vec3::Zero());
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), theta2), Vec3(pair.center_distance_m(), 0, 0));
    element.UpdateGaps(X_W1, X_W2, ws);
    const Transform X_2W = X_W2.Inverse();
    // Pressed points on the planet's spalled tooth: their roll distance and axial position.
    double roll_min = 1e9, roll_max = -1e9;
    int in_band = 0, pressed = 0;
    auto visit = [&](const Vec3& p_W) {
      const Vec3 q = X_2W * p_W;
      const int tooth = static_cast<int>(std::lround(std::atan2(q.y(), q.x()) * z2 / (2 * kPi)) + z2) % int(z2);
      if (tooth != kPlanetTooth) return;
      const double rho = gears::RollDistance(planet, std::hypot(q.x(), q.y()));
      roll_min = std::min(roll_min, rho), roll_max = std::max(roll_max, rho);
      ++pressed;
      in_band += q.z() > spall.axial_start_m + 1e-9 && q.z() < spall.axial_end_m - 1e-9;
    };
    for (const NodeGap& g : ws.gaps_a)
      if (g.gap < 0 && g.on_surface) visit(g.q_W);
    for (const NodeGap& g : ws.gaps_b)
      if (g.gap < 0 && g.on_surface) visit(g.p_W);
    if (pressed == 0) continue;
    // The strip: its roll extent on the planet; faceting of the flank (100 intervals) and the
    // strip's width are below 10 um.
    const double rho = 0.5 * (roll_min + roll_max), half = 0.5 * (roll_max - roll_min) + 10e-6;
    if (rho + half < spall.roll_start_m || rho - half > spall.roll_end_m) {
      EXPECT_GT(in_band, 0) << "outside the spall, roll " << rho * 1e3 << " mm";
      ++outside;
    } else if (rho - half > spall.roll_start_m && rho + half < spall.roll_end_m) {
      EXPECT_EQ(in_band, 0) << "inside the spall, roll " << rho * 1e3 << " mm";
      ++inside;
    }
  }
  std::printf("spall [%.3f, %.3f] mm: %d sweep points inside lose the band, %d outside keep it\n",
              spall.roll_start_m * 1e3, spall.roll_end_m * 1e3, inside, outside);
  EXPECT_GE(inside, 3);
  EXPECT_GE(outside, 10);
}

}  // namespace
}  // namespace orrery::gears

// Mesh-zone broad phase of gear surfaces (candidate_pairs.h, stage 1a; tooth rings from
// models/gear_contact.h). Oracle: the same tooth meshes without tooth rings (sphere broad phase
// only) must give exactly the same candidate triangle pairs at every pose, for an external
// pair and an internal (planet-ring) pair, each at many roll angles and with the flanks pressed,
// while the zone keeps fewer tooth pairs (or the test could not fail on the count).
// Backlash: WithNormalBacklash gives the requested normal backlash (GearPair's own measure), and
// the coast flanks of a loaded backlash pair leave the candidates.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "contact/candidate_pairs.h"
#include "models/gear_contact.h"

namespace orrery::contact {
namespace {

using namespace orrery::gears;  // gear surfaces as the workload

constexpr double kPi = 3.14159265358979323846;

// The gear's surface with a tooth ring (MakeGearContactSurface) and the same parts without one.
struct Surfaces {
  std::shared_ptr<const ContactSurface> zoned, plain;
};

Surfaces Make(const gears::Gear& gear, const GearContactOptions& o) {
  Surfaces s;
  s.zoned = MakeGearContactSurface(gear, o, {}, Transform());
  std::vector<TriangleMesh> parts;
  for (int t = 0; t < gear.teeth(); ++t)
    parts.push_back(gears::MakeToothSurfaceMesh(
        gear, t, {.root = o.root_intervals, .fillet = o.fillet_intervals,
                  .involute = o.involute_intervals, .tip = o.tip_intervals,
                  .fillet_max_sag_m = o.fillet_max_sag_m}, o.face_intervals));
  s.plain = std::make_shared<const ContactSurface>(parts, o.margin_m, o.slack_m);
  EXPECT_TRUE(s.zoned->part_ring().has_value());
  return s;
}

void ExpectSamePairs(const gears::GearPair& pair, const char* what) {
  GearContactOptions o;
  o.involute_intervals = 12;
  o.face_intervals = 3;
  const Surfaces s1 = Make(pair.gear1(), o), s2 = Make(pair.gear2(), o);
  CandidateSearch zoned(*s1.zoned, *s2.zoned), plain(*s1.plain, *s2.plain);
  const double z1 = pair.gear1().teeth(), z2 = pair.gear2().teeth();
  const double a = pair.center_distance_m();
  const Vec3 p2 = pair.internal() ? Vec3(-a, 0, 0) : Vec3(a, 0, 0);
  int fewer = 0;
  for (int i = 0; i < 16; ++i) {
    // Kinematic angles (SweepGearMesh's convention) over a bit more than one mesh period, gear 1
    // pressed ahead by 5 um along the line of action, the whole pair turned by psi.
    const double th1 = 2.3 * kPi / z1 * i / 16 + 5e-6 / pair.gear1().base_radius_m();
    const double th2 = pair.internal() ? kPi / z2 + z1 / z2 * th1 : kPi + kPi / z2 - z1 / z2 * th1;
    const double psi = 0.7 * i;
    const Transform X_W1(AxisAngle(Vec3::UnitZ(), psi + th1), Vec3::Zero());
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), psi + th2), AxisAngle(Vec3::UnitZ(), psi) * p2);
    std::vector<TrianglePair> pz, pp;
    zoned.Invalidate();
    plain.Invalidate();
    zoned.Find(X_W1, X_W2, &pz);
    plain.Find(X_W1, X_W2, &pp);
    std::sort(pz.begin(), pz.end());
    std::sort(pp.begin(), pp.end());
    ASSERT_FALSE(pp.empty()) << what << " pose " << i;
    EXPECT_EQ(pz, pp) << what << " pose " << i;
    EXPECT_LE(zoned.stats().part_pairs, plain.stats().part_pairs);
    fewer += zoned.stats().part_pairs < plain.stats().part_pairs;
    // Teeth in the zone: a few per gear around the contact path.
    EXPECT_LE(zoned.stats().zone_parts_a, 6) << what;
    EXPECT_LE(zoned.stats().zone_parts_b, 6) << what;
  }
  EXPECT_GT(fewer, 0) << what << ": the zone never removed a tooth pair";
}

TEST(MeshZoneTest, SamePairsAsTheSphereBroadPhaseExternalAndInternal) {
  const double deg = kPi / 180;
  // Seed 003's stage: sun 22, planet 14, ring 50, m = 4 mm, 22.5 deg, b = 40 mm.
  gears::GearSpec sun{.teeth = 22, .normal_module_m = 4e-3,
                      .normal_pressure_angle_rad = 22.5 * deg, .face_width_m = 0.04};
  gears::GearSpec planet = sun, ring = sun;
  planet.teeth = 14;
  ring.teeth = 50;
  ring.internal = true;
  ring.addendum_coef = 0.85;  // 0.9 reaches past the interference point T1 of the planet
  ring.root_fillet_coef = 0.25;  // 0.38 overlaps in the ring's narrow spaces
  ExpectSamePairs(gears::GearPair(gears::Gear(sun), gears::Gear(planet)), "sun-planet");
  ExpectSamePairs(gears::GearPair(gears::Gear(planet), gears::Gear(ring)), "planet-ring");
}

TEST(MeshZoneTest, BacklashIsTheRequestedOneAndUnloadsTheCoastFlank) {
  const double deg = kPi / 180;
  gears::GearSpec g1{.teeth = 22, .normal_module_m = 4e-3, .normal_pressure_angle_rad = 22.5 * deg,
                     .face_width_m = 0.04};
  gears::GearSpec g2 = g1;
  g2.teeth = 14;
  const gears::GearPair pair{gears::Gear(g1), gears::Gear(g2)};
  EXPECT_NEAR(pair.normal_backlash_m(), 0, 1e-12);
  const gears::GearPair thinned = WithNormalBacklash(pair, 100e-6, 1.0);  // 14 teeth: near undercut
  EXPECT_NEAR(thinned.normal_backlash_m(), 100e-6, 1e-12);
  // Pressed by 5 um on the drive flank: with 100 um backlash only the drive flanks lie within
  // d + s = 130 um, so fewer candidates than at zero backlash.
  GearContactOptions o;
  o.involute_intervals = 12;
  o.backlash_share1 = 1.0;
  auto count = [&](double backlash) {
    o.normal_backlash_m = backlash;
    const ContactElementSpec spec = MakeGearContactSpec("m", pair, 1, 2, o);
    CandidateSearch search(*spec.surface_a, *spec.surface_b);
    const double a = pair.center_distance_m();
    const Transform X_W1(AxisAngle(Vec3::UnitZ(), 5e-6 / pair.gear1().base_radius_m() +
                                                       0.5 * WithNormalBacklash(pair, backlash, 1.0).angular_backlash1_rad()),
                         Vec3::Zero());
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), kPi + kPi / 14), Vec3(a, 0, 0));
    std::vector<TrianglePair> pairs;
    search.Find(X_W1, X_W2, &pairs);
    return pairs.size();
  };
  const size_t zero = count(0), loose = count(100e-6);
  EXPECT_GT(loose, 0u);
  EXPECT_LT(loose, 0.7 * zero);
}

}  // namespace
}  // namespace orrery::contact

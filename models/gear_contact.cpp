#include "models/gear_contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "models/mesh_stiffness.h"
#include "models/tooth_fault_geometry.h"

namespace orrery::gears {

// The general contact engine this layer builds on.
using namespace orrery::contact;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The two halves of a tooth mesh (minus: triangles whose centroid lies at a smaller polar
// angle than the tooth's centre line, turned by the helix at the centroid's z; plus: the rest),
// each with its own vertices in the tooth's order (row by row, so that a spur tooth's halves
// are extruded parts, contact/contact_surface.h, and share their rows' evaluation).
std::pair<TriangleMesh, TriangleMesh> SplitTooth(const TriangleMesh& m, double angle,
                                                               double twist) {
  // Each triangle's half, and the vertices each half uses.
  std::vector<int> side(m.triangles.size());
  std::vector<int> index[2] = {std::vector<int>(m.vertices.size(), -1), std::vector<int>(m.vertices.size(), -1)};
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    const Vec3 c = (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0;
    double d = std::atan2(c.y(), c.x()) - angle - twist * c.z();
    d -= 2 * kPi * std::floor((d + kPi) / (2 * kPi));
    side[i] = d < 0 ? 0 : 1;
    for (const int v : t) index[side[i]][v] = 0;
  }
  TriangleMesh half[2];
  for (int h = 0; h < 2; ++h)
    for (size_t v = 0; v < m.vertices.size(); ++v)
      if (index[h][v] == 0) {
        index[h][v] = static_cast<int>(half[h].vertices.size());
        half[h].vertices.push_back(m.vertices[v]);
      }
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    const std::vector<int>& to = index[side[i]];
    half[side[i]].triangles.push_back({to[t[0]], to[t[1]], to[t[2]]});
  }
  return {std::move(half[0]), std::move(half[1])};
}

// Index of the part holding element `index` given the part start offsets.
int PartOf(const std::vector<int>& starts, int index) {
  return static_cast<int>(std::upper_bound(starts.begin(), starts.end(), index) - starts.begin()) - 1;
}

}  // namespace

GearContactCalibration CalibrateGearContact(const gears::GearPair& pair,
                                            const GearContactOptions& options) {
  GearContactCalibration c;
  const double b = pair.face_width_m();
  c.single_pair_stiffness_n_per_m = options.single_pair_stiffness_n_per_m
                                        ? *options.single_pair_stiffness_n_per_m
                                        : gears::CalcIso6336Stiffness(pair).c_single_n_per_m;
  if (!(c.single_pair_stiffness_n_per_m > 0))
    throw std::invalid_argument("CalibrateGearContact: single-pair stiffness must be > 0, got " +
                                std::to_string(c.single_pair_stiffness_n_per_m));
  if (!(options.calibration_load_n > 0))
    throw std::invalid_argument("CalibrateGearContact: calibration load must be > 0, got " +
                                std::to_string(options.calibration_load_n));
  // Curvature radii of the involutes at the pitch point: distances to T1 and T2.
  const double rho1 = pair.pitch_point_m();
  const double rho2 = pair.internal() ? pair.line_of_action_length_m() + rho1
                                      : pair.line_of_action_length_m() - rho1;
  c.equivalent_radius_m = pair.internal() ? rho1 * rho2 / (rho2 - rho1) : rho1 * rho2 / (rho1 + rho2);
  c.reference_deflection_m = options.calibration_load_n / c.single_pair_stiffness_n_per_m;
  c.stiffness_per_area = (options.calibration_load_n / b) /
                         (4.0 / 3.0 * std::sqrt(2 * c.equivalent_radius_m) *
                          std::pow(c.reference_deflection_m, 1.5));
  return c;
}

std::shared_ptr<const ContactSurface> MakeGearContactSurface(
    const gears::Gear& gear, const GearContactOptions& options, const std::vector<int>& missing,
    const Transform& X_BG, const std::vector<gears::ToothFaultSpec>& faults,
    const std::vector<std::pair<int, double>>& crack_scales,
    const std::vector<TriangleMesh>* imported) {
  if (imported && (!faults.empty() || static_cast<int>(imported->size()) != gear.teeth()))
    throw std::invalid_argument(
        faults.empty() ? "MakeGearContactSurface: " + std::to_string(imported->size()) +
                             " imported teeth for a gear of " + std::to_string(gear.teeth())
                       : std::string("MakeGearContactSurface: tooth faults on an imported gear "
                                     "are not supported (its surface is the file's)"));
  for (int t : missing)
    if (t < 0 || t >= gear.teeth())
      throw std::invalid_argument("MakeGearContactSurface: missing tooth " + std::to_string(t) +
                                  " is not in [0, " + std::to_string(gear.teeth()) + ")");
  gears::ValidateToothFaults(gear, faults);
  const gears::ProfileResolution res{.root = options.root_intervals,
                                     .fillet = options.fillet_intervals,
                                     .involute = options.involute_intervals,
                                     .tip = options.tip_intervals,
                                     .fillet_max_sag_m = options.fillet_max_sag_m};
  std::vector<TriangleMesh> parts;
  std::vector<double> scales;
  // The tooth ring of the mesh-zone test: tooth t about angle 2 pi t / z, radial band and half
  // angle measured on the vertices (gear frame).
  PartRing ring;
  ring.X_BG = X_BG;
  ring.inner_radius_m = 1e300;
  auto add_part = [&](TriangleMesh m, double angle, double scale) {
    for (const Vec3& v : m.vertices) {
      const double r = std::hypot(v.x(), v.y());
      ring.inner_radius_m = std::min(ring.inner_radius_m, r);
      ring.outer_radius_m = std::max(ring.outer_radius_m, r);
      double d = std::atan2(v.y(), v.x()) - angle;
      d -= 2 * kPi * std::floor((d + kPi) / (2 * kPi));
      ring.part_half_angle_rad = std::max(ring.part_half_angle_rad, std::abs(d));
    }
    ring.part_angles_rad.push_back(angle);
    for (Vec3& v : m.vertices) v = X_BG * v;
    parts.push_back(std::move(m));
    scales.push_back(scale);
  };
  for (int t = 0; t < gear.teeth(); ++t) {
    if (std::find(missing.begin(), missing.end(), t) != missing.end()) continue;
    const double angle = 2 * kPi * t / gear.teeth();
    const bool reshaped = std::any_of(faults.begin(), faults.end(), [&](const gears::ToothFaultSpec& f) {
      return f.tooth == t && f.kind != gears::ToothFaultSpec::Kind::kRootCrack;
    });
    TriangleMesh m =
        imported   ? (*imported)[t]
        : reshaped ? gears::MakeFaultyToothSurfaceMesh(gear, t, res, options.face_intervals, faults)
                   : gears::MakeToothSurfaceMesh(gear, t, res, options.face_intervals);
    // A cracked tooth: its halves, the crack's flank softer (header).
    const auto crack = std::find_if(crack_scales.begin(), crack_scales.end(), [&](const auto& c) { return c.first == t; });
    const auto fault = std::find_if(faults.begin(), faults.end(), [&](const gears::ToothFaultSpec& f) {
      return f.tooth == t && f.kind == gears::ToothFaultSpec::Kind::kRootCrack;
    });
    if (crack == crack_scales.end() || fault == faults.end()) {
      add_part(std::move(m), angle, 1.0);
      continue;
    }
    auto [minus, plus] = SplitTooth(m, angle, gear.twist_per_length());
    const bool plus_cracked = fault->flank == gears::ToothFaultSpec::Flank::kPlus;
    add_part(std::move(minus), angle, plus_cracked ? 1.0 : crack->second);
    add_part(std::move(plus), angle, plus_cracked ? crack->second : 1.0);
  }
  if (parts.empty()) throw std::invalid_argument("MakeGearContactSurface: no tooth left");
  return std::make_shared<const ContactSurface>(parts, options.margin_m, options.slack_m,
                                                std::move(ring), std::move(scales),
                                                options.smooth_normals);
}

std::vector<std::pair<int, double>> CrackStiffnessScales(const gears::GearPair& pair, int gear,
                                                         const GearContactOptions& options) {
  std::vector<std::pair<int, double>> out;
  for (const gears::ToothFaultSpec& f : gear == 1 ? options.faults1 : options.faults2) {
    if (f.kind != gears::ToothFaultSpec::Kind::kRootCrack) continue;
    const double ratio = gears::CrackStiffnessRatio(pair, gear, f, options.material, options.rim_radius1_m,
                                                    options.rim_radius2_m);
    out.emplace_back(f.tooth, std::pow(ratio, 1.5));
  }
  return out;
}

gears::GearPair WithNormalBacklash(const gears::GearPair& pair, double normal_backlash_m,
                                   double gear1_share) {
  if (!(normal_backlash_m >= 0))
    throw std::invalid_argument("WithNormalBacklash: backlash must be >= 0, got " +
                                std::to_string(normal_backlash_m));
  if (!(gear1_share >= 0 && gear1_share <= 1))
    throw std::invalid_argument("WithNormalBacklash: gear1_share must be in [0, 1]");
  if (normal_backlash_m == 0) return pair;
  // Teeth thinned by the allowances 2 A share_1 and 2 A (1 - share_1); the backlash is linear in
  // A, so one secant step from the guess A = -j_n / 2 hits it.
  auto thinned = [&](double allowance) {
    gears::GearSpec s1 = pair.gear1().spec(), s2 = pair.gear2().spec();
    s1.thickness_allowance_m += 2 * allowance * gear1_share;
    s2.thickness_allowance_m += 2 * allowance * (1 - gear1_share);
    return gears::GearPair(gears::Gear(s1), gears::Gear(s2), pair.center_distance_m());
  };
  const double j0 = pair.normal_backlash_m();
  const double guess = -0.5 * normal_backlash_m;
  const double j1 = thinned(guess).normal_backlash_m();
  if (!(std::abs(j1 - j0) > 0))
    throw std::runtime_error("WithNormalBacklash: thinning the teeth does not change the backlash");
  return thinned(guess * (normal_backlash_m - j0) / (j1 - j0));
}

contact::PenetrationLimit GearPenetrationLimit(const gears::GearPair& pair) {
  const double s1 = pair.gear1().ToothThickness(pair.gear1().reference_radius_m());
  const double s2 = pair.gear2().ToothThickness(pair.gear2().reference_radius_m());
  const double depth = 0.5 * std::min(s1, s2);
  return {.depth_m = depth,
          .reason = "the teeth have passed through each other (the limit is half the thinner tooth's thickness at "
                    "its reference circle, beyond which the gaps turn to the tooth's other flank): the contact is "
                    "too soft for its load, or the step too large"};
}

ContactElementSpec MakeGearContactSpec(const std::string& name, const gears::GearPair& given_pair,
                                       BodyIndex body1, BodyIndex body2,
                                       const GearContactOptions& options) {
  // Imported teeth keep the file's shape: the backlash thinning goes to a generated gear
  if (options.normal_backlash_m > 0 && ((options.imported_teeth1 && options.backlash_share1 > 0) ||
                                        (options.imported_teeth2 && options.backlash_share1 < 1)))
    throw std::invalid_argument("MakeGearContactSpec '" + name +
                                "': backlash would thin an imported gear's teeth "
                                "(give the thinning to the generated gear, backlash_share1)");
  const gears::GearPair pair =
      WithNormalBacklash(given_pair, options.normal_backlash_m, options.backlash_share1);
  const GearContactCalibration c = CalibrateGearContact(pair, options);
  ContactElementSpec spec;
  spec.name = name;
  spec.body_a = body1;
  spec.body_b = body2;
  spec.surface_a = MakeGearContactSurface(
      pair.gear1(), options, options.missing_teeth1, options.X_B1G1, options.faults1,
      CrackStiffnessScales(pair, 1, options), options.imported_teeth1.get());
  spec.surface_b = MakeGearContactSurface(
      pair.gear2(), options, options.missing_teeth2, options.X_B2G2, options.faults2,
      CrackStiffnessScales(pair, 2, options), options.imported_teeth2.get());
  spec.law = {.stiffness_per_area = c.stiffness_per_area,
              .hunt_crossley_s_per_m = options.hunt_crossley_s_per_m,
              .friction_coefficient = options.friction_coefficient,
              .slip_velocity_m_s = options.slip_velocity_m_s};
  spec.monitor = std::make_shared<const GearMeshMonitor>(
      GearMeshInfo{.X_AG1 = options.X_B1G1, .X_BG2 = options.X_B2G2,
                   .base_radius1_m = pair.gear1().base_radius_m(),
                   .base_radius2_m = pair.gear2().base_radius_m(),
                   .teeth1 = pair.gear1().teeth(), .teeth2 = pair.gear2().teeth(),
                   .internal = pair.internal()});
  spec.record_points = options.record_points;
  spec.penetration_limit = GearPenetrationLimit(pair);
  return spec;
}

MeshSweep SweepGearMesh(const gears::GearPair& pair, const GearContactOptions& options,
                        double load_n, int points, const MeshSweepRange& range) {
  if (!(load_n > 0)) throw std::invalid_argument("SweepGearMesh: load must be > 0");
  if (points < 1) throw std::invalid_argument("SweepGearMesh: points must be >= 1");
  GearContactOptions o = options;
  o.X_B1G1 = o.X_B2G2 = Transform();
  MeshSweep sweep;
  sweep.load_n = load_n;
  sweep.calibration = CalibrateGearContact(pair, o);
  const ContactElement element(MakeGearContactSpec("sweep", pair, 1, 2, o));
  ContactWorkspace ws(*element.spec().surface_a, *element.spec().surface_b);
  const ContactSurface& sa = *element.spec().surface_a;

  const double z1 = pair.gear1().teeth(), z2 = pair.gear2().teeth();
  const double rb1 = pair.gear1().base_radius_m();
  const double a = pair.center_distance_m();
  const double torque = load_n * rb1;
  const Vec3 p2 = pair.internal() ? Vec3(-a, 0, 0) : Vec3(a, 0, 0);
  const Vec6 zero = Vec6::Zero();

  for (int i = 0; i < points; ++i) {
    MeshSweepPoint pt;
    const double span = range.span_rad > 0 ? range.span_rad : 2 * kPi / z1;
    pt.roll_angle_rad = range.start_rad + span * i / points;
    // Gear 2 held at its kinematic angle.
    const double theta2 = pair.internal() ? kPi / z2 + z1 / z2 * pt.roll_angle_rad
                                          : kPi + kPi / z2 - z1 / z2 * pt.roll_angle_rad;
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), theta2), p2);
    // Moment balance of gear 1 as a function of the TE: contact moment + applied torque.
    Vec6 f1 = Vec6::Zero();
    auto residual = [&](double te) {
      const Transform X_W1(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + te / rb1), Vec3::Zero());
      element.UpdateGaps(X_W1, X_W2, ws);
      Vec6 f2;
      double e = 0, p = 0;
      element.CalcForces(zero, zero, ws, &f1, &f2, &e, &p);
      ++pt.evaluations;
      return -(torque + f1(2));  // increases with te: the contact moment opposes the drive
    };
    // Bracket the equilibrium, then the Illinois variant of regula falsi.
    const double d = sweep.calibration.reference_deflection_m * std::pow(
        load_n / o.calibration_load_n, 2.0 / 3.0);
    double lo = -0.25 * d, hi = 2 * d;
    double r_lo = residual(lo), r_hi = residual(hi);
    while (r_lo > 0 && lo > -20 * d) r_lo = residual(lo -= d);
    while (r_hi < 0 && hi < 20 * d) r_hi = residual(hi += 2 * d);
    if (!(r_lo <= 0 && r_hi >= 0))
      throw std::runtime_error("SweepGearMesh: no equilibrium within 20 reference deflections "
                               "at roll angle " + std::to_string(pt.roll_angle_rad));
    const double tol = 1e-7 * d;
    double te = hi;
    int side = 0;
    for (int k = 0; k < 100 && hi - lo > tol; ++k) {
      te = (lo * r_hi - hi * r_lo) / (r_hi - r_lo);
      if (!(te > lo && te < hi)) te = 0.5 * (lo + hi);
      const double r = residual(te);
      if (r == 0) break;
      if (r < 0) {
        lo = te, r_lo = r;
        if (side == -1) r_hi *= 0.5;
        side = -1;
      } else {
        hi = te, r_hi = r;
        if (side == 1) r_lo *= 0.5;
        side = 1;
      }
    }
    residual(te);  // leave the workspace at the solution
    pt.transmission_error_m = te;
    pt.stiffness_n_per_m = load_n / te;
    pt.normal_force_n = ws.normal_force;
    pt.friction_force_n = ws.friction_force;
    pt.force_x_n = f1(3);
    pt.force_y_n = f1(4);
    pt.contact_points = ws.contact_points;
    // Contact pattern on gear 1: roll distance of every contact, per tooth of gear 1 (its
    // gear-frame index from the part's angle: a cracked tooth has two parts).
    const Transform X_W1(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + te / rb1), Vec3::Zero());
    const Transform X_1W = X_W1.Inverse();
    ContactPattern pattern(pt, X_1W, rb1);
    const std::vector<double>& part_angles = sa.part_ring()->part_angles_rad;
    auto add = [&](int part, const Vec3& p_W) {
      const int tooth = static_cast<int>(std::lround(part_angles[part] * z1 / (2 * kPi))) % static_cast<int>(z1);
      pattern.Add(tooth, p_W);
    };
    for (const NodeGap& g : ws.gaps_a)
      if (g.gap < 0 && g.on_surface) add(PartOf(sa.part_vertex_start(), g.node), g.p_W);
    for (const NodeGap& g : ws.gaps_b)
      if (g.gap < 0 && g.on_surface) add(PartOf(sa.part_triangle_start(), g.face), g.q_W);
    sweep.points.push_back(pt);
  }
  // Mean stiffness and TE peak to peak.
  double sum = 0, te_min = 1e300, te_max = -1e300;
  for (const MeshSweepPoint& p : sweep.points) {
    sum += p.stiffness_n_per_m;
    te_min = std::min(te_min, p.transmission_error_m);
    te_max = std::max(te_max, p.transmission_error_m);
  }
  sweep.mean_stiffness_n_per_m = sum / points;
  sweep.te_peak_to_peak_m = te_max - te_min;
  sweep.searches = ws.search.stats().searches;
  return sweep;
}

void ContactPattern::Add(int tooth, const Vec3& p_W) {
  const Vec3 p = X_1W_ * p_W;
  const double r = std::hypot(p.x(), p.y());
  const double s = r > rb1_ ? std::sqrt(r * r - rb1_ * rb1_) : 0.0;
  int k = 0;
  while (k < 3 && teeth_[k] != tooth && teeth_[k] >= 0) ++k;
  if (k == 3) return;
  if (teeth_[k] < 0) {
    teeth_[k] = tooth;
    point_.teeth[k] = tooth;
    point_.pattern_min_m[k] = point_.pattern_max_m[k] = s;
    ++point_.teeth_in_contact;
  }
  point_.pattern_min_m[k] = std::min(point_.pattern_min_m[k], s);
  point_.pattern_max_m[k] = std::max(point_.pattern_max_m[k], s);
}

}  // namespace orrery::gears

#include "models/planetary_train.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "models/planetary_kinematics.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
// Tolerance on "integer" tooth counts from angles given in radians (double rounding only).
constexpr double kIntegerTolerance = 1e-6;

[[noreturn]] void Fail(const std::string& msg) { throw std::invalid_argument(msg); }

std::string Num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// Radii used by the geometric checks: the gear's own, or those of a standard spur gear of module 1.
struct CheckRadii {
  double pitch = 0, tip = 0;
};

CheckRadii RadiiForChecks(const TrainGear& g) {
  if (g.has_tooth_form) return {g.pitch_radius_m, g.tip_radius_m};
  const double r = 0.5 * g.teeth;
  return {r, g.internal ? r - 1.0 : r + 1.0};
}

bool SameToothForm(const ToothForm& a, const ToothForm& b) {
  auto close = [](double x, double y) { return std::abs(x - y) <= 1e-12 * std::max(1.0, std::abs(x)); };
  return close(a.normal_module_m, b.normal_module_m) &&
         close(a.normal_pressure_angle_rad, b.normal_pressure_angle_rad) &&
         close(std::abs(a.helix_angle_rad), std::abs(b.helix_angle_rad));
}

// Planet angles: equal spacing if none are given, after the assembly condition(s) "T psi / 2 pi
// integer" for every tooth sum T in `sums` (each with its formula text for the message).
std::vector<double> PlanetAngles(const std::string& stage, int n, const std::vector<double>& given,
                                 const std::vector<std::pair<int, std::string>>& sums) {
  for (const auto& [t, formula] : sums)
    if (t <= 0) Fail("stage '" + stage + "': " + formula + " = " + std::to_string(t) +
                     " must be positive");
  // Equal spacing: every T / n must be an integer.
  if (given.empty()) {
    for (const auto& [t, formula] : sums)
      if (t % n != 0)
        Fail("stage '" + stage + "': " + std::to_string(n) +
             " planets cannot be equally spaced: (" + formula + ")/n = " + std::to_string(t) +
             "/" + std::to_string(n) + " = " + Num(static_cast<double>(t) / n) +
             " is not an integer; give planet_angles_rad (see AssemblablePlanetAngles)");
    std::vector<double> angles(n);
    for (int i = 0; i < n; ++i) angles[i] = 2.0 * kPi * i / n;
    return angles;
  }
  // Explicit angles: T (psi_i - psi_0) / 2 pi must be an integer for every planet.
  if (static_cast<int>(given.size()) != n)
    Fail("stage '" + stage + "': " + std::to_string(given.size()) + " planet angles for " +
         std::to_string(n) + " planets");
  for (int i = 1; i < n; ++i)
    for (const auto& [t, formula] : sums) {
      const double x = t * (given[i] - given[0]) / (2.0 * kPi);
      if (std::abs(x - std::round(x)) > kIntegerTolerance)
        Fail("stage '" + stage + "': planet " + std::to_string(i) + " at " +
             Num(given[i] * 180.0 / kPi) + " deg cannot be assembled: (" + formula +
             ") (psi_i - psi_0) / 2 pi = " + Num(x) + " is not an integer");
    }
  return given;
}

// One planet circle on the carrier for the overlap check.
struct PlanetCircle {
  std::string name;
  int branch = 0;
  double x = 0, y = 0, tip = 0;
};

// Tip circles of planets that do not mesh each other must not intersect.
void CheckOverlap(const std::string& stage, const std::vector<PlanetCircle>& circles,
                  const std::vector<std::pair<std::string, std::string>>& meshing_kinds) {
  auto mesh = [&](const PlanetCircle& a, const PlanetCircle& b) {
    if (a.branch != b.branch) return false;
    for (const auto& [u, v] : meshing_kinds)
      if ((a.name == u && b.name == v) || (a.name == v && b.name == u)) return true;
    return false;
  };
  for (size_t i = 0; i < circles.size(); ++i)
    for (size_t j = i + 1; j < circles.size(); ++j) {
      const PlanetCircle& a = circles[i];
      const PlanetCircle& b = circles[j];
      if (mesh(a, b)) continue;
      const double d = std::hypot(a.x - b.x, a.y - b.y);
      if (d < a.tip + b.tip)
        Fail("stage '" + stage + "': planets overlap: " + a.name + " " + std::to_string(a.branch) +
             " and " + b.name + " " + std::to_string(b.branch) + " have centre distance " +
             Num(d) + " < sum of tip radii " + Num(a.tip + b.tip) +
             " (units of m, or of the module without tooth form)");
    }
}

// Angle between the two planets of a branch seen from the axis, from the triangle of centre
// distances (law of cosines).
double BranchAngle(const std::string& stage, double r1, double r2, double d) {
  const double c = (r1 * r1 + r2 * r2 - d * d) / (2.0 * r1 * r2);
  if (!(r1 > 0 && r2 > 0) || std::abs(c) > 1.0)
    Fail("stage '" + stage + "': the planet pair cannot mesh: pin radii " + Num(r1) + " and " +
         Num(r2) + " with centre distance " + Num(d) + " do not form a triangle");
  return std::acos(c);
}

// Runs f on the draft; on a throw restores the draft so a failed Add* leaves no trace.
template <class F>
int Transaction(PlanetaryTrain& train, F&& f) {
  PlanetaryTrain backup = train;
  try {
    return f();
  } catch (...) {
    train = std::move(backup);
    throw;
  }
}

}  // namespace

const char* StageTypeName(StageType type) {
  switch (type) {
    case StageType::kSinglePlanet: return "single-planet";
    case StageType::kDoublePlanet: return "double-planet";
    case StageType::kRavigneaux: return "Ravigneaux";
  }
  return "?";
}

const char* MemberKindName(MemberKind kind) {
  switch (kind) {
    case MemberKind::kSun: return "sun";
    case MemberKind::kRing: return "ring";
    case MemberKind::kCarrier: return "carrier";
  }
  return "?";
}

template <class Map>
static int LookUp(const Map& map, const char* kind, const std::string& name) {
  const auto it = map.find(name);
  if (it == map.end()) throw std::out_of_range(std::string("no ") + kind + " named '" + name + "'");
  return it->second;
}

int PlanetaryTrain::MemberIndex(const std::string& name) const {
  return LookUp(member_by_name, "member", name);
}
int PlanetaryTrain::RangeIndex(const std::string& name) const {
  return LookUp(range_by_name, "gear range", name);
}
int PlanetaryTrain::MeshIndex(const std::string& name) const {
  return LookUp(mesh_by_name, "mesh", name);
}
int PlanetaryTrain::PlanetSetIndex(const std::string& name) const {
  return LookUp(planet_set_by_name, "planet set", name);
}
const std::string& PlanetaryTrain::SpeedName(int i) const {
  return i < num_members() ? members.at(i).name : planet_sets.at(i - num_members()).name;
}

std::vector<double> AssemblablePlanetAngles(int tooth_sum, int num_planets) {
  if (num_planets < 1 || tooth_sum < num_planets)
    Fail("AssemblablePlanetAngles: tooth sum " + std::to_string(tooth_sum) + " < " +
         std::to_string(num_planets) + " planets");
  std::vector<double> angles(num_planets);
  for (int i = 0; i < num_planets; ++i) {
    const long k = std::lround(static_cast<double>(i) * tooth_sum / num_planets);
    angles[i] = 2.0 * kPi * static_cast<double>(k) / tooth_sum;
  }
  return angles;
}

PlanetaryTrainBuilder::PlanetaryTrainBuilder() : train_(std::make_unique<PlanetaryTrain>()) {}
PlanetaryTrainBuilder::~PlanetaryTrainBuilder() = default;
PlanetaryTrainBuilder::PlanetaryTrainBuilder(PlanetaryTrainBuilder&&) noexcept = default;
PlanetaryTrainBuilder& PlanetaryTrainBuilder::operator=(PlanetaryTrainBuilder&&) noexcept = default;

int PlanetaryTrainBuilder::NewStage(const std::string& name, StageType type, int num_planets) {
  if (name.empty() || name.find('.') != std::string::npos)
    Fail("stage name '" + name + "' must be non-empty and without '.'");
  for (const Stage& s : train_->stages)
    if (s.name == name) Fail("duplicate stage name '" + name + "'");
  if (num_planets < 1)
    Fail("stage '" + name + "': num_planets = " + std::to_string(num_planets) + " must be >= 1");
  Stage s;
  s.name = name;
  s.type = type;
  s.num_planets = num_planets;
  train_->stages.push_back(s);
  return static_cast<int>(train_->stages.size()) - 1;
}

int PlanetaryTrainBuilder::AddGear(int stage, const std::string& suffix, const TrainGearSpec& spec,
                                   bool internal, const std::optional<ToothForm>& stage_form) {
  const std::string name = train_->stages[stage].name + "." + suffix;
  if (spec.teeth < 1) Fail("gear '" + name + "': teeth = " + std::to_string(spec.teeth) + " < 1");
  TrainGear g;
  g.name = name;
  g.stage = stage;
  g.teeth = spec.teeth;
  g.internal = internal;
  const std::optional<ToothForm>& form = spec.tooth_form ? spec.tooth_form : stage_form;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  g.transverse_module_m = g.pitch_radius_m = g.base_radius_m = g.tip_radius_m = nan;
  g.transverse_pressure_angle_rad = nan;
  if (form) {
    const ToothForm& f = *form;
    if (!(f.normal_module_m > 0))
      Fail("gear '" + name + "': normal module " + Num(f.normal_module_m) + " m must be > 0");
    if (!(f.normal_pressure_angle_rad > 0 && f.normal_pressure_angle_rad < kPi / 2))
      Fail("gear '" + name + "': pressure angle " + Num(f.normal_pressure_angle_rad) +
           " rad outside (0, pi/2)");
    if (!(std::abs(f.helix_angle_rad) < kPi / 2))
      Fail("gear '" + name + "': helix angle " + Num(f.helix_angle_rad) + " rad outside (-pi/2, pi/2)");
    // Reference geometry: m_t = m_n / cos(beta), r = m_t z / 2, alpha_t, r_b = r cos(alpha_t).
    g.has_tooth_form = true;
    g.tooth_form = f;
    const double cb = std::cos(f.helix_angle_rad);
    g.transverse_module_m = f.normal_module_m / cb;
    g.pitch_radius_m = 0.5 * g.transverse_module_m * spec.teeth;
    g.transverse_pressure_angle_rad = std::atan(std::tan(f.normal_pressure_angle_rad) / cb);
    g.base_radius_m = g.pitch_radius_m * std::cos(g.transverse_pressure_angle_rad);
    const double addendum = f.addendum_coefficient * f.normal_module_m;
    g.tip_radius_m = internal ? g.pitch_radius_m - addendum : g.pitch_radius_m + addendum;
  }
  if (spec.tip_radius_m > 0) {
    g.tip_radius_m = spec.tip_radius_m;
    g.tip_given = true;
  }
  train_->gears.push_back(g);
  return static_cast<int>(train_->gears.size()) - 1;
}

int PlanetaryTrainBuilder::AddMember(int stage, const std::string& suffix, MemberKind kind,
                                     int gear) {
  Member m;
  m.name = train_->stages[stage].name + "." + suffix;
  m.stage = stage;
  m.kind = kind;
  m.gear = gear;
  const int index = static_cast<int>(train_->members.size());
  train_->members.push_back(m);
  train_->member_by_name[m.name] = index;
  train_->stages[stage].members.push_back(index);
  if (kind == MemberKind::kCarrier) train_->stages[stage].carrier = index;
  if (gear >= 0) train_->gears[gear].member = index;
  return index;
}

int PlanetaryTrainBuilder::AddPlanetSet(int stage, const std::string& suffix, int gear,
                                        int num_meshes) {
  PlanetSet p;
  p.name = train_->stages[stage].name + "." + suffix;
  p.stage = stage;
  p.gear = gear;
  p.num_meshes = num_meshes;
  const int index = static_cast<int>(train_->planet_sets.size());
  train_->planet_sets.push_back(p);
  train_->planet_set_by_name[p.name] = index;
  train_->stages[stage].planet_sets.push_back(index);
  train_->gears[gear].planet_set = index;
  return index;
}

int PlanetaryTrainBuilder::AddMesh(int stage, MeshKind kind, int gear_a, int gear_b) {
  const TrainGear& a = train_->gears[gear_a];
  const TrainGear& b = train_->gears[gear_b];
  // Gears in mesh share the tooth form (or both lack one).
  if (a.has_tooth_form != b.has_tooth_form)
    Fail("mesh of '" + a.name + "' and '" + b.name + "': only one of them has a tooth form");
  if (a.has_tooth_form && !SameToothForm(a.tooth_form, b.tooth_form))
    Fail("mesh of '" + a.name + "' and '" + b.name +
         "': normal module, pressure angle or |helix angle| differ");
  TrainMesh m;
  const std::string short_a = a.name.substr(a.name.find('.') + 1);
  const std::string short_b = b.name.substr(b.name.find('.') + 1);
  m.name = train_->stages[stage].name + "." + short_a + "-" + short_b;
  m.stage = stage;
  m.kind = kind;
  m.gear_a = gear_a;
  m.gear_b = gear_b;
  const int index = static_cast<int>(train_->meshes.size());
  train_->meshes.push_back(m);
  train_->mesh_by_name[m.name] = index;
  train_->stages[stage].meshes.push_back(index);
  return index;
}

int PlanetaryTrainBuilder::AddSinglePlanetStage(const SinglePlanetStageSpec& spec) {
  return Transaction(*train_, [&] {
  const int n = spec.num_planets;
  const int st = NewStage(spec.name, StageType::kSinglePlanet, n);
    // Gears, members, planet set, meshes s-p and r-p.
    const int gs = AddGear(st, "sun", spec.sun, false, spec.tooth_form);
    const int gp = AddGear(st, "planet", spec.planet, false, spec.tooth_form);
    const int gr = AddGear(st, "ring", spec.ring, true, spec.tooth_form);
    if (spec.ring.teeth <= spec.planet.teeth)
      Fail("stage '" + spec.name + "': ring teeth " + std::to_string(spec.ring.teeth) +
           " must exceed planet teeth " + std::to_string(spec.planet.teeth));
    AddMember(st, "sun", MemberKind::kSun, gs);
    AddMember(st, "ring", MemberKind::kRing, gr);
    AddMember(st, "carrier", MemberKind::kCarrier, -1);
    const int ps = AddPlanetSet(st, "planet", gp, 2);
    AddMesh(st, MeshKind::kExternal, gs, gp);
    AddMesh(st, MeshKind::kInternal, gr, gp);
    // Assembly condition (Z_s + Z_r) psi / 2 pi integer.
    PlanetSet& p = train_->planet_sets[ps];
    p.angles_rad = PlanetAngles(spec.name, n, spec.planet_angles_rad,
                                {{spec.sun.teeth + spec.ring.teeth, "Z_s + Z_r"}});
    // Pin circle and planet overlap.
    const CheckRadii rs = RadiiForChecks(train_->gears[gs]);
    const CheckRadii rp = RadiiForChecks(train_->gears[gp]);
    p.center_radius_m = spec.pin_radius_m > 0 ? spec.pin_radius_m : rs.pitch + rp.pitch;
    std::vector<PlanetCircle> circles;
    for (int i = 0; i < n; ++i)
      circles.push_back({"planet", i, p.center_radius_m * std::cos(p.angles_rad[i]),
                         p.center_radius_m * std::sin(p.angles_rad[i]), rp.tip});
    CheckOverlap(spec.name, circles, {});
    return st;
  });
}

int PlanetaryTrainBuilder::AddDoublePlanetStage(const DoublePlanetStageSpec& spec) {
  return Transaction(*train_, [&] {
  const int n = spec.num_planets;
  const int st = NewStage(spec.name, StageType::kDoublePlanet, n);
  // Gears, members, planet sets, meshes s-b, b-d, r-d.
  const int gs = AddGear(st, "sun", spec.sun, false, spec.tooth_form);
  const int gb = AddGear(st, "inner", spec.inner_planet, false, spec.tooth_form);
  const int gd = AddGear(st, "outer", spec.outer_planet, false, spec.tooth_form);
  const int gr = AddGear(st, "ring", spec.ring, true, spec.tooth_form);
  if (spec.ring.teeth <= spec.outer_planet.teeth)
    Fail("stage '" + spec.name + "': ring teeth " + std::to_string(spec.ring.teeth) +
         " must exceed outer planet teeth " + std::to_string(spec.outer_planet.teeth));
  AddMember(st, "sun", MemberKind::kSun, gs);
  AddMember(st, "ring", MemberKind::kRing, gr);
  AddMember(st, "carrier", MemberKind::kCarrier, -1);
  const int pb = AddPlanetSet(st, "inner", gb, 2);
  const int pd = AddPlanetSet(st, "outer", gd, 2);
  AddMesh(st, MeshKind::kExternal, gs, gb);
  AddMesh(st, MeshKind::kExternal, gb, gd);
  AddMesh(st, MeshKind::kInternal, gr, gd);
  // Assembly condition (Z_r - Z_s) psi / 2 pi integer.
  const std::vector<double> angles =
      PlanetAngles(spec.name, n, spec.planet_angles_rad,
                   {{spec.ring.teeth - spec.sun.teeth, "Z_r - Z_s"}});
  // Pin circles and the branch angle between inner and outer planet.
  const CheckRadii rs = RadiiForChecks(train_->gears[gs]);
  const CheckRadii rb = RadiiForChecks(train_->gears[gb]);
  const CheckRadii rd = RadiiForChecks(train_->gears[gd]);
  const CheckRadii rr = RadiiForChecks(train_->gears[gr]);
  PlanetSet& inner = train_->planet_sets[pb];
  PlanetSet& outer = train_->planet_sets[pd];
  inner.center_radius_m = rs.pitch + rb.pitch;
  outer.center_radius_m = rr.pitch - rd.pitch;
  const double phi =
      BranchAngle(spec.name, inner.center_radius_m, outer.center_radius_m, rb.pitch + rd.pitch);
  inner.angles_rad = angles;
  outer.angles_rad = angles;
  for (double& a : outer.angles_rad) a += phi;
  // Overlap of every planet pair that does not mesh.
  std::vector<PlanetCircle> circles;
  for (int i = 0; i < n; ++i) {
    circles.push_back({"inner", i, inner.center_radius_m * std::cos(inner.angles_rad[i]),
                       inner.center_radius_m * std::sin(inner.angles_rad[i]), rb.tip});
    circles.push_back({"outer", i, outer.center_radius_m * std::cos(outer.angles_rad[i]),
                       outer.center_radius_m * std::sin(outer.angles_rad[i]), rd.tip});
  }
  CheckOverlap(spec.name, circles, {{"inner", "outer"}});
  return st;
  });
}

int PlanetaryTrainBuilder::AddRavigneauxStage(const RavigneauxStageSpec& spec) {
  return Transaction(*train_, [&] {
  const int n = spec.num_planets;
  const int st = NewStage(spec.name, StageType::kRavigneaux, n);
  // Gears, members, planet sets, meshes s1-a, a-b, s2-b, r-b.
  const int g1 = AddGear(st, "sun1", spec.small_sun, false, spec.tooth_form);
  const int g2 = AddGear(st, "sun2", spec.large_sun, false, spec.tooth_form);
  const int ga = AddGear(st, "short", spec.short_planet, false, spec.tooth_form);
  const int gb = AddGear(st, "long", spec.long_planet, false, spec.tooth_form);
  const int gr = AddGear(st, "ring", spec.ring, true, spec.tooth_form);
  if (spec.ring.teeth <= spec.long_planet.teeth)
    Fail("stage '" + spec.name + "': ring teeth " + std::to_string(spec.ring.teeth) +
         " must exceed long planet teeth " + std::to_string(spec.long_planet.teeth));
  AddMember(st, "sun1", MemberKind::kSun, g1);
  AddMember(st, "sun2", MemberKind::kSun, g2);
  AddMember(st, "ring", MemberKind::kRing, gr);
  AddMember(st, "carrier", MemberKind::kCarrier, -1);
  const int pa = AddPlanetSet(st, "short", ga, 2);
  const int pb = AddPlanetSet(st, "long", gb, 3);
  AddMesh(st, MeshKind::kExternal, g1, ga);
  AddMesh(st, MeshKind::kExternal, ga, gb);
  AddMesh(st, MeshKind::kExternal, g2, gb);
  AddMesh(st, MeshKind::kInternal, gr, gb);
  // Assembly: s2-b-r is a single-planet set, s1-a-b-r a double-planet chain.
  const std::vector<double> angles = PlanetAngles(
      spec.name, n, spec.planet_angles_rad,
      {{spec.large_sun.teeth + spec.ring.teeth, "Z_s2 + Z_r"},
       {spec.ring.teeth - spec.small_sun.teeth, "Z_r - Z_s1"}});
  // Pin circles: long planet on s2, short planet on s1; branch angle from the a-b mesh.
  const CheckRadii r1 = RadiiForChecks(train_->gears[g1]);
  const CheckRadii r2 = RadiiForChecks(train_->gears[g2]);
  const CheckRadii ra = RadiiForChecks(train_->gears[ga]);
  const CheckRadii rb = RadiiForChecks(train_->gears[gb]);
  PlanetSet& shorts = train_->planet_sets[pa];
  PlanetSet& longs = train_->planet_sets[pb];
  longs.center_radius_m = r2.pitch + rb.pitch;
  shorts.center_radius_m = r1.pitch + ra.pitch;
  const double phi =
      BranchAngle(spec.name, shorts.center_radius_m, longs.center_radius_m, ra.pitch + rb.pitch);
  longs.angles_rad = angles;
  shorts.angles_rad = angles;
  for (double& a : shorts.angles_rad) a += phi;
  // Overlap of every planet pair that does not mesh.
  std::vector<PlanetCircle> circles;
  for (int i = 0; i < n; ++i) {
    circles.push_back({"short", i, shorts.center_radius_m * std::cos(shorts.angles_rad[i]),
                       shorts.center_radius_m * std::sin(shorts.angles_rad[i]), ra.tip});
    circles.push_back({"long", i, longs.center_radius_m * std::cos(longs.angles_rad[i]),
                       longs.center_radius_m * std::sin(longs.angles_rad[i]), rb.tip});
  }
  CheckOverlap(spec.name, circles, {{"short", "long"}});
  return st;
  });
}

void PlanetaryTrainBuilder::CheckNewName(const std::string& kind, const std::string& name) const {
  if (name.empty()) Fail(kind + " name must not be empty");
  if (connection_by_name_.count(name) || clutch_by_name_.count(name) || brake_by_name_.count(name))
    Fail(kind + " '" + name + "': name already used by a connection, clutch or brake");
}

int PlanetaryTrainBuilder::MemberByName(const std::string& what, const std::string& name) const {
  const auto it = train_->member_by_name.find(name);
  if (it == train_->member_by_name.end()) Fail(what + ": no member named '" + name + "'");
  return it->second;
}

int PlanetaryTrainBuilder::AddConnection(const std::string& name, const std::string& member_a,
                                         const std::string& member_b) {
  CheckNewName("connection", name);
  const int a = MemberByName("connection '" + name + "'", member_a);
  const int b = MemberByName("connection '" + name + "'", member_b);
  if (train_->members[a].stage == train_->members[b].stage)
    Fail("connection '" + name + "': " + member_a + " and " + member_b +
         " belong to the same stage (use a clutch)");
  train_->connections.push_back({name, a, b});
  connection_by_name_[name] = static_cast<int>(train_->connections.size()) - 1;
  return connection_by_name_[name];
}

int PlanetaryTrainBuilder::AddClutch(const std::string& name, const std::string& member_a,
                                     const std::string& member_b) {
  CheckNewName("clutch", name);
  const int a = MemberByName("clutch '" + name + "'", member_a);
  const int b = MemberByName("clutch '" + name + "'", member_b);
  if (a == b) Fail("clutch '" + name + "': joins " + member_a + " to itself");
  train_->clutches.push_back({name, a, b});
  clutch_by_name_[name] = static_cast<int>(train_->clutches.size()) - 1;
  return clutch_by_name_[name];
}

int PlanetaryTrainBuilder::AddBrake(const std::string& name, const std::string& member) {
  CheckNewName("brake", name);
  const int m = MemberByName("brake '" + name + "'", member);
  train_->brakes.push_back({name, m});
  brake_by_name_[name] = static_cast<int>(train_->brakes.size()) - 1;
  return brake_by_name_[name];
}

int PlanetaryTrainBuilder::AddRange(const std::string& name,
                                    const std::vector<std::string>& engaged) {
  if (name.empty() || train_->range_by_name.count(name))
    Fail("gear range '" + name + "': empty or duplicate name");
  GearRange r;
  r.name = name;
  for (const std::string& e : engaged) {
    if (auto c = clutch_by_name_.find(e); c != clutch_by_name_.end()) {
      if (std::find(r.clutches.begin(), r.clutches.end(), c->second) != r.clutches.end())
        Fail("gear range '" + name + "': clutch '" + e + "' listed twice");
      r.clutches.push_back(c->second);
    } else if (auto b = brake_by_name_.find(e); b != brake_by_name_.end()) {
      if (std::find(r.brakes.begin(), r.brakes.end(), b->second) != r.brakes.end())
        Fail("gear range '" + name + "': brake '" + e + "' listed twice");
      r.brakes.push_back(b->second);
    } else {
      Fail("gear range '" + name + "': no clutch or brake named '" + e + "'");
    }
  }
  train_->ranges.push_back(r);
  const int index = static_cast<int>(train_->ranges.size()) - 1;
  train_->range_by_name[name] = index;
  return index;
}

void PlanetaryTrainBuilder::AddInput(const std::string& member) {
  const int m = MemberByName("input", member);
  if (std::find(train_->inputs.begin(), train_->inputs.end(), m) != train_->inputs.end())
    Fail("input: member '" + member + "' is already an input");
  train_->inputs.push_back(m);
}

void PlanetaryTrainBuilder::SetOutput(const std::string& member) {
  train_->output = MemberByName("output", member);
}

std::shared_ptr<const PlanetaryTrain> PlanetaryTrainBuilder::Finalize() && {
  PlanetaryTrain& t = *train_;
  if (t.stages.empty()) Fail("planetary train: no stage");
  if (t.inputs.empty()) Fail("planetary train: no input member");
  if (t.output < 0) Fail("planetary train: no output member");
  if (std::find(t.inputs.begin(), t.inputs.end(), t.output) != t.inputs.end())
    Fail("planetary train: output '" + t.members[t.output].name + "' is also an input");
  if (t.ranges.empty()) Fail("planetary train: no gear range");
  // Speed indices: members first, then planet sets.
  for (TrainGear& g : t.gears)
    g.speed_index = g.member >= 0 ? g.member : t.num_members() + g.planet_set;
  // Every range must be kinematically determinate.
  for (int r = 0; r < static_cast<int>(t.ranges.size()); ++r) {
    const RangeAnalysis a = AnalyzeRange(t, r);
    if (!a.determinate) Fail(a.message);
  }
  std::shared_ptr<const PlanetaryTrain> out = std::move(train_);
  train_ = std::make_unique<PlanetaryTrain>();
  return out;
}

}  // namespace orrery::gears

#pragma once
// Planetary gear trains of N stages (seed 001, Inalpolat & Kahraman 2008, section 2.1): the data
// model shared by kinematics (planetary_kinematics.h), power flow (planetary_power_flow.h) and the
// dynamic models built on top of them.
//
// A `PlanetaryTrainBuilder` takes stages, connections, clutches, brakes, gear ranges, input and
// output members, validates each as it comes (tooth counts, planet spacing, planet overlap, names)
// and `Finalize()` checks that every gear range is kinematically determinate, then returns an
// immutable `PlanetaryTrain` of flat arrays and indices. Names live in the train for look-up and
// messages; the solvers work on indices.
//
// Stage types and their topology (n identical branches on one carrier c; every planet turns on a
// pin of c; "meshes" lists every gear contact of one branch):
//   single-planet (seed 001 Fig. 2a):  members sun s, ring r, carrier c; planet p.
//                                      meshes s-p (external), r-p (internal).
//   double-planet (seed 001 Fig. 2b):  members s, r, c; inner planet b, outer planet d.
//                                      meshes s-b (external), b-d (external), r-d (internal).
//   Ravigneaux (complex-compound, seed 001 Fig. 2c with one ring): members small sun s1, large
//                                      sun s2, ring r, carrier c; short planet a, long planet b.
//                                      meshes s1-a (external), a-b (external), s2-b (external),
//                                      r-b (internal). The long planet has one tooth count along
//                                      its length; it meets a and r in one axial section and s2
//                                      in the other. (The paper's variant with a second ring and a
//                                      third planet d is not modelled.)
//
// Speed vector (PlanetaryKinematics::speeds): the members first (index = member index), then one
// speed per planet set (index = num_members + planet set index): all n planets of a set turn alike.
//
// Geometry (optional per gear, from a ToothForm): transverse module m_t = m_n / cos(beta), pitch
// radius r = m_t z / 2, transverse pressure angle alpha_t = atan(tan(alpha_n) / cos(beta)), base
// radius r_b = r cos(alpha_t), tip radius r +- h_a* m_n (external +, internal -), reference
// values without profile shift. Planet centres sit on the pin circle: single-planet and the long
// planet of a Ravigneaux stage at r_s + r_p (or `pin_radius_m`), the outer planet of a double-
// planet stage at r_r - r_d, the short planet of a Ravigneaux stage at r_s1 + r_a; the partner
// planet of a branch is offset by the angle that closes the triangle of centre distances.
//
// Usage:
//   PlanetaryTrainBuilder b;
//   b.AddSinglePlanetStage({.name = "S1", .sun = {25}, .planet = {34}, .ring = {95},
//                           .num_planets = 3, .tooth_form = ToothForm{.normal_module_m = 0.010}});
//   b.AddBrake("B1", "S1.ring");
//   b.AddRange("low", {"B1"});
//   b.AddInput("S1.sun");
//   b.SetOutput("S1.carrier");
//   std::shared_ptr<const PlanetaryTrain> train = std::move(b).Finalize();
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace orrery::gears {

enum class StageType { kSinglePlanet, kDoublePlanet, kRavigneaux };
enum class MemberKind { kSun, kRing, kCarrier };
enum class MeshKind { kExternal, kInternal };

const char* StageTypeName(StageType type);
const char* MemberKindName(MemberKind kind);

// Tooth form of an involute gear (reference rack values; no profile shift).
struct ToothForm {
  double normal_module_m = 0;                       // m_n > 0
  double normal_pressure_angle_rad = 0.3490658503988659;  // alpha_n, 20 deg
  double helix_angle_rad = 0;                       // beta, 0 for spur gears
  double addendum_coefficient = 1.0;                // h_a*, tip = pitch +- h_a* m_n
};

// One gear as given to the builder: tooth count and optional tooth form (falls back to the
// stage's). tip_radius_m > 0 overrides the computed tip radius (e.g. a measured outside diameter).
struct TrainGearSpec {
  int teeth = 0;
  std::optional<ToothForm> tooth_form;
  double tip_radius_m = 0;
};

// Planet positions: empty `planet_angles_rad` means n equally spaced planets (angle 2 pi i / n),
// which requires the assembly condition of the stage (see PlanetaryTrainBuilder). Explicit angles
// (n of them, the first planet of each branch) must satisfy the same condition planet by planet;
// AssemblablePlanetAngles() gives the valid angles nearest to equal spacing.
struct SinglePlanetStageSpec {
  std::string name;
  TrainGearSpec sun, planet, ring;
  int num_planets = 3;
  std::optional<ToothForm> tooth_form;     // for gears without their own
  std::vector<double> planet_angles_rad;   // empty: equally spaced
  double pin_radius_m = 0;                 // 0: r_s + r_p
};

struct DoublePlanetStageSpec {
  std::string name;
  TrainGearSpec sun, inner_planet, outer_planet, ring;  // s-b, b-d, d-r
  int num_planets = 3;                              // branches (pairs)
  std::optional<ToothForm> tooth_form;
  std::vector<double> planet_angles_rad;            // of the inner planets
};

struct RavigneauxStageSpec {
  std::string name;
  TrainGearSpec small_sun, large_sun, short_planet, long_planet, ring;  // s1-a, a-b, s2-b, r-b
  int num_planets = 3;                                              // branches (a, b pairs)
  std::optional<ToothForm> tooth_form;
  std::vector<double> planet_angles_rad;                            // of the long planets
};

// ---- The finalized train. Every field is filled by PlanetaryTrainBuilder (Add* / Finalize). ----

// A gear (central gear or planet) with its derived geometry.
struct TrainGear {
  std::string name;          // "<stage>.sun", "<stage>.planet", ...
  int stage = -1;
  int teeth = 0;
  bool internal = false;     // ring gears
  bool has_tooth_form = false;
  ToothForm tooth_form;      // valid if has_tooth_form
  // Geometry in metres/radians, NaN without tooth form (tip_radius_m also set by TrainGearSpec).
  double transverse_module_m = 0, pitch_radius_m = 0, base_radius_m = 0, tip_radius_m = 0;
  double transverse_pressure_angle_rad = 0;
  bool tip_given = false;    // tip_radius_m from TrainGearSpec (a measured outside diameter)
  int member = -1;           // central gear: index into members; planet: -1
  int planet_set = -1;       // planet: index into planet_sets; central gear: -1
  int speed_index = -1;      // index into the speed vector
};

// A central member (sun, ring or carrier): what connections, clutches, brakes and ports attach to.
struct Member {
  std::string name;          // "<stage>.sun", "<stage>.sun1", "<stage>.sun2", "<stage>.ring",
                             // "<stage>.carrier"
  int stage = -1;
  MemberKind kind = MemberKind::kSun;
  int gear = -1;             // index into gears; -1 for the carrier
};

// The n identical planets of one kind in one stage (one per branch).
struct PlanetSet {
  std::string name;          // "<stage>.planet" | ".inner" | ".outer" | ".short" | ".long"
  int stage = -1;
  int gear = -1;             // index into gears
  double center_radius_m = 0;            // pin circle radius (module units without tooth form)
  std::vector<double> angles_rad;        // (n) planet centre angles on the carrier
  int num_meshes = 0;                    // meshes of one planet (local fault hits per turn)
};

// One gear contact of a branch (repeated on the n branches). gear_b is always a planet; gear_a is
// a central gear or (planet-planet mesh) the other planet. Kinematic row (seed 001 eqs. 1-2):
//   external: Z_a w_a + Z_b w_b - (Z_a + Z_b) w_c = 0
//   internal: Z_a w_a - Z_b w_b - (Z_a - Z_b) w_c = 0     (a = ring)
struct TrainMesh {
  std::string name;          // "<stage>.sun-planet", ...
  int stage = -1;
  MeshKind kind = MeshKind::kExternal;
  int gear_a = -1, gear_b = -1;  // indices into gears
};

struct Stage {
  std::string name;
  StageType type = StageType::kSinglePlanet;
  int num_planets = 0;           // branches n
  int carrier = -1;              // member index
  std::vector<int> members;      // central members of the stage (suns, ring, carrier)
  std::vector<int> planet_sets;
  std::vector<int> meshes;
};

// A rigid joint of two members: a connection (always engaged; members of different stages) or a
// clutch (engaged in the ranges that list it).
struct Coupling {
  std::string name;
  int member_a = -1, member_b = -1;
};

// Holds a member to ground when engaged.
struct Brake {
  std::string name;
  int member = -1;
};

// A gear range: the clutches and brakes engaged (a row of the clutching schedule, seed 001 Fig. 4).
struct GearRange {
  std::string name;
  std::vector<int> clutches;  // indices into clutches
  std::vector<int> brakes;    // indices into brakes
};

struct PlanetaryTrain {
  std::vector<Stage> stages;
  std::vector<Member> members;
  std::vector<TrainGear> gears;
  std::vector<PlanetSet> planet_sets;
  std::vector<TrainMesh> meshes;
  std::vector<Coupling> connections;
  std::vector<Coupling> clutches;
  std::vector<Brake> brakes;
  std::vector<GearRange> ranges;
  std::vector<int> inputs;   // members with given speed (1 for a reducer, 2 for a differential)
  int output = -1;           // member

  int num_members() const { return static_cast<int>(members.size()); }
  int num_speeds() const { return static_cast<int>(members.size() + planet_sets.size()); }
  // Index look-ups; throw std::out_of_range naming the missing name.
  int MemberIndex(const std::string& name) const;
  int RangeIndex(const std::string& name) const;
  int MeshIndex(const std::string& name) const;
  int PlanetSetIndex(const std::string& name) const;
  // Name of entry i of the speed vector (member or planet set).
  const std::string& SpeedName(int i) const;

  std::unordered_map<std::string, int> member_by_name, range_by_name, mesh_by_name,
      planet_set_by_name;
};

// Planet angles 2 pi k_i / T with k_i = round(i T / n), i = 0..n-1: the assemblable positions
// nearest to equal spacing for a stage whose assembly condition reads "T psi / 2 pi integer"
// (T = Z_s + Z_r single-planet, Z_r - Z_s double-planet). Throws std::invalid_argument if T < n.
std::vector<double> AssemblablePlanetAngles(int tooth_sum, int num_planets);

// Builds and validates a train. Every Add* throws std::invalid_argument with a message naming the
// element and the offending value. Checks per stage:
//   - tooth counts >= 1 (planets >= 1 branch); gears in mesh share m_n, alpha_n, |beta|;
//   - equal spacing: (Z_s + Z_r)/n integer (single-planet), (Z_r - Z_s)/n integer (double-planet),
//     both (Z_s2 + Z_r)/n and (Z_r - Z_s1)/n (Ravigneaux); explicit angles psi_i - psi_0 must make
//     the same tooth sums times (psi_i - psi_0)/(2 pi) integers;
//   - no two planets of different branches (or of different kinds that do not mesh) whose tip
//     circles intersect (module 1, alpha_n 20 deg, beta 0 assumed for gears without tooth form);
//   - double-planet / Ravigneaux: the triangle of centre distances of a branch must close.
class PlanetaryTrainBuilder {
 public:
  PlanetaryTrainBuilder();
  ~PlanetaryTrainBuilder();
  PlanetaryTrainBuilder(PlanetaryTrainBuilder&&) noexcept;
  PlanetaryTrainBuilder& operator=(PlanetaryTrainBuilder&&) noexcept;

  // Return the stage index. Members are named "<stage>.sun", ".ring", ".carrier" (Ravigneaux:
  // ".sun1" small, ".sun2" large, ".ring", ".carrier").
  int AddSinglePlanetStage(const SinglePlanetStageSpec& spec);
  int AddDoublePlanetStage(const DoublePlanetStageSpec& spec);
  int AddRavigneauxStage(const RavigneauxStageSpec& spec);

  // A permanent rigid connection (shaft) between members of two different stages.
  int AddConnection(const std::string& name, const std::string& member_a,
                    const std::string& member_b);
  // A clutch between two distinct members (same stage allowed: a lock-up clutch).
  int AddClutch(const std::string& name, const std::string& member_a, const std::string& member_b);
  int AddBrake(const std::string& name, const std::string& member);
  // A gear range engaging the named clutches and brakes.
  int AddRange(const std::string& name, const std::vector<std::string>& engaged);
  // Members with a given speed (called once per input, in the order of the input speed vector).
  void AddInput(const std::string& member);
  void SetOutput(const std::string& member);

  const PlanetaryTrain& draft() const { return *train_; }

  // Requires >= 1 stage, >= 1 input, an output that is not an input, >= 1 range; checks that every
  // range is kinematically determinate (AnalyzeRange in planetary_kinematics.h) and throws
  // std::invalid_argument naming the range and the free or conflicting members otherwise.
  // The builder is consumed.
  std::shared_ptr<const PlanetaryTrain> Finalize() &&;

 private:
  int AddMember(int stage, const std::string& suffix, MemberKind kind, int gear);
  int AddGear(int stage, const std::string& suffix, const TrainGearSpec& spec, bool internal,
              const std::optional<ToothForm>& stage_form);
  int AddPlanetSet(int stage, const std::string& suffix, int gear, int num_meshes);
  int AddMesh(int stage, MeshKind kind, int gear_a, int gear_b);
  int NewStage(const std::string& name, StageType type, int num_planets);
  int MemberByName(const std::string& what, const std::string& name) const;
  void CheckNewName(const std::string& kind, const std::string& name) const;

  std::unique_ptr<PlanetaryTrain> train_;
  std::unordered_map<std::string, int> clutch_by_name_, brake_by_name_, connection_by_name_;
};

}  // namespace orrery::gears

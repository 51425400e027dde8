// Stage 5 of BuildTrainModel: the meshes, stage by stage. Per stage the loaded flanks, working
// pressure angles and phases of its meshes (train_dynamics.h, "Loaded flank", "Mesh phasing");
// per mesh its lumped parameters where a branch is lumped (stiffness from its source, TVMS tables
// with faults, damping, transmission error); then per branch the element of its mesh model:
// a lumped GearMeshSpec, a kinematic GearConstraintSpec, or tooth contact
// (train_contact_meshes.cpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include <Eigen/Dense>

#include "mbd/constraints.h"
#include "mbd/kinematics.h"
#include "models/train_assembly.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

// Half the base-circle tooth angle of a gear of standard tooth thickness (s = pi m_t / 2 at the
// reference circle, no profile shift): theta_b = s / (2 r) + inv(alpha_t) = pi / (2 Z) + inv.
double HalfBaseToothAngle(const TrainGear& g, double alpha_w) {
  const double alpha_t = g.has_tooth_form ? g.transverse_pressure_angle_rad : alpha_w;
  return kPi / (2.0 * g.teeth) + Involute(alpha_t);
}

// Periodic linear interpolation of TVMS samples at gear-1 cycles u.
double TvmsAt(const Tvms& t, int samples_per_cycle, double u) {
  const int n = static_cast<int>(t.stiffness_n_per_m.size());
  double x = std::fmod(u * samples_per_cycle, static_cast<double>(n));
  if (x < 0) x += n;
  const int i = std::min(static_cast<int>(x), n - 1);
  const double f = x - i;
  return (1 - f) * t.stiffness_n_per_m[i] + f * t.stiffness_n_per_m[(i + 1) % n];
}

const TrainMeshOverride& MeshOverrideOf(const TrainModelOptions& o, const std::string& name) {
  static const TrainMeshOverride kNone;
  const auto it = o.meshes.find(name);
  return it == o.meshes.end() ? kNone : it->second;
}

// What the meshes of one stage share: flanks, working pressure angles, whether the centre
// distance is consistent with the base radii, and the phases (meshes x branches).
struct StageMeshes {
  int stage = -1;
  std::vector<bool> drive;
  std::vector<double> alpha;
  std::vector<bool> geometric;
  std::vector<std::vector<double>> phases;
};

// Direction (rad, carrier frame) from gear g's centre to the pitch point of mesh m on branch i.
double PitchPointDirection(const PlanetaryTrain& train, const TrainMesh& m, int g, int i) {
  if (m.kind == MeshKind::kInternal) {
    const Vec3 c = TrainGearCentre(train, m.gear_b, i);  // the planet: P lies beyond it
    return std::atan2(c.y(), c.x());
  }
  const Vec3 d = TrainGearCentre(train, g == m.gear_a ? m.gear_b : m.gear_a, i) - TrainGearCentre(train, g, i);
  return std::atan2(d.y(), d.x());
}

// Polar angle (rad, carrier frame) of gear-frame tooth 0 of gear g on branch i at q = 0.
double ToothZeroAngle(const PlanetaryTrain& train, int g, int i) {
  const TrainGear& gear = train.gears[g];
  const double body = gear.planet_set >= 0 ? train.planet_sets[gear.planet_set].angles_rad[i] : 0.0;
  // A ring's frame is its branch-0 frame (one physical tooth numbering for every branch).
  return body + GearFrameRotation(train, g, gear.planet_set >= 0 ? i : 0);
}

// Phase (mod 1) of the centred-tooth configuration of spec gear a (train_dynamics.h, "Tooth
// faults": f_a = sigma Z_a (theta_ba - inv alpha_w) / 2 pi).
double CentredToothPhase(const TrainGear& ga, bool drive, double alpha_w) {
  return (drive ? 1.0 : -1.0) * ga.teeth * (HalfBaseToothAngle(ga, alpha_w) - Involute(alpha_w)) / (2 * kPi);
}

// The stage's reference phase (its first mesh, branch 0) with the gears' teeth where the
// assembler places their frames (train_dynamics.h, "Tooth faults").
double BodyFrameReferencePhase(const TrainAssembly& a, const StageMeshes& sm) {
  const PlanetaryTrain& train = a.train;
  const TrainMesh& m = train.meshes[train.stages[sm.stage].meshes[0]];
  const int ga = TrainSpecGears(m).first;
  const double chi = ToothZeroAngle(train, ga, 0), phi = PitchPointDirection(train, m, ga, 0);
  return Frac(train.gears[ga].teeth * (chi - phi) / (2 * kPi) + CentredToothPhase(train.gears[ga], sm.drive[0], sm.alpha[0]));
}

StageMeshes ResolveStageMeshes(const TrainAssembly& a, int si) {
  const PlanetaryTrain& train = a.train;
  const Stage& st = train.stages[si];
  StageMeshes sm;
  sm.stage = si;
  for (int mi : st.meshes) {
    const TrainMesh& m = train.meshes[mi];
    const auto [ga, gb] = TrainSpecGears(m);
    const TrainMeshOverride& ov = MeshOverrideOf(a.o, m.name);
    // Loaded flank: the mesh torque on spec gear a is Z_a lambda (external) or -Z_p lambda
    // (internal: a is the planet); drive when it is negative.
    const double lambda = a.tm.power_flow.mesh_loads_n_m(mi);
    const double t_a = (m.kind == MeshKind::kInternal ? -1.0 : 1.0) * train.gears[ga].teeth * lambda;
    bool d = !(t_a > 0);
    if (ov.contact) d = *ov.contact != GearMeshSpec::Contact::kLinearCoast;
    sm.drive.push_back(d);
    // Working pressure angle from the centre distance (profile-shifted or not) unless given.
    const double rba = a.GearParams(ga).base_radius_m, rbb = a.GearParams(gb).base_radius_m;
    const double dist = (TrainGearCentre(train, ga, 0) - TrainGearCentre(train, gb, 0)).norm();
    const double c = (m.kind == MeshKind::kInternal ? rbb - rba : rba + rbb) / dist;
    if (!ov.working_pressure_angle_rad && !(c > 0 && c < 1))
      FailTrain("mesh '" + m.name + "': base radii " + std::to_string(rba) + ", " + std::to_string(rbb) +
                " m do not fit the centre distance " + std::to_string(dist) + " m");
    sm.alpha.push_back(ov.working_pressure_angle_rad.value_or(std::acos(std::clamp(c, -1.0, 1.0))));
    sm.geometric.push_back(!ov.working_pressure_angle_rad);
  }
  sm.phases.assign(st.meshes.size(), std::vector<double>(st.num_planets, 0.0));
  const bool given = si < static_cast<int>(a.o.stage_phase_cycles.size());
  const double gamma = given ? a.o.stage_phase_cycles[si] : BodyFrameReferencePhase(a, sm);
  if (a.o.mesh_phasing) sm.phases = CalcStageMeshPhases(train, si, sm.drive, sm.alpha, gamma);
  else for (auto& row : sm.phases) std::fill(row.begin(), row.end(), Frac(gamma));
  return sm;
}

// A lumped mesh's parameters, shared by its lumped branches.
struct LumpedMesh {
  MeshStiffnessSource source = MeshStiffnessSource::kGiven;
  double k_mean = 0;                               // N/m
  std::vector<double> table;                       // one table for every branch, or
  std::vector<std::vector<double>> branch_tables;  // (branches) when a planet is faulted
  int fault_gear = -1;                             // faulted gear of the mesh, or -1
  int table_cycles = 1;
  bool loaded = false;
};

// Faults on a gear of mesh (a, b): (train gear, branch or -1 for every branch, fault).
struct MeshFault {
  int gear, branch;
  ToothFaultSpec spec;  // gear-frame tooth
};

std::vector<MeshFault> MeshFaults(const TrainAssembly& a, const TrainMesh& m, int ga, int gb) {
  std::vector<MeshFault> faults;
  for (size_t f = 0; f < a.o.tooth_faults.size(); ++f) {
    const int g = a.fault_gear[f];
    if (g != ga && g != gb) continue;
    faults.push_back({g, a.train.gears[g].planet_set >= 0 ? a.o.tooth_faults[f].branch : -1, a.o.tooth_faults[f].spec});
  }
  for (const MeshFault& f : faults)
    if (f.gear != faults[0].gear) FailTrain("mesh '" + m.name + "': faults on both of its gears are not supported");
  return faults;
}

// The mesh phase n_k (mod Z_G) at which gear-frame tooth k of gear g (a spec gear of stage mesh k
// of `sm`) reaches the pitch point on the loaded flank, on branch i whose phase at q = 0 is
// phase0 (train_dynamics.h, "Tooth faults").
int ToothArrivalPhase(const TrainAssembly& a, const StageMeshes& sm, int k, int g, int tooth, int i, double phase0) {
  const PlanetaryTrain& train = a.train;
  const TrainMesh& m = train.meshes[train.stages[sm.stage].meshes[k]];
  const auto [ga, gb] = TrainSpecGears(m);
  const int z = train.gears[g].teeth;
  // Phase per radian of g's turn relative to the carrier (MeshPhase in mbd/gear_mesh.cpp).
  const double rate = (g == ga ? 1.0 : m.kind == MeshKind::kInternal ? 1.0 : -1.0) * z / (2 * kPi);
  const double chi = ToothZeroAngle(train, g, i) + 2 * kPi * tooth / z;
  const double psi_c = phase0 + rate * (PitchPointDirection(train, m, g, i) - chi);
  const double f_a = CentredToothPhase(train.gears[ga], sm.drive[k], sm.alpha[k]);
  const double f = g == ga ? f_a : f_a - (sm.drive[k] ? 0.5 : -0.5);
  const long n = std::lround(psi_c - f);
  return static_cast<int>(((n % z) + z) % z);
}

// The TVMS table of one branch (-1: every branch) over `cycles` mesh cycles, samples at
// psi_j = j / samples_per_cycle read at u = u_P + sigma psi (train_dynamics.h), with the faults
// at their mesh-order teeth (the coast flank read backwards: the mirror image of a drive mesh,
// whose plus and minus flanks swap).
std::vector<double> TvmsTable(const TrainAssembly& a, const StageMeshes& sm, int k, const GearPair& pair,
                              int cycles, const std::vector<MeshFault>& faults, int branch, double phase0) {
  const int mi = a.train.stages[sm.stage].meshes[k];
  const auto [ga, gb] = TrainSpecGears(a.train.meshes[mi]);
  const int spc = a.o.tvms_samples_per_cycle;
  const bool drive = sm.drive[k];
  const double sigma = drive ? 1.0 : -1.0;
  TvmsOptions to = MakeTrainTvmsOptions(a.train, mi, a.o);
  to.samples_per_period = spc;
  to.periods = cycles;
  for (const MeshFault& f : faults) {
    if (f.branch >= 0 && f.branch != branch) continue;
    ToothFaultSpec spec = f.spec;
    // Physical order (tooth e reaches P at phase e) to CalcTvms' mesh order.
    const int e = ToothArrivalPhase(a, sm, k, f.gear, f.spec.tooth, std::max(branch, 0), phase0);
    spec.tooth = drive ? e : (cycles - e) % cycles;
    if (!drive) spec.flank = spec.flank == ToothFaultSpec::Flank::kPlus ? ToothFaultSpec::Flank::kMinus
                                                                        : ToothFaultSpec::Flank::kPlus;
    to.faults.emplace_back(f.gear == ga ? 1 : 2, spec);
  }
  const Tvms t = CalcTvms(pair, to);
  const double pb = pair.transverse_base_pitch_m();
  const double u_p = (pair.pitch_point_m() - pair.contact_start_m()) / pb -
                     0.5 * pair.face_width_m() * std::tan(pair.gear1().base_helix_angle_rad()) / pb;
  std::vector<double> tab(static_cast<size_t>(cycles) * spc);
  for (size_t j = 0; j < tab.size(); ++j) tab[j] = TvmsAt(t, spc, u_p + sigma * double(j) / spc);
  return tab;
}

LumpedMesh ResolveLumpedMesh(const TrainAssembly& a, const StageMeshes& sm, int k) {
  const PlanetaryTrain& train = a.train;
  const TrainModelOptions& o = a.o;
  const Stage& st = train.stages[sm.stage];
  const int mi = st.meshes[k];
  const TrainMesh& m = train.meshes[mi];
  const auto [ga, gb] = TrainSpecGears(m);
  const TrainMeshOverride& ov = MeshOverrideOf(o, m.name);
  LumpedMesh lm;
  // Mean stiffness: override, else one value for all, else c_gamma b; or from geometry.
  const double face = std::min(a.GearParams(ga).face_width_m, a.GearParams(gb).face_width_m);
  const bool given = ov.stiffness_n_per_m || ov.stiffness_table_n_per_m;
  lm.source = given ? MeshStiffnessSource::kGiven : ov.stiffness_source.value_or(o.mesh_stiffness_source);
  lm.k_mean = ov.stiffness_n_per_m ? *ov.stiffness_n_per_m
              : o.mesh_stiffness_n_per_m ? *o.mesh_stiffness_n_per_m
                                         : o.mesh_stiffness_per_face_width_n_per_m2 * face;
  lm.table = ov.stiffness_table_n_per_m.value_or(std::vector<double>{});
  const std::vector<MeshFault> faults = MeshFaults(a, m, ga, gb);
  const bool tvms = lm.source == MeshStiffnessSource::kTvms;
  if (!faults.empty() && !tvms)
    FailTrain("mesh '" + m.name + "': tooth faults on its lumped branches need 'mesh_stiffness: tvms' (the " +
              "time-varying stiffness over a turn of the faulty gear)");
  std::optional<GearPair> pair;
  if (lm.source != MeshStiffnessSource::kGiven) pair.emplace(MakeTrainGearPair(train, mi, o));
  for (const MeshFault& f : faults) {
    try {
      ValidateToothFault(f.gear == ga ? pair->gear1() : pair->gear2(), f.spec);
    } catch (const std::invalid_argument& e) {
      FailTrain("tooth fault on '" + train.gears[f.gear].name + "': " + e.what());
    }
  }
  if (lm.source == MeshStiffnessSource::kIso6336) lm.k_mean = CalcIso6336Stiffness(*pair, o.iso6336).c_gamma_alpha_n_per_m;
  if (lm.source == MeshStiffnessSource::kTvmsMean) lm.k_mean = CalcTvms(*pair, MakeTrainTvmsOptions(train, mi, o)).mean_n_per_m;
  lm.fault_gear = faults.empty() ? -1 : faults[0].gear;
  const int cycles = lm.fault_gear < 0 ? 1 : train.gears[lm.fault_gear].teeth;
  if (tvms) {
    if (lm.fault_gear >= 0 && train.gears[lm.fault_gear].planet_set >= 0) {
      for (int i = 0; i < st.num_planets; ++i)
        lm.branch_tables.push_back(TvmsTable(a, sm, k, *pair, cycles, faults, i, sm.phases[k][i]));
      lm.table = lm.branch_tables[0];
    } else {
      lm.table = TvmsTable(a, sm, k, *pair, cycles, faults, -1, sm.phases[k][0]);
    }
  }
  lm.loaded = a.tm.power_flow.mesh_loaded[mi];
  if (!lm.loaded) {
    lm.k_mean *= o.unloaded_mesh_stiffness_factor;
    for (double& x : lm.table) x *= o.unloaded_mesh_stiffness_factor;
    for (auto& t : lm.branch_tables)
      for (double& x : t) x *= o.unloaded_mesh_stiffness_factor;
  }
  if (!lm.table.empty()) {
    lm.k_mean = 0;
    for (double x : lm.table) lm.k_mean += x / lm.table.size();
  }
  if (!(lm.k_mean > 0)) FailTrain("mesh '" + m.name + "': stiffness must be > 0");
  if (ov.phase_cycles && static_cast<int>(ov.phase_cycles->size()) != st.num_planets)
    FailTrain("mesh '" + m.name + "': phase_cycles needs one phase per branch");
  lm.table_cycles = lm.fault_gear >= 0 ? cycles : ov.table_cycles.value_or(1);
  return lm;
}

// Base helix angle signed by gear a's hand (central external gears +, alternating across
// external meshes, a ring like its planet); 0 outside the spatial DOF set.
double SignedBaseHelix(const TrainAssembly& a, int ga) {
  const TrainGear& g = a.train.gears[ga];
  if (!a.spatial || !g.has_tooth_form || g.tooth_form.helix_angle_rad == 0) return 0;
  const double hand = (g.planet_set < 0) ? 1.0 : -1.0;
  return hand * std::atan(std::tan(std::abs(g.tooth_form.helix_angle_rad)) * std::cos(g.transverse_pressure_angle_rad));
}

// Phase of branch i: given, over Z_G cycles for a faulted central gear (one physical tooth meets
// every branch), else as derived.
double BranchPhase(const TrainAssembly& a, const StageMeshes& sm, int k, const LumpedMesh& lm, int i) {
  const PlanetaryTrain& train = a.train;
  const TrainMesh& m = train.meshes[train.stages[sm.stage].meshes[k]];
  const TrainMeshOverride& ov = MeshOverrideOf(a.o, m.name);
  if (ov.phase_cycles) return (*ov.phase_cycles)[i];
  if (lm.fault_gear < 0 || train.gears[lm.fault_gear].planet_set >= 0) return sm.phases[k][i];
  const auto [ga, gb] = TrainSpecGears(m);
  const int ps = train.gears[m.kind == MeshKind::kInternal ? ga : gb].planet_set;
  const double psi = train.planet_sets[ps].angles_rad[i] - train.planet_sets[ps].angles_rad[0];
  const double cycles = lm.table_cycles;
  const double p = std::fmod(sm.phases[k][0] - cycles * psi / (2 * kPi), cycles);
  return p < 0 ? p + cycles : p;
}

void AddLumpedMesh(TrainAssembly& a, const StageMeshes& sm, int k, const LumpedMesh& lm, int i) {
  const PlanetaryTrain& train = a.train;
  const TrainModelOptions& o = a.o;
  const int mi = train.stages[sm.stage].meshes[k];
  const TrainMesh& m = train.meshes[mi];
  const auto [ga, gb] = TrainSpecGears(m);
  const TrainMeshOverride& ov = MeshOverrideOf(o, m.name);
  const std::vector<double>& tab = lm.branch_tables.empty() ? lm.table : lm.branch_tables[i];
  const GearMeshSpec::Contact contact =
      o.two_sided_contact ? GearMeshSpec::Contact::kTwoSided
                          : (sm.drive[k] ? GearMeshSpec::Contact::kLinearDrive : GearMeshSpec::Contact::kLinearCoast);
  GearMeshSpec spec{
      .name = m.name + "#" + std::to_string(i + 1), .gear_a = a.GearMeshFrame(ga, i),
      .gear_b = a.GearMeshFrame(gb, i), .reference = a.b.body_frame(a.tm.member_bodies[train.stages[sm.stage].carrier]),
      .teeth_a = train.gears[ga].teeth, .teeth_b = train.gears[gb].teeth,
      .base_radius_a = a.GearParams(ga).base_radius_m, .base_radius_b = a.GearParams(gb).base_radius_m,
      .working_pressure_angle = sm.alpha[k], .base_helix_angle = SignedBaseHelix(a, ga),
      .internal_b = m.kind == MeshKind::kInternal,
      .contact = contact, .backlash = o.two_sided_contact ? ov.backlash_m.value_or(o.backlash_m) : 0.0,
      .stiffness = tab.empty() ? lm.k_mean : 0.0, .stiffness_table = tab,
      .table_cycles = lm.table_cycles,
      .phase_gear = lm.fault_gear == gb ? GearMeshSpec::PhaseGear::kB : GearMeshSpec::PhaseGear::kA,
      .phase = BranchPhase(a, sm, k, lm, i),
      .damping_ratio = ov.damping_ratio.value_or(o.mesh_damping_ratio),
      .ste_amplitudes = ov.ste_amplitudes_m.value_or(std::vector<double>{}),
      .ste_phases = ov.ste_phases_rad.value_or(std::vector<double>{}),
      .check_centre_distance = sm.geometric[k]};
  a.b.AddGearMesh(spec);
  TrainMeshElement e;
  e.train_mesh = mi;
  e.branch = i;
  e.stage = sm.stage;
  e.model_mesh = static_cast<int>(a.tm.meshes.size());
  e.stiffness_n_per_m = lm.k_mean;
  e.working_pressure_angle_rad = sm.alpha[k];
  e.contact = sm.drive[k] ? GearMeshSpec::Contact::kLinearDrive : GearMeshSpec::Contact::kLinearCoast;
  e.phase_cycles = spec.phase;
  e.loaded = lm.loaded;
  e.phase_gear_speed = train.gears[ga].speed_index;
  e.stiffness_source = lm.source;
  e.stiffness_min_n_per_m = tab.empty() ? lm.k_mean : *std::min_element(tab.begin(), tab.end());
  e.stiffness_max_n_per_m = tab.empty() ? lm.k_mean : *std::max_element(tab.begin(), tab.end());
  e.table_cycles = lm.table_cycles;
  e.faulted_gear = lm.fault_gear;
  a.tm.branches.push_back({.train_mesh = mi, .branch = i, .model = MeshModel::kLumped,
                           .index = static_cast<int>(a.tm.meshes.size())});
  a.tm.meshes.push_back(e);
}

void AddKinematicMesh(TrainAssembly& a, const StageMeshes& sm, int k, int i) {
  const PlanetaryTrain& train = a.train;
  const int mi = train.stages[sm.stage].meshes[k];
  const TrainMesh& m = train.meshes[mi];
  const auto [ga, gb] = TrainSpecGears(m);
  a.b.AddGearConstraint({.name = m.name + "#" + std::to_string(i + 1), .gear_a = a.GearMeshFrame(ga, i),
                         .gear_b = a.GearMeshFrame(gb, i),
                         .reference = a.b.body_frame(a.tm.member_bodies[train.stages[sm.stage].carrier]),
                         .teeth_a = train.gears[ga].teeth, .teeth_b = train.gears[gb].teeth,
                         .base_radius_a = a.GearParams(ga).base_radius_m,
                         .base_radius_b = a.GearParams(gb).base_radius_m,
                         .working_pressure_angle = sm.alpha[k], .base_helix_angle = SignedBaseHelix(a, ga),
                         .internal_b = m.kind == MeshKind::kInternal, .check_centre_distance = sm.geometric[k]});
  a.tm.branches.push_back({.train_mesh = mi, .branch = i, .model = MeshModel::kKinematic,
                           .index = static_cast<int>(a.tm.kinematic_meshes.size())});
  a.tm.kinematic_meshes.push_back({.train_mesh = mi, .branch = i, .stage = sm.stage,
                                   .model_constraint = static_cast<int>(a.tm.kinematic_meshes.size()),
                                   .working_pressure_angle_rad = sm.alpha[k]});
}

// The models of every branch of mesh k of a stage, and whether any is lumped / contact.
std::vector<MeshModel> BranchModels(const TrainAssembly& a, int mi, int branches, bool* lumped, bool* contact) {
  std::vector<MeshModel> models;
  *lumped = *contact = false;
  for (int i = 0; i < branches; ++i) {
    models.push_back(MeshModelOf(a.train, mi, i, a.o));
    *lumped |= models.back() == MeshModel::kLumped;
    *contact |= models.back() == MeshModel::kContact;
  }
  return models;
}

}  // namespace

std::vector<std::vector<double>> CalcStageMeshPhases(const PlanetaryTrain& train, int stage,
                                                     const std::vector<bool>& drive,
                                                     const std::vector<double>& pressure_angles,
                                                     double reference_phase) {
  const Stage& st = train.stages.at(stage);
  const int n = st.num_planets;
  if (drive.size() != st.meshes.size() || pressure_angles.size() != st.meshes.size())
    FailTrain("stage '" + st.name + "': one flank and one pressure angle per mesh are needed");
  // tau = Z chi / 2 pi (mod 1) of a tooth centre chi of each gear in the carrier frame; central
  // gears have one value for all branches (key branch -1).
  std::map<std::pair<int, int>, double> tau;
  auto key = [&](int g, int branch) {
    return std::pair{g, train.gears[g].planet_set < 0 ? -1 : branch};
  };
  std::vector<std::vector<double>> phases(st.meshes.size(), std::vector<double>(n, 0.0));
  for (size_t k = 0; k < st.meshes.size(); ++k) {
    const TrainMesh& m = train.meshes[st.meshes[k]];
    const auto [a, b] = TrainSpecGears(m);
    const bool internal = m.kind == MeshKind::kInternal;
    const double sigma = drive[k] ? 1.0 : -1.0;
    const double inv_w = Involute(pressure_angles[k]);
    for (int i = 0; i < n; ++i) {
      const Vec3 ca = TrainGearCentre(train, a, i), cb = TrainGearCentre(train, b, i);
      // Per external gear G of the mesh: eps, Z, the pitch-point direction phi_P and the flank
      // offset sigma (theta_b - inv alpha_w), all in cycles of G's teeth.
      struct Side { int g; double eps, z, phi_p, offset; };
      auto side = [&](int g, double eps, const Vec3& from, const Vec3& to, bool outward) {
        const Vec3 d = outward ? from : Vec3(to - from);
        const TrainGear& gear = train.gears[g];
        return Side{g, eps, double(gear.teeth), std::atan2(d.y(), d.x()),
                    sigma * (HalfBaseToothAngle(gear, pressure_angles[k]) - inv_w)};
      };
      const Side sa = side(a, 1.0, ca, cb, internal);  // internal: a planet, P away from the axis
      const bool b_external = !internal;
      const Side sb = b_external ? side(b, -1.0, cb, ca, false) : Side{};
      // Phase seen from G's teeth, and G's teeth from a phase (conjugacy).
      auto phase_from = [&](const Side& s, double t) {
        return s.eps * (t - s.z * s.phi_p / (2 * kPi) + s.z * s.offset / (2 * kPi));
      };
      auto tau_from = [&](const Side& s, double psi) {
        return Frac(s.eps * psi + s.z * s.phi_p / (2 * kPi) - s.z * s.offset / (2 * kPi));
      };
      double psi;
      if (tau.count(key(a, i))) psi = phase_from(sa, tau[key(a, i)]);
      else if (b_external && tau.count(key(b, i))) psi = phase_from(sb, tau[key(b, i)]);
      else psi = reference_phase;  // the reference mesh fixes the sun's teeth
      if (!tau.count(key(a, i))) tau[key(a, i)] = tau_from(sa, psi);
      if (b_external && !tau.count(key(b, i))) tau[key(b, i)] = tau_from(sb, psi);
      phases[k][i] = Frac(psi);
    }
  }
  return phases;
}

void AddMeshes(TrainAssembly& a) {
  const PlanetaryTrain& train = a.train;
  for (int si = 0; si < static_cast<int>(train.stages.size()); ++si) {
    const Stage& st = train.stages[si];
    const StageMeshes sm = ResolveStageMeshes(a, si);
    for (int k = 0; k < static_cast<int>(st.meshes.size()); ++k) {
      const int mi = st.meshes[k];
      bool any_lumped = false, any_contact = false;
      const std::vector<MeshModel> models = BranchModels(a, mi, st.num_planets, &any_lumped, &any_contact);
      // Parameters and geometry before any element (errors before the model grows).
      const LumpedMesh lm = any_lumped ? ResolveLumpedMesh(a, sm, k) : LumpedMesh{};
      std::optional<GearPair> contact_pair;
      if (any_contact) {
        const TrainMesh& m = train.meshes[mi];
        if (train.gears[m.gear_a].planet_set >= 0 && train.gears[m.gear_b].planet_set >= 0)
          FailTrain("mesh '" + m.name + "': planet-planet meshes are not supported by the contact model yet");
        contact_pair.emplace(MakeTrainGearPair(train, mi, a.o));
      }
      for (int i = 0; i < st.num_planets; ++i) {
        switch (models[i]) {
          case MeshModel::kLumped: AddLumpedMesh(a, sm, k, lm, i); break;
          case MeshModel::kKinematic: AddKinematicMesh(a, sm, k, i); break;
          case MeshModel::kContact: AddContactMesh(a, mi, i, *contact_pair); break;
        }
      }
    }
  }
}

void CheckKinematicMeshes(const TrainModel& tm) {
  if (tm.kinematic_meshes.empty()) return;
  // The constraint rows at the initial configuration, in order (loop closures, gear constraints,
  // drivers): a row in the span of the rows before it makes the system redundant. Gram-Schmidt
  // with a relative tolerance (rows are scaled to unit length first).
  const Model& m = *tm.model;
  Data d(m);
  const State x = State::Initial(m);
  CalcPositionKinematics(m, x.q, d);
  CalcConstraints(m, x.t, d);
  std::vector<Eigen::VectorXd> basis;
  for (int row = 0; row < m.n_constraints; ++row) {
    Eigen::VectorXd r = d.G.row(row).transpose();
    if (r.norm() == 0) continue;
    r /= r.norm();
    for (const Eigen::VectorXd& e : basis) r -= e.dot(r) * e;
    if (r.norm() > 1e-9) {
      basis.push_back(r / r.norm());
      continue;
    }
    FailTrain(ConstraintRowName(m, row) + " depends on the constraints before it: the kinematic meshes " +
              "close a redundant loop (the load sharing between planets would be indeterminate, or a " +
              "driven speed is fixed twice); model the other planets' branches as lumped or contact");
  }
}

}  // namespace orrery::gears

#include "models/planetary_kinematics.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

namespace orrery::gears {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Index of a gear's speed in the speed vector (members first, then planet sets).
int SpeedIndex(const PlanetaryTrain& train, const TrainGear& g) {
  return g.member >= 0 ? g.member : train.num_members() + g.planet_set;
}

void CheckRange(const PlanetaryTrain& train, int range) {
  if (range < 0 || range >= static_cast<int>(train.ranges.size()))
    throw std::out_of_range("gear range index " + std::to_string(range) + " out of [0, " +
                            std::to_string(train.ranges.size()) + ")");
}

// Rank threshold for matrices whose entries are tooth counts (integers up to a few hundred).
constexpr double kRankThreshold = 1e-10;

}  // namespace

ConstraintRows AssembleConstraints(const PlanetaryTrain& train, int range) {
  CheckRange(train, range);
  const GearRange& gr = train.ranges[range];
  const int rows = static_cast<int>(train.meshes.size() + train.connections.size() +
                                    gr.clutches.size() + gr.brakes.size());
  ConstraintRows c;
  c.G = Eigen::MatrixXd::Zero(rows, train.num_speeds());
  int row = 0;
  auto add = [&](ConstraintKind kind, int element, std::string label) {
    c.kind.push_back(kind);
    c.element.push_back(element);
    c.label.push_back(std::move(label));
    return row++;
  };
  // Meshes (seed 001 eqs. 1a/2a/2c external, 1b/2b internal).
  for (int m = 0; m < static_cast<int>(train.meshes.size()); ++m) {
    const TrainMesh& mesh = train.meshes[m];
    const TrainGear& a = train.gears[mesh.gear_a];
    const TrainGear& b = train.gears[mesh.gear_b];
    const int carrier = train.stages[mesh.stage].carrier;
    const int r = add(ConstraintKind::kMesh, m, "mesh " + mesh.name);
    const double sign_b = mesh.kind == MeshKind::kExternal ? 1.0 : -1.0;
    c.G(r, SpeedIndex(train, a)) += a.teeth;
    c.G(r, SpeedIndex(train, b)) += sign_b * b.teeth;
    c.G(r, carrier) -= a.teeth + sign_b * b.teeth;
  }
  // Connections and engaged clutches: w_a - w_b = 0.
  for (int k = 0; k < static_cast<int>(train.connections.size()); ++k) {
    const Coupling& cp = train.connections[k];
    const int r = add(ConstraintKind::kConnection, k,
                      "connection " + cp.name + " (" + train.members[cp.member_a].name + " = " +
                          train.members[cp.member_b].name + ")");
    c.G(r, cp.member_a) = 1.0;
    c.G(r, cp.member_b) = -1.0;
  }
  for (int k : gr.clutches) {
    const Coupling& cp = train.clutches[k];
    const int r = add(ConstraintKind::kClutch, k,
                      "clutch " + cp.name + " (" + train.members[cp.member_a].name + " = " +
                          train.members[cp.member_b].name + ")");
    c.G(r, cp.member_a) = 1.0;
    c.G(r, cp.member_b) = -1.0;
  }
  // Engaged brakes: w_k = 0.
  for (int k : gr.brakes) {
    const Brake& b = train.brakes[k];
    const int r = add(ConstraintKind::kBrake, k,
                      "brake " + b.name + " (" + train.members[b.member].name + " = 0)");
    c.G(r, b.member) = 1.0;
  }
  return c;
}

RangeAnalysis AnalyzeRange(const PlanetaryTrain& train, int range) {
  ConstraintRows c = AssembleConstraints(train, range);
  const int n = train.num_speeds();
  const int nc = static_cast<int>(c.G.rows());
  const int ni = static_cast<int>(train.inputs.size());
  // A = [G; input rows].
  Eigen::MatrixXd A(nc + ni, n);
  A.topRows(nc) = c.G;
  A.bottomRows(ni).setZero();
  std::vector<std::string> labels = c.label;
  for (int i = 0; i < ni; ++i) {
    A(nc + i, train.inputs[i]) = 1.0;
    labels.push_back("input " + train.members[train.inputs[i]].name);
  }
  RangeAnalysis out;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
  lu.setThreshold(kRankThreshold);
  out.rank = static_cast<int>(lu.rank());
  // Free motions: the support of the null space of A.
  if (out.rank < n) {
    const Eigen::MatrixXd K = lu.kernel();
    for (int i = 0; i < n; ++i)
      if (K.row(i).cwiseAbs().maxCoeff() > 1e-9) out.free_speeds.push_back(i);
  }
  // Conflicting or repeated rows: the support of the left null space of A.
  if (out.rank < A.rows()) {
    Eigen::FullPivLU<Eigen::MatrixXd> lut(A.transpose());
    lut.setThreshold(kRankThreshold);
    const Eigen::MatrixXd L = lut.kernel();
    for (int i = 0; i < A.rows(); ++i)
      if (L.row(i).cwiseAbs().maxCoeff() > 1e-9) out.redundant.push_back(labels[i]);
  }
  out.determinate = out.free_speeds.empty() && out.redundant.empty();
  if (out.determinate) return out;
  // Message naming the range and the members involved.
  const std::string& name = train.ranges[range].name;
  if (!out.free_speeds.empty()) {
    out.message = "gear range '" + name + "' is under-determined (" +
                  std::to_string(n - out.rank) +
                  " free motion(s) with the inputs held); free: ";
    for (size_t i = 0; i < out.free_speeds.size(); ++i)
      out.message += (i ? ", " : "") + train.SpeedName(out.free_speeds[i]);
  }
  if (!out.redundant.empty()) {
    if (!out.message.empty()) out.message += "; and ";
    out.message += "gear range '" + name + "' is over-determined (" +
                   std::to_string(A.rows() - out.rank) +
                   " conflicting or repeated constraint(s)) among: ";
    for (size_t i = 0; i < out.redundant.size(); ++i)
      out.message += (i ? ", " : "") + out.redundant[i];
  }
  return out;
}

PlanetaryKinematics SolvePlanetaryKinematics(const PlanetaryTrain& train, int range,
                                             const Eigen::VectorXd& input_speeds_rad_s) {
  CheckRange(train, range);
  const int ni = static_cast<int>(train.inputs.size());
  if (input_speeds_rad_s.size() != ni)
    throw std::invalid_argument("SolvePlanetaryKinematics: " +
                                std::to_string(input_speeds_rad_s.size()) +
                                " input speeds for " + std::to_string(ni) + " inputs");
  const RangeAnalysis analysis = AnalyzeRange(train, range);
  if (!analysis.determinate) throw std::runtime_error(analysis.message);
  // Assemble A w = B: constraint rows, then the input speeds.
  const ConstraintRows c = AssembleConstraints(train, range);
  const int n = train.num_speeds();
  const int nc = static_cast<int>(c.G.rows());
  PlanetaryKinematics k;
  k.range = range;
  k.input_speeds_rad_s = input_speeds_rad_s;
  k.A = Eigen::MatrixXd::Zero(n, n);
  k.B = Eigen::VectorXd::Zero(n);
  k.A.topRows(nc) = c.G;
  for (int i = 0; i < ni; ++i) {
    k.A(nc + i, train.inputs[i]) = 1.0;
    k.B(nc + i) = input_speeds_rad_s(i);
  }
  k.speeds_rad_s = k.A.fullPivLu().solve(k.B);
  // Planet speeds relative to their carrier.
  const int np = static_cast<int>(train.planet_sets.size());
  k.planet_relative_speeds_rad_s.resize(np);
  for (int p = 0; p < np; ++p)
    k.planet_relative_speeds_rad_s(p) =
        k.speeds_rad_s(train.num_members() + p) -
        k.speeds_rad_s(train.stages[train.planet_sets[p].stage].carrier);
  // Mesh frequencies f_m = Z_a |w_a - w_c| / 2 pi (seed 001 eq. 3).
  k.mesh_frequencies_hz.resize(train.meshes.size());
  k.stage_mesh_frequencies_hz = Eigen::VectorXd::Zero(train.stages.size());
  for (int m = 0; m < static_cast<int>(train.meshes.size()); ++m) {
    const TrainMesh& mesh = train.meshes[m];
    const TrainGear& a = train.gears[mesh.gear_a];
    const double wc = k.speeds_rad_s(train.stages[mesh.stage].carrier);
    k.mesh_frequencies_hz(m) = a.teeth * std::abs(k.speeds_rad_s(SpeedIndex(train, a)) - wc) / kTwoPi;
    k.stage_mesh_frequencies_hz(mesh.stage) =
        std::max(k.stage_mesh_frequencies_hz(mesh.stage), k.mesh_frequencies_hz(m));
  }
  // Local tooth-fault frequencies: n f_m / Z for central gears, k f_m / Z_p for planets.
  k.gear_fault_frequencies_hz.resize(train.gears.size());
  for (int g = 0; g < static_cast<int>(train.gears.size()); ++g) {
    const TrainGear& gear = train.gears[g];
    const double fm = k.stage_mesh_frequencies_hz(gear.stage);
    const double hits = gear.member >= 0 ? train.stages[gear.stage].num_planets
                                         : train.planet_sets[gear.planet_set].num_meshes;
    k.gear_fault_frequencies_hz(g) = hits * fm / gear.teeth;
  }
  // Overall ratio for a single input.
  const double w_out = k.speeds_rad_s(train.output);
  k.ratio = (ni == 1 && w_out != 0.0) ? input_speeds_rad_s(0) / w_out
                                      : std::numeric_limits<double>::quiet_NaN();
  return k;
}

}  // namespace orrery::gears

#include "models/modal_analysis.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "mbd/data.h"
#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kEigenSafety = 1e3;         // see the header: tolerance = safety n eps lambda_max
constexpr double kCentralEnergyShare = 1e-6; // below it a central member "does not move"
using Complex = std::complex<double>;

// Velocity indices of a joint's coordinates.
std::vector<int> JointCoords(const Model& m, JointIndex j) {
  std::vector<int> v;
  for (int k = 0; k < m.joints[j].nv; ++k) v.push_back(m.joints[j].v_start + k);
  return v;
}

// x_S^T A_SS x_S: the energy of coordinates S alone.
double BlockEnergy(const Eigen::MatrixXd& A, const Eigen::VectorXd& x, const std::vector<int>& s) {
  double e = 0;
  for (int i : s)
    for (int j : s) e += x(i) * A(i, j) * x(j);
  return e;
}

}  // namespace

const char* ModeClassName(ModeClass c) {
  switch (c) {
    case ModeClass::kRigidBody: return "rigid body";
    case ModeClass::kRotational: return "rotational";
    case ModeClass::kTranslational: return "translational";
    case ModeClass::kPlanet: return "planet";
    case ModeClass::kMixed: return "mixed";
  }
  return "?";
}

TrainModelOptions OperatingPointOptions(const TrainModel& tm) {
  TrainModelOptions o = tm.options;
  if (o.input == TrainModelOptions::Input::kTorque) o.input = TrainModelOptions::Input::kNone;
  o.port_loads = false;
  o.output_torque_n_m.reset();
  o.two_sided_contact = false;
  o.backlash_m = 0;
  o.tooth_faults.clear();
  for (const TrainMeshElement& e : tm.meshes) {
    TrainMeshOverride& ov = o.meshes[tm.train->meshes[e.train_mesh].name];
    // The stiffness as used, before the unloaded factor that the build applies again.
    ov.stiffness_n_per_m = e.stiffness_n_per_m / (e.loaded ? 1.0 : o.unloaded_mesh_stiffness_factor);
    ov.stiffness_table_n_per_m.reset();
    ov.ste_amplitudes_m = std::vector<double>{};
    ov.ste_phases_rad = std::vector<double>{};
  }
  return o;
}

TrainModes CalcTrainModes(const TrainModel& tm, const ModalOptions& options) {
  const PlanetaryTrain& train = *tm.train;
  // Operating-point model: built anew from the model's options (OperatingPointOptions).
  const TrainModel lin_tm = BuildTrainModel(train, tm.range, OperatingPointOptions(tm));
  const Model& lin = *lin_tm.model;
  const int nv = lin.nv;
  State op{0.0, lin.q_initial, Eigen::VectorXd::Zero(nv)};
  TrainModes r;
  r.linear = Linearize(lin, op);
  const ModalResult modal = CalcModes(r.linear);
  r.shapes = modal.shapes;
  const int nm = static_cast<int>(modal.frequencies_hz.size());

  // Eigenvalue tolerance from the largest eigenvalue.
  double lambda_max = 0;
  std::vector<double> lambda(nm);
  for (int i = 0; i < nm; ++i) {
    const double w = 2 * kPi * modal.frequencies_hz[i];
    lambda[i] = (modal.frequencies_hz[i] < 0 ? -1.0 : 1.0) * w * w;
    lambda_max = std::max(lambda_max, std::abs(lambda[i]));
  }
  r.eigenvalue_tolerance = kEigenSafety * nv * std::numeric_limits<double>::epsilon() * lambda_max;

  // Coordinate sets: per stage, central rotations, central translations.
  const int ns = static_cast<int>(train.stages.size());
  std::vector<std::vector<int>> stage_coords(ns);
  std::vector<std::vector<int>> central_rot, central_trans;  // per member
  for (int i = 0; i < train.num_members(); ++i) {
    const std::vector<int> c = JointCoords(lin, tm.member_joints[i]);
    stage_coords[train.members[i].stage].insert(stage_coords[train.members[i].stage].end(), c.begin(), c.end());
    std::vector<int> rot, trans;
    for (size_t k = 0; k < c.size(); ++k) {
      const bool is_rot = static_cast<int>(k) == tm.rotation_coordinate;
      const bool is_tilt = tm.dofs == TrainDofs::kSpatial && (k == 3 || k == 4);
      (is_rot ? rot : is_tilt ? trans : trans).push_back(c[k]);
    }
    central_rot.push_back(rot);
    central_trans.push_back(trans);
  }
  for (size_t s = 0; s < train.planet_sets.size(); ++s)
    for (JointIndex j : tm.planet_joints[s]) {
      const std::vector<int> c = JointCoords(lin, j);
      stage_coords[train.planet_sets[s].stage].insert(stage_coords[train.planet_sets[s].stage].end(), c.begin(), c.end());
    }

  // Classify every mode.
  const Eigen::MatrixXd& M = r.linear.M;
  const Eigen::MatrixXd Ks = 0.5 * (r.linear.K + r.linear.K.transpose());
  for (int i = 0; i < nm; ++i) {
    TrainMode mode;
    mode.frequency_hz = modal.frequencies_hz[i];
    const Eigen::VectorXd x = r.shapes.col(i);
    const Eigen::VectorXd Mx = M * x, Kx = Ks * x;
    const double kinetic = x.dot(Mx), strain = x.dot(Kx);
    const bool rigid = std::abs(lambda[i]) <= r.eigenvalue_tolerance;
    // Stage shares.
    for (int s = 0; s < ns; ++s) {
      double ke = 0, se = 0;
      for (int c : stage_coords[s]) {
        ke += x(c) * Mx(c);
        se += x(c) * Kx(c);
      }
      mode.stage_kinetic_share.push_back(ke / kinetic);
      mode.stage_strain_share.push_back(rigid ? 0.0 : se / strain);
      if (mode.stage_kinetic_share.back() >= options.participation_threshold ||
          mode.stage_strain_share.back() >= options.participation_threshold)
        mode.stages.push_back(s);
    }
    // Class from the central members' kinetic energy in rotation and translation.
    double e_rot = 0, e_trans = 0;
    for (size_t m = 0; m < central_rot.size(); ++m) {
      e_rot = std::max(e_rot, BlockEnergy(M, x, central_rot[m]) / kinetic);
      e_trans = std::max(e_trans, BlockEnergy(M, x, central_trans[m]) / kinetic);
    }
    const bool still_rot = e_rot < kCentralEnergyShare, still_trans = e_trans < kCentralEnergyShare;
    if (rigid) mode.mode_class = ModeClass::kRigidBody;
    else if (still_rot && still_trans) mode.mode_class = ModeClass::kPlanet;
    else if (tm.dofs == TrainDofs::kTorsional || still_trans) mode.mode_class = ModeClass::kRotational;
    else if (still_rot) mode.mode_class = ModeClass::kTranslational;
    else mode.mode_class = ModeClass::kMixed;
    r.num_rigid_body_modes += rigid ? 1 : 0;
    r.modes.push_back(mode);
  }
  // Groups of equal eigenvalues (ascending order: neighbours).
  for (int i = 0; i < nm; ++i) {
    const bool same = !r.groups.empty() &&
                      SameEigenvalue(lambda[i], lambda[r.groups.back().first_mode], r.eigenvalue_tolerance);
    if (same) {
      ++r.groups.back().multiplicity;
    } else {
      r.groups.push_back({modal.frequencies_hz[i], i, 1, r.modes[i].mode_class});
    }
    r.modes[i].group = static_cast<int>(r.groups.size()) - 1;
  }

  // Mesh line-of-action vectors J_m = d delta_m / dq by central differences of the deflection.
  const int nmesh = static_cast<int>(lin.gear_meshes.size());
  r.mesh_directions.setZero(nmesh, nv);
  r.mesh_stiffness.resize(nmesh);
  Data data(lin);
  const double h = 1e-7;
  Eigen::VectorXd qp(lin.nq), qm(lin.nq), dq(nv);
  auto deflections = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    CalcPositionKinematics(lin, q, data);
    for (int m = 0; m < nmesh; ++m) {
      const GearMesh& g = lin.gear_meshes[m];
      const MeshState s = CalcMeshState(g.geometry, data, g.spec.gear_a, g.spec.gear_b, g.spec.reference,
                                        g.spec.base_radius_a, g.spec.base_radius_b, 0.0);
      out(m) = g.spec.contact == GearMeshSpec::Contact::kLinearCoast ? s.delta_coast : s.delta_drive;
    }
  };
  Eigen::VectorXd dp(nmesh), dm(nmesh);
  for (int k = 0; k < nv; ++k) {
    dq.setZero();
    dq(k) = h;
    qp = lin.q_initial;
    qm = lin.q_initial;
    IntegratePositions(lin, dq, qp);
    IntegratePositions(lin, -dq, qm);
    deflections(qp, dp);
    deflections(qm, dm);
    r.mesh_directions.col(k) = (dp - dm) / (2 * h);
  }
  for (int m = 0; m < nmesh; ++m) r.mesh_stiffness(m) = lin.gear_meshes[m].k_mean;
  return r;
}

ForcedResponse CalcForcedResponse(const TrainModel& tm, const TrainModes& modes,
                                  const ForcedResponseOptions& o) {
  if (!(o.modal_damping_ratio >= 0) || o.samples_per_period < 4 || !(o.window_periods > 0))
    throw std::invalid_argument("forced response: damping ratio >= 0, samples_per_period >= 4 and "
                                "window_periods > 0 are required");
  const PlanetaryTrain& train = *tm.train;
  const Model& model = *tm.model;
  const int nmesh = static_cast<int>(tm.meshes.size());
  const int nmodes = static_cast<int>(modes.shapes.cols());
  const int nmem = train.num_members();
  const int ns = static_cast<int>(train.stages.size());
  const int nspeeds = static_cast<int>(o.input_speeds_rad_s.size());
  const double zeta = o.modal_damping_ratio;

  // Modal projections: P = J Phi (meshes x modes), R = member rotations of Phi (members x modes).
  const Eigen::MatrixXd P = modes.mesh_directions * modes.shapes;
  Eigen::MatrixXd R(nmem, nmodes);
  for (int i = 0; i < nmem; ++i)
    R.row(i) = modes.shapes.row(model.joints[tm.member_joints[i]].v_start + tm.rotation_coordinate);
  std::vector<double> w2(nmodes);
  for (int i = 0; i < nmodes; ++i) {
    const bool rigid = modes.modes[i].mode_class == ModeClass::kRigidBody;
    const double w = 2 * kPi * modes.modes[i].frequency_hz;
    w2[i] = rigid ? 0.0 : w * w;
  }

  // Excitation components: (stage, harmonic) with the meshes' complex amplitudes E_m.
  struct Component {
    int stage = 0, harmonic = 0;
    Eigen::VectorXcd e;  // (meshes) complex transmission-error amplitude, 0 outside the stage
  };
  std::vector<Component> comps;
  for (int s = 0; s < ns; ++s) {
    int lmax = 0;
    for (const TrainMeshElement& me : tm.meshes)
      if (me.stage == s) lmax = std::max(lmax, int(model.gear_meshes[me.model_mesh].spec.ste_amplitudes.size()));
    for (int l = 1; l <= lmax; ++l) {
      Component c{s, l, Eigen::VectorXcd::Zero(nmesh)};
      for (const TrainMeshElement& me : tm.meshes) {
        const GearMeshSpec& spec = model.gear_meshes[me.model_mesh].spec;
        if (me.stage != s || static_cast<int>(spec.ste_amplitudes.size()) < l) continue;
        // Direction of the mesh phase: gear a's speed relative to the carrier.
        const double rel = tm.unit_kinematics.speeds_rad_s(me.phase_gear_speed) -
                           tm.unit_kinematics.speeds_rad_s(train.stages[s].carrier);
        const double sgn = rel >= 0 ? 1.0 : -1.0;
        const double phi = l - 1 < static_cast<int>(spec.ste_phases.size()) ? spec.ste_phases[l - 1] : 0.0;
        c.e(me.model_mesh) = std::polar(spec.ste_amplitudes[l - 1], sgn * (2 * kPi * l * spec.phase + phi));
      }
      comps.push_back(c);
    }
  }
  const int nc = static_cast<int>(comps.size());
  // Generalized modal forces per unit of each component: B = Phi^T J^T diag(k) E.
  Eigen::MatrixXcd G(nmodes, nc);
  const Eigen::MatrixXd PK = P.transpose() * modes.mesh_stiffness.asDiagonal();  // modes x meshes
  for (int c = 0; c < nc; ++c) G.col(c) = PK.cast<Complex>() * comps[c].e;

  ForcedResponse fr;
  fr.input_speeds_rad_s = o.input_speeds_rad_s;
  fr.stage_mesh_frequencies_hz.setZero(nspeeds, ns);
  fr.mesh_force_p2p_n.setZero(nspeeds, nmesh);
  fr.mesh_deflection_p2p_m.setZero(nspeeds, nmesh);
  fr.member_angle_p2p_rad.setZero(nspeeds, nmem);
  // Work arrays, sized once for the sweep.
  Eigen::MatrixXcd F(nmesh, nc), X(nmesh, nc), A(nmem, nc);
  Eigen::VectorXcd eta(nmodes);
  Eigen::VectorXd omega(nc);
  for (int k = 0; k < nspeeds; ++k) {
    const double scale = o.input_speeds_rad_s[k];
    const Eigen::VectorXd f = tm.unit_kinematics.stage_mesh_frequencies_hz * std::abs(scale);
    fr.stage_mesh_frequencies_hz.row(k) = f.transpose();
    // Complex responses per component: modal coordinates, mesh deflections and forces.
    double f_min = std::numeric_limits<double>::infinity(), f_max = 0;
    for (int c = 0; c < nc; ++c) {
      const double fc = comps[c].harmonic * f(comps[c].stage);
      omega(c) = 2 * kPi * fc;
      f_max = std::max(f_max, fc);
      if (fc > 0) f_min = std::min(f_min, f(comps[c].stage));
      for (int i = 0; i < nmodes; ++i) {
        const double w = std::sqrt(w2[i]);
        const Complex den(w2[i] - omega(c) * omega(c), 2 * zeta * w * omega(c));
        eta(i) = std::abs(den) > 0 ? G(i, c) / den : Complex(0);
      }
      X.col(c).noalias() = P.cast<Complex>() * eta;
      F.col(c) = modes.mesh_stiffness.cast<Complex>().cwiseProduct(X.col(c) - comps[c].e);
      A.col(c).noalias() = R.cast<Complex>() * eta;
    }
    if (nc == 0 || !(f_max > 0)) continue;
    // Time window: one period of a single stage's fundamental, else window_periods of the lowest.
    bool one_stage = true;
    for (int c = 1; c < nc; ++c) one_stage = one_stage && comps[c].stage == comps[0].stage;
    const double window = (one_stage ? 1.0 : o.window_periods) / f_min;
    const int samples = std::max(8, static_cast<int>(std::ceil(o.samples_per_period * f_max * window)));
    // Peak to peak of Re sum_c C_c exp(i W_c t) over the window.
    auto p2p = [&](const Eigen::MatrixXcd& C, Eigen::MatrixXd& out) {
      for (int row = 0; row < C.rows(); ++row) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (int s = 0; s < samples; ++s) {
          const double t = window * s / samples;
          double v = 0;
          for (int c = 0; c < nc; ++c) v += (C(row, c) * std::polar(1.0, omega(c) * t)).real();
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
        out(k, row) = hi - lo;
      }
    };
    p2p(F, fr.mesh_force_p2p_n);
    p2p(X, fr.mesh_deflection_p2p_m);
    p2p(A, fr.member_angle_p2p_rad);
  }
  return fr;
}

}  // namespace orrery::gears

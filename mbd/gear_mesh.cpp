#include "mbd/gear_mesh.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace orrery {
namespace {

constexpr double kPi = 3.141592653589793238463;
constexpr double kTwoPi = 6.283185307179586476925;

// Angle of a gear frame about the reference z axis.
double SpinAngle(const Mat3& R_CG) { return std::atan2(R_CG(1, 0), R_CG(0, 0)); }

}  // namespace

MeshGeometry ComputeMeshGeometry(const std::string& what, const Data& data, FrameIndex gear_a,
                                 FrameIndex gear_b, FrameIndex reference, double rba, double rbb,
                                 double alpha_w, double beta_b, bool internal_b, int teeth_a,
                                 bool check_centre_distance) {
  auto fail = [&](const std::string& msg) { throw std::invalid_argument(what + ": " + msg); };
  if (!(rba > 0) || !(rbb > 0)) fail("base radii must be > 0");
  if (!(alpha_w > 0 && alpha_w < 1.2)) fail("working pressure angle must be in (0, 1.2) rad");
  if (internal_b && !(rbb > rba)) fail("an internal gear b must be larger than gear a");
  const Transform X_CW = data.X_WFrame[reference].Inverse();
  const Transform X_CA = X_CW * data.X_WFrame[gear_a];
  const Transform X_CB = X_CW * data.X_WFrame[gear_b];
  const Vec3 z = Vec3::UnitZ();
  if ((X_CA.R.col(2) - z).norm() > 1e-6 || (X_CB.R.col(2) - z).norm() > 1e-6)
    fail("gear frames' z axes must be parallel to the reference frame's z axis");
  Vec3 d = X_CB.p - X_CA.p;
  d.z() = 0;
  const double dist = d.norm();
  const double expected = (internal_b ? rbb - rba : rba + rbb) / std::cos(alpha_w);
  if (!(dist > 0)) fail("the gear centres coincide");
  if (check_centre_distance && std::abs(dist - expected) > 1e-6 * expected) {
    std::ostringstream s;
    s << "centre distance " << dist << " m in the initial configuration, but base radii " << rba
      << ", " << rbb << " m and working pressure angle " << alpha_w << " rad give " << expected << " m";
    fail(s.str());
  }
  MeshGeometry g;
  const Vec3 u = (internal_b ? -d : d) / dist;
  const Vec3 t = z.cross(u);
  const double ca = std::cos(alpha_w), sa = std::sin(alpha_w);
  g.n_drive_C = ca * t + sa * u;
  g.n_coast_C = ca * t - sa * u;
  g.r_a_C = (rba / ca) * u;
  g.r_b_C = (internal_b ? 1.0 : -1.0) * (rbb / ca) * u;
  g.dc0_C = X_CA.p - X_CB.p;
  g.R_CA0 = X_CA.R;
  g.R_CB0 = X_CB.R;
  g.sigma = internal_b ? -1.0 : 1.0;
  g.cos_beta = std::cos(beta_b);
  g.sin_beta = std::sin(beta_b);
  g.n_drive_helix_C = g.cos_beta * g.n_drive_C + g.sin_beta * Vec3::UnitZ();
  g.n_coast_helix_C = g.cos_beta * g.n_coast_C + g.sin_beta * Vec3::UnitZ();
  g.k_spin_base = g.cos_beta * (rba + g.sigma * rbb);
  g.base_pitch = teeth_a > 0 ? kTwoPi * rba / teeth_a : 0.0;
  return g;
}

double GearSpinAngle(const Data& data, FrameIndex gear, FrameIndex reference, const Mat3& R_CG0) {
  const Mat3 R_CG = data.X_WFrame[reference].R.transpose() * data.X_WFrame[gear].R;
  return SpinAngle(R_CG * R_CG0.transpose());
}

namespace {

// Tolerance on the components of joint axes and of fixed rotations' z columns against +-z.
constexpr double kAxisTolerance = 1e-9;

bool Near(const Vec3& a, const Vec3& b) { return (a - b).cwiseAbs().maxCoeff() <= kAxisTolerance; }

// Appends the rotation coordinate of joint `jt` (side +1 below the gear, -1 below the reference);
// false if the joint turns its child other than about z.
bool AddJointTerm(const Model& model, const Joint& jt, double side, std::vector<GearAngleTerm>* terms) {
  const Vec3 z = Vec3::UnitZ();
  if (!Near(jt.spec.X_PF.R.col(2), z) || !Near(jt.X_MC.R.col(2), z)) return false;
  int rotation = -1;  // offset of the rotation coordinate in the joint's q
  switch (jt.spec.type) {
    case JointType::kFixed:
    case JointType::kPrismatic: return true;  // no rotation
    case JointType::kRevolute:
    case JointType::kCylindrical: rotation = 0; break;
    case JointType::kPlanar: rotation = 2; break;
    default: return false;
  }
  const double axis_sign = Near(jt.axis, z) ? 1.0 : Near(jt.axis, -z) ? -1.0 : 0.0;
  if (axis_sign == 0) return false;
  const int q = jt.q_start + rotation;
  terms->push_back({q, side * axis_sign, model.q_initial(q)});
  return true;
}

// Bodies from `b` up to the world (inclusive).
std::vector<BodyIndex> PathToWorld(const Model& model, BodyIndex b) {
  std::vector<BodyIndex> path{b};
  while (b != kWorldBody) {
    b = model.joints[model.bodies[b].parent_joint].spec.parent;
    path.push_back(b);
  }
  return path;
}

}  // namespace

bool FindGearAngleTerms(const Model& model, FrameIndex gear, FrameIndex reference,
                        std::vector<GearAngleTerm>* terms) {
  terms->clear();
  const Frame& fg = model.frames[gear];
  const Frame& fc = model.frames[reference];
  if (fg.node >= 0 || fc.node >= 0) return false;
  if (!Near(fg.X_BF.R.col(2), Vec3::UnitZ()) || !Near(fc.X_BF.R.col(2), Vec3::UnitZ())) return false;
  const std::vector<BodyIndex> up_g = PathToWorld(model, fg.body), up_c = PathToWorld(model, fc.body);
  // The lowest common body; the joints below it on each side.
  BodyIndex common = kWorldBody;
  for (BodyIndex b : up_c)
    if (std::find(up_g.begin(), up_g.end(), b) != up_g.end()) {
      common = b;
      break;
    }
  for (const auto& [path, side] : {std::pair(&up_g, 1.0), std::pair(&up_c, -1.0)})
    for (BodyIndex b : *path) {
      if (b == common) break;
      if (!AddJointTerm(model, model.joints[model.bodies[b].parent_joint], side, terms)) {
        terms->clear();
        return false;
      }
    }
  return true;
}

double GearAngleFromCoordinates(const GearAngle& angle, const double* q) {
  double theta = 0;
  for (const GearAngleTerm& t : angle.terms) theta += t.sign * (q[t.q] - t.q0);
  if (std::abs(theta) <= kPi) return theta;
  return theta - kTwoPi * std::nearbyint(theta / kTwoPi);
}

double GearAngleAt(const Model& model, const Data& data, int i) {
  const GearAngle& a = model.gear_angles[i];
  if (a.by_coordinates) return GearAngleFromCoordinates(a, data.q_normalized.data());
  return GearSpinAngle(data, a.gear, a.reference, a.R_CG0);
}

void CalcGearAngles(const Model& model, Data& data) {
  for (size_t i = 0; i < model.gear_angles.size(); ++i) data.gear_angle[i] = GearAngleAt(model, data, int(i));
}

double MeshTransmissionCoordinate(const MeshGeometry& g, double rba, double rbb, double backlash,
                                  double theta_a, double theta_b) {
  double e = rba * theta_a + g.sigma * rbb * theta_b;
  if (g.base_pitch > 0) e -= g.base_pitch * std::round((e + 0.5 * backlash) / g.base_pitch);
  return e;
}

MeshState CalcMeshState(const MeshGeometry& g, const Data& data, FrameIndex gear_a,
                        FrameIndex gear_b, FrameIndex reference, double rba, double rbb,
                        double backlash) {
  return CalcMeshState(g, data, gear_a, gear_b, reference, rba, rbb, backlash,
                       GearSpinAngle(data, gear_a, reference, g.R_CA0),
                       GearSpinAngle(data, gear_b, reference, g.R_CB0));
}

namespace {

// CalcMeshState into `s` (every field set).
inline void FillMeshState(const MeshGeometry& g, const Data& data, FrameIndex gear_a,
                          FrameIndex gear_b, FrameIndex reference, double rba, double rbb,
                          double backlash, double theta_a, double theta_b, MeshState& s) {
  const Transform& X_WC = data.X_WFrame[reference];
  const Mat3 R_CW = X_WC.R.transpose();
  const Transform& X_WA = data.X_WFrame[gear_a];
  const Transform& X_WB = data.X_WFrame[gear_b];
  const Vec3 c_a = R_CW * (X_WA.p - X_WC.p), c_b = R_CW * (X_WB.p - X_WC.p);
  // Rotational part, wrapped to one base pitch around the middle of the backlash.
  s.theta_a = theta_a;
  s.theta_b = theta_b;
  const double e = MeshTransmissionCoordinate(g, rba, rbb, backlash, theta_a, theta_b);
  s.e = e;
  // Small displacements of the material points at P: centre translation plus tilt.
  const Vec3 dc = (c_a - c_b) - g.dc0_C;
  s.delta_drive = g.cos_beta * (e + g.n_drive_C.dot(dc));
  s.delta_coast = -g.cos_beta * (e + g.n_coast_C.dot(dc));
  if (g.sin_beta != 0) {  // helical: the axial part (spur gears add exactly nothing)
    // Gear axes in C (the third columns of R_CA = R_CW R_WA, R_CB).
    const Vec3 za = R_CW * X_WA.R.col(2), zb = R_CW * X_WB.R.col(2);
    const double tilt_a = -(za.x() * g.r_a_C.x() + za.y() * g.r_a_C.y());
    const double tilt_b = -(zb.x() * g.r_b_C.x() + zb.y() * g.r_b_C.y());
    const double dz = dc.z() + tilt_a - tilt_b;
    s.delta_drive += g.sin_beta * dz;
    s.delta_coast -= g.sin_beta * dz;
  }
  s.delta_coast -= g.cos_beta * backlash;
  // World quantities for the forces.
  s.p_a_W = X_WA.p + X_WC.R * g.r_a_C;
  s.p_b_W = X_WB.p + X_WC.R * g.r_b_C;
  s.n_drive_W = X_WC.R * g.n_drive_helix_C;
  s.n_coast_W = X_WC.R * g.n_coast_helix_C;
  s.z_W = X_WC.R.col(2);
  s.dc_W = X_WA.p - X_WB.p;
  s.k_spin_base = g.k_spin_base;
}

}  // namespace

MeshState CalcMeshState(const MeshGeometry& g, const Data& data, FrameIndex gear_a,
                        FrameIndex gear_b, FrameIndex reference, double rba, double rbb,
                        double backlash, double theta_a, double theta_b) {
  MeshState s;
  FillMeshState(g, data, gear_a, gear_b, reference, rba, rbb, backlash, theta_a, theta_b, s);
  return s;
}

double CalcMeshRate(const Model& model, const Data& data, FrameIndex gear_a, FrameIndex gear_b,
                    FrameIndex reference, const MeshState& s, const Vec3& n_W) {
  (void)model;
  const Vec6& Va = data.V_WFrame[gear_a];
  const Vec6& Vb = data.V_WFrame[gear_b];
  const Vec6& Vc = data.V_WFrame[reference];
  return n_W.dot(PointVelocity(Va, s.p_a_W) - PointVelocity(Vb, s.p_b_W)) -
         Vc.head<3>().dot(s.z_W) * s.KSpin(n_W);
}

double MeshPhase(const GearMeshSpec& spec, const MeshGeometry& g, const MeshState& s) {
  if (spec.phase_gear == GearMeshSpec::PhaseGear::kA)
    return spec.phase + spec.teeth_a * s.theta_a / kTwoPi;
  return spec.phase - g.sigma * spec.teeth_b * s.theta_b / kTwoPi;
}

namespace {

// Periodic linear interpolation of uniform samples over `cycles` mesh cycles at phase psi.
double TableAt(const std::vector<double>& table, int cycles, double psi) {
  const int n = static_cast<int>(table.size());
  double tau = std::fmod(psi, double(cycles));
  if (tau < 0) tau += cycles;
  const double x = tau / cycles * n;
  const int i = std::min(static_cast<int>(x), n - 1);
  const double f = x - i;
  return (1 - f) * table[i] + f * table[(i + 1) % n];
}

// Slope per cycle of the periodic linear interpolation of TableAt at psi.
double TableSlopeAt(const std::vector<double>& table, int cycles, double psi) {
  const int n = static_cast<int>(table.size());
  double tau = std::fmod(psi, double(cycles));
  if (tau < 0) tau += cycles;
  const int i = std::min(static_cast<int>(tau / cycles * n), n - 1);
  return (table[(i + 1) % n] - table[i]) * n / cycles;
}

// Calls f(a_k, omega_k, cos(omega_k psi + phi_k), sin(omega_k psi + phi_k)) for each harmonic
// k = 1, 2, ... of the static transmission error (omega_k = 2 pi k per cycle, a_k and phi_k the
// spec's amplitudes and phases; phase(k) returns cos phi_k and sin phi_k). One cosine and sine
// of 2 pi frac(psi); the multiples by the angle-addition recurrence cos((k+1) x) = cos(k x) cos x
// - sin(k x) sin x (and the sine's), whose rounding grows by about an ulp per harmonic; the
// phase turns each by its cosine and sine. frac(psi) is exact, so the argument keeps its
// accuracy over a long run, where 2 pi k psi loses digits to psi's size.
template <typename Phase, typename F>
void ForEachHarmonic(const GearMeshSpec& spec, double psi, Phase&& phase, F&& f) {
  const size_t n = spec.ste_amplitudes.size();
  if (n == 0) return;
  const double x = kTwoPi * (psi - std::floor(psi));
  const double c1 = std::cos(x), s1 = std::sin(x);
  double c = c1, s = s1;
  for (size_t k = 0; k < n; ++k) {
    const auto [cp, sp] = phase(k);
    f(spec.ste_amplitudes[k], kTwoPi * double(k + 1), c * cp - s * sp, s * cp + c * sp);
    const double c_next = c * c1 - s * s1;
    s = s * c1 + c * s1;
    c = c_next;
  }
}

// The phases' cosines and sines from the spec (computed at each call).
struct SpecPhase {
  const GearMeshSpec& spec;
  std::pair<double, double> operator()(size_t k) const {
    const double phi = k < spec.ste_phases.size() ? spec.ste_phases[k] : 0.0;
    return phi == 0 ? std::pair(1.0, 0.0) : std::pair(std::cos(phi), std::sin(phi));
  }
};

// The same kept by the model (GearMesh::ste_phase_cos, ste_phase_sin).
struct MeshPhaseTrig {
  const GearMesh& mesh;
  std::pair<double, double> operator()(size_t k) const { return {mesh.ste_phase_cos[k], mesh.ste_phase_sin[k]}; }
};

// Transmission error of the mesh at psi: the table and the harmonics (phases from `phase`).
template <typename Phase>
double TransmissionError(const GearMeshSpec& spec, double psi, Phase&& phase) {
  double e = spec.ste_table_m.empty() ? 0.0 : TableAt(spec.ste_table_m, spec.ste_table_cycles, psi);
  ForEachHarmonic(spec, psi, phase, [&](double a, double, double c, double) { e += a * c; });
  return e;
}

// w += scale J_frame^T F: the row of the power F . V_frame (J_frame: the frame's body Jacobian,
// plus the modal columns of a frame on a flexible body's node).
void AddFrameRow(const Model& model, const Data& data, FrameIndex f, const Vec6& F, double scale,
                 Eigen::Ref<Eigen::VectorXd> w) {
  const Frame& frame = model.frames[f];
  w.noalias() += scale * (data.J_WB[frame.body].transpose() * F);
  if (frame.node >= 0) {
    const FlexibleBody& fb = model.flexible_bodies[model.bodies[frame.body].flexible];
    w.segment(fb.v_start, fb.nf).noalias() += scale * (data.J_frame_modal[f].transpose() * F);
  }
}

}  // namespace

double MeshStiffness(const GearMeshSpec& spec, double psi) {
  if (spec.stiffness_table.empty()) return spec.stiffness;
  return TableAt(spec.stiffness_table, spec.table_cycles, psi);
}

double MeshTransmissionError(const GearMeshSpec& spec, double psi) {
  return TransmissionError(spec, psi, SpecPhase{spec});
}

double MeshStiffnessSlope(const GearMeshSpec& spec, double psi) {
  if (spec.stiffness_table.empty()) return 0.0;
  return TableSlopeAt(spec.stiffness_table, spec.table_cycles, psi);
}

double MeshTransmissionErrorSlope(const GearMeshSpec& spec, double psi) {
  double slope = spec.ste_table_m.empty() ? 0.0 : TableSlopeAt(spec.ste_table_m, spec.ste_table_cycles, psi);
  ForEachHarmonic(spec, psi, SpecPhase{spec}, [&](double a, double omega, double, double s) { slope -= a * omega * s; });
  return slope;
}

namespace {

// EvaluateGearMesh at the gear angles theta_a, theta_b.
MeshEvaluation EvaluateAt(const Model& model, const GearMesh& mesh, const Data& data, double theta_a,
                          double theta_b) {
  const GearMeshSpec& s = mesh.spec;
  const bool two_sided = s.contact == GearMeshSpec::Contact::kTwoSided;
  // The state filled in place: assigning CalcMeshState's value zeroed two states and copied one,
  // about 60 instructions a mesh.
  MeshEvaluation e;
  FillMeshState(mesh.geometry, data, s.gear_a, s.gear_b, s.reference, s.base_radius_a,
                s.base_radius_b, two_sided ? s.backlash : 0.0, theta_a, theta_b, e.state);
  const MeshState& st = e.state;
  if (mesh.small_rotations_only && (std::abs(st.theta_a) > 1 || std::abs(st.theta_b) > 1))
    throw std::runtime_error("gear mesh '" + s.name +
                             "' has no tooth counts and holds for small rotations only, but its "
                             "gears turned more than 1 rad; give teeth_a and teeth_b");
  e.psi = MeshPhase(s, mesh.geometry, st);
  e.k = MeshStiffness(s, e.psi);
  e.ste = TransmissionError(s, e.psi, MeshPhaseTrig{mesh});
  // Engaged flank.
  e.side = s.contact == GearMeshSpec::Contact::kLinearCoast ? -1 : 1;
  if (two_sided) e.side = st.delta_drive - e.ste > 0 ? 1 : (st.delta_coast - e.ste > 0 ? -1 : 0);
  if (e.side == 0) return e;
  const Vec3& n = e.side > 0 ? st.n_drive_W : st.n_coast_W;
  e.delta = e.side > 0 ? st.delta_drive : st.delta_coast;
  e.rate = e.side * CalcMeshRate(model, data, s.gear_a, s.gear_b, s.reference, st, n);
  e.force = e.k * (e.delta - e.ste) + mesh.c * e.rate;
  if (two_sided) e.force = std::max(e.force, 0.0);  // teeth push, never pull
  return e;
}

}  // namespace

MeshEvaluation EvaluateGearMesh(const Model& model, const GearMesh& mesh, const Data& data) {
  return EvaluateAt(model, mesh, data, GearAngleAt(model, data, mesh.angle_a), GearAngleAt(model, data, mesh.angle_b));
}

MeshEvaluation EvaluateGearMeshAtAngles(const Model& model, const GearMesh& mesh, const Data& data) {
  return EvaluateAt(model, mesh, data, data.gear_angle[mesh.angle_a], data.gear_angle[mesh.angle_b]);
}


void AddGearMeshTangents(const Model& model, const Data& data, Eigen::Ref<Eigen::MatrixXd> K,
                         Eigen::Ref<Eigen::MatrixXd> C, Eigen::Ref<Eigen::VectorXd> w,
                         Eigen::Ref<Eigen::VectorXd> w_psi) {
  for (const GearMesh& mesh : model.gear_meshes) {
    const GearMeshSpec& s = mesh.spec;
    const MeshEvaluation e = EvaluateGearMesh(model, mesh, data);
    if (e.side == 0 || (s.contact == GearMeshSpec::Contact::kTwoSided && !(e.force > 0))) continue;
    const MeshState& st = e.state;
    const Vec3& n = e.side > 0 ? st.n_drive_W : st.n_coast_W;
    Vec6 spin;
    spin << st.z_W, Vec3::Zero();
    // Rate row of the engaged flank's compression.
    w.setZero();
    AddFrameRow(model, data, s.gear_a, ForceAtPoint(st.p_a_W, n), e.side, w);
    AddFrameRow(model, data, s.gear_b, ForceAtPoint(st.p_b_W, n), -e.side, w);
    AddFrameRow(model, data, s.reference, spin, -e.side * st.KSpin(n), w);
    K.noalias() += e.k * (w * w.transpose());
    C.noalias() += mesh.c * (w * w.transpose());
    // Phase row: the stiffness and transmission error turn with the phase gear.
    const double dfdpsi = MeshStiffnessSlope(s, e.psi) * (e.delta - e.ste) - e.k * MeshTransmissionErrorSlope(s, e.psi);
    if (dfdpsi == 0) continue;
    const bool gear_a = s.phase_gear == GearMeshSpec::PhaseGear::kA;
    const double per_rad = gear_a ? s.teeth_a / kTwoPi : -mesh.geometry.sigma * s.teeth_b / kTwoPi;
    w_psi.setZero();
    AddFrameRow(model, data, gear_a ? s.gear_a : s.gear_b, spin, per_rad, w_psi);
    AddFrameRow(model, data, s.reference, spin, -per_rad, w_psi);
    K.noalias() += dfdpsi * (w * w_psi.transpose());
  }
}

}  // namespace orrery

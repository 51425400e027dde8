#include "models/gear_mesh_monitor.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace orrery::gears {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The frame F of the header (world pose): origin and z on gear 1's axis, x towards gear 2's axis
// (external) or away from it (internal).
Transform MeshFrame(const GearMeshInfo& info, const Transform& X_WG1, const Transform& X_WG2) {
  const Vec3 z = X_WG1.R.col(2);
  Vec3 x = X_WG2.p - X_WG1.p;
  x -= x.dot(z) * z;
  if (info.internal) x = -x;
  x.normalize();
  Mat3 R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return Transform(R, X_WG1.p);
}

// The angle of a gear frame's x axis about F's z.
double AngleIn(const Transform& X_WF, const Transform& X_WG) {
  const Vec3 x = X_WF.R.transpose() * X_WG.R.col(0);
  return std::atan2(x.y(), x.x());
}

}  // namespace

double GearTransmissionError(const GearMeshInfo& info, const Transform& X_WA,
                             const Transform& X_WB) {
  const Transform X_WG1 = X_WA * info.X_AG1, X_WG2 = X_WB * info.X_BG2;
  const Transform X_WF = MeshFrame(info, X_WG1, X_WG2);
  const double theta1 = AngleIn(X_WF, X_WG1), theta2 = AngleIn(X_WF, X_WG2);
  const double rb1 = info.base_radius1_m, rb2 = info.base_radius2_m;
  const double z2 = info.teeth2;
  const double te = info.internal ? rb1 * theta1 - rb2 * theta2 + rb2 * kPi / z2
                                  : rb1 * theta1 + rb2 * theta2 - rb2 * (kPi + kPi / z2);
  // One base pitch about zero (whole turns of either gear are whole pitches).
  const double pitch = 2 * kPi * rb1 / info.teeth1;
  return te - pitch * std::round(te / pitch);
}

namespace {

// A monitor's state: the outputs being accumulated and gear 1's frame of this evaluation.
struct GearMeshState final : contact::ContactMonitorState {
  GearMeshOutputs out;
  Transform X_G1W;  // gear 1 frame from world
};

}  // namespace

GearMeshMonitor::GearMeshMonitor(const GearMeshInfo& info)
    : info_(info),
      outputs_{{.name = "transmission_error", .unit = "m"},
               {.name = "line_of_action_force", .unit = "N"},
               {.name = "mesh_stiffness", .unit = "N/m"},
               {.name = "pattern_roll_min", .unit = "m"},
               {.name = "pattern_roll_max", .unit = "m"},
               {.name = "pattern_axial_min", .unit = "m"},
               {.name = "pattern_axial_max", .unit = "m"}} {}

std::unique_ptr<contact::ContactMonitorState> GearMeshMonitor::MakeState() const {
  return std::make_unique<GearMeshState>();
}

const GearMeshOutputs& GearMeshMonitor::Outputs(const contact::ContactMonitorState& state) {
  return static_cast<const GearMeshState&>(state).out;
}

void GearMeshMonitor::Start(const Transform& X_WA, const Transform& X_WB,
                            contact::ContactMonitorState& state) const {
  auto& s = static_cast<GearMeshState&>(state);
  s.out = GearMeshOutputs{};
  s.out.transmission_error_m = GearTransmissionError(info_, X_WA, X_WB);
  s.X_G1W = (X_WA * info_.X_AG1).Inverse();
}

void GearMeshMonitor::Add(const Vec3& p_a_W, const Vec3& n_W, double k,
                          contact::ContactMonitorState& state) const {
  auto& s = static_cast<GearMeshState&>(state);
  GearMeshOutputs& out = s.out;
  const double rb1 = info_.base_radius1_m;
  // In gear 1's frame: the point, and its motion per unit TE (gear 1 turned by 1 / r_b1).
  const Vec3 p = s.X_G1W * p_a_W;
  const Vec3 n = s.X_G1W.R * n_W;
  const double lever = n.dot(Vec3::UnitZ().cross(Vec3(p.x(), p.y(), 0))) / rb1;
  out.mesh_stiffness_n_per_m += k * lever * lever;
  const double r = std::hypot(p.x(), p.y());
  const double roll = std::sqrt(std::max(0.0, r * r - rb1 * rb1));
  auto extend = [](double& lo, double& hi, double x) {
    lo = std::isnan(lo) ? x : std::min(lo, x);
    hi = std::isnan(hi) ? x : std::max(hi, x);
  };
  extend(out.pattern_roll_min_m, out.pattern_roll_max_m, roll);
  extend(out.pattern_axial_min_m, out.pattern_axial_max_m, p.z());
}

void GearMeshMonitor::Finish(const Vec6& f_A_W, contact::ContactMonitorState& state) const {
  auto& s = static_cast<GearMeshState&>(state);
  // The moment about gear 1's axis: in its frame, about its origin.
  const Transform X_WG1 = s.X_G1W.Inverse();
  const Vec3 moment = f_A_W.head<3>() - X_WG1.p.cross(f_A_W.tail<3>());
  s.out.line_of_action_force_n = -X_WG1.R.col(2).dot(moment) / info_.base_radius1_m;
}

void GearMeshMonitor::Write(const contact::ContactMonitorState& state, double* values) const {
  const GearMeshOutputs& o = Outputs(state);
  values[0] = o.transmission_error_m;
  values[1] = o.line_of_action_force_n;
  values[2] = o.mesh_stiffness_n_per_m;
  values[3] = o.pattern_roll_min_m;
  values[4] = o.pattern_roll_max_m;
  values[5] = o.pattern_axial_min_m;
  values[6] = o.pattern_axial_max_m;
}

}  // namespace orrery::gears

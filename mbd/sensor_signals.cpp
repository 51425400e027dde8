#include "mbd/sensor_signals.h"

#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"

namespace orrery {
namespace {

// Motion of a sensor's point P and of its axes (world axes, classical vectors).
struct PointMotion {
  Vec3 p, v, a;        // position, velocity, acceleration of P
  Vec3 omega, alpha;   // angular velocity and acceleration of the sensor's axes
};

// The motion of point P = X_WF p_FS fixed in frame f, from the kinematics in `data`
// (accelerations only if `accelerations`): the rigid motion of its body, plus for a node frame
// the elastic terms of sensor.h (P turns with the node).
PointMotion SensorMotion(const Model& model, const Data& data, int f, const Vec3& p_FS,
                         bool accelerations, const Eigen::Ref<const Eigen::VectorXd>& vdot) {
  const Frame& frame = model.frames[f];
  const BodyIndex b = frame.body;
  PointMotion m;
  m.p = data.X_WFrame[f] * p_FS;
  const Vec6& V_B = data.V_WB[b];
  const Vec3 w_B = V_B.head<3>();
  const Vec3 v_rigid = PointVelocity(V_B, m.p);
  m.v = PointVelocity(data.V_WFrame[f], m.p);
  m.omega = data.V_WFrame[f].head<3>();
  if (!accelerations) return m;
  // Rigid part: the body's spatial acceleration without the base offset (0, -g).
  const Vec6& A = data.A_WB[b];
  const Vec3 alpha_B = A.head<3>();
  const Vec3 a_o = A.tail<3>() + model.gravity;
  m.a = a_o + alpha_B.cross(m.p) + w_B.cross(v_rigid);
  m.alpha = alpha_B;
  if (frame.node < 0) return m;
  // Node frame: J_frame_modal's columns are (R psi_k, R (phi_k + psi_k x d) + p x R psi_k), the
  // modal velocity of a point x turning with the node is their v + w x x.
  const FlexibleBody& fb = model.flexible_bodies[model.bodies[b].flexible];
  const auto& J = data.J_frame_modal[f];
  const Eigen::VectorXd& qf_dot = data.flex[model.bodies[b].flexible].qf_dot;
  const auto qf_ddot = vdot.segment(fb.v_start, fb.nf);
  const Vec6 Jqd = J * qf_dot, Jqdd = J * qf_ddot;  // fixed size: no heap temporaries
  const Vec3 w_e = Jqd.head<3>(), dw_e = Jqdd.head<3>();
  const Vec3 u_dot = Jqd.tail<3>() - m.p.cross(w_e);
  Vec3 u_ddot = Jqdd.tail<3>() - m.p.cross(dw_e);
  // The offset d from the node turns with the node: w_e x (w_e x d), d in world axes.
  if (w_e.squaredNorm() > 0) {
    const Transform& X_WB = data.X_WB[b];
    const FlexibleBodyModes::Node& node = fb.modes->nodes[frame.node];
    const Vec3 d_W = m.p - X_WB.p - X_WB.R * (node.position + node.translation_shapes.leftCols(fb.nf) *
                                                                   data.flex[model.bodies[b].flexible].qf);
    u_ddot += w_e.cross(w_e.cross(d_W));
  }
  m.a += 2 * w_B.cross(u_dot) + u_ddot;
  m.alpha += dw_e + w_B.cross(w_e);
  return m;
}

// Writes the sensor's components of `x_W` (world axes) expressed in axes R_WE.
void WriteAxes(const Sensor& s, const Mat3& R_WE, const Vec3& x_W, Data& data) {
  const Vec3 x_E = R_WE.transpose() * x_W;
  for (int c = 0; c < s.channels; ++c) data.sensor_values(s.channel_start + c) = x_E(s.spec.axes[c]);
}

void FrameSensor(const Model& model, const Sensor& s, const Eigen::Ref<const Eigen::VectorXd>& vdot,
                 Data& data) {
  const SensorSpec& spec = s.spec;
  const Transform& X_WF = data.X_WFrame[spec.frame];
  const Transform X_WE = spec.measured_in == kSensorAxes ? X_WF * spec.X_FS : data.X_WFrame[spec.measured_in];
  const PointMotion m = SensorMotion(model, data, spec.frame, spec.X_FS.p, s.needs_accelerations, vdot);
  switch (spec.kind) {
    case SensorKind::kAccelerometer:
      WriteAxes(s, X_WE.R, spec.include_gravity ? Vec3(m.a - model.gravity) : m.a, data);
      break;
    case SensorKind::kVelocity: WriteAxes(s, X_WE.R, m.v, data); break;
    case SensorKind::kGyroscope: WriteAxes(s, X_WE.R, m.omega, data); break;
    case SensorKind::kAngularAccelerometer: WriteAxes(s, X_WE.R, m.alpha, data); break;
    case SensorKind::kDisplacement: {
      const Vec3 d_E = X_WE.R.transpose() * (m.p - X_WE.p) - s.p0_E;
      WriteAxes(s, Mat3::Identity(), d_E, data);
      break;
    }
    default: break;
  }
}

}  // namespace

void CalcSensorSignals(const Model& model, double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& v,
                       const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data) {
  // Poses (elements get the whole position stage, inertias included, as in a step).
  if (model.sensor_elements.empty()) CalcFramePoses(model, q, data);
  else CalcPositionKinematics(model, q, data);
  CalcVelocityKinematics(model, v, data);
  bool accelerations = false;
  for (const Sensor& s : model.sensors) accelerations = accelerations || s.needs_accelerations;
  if (accelerations) CalcAccelerationKinematics(model, vdot, data);
  // Frame, joint and mesh sensors.
  for (const Sensor& s : model.sensors) {
    double* out = data.sensor_values.data() + s.channel_start;
    switch (s.spec.kind) {
      case SensorKind::kEncoder: *out = data.q_normalized(s.q_index); break;
      case SensorKind::kTachometer: *out = v(s.v_index); break;
      case SensorKind::kGearMesh: {
        const MeshEvaluation e = EvaluateGearMesh(model, model.gear_meshes[s.spec.gear_mesh], data);
        *out = s.spec.mesh_quantity == MeshQuantity::kForce        ? e.force
               : s.spec.mesh_quantity == MeshQuantity::kDeflection ? e.delta
                                                                   : e.state.e;
        break;
      }
      case SensorKind::kElementOutput: break;  // below
      default: FrameSensor(model, s, vdot, data); break;
    }
  }
  // External elements: evaluated once each at this state, their outputs copied.
  for (const int e : model.sensor_elements) {
    for (Vec6& f : data.f_ext) f.setZero();
    data.tau_applied.setZero();
    const ExternalForceElement& element = *model.external_forces[e];
    element.Apply(model, t, data, *data.external[e]);
    element.GetOutputs(*data.external[e], data.element_outputs.data());
    for (const Sensor& s : model.sensors)
      if (s.spec.kind == SensorKind::kElementOutput && s.spec.element == e)
        data.sensor_values.segment(s.channel_start, s.channels) =
            data.element_outputs.segment(s.output_offset, s.channels);
  }
}

}  // namespace orrery

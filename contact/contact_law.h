#pragma once
// Contact law at one node: penalty normal pressure with Hunt-Crossley damping and regularized
// Coulomb friction, integrated over the node's area weight.
//
// The penalty is defined PER UNIT AREA (seed 000 eq. 20 integrates alpha_N over the contact
// surface): with penetration delta = -g >= 0 and its rate delta_dot,
//   pressure   p = k_A delta^e (1 + b delta_dot), clamped at p >= 0 (never pulling)
//              e = 1: the linear penalty of seed 000 eq. 23 (k_A in N/m^3, the alpha_N of eq. 20);
//              e = 1.5 (or any e >= 1): a Hertz-type exponent (k_A in N/m^(2+e));
//              b: the Hunt-Crossley damping factor (s/m; Hunt & Crossley 1975: the damping force
//              is b times the elastic force times delta_dot), chi = b k in Lankarani-Nikravesh's
//              notation; HuntCrossleyFactorLankaraniNikravesh() sets it from a restitution;
//   normal force F_N = A_w p, A_w the node's area weight (contact_surface.h),
//   friction   F_T = -mu F_N v_t / v_s      for |v_t| < v_s (stiction regularized as a linear
//                                            viscous ramp),
//              F_T = -mu F_N v_t / |v_t|    for |v_t| >= v_s (Coulomb, seed 000 eq. 25),
//   v_t the tangential slip velocity of the node relative to the face.
// A flat contact of area A pressed by delta carries F = k_A A delta (e = 1) when both surfaces'
// nodes cover the contact area (the two-way sum weighs each pass by 1/2, contact_element.h).
//
// Energy bookkeeping per node: elastic energy U = A_w k_A delta^(e+1) / (e+1); dissipated
// power (F_N - A_w k_A delta^e) delta_dot (damping, also when the clamp acts) - F_T . v_t.
#include <algorithm>
#include <cmath>

#include "mbd/spatial.h"

namespace orrery::contact {

struct ContactLaw {
  double stiffness_per_area = 0;    // k_A > 0: N/m^3 for e = 1, N/m^(2+e) in general
  double exponent = 1.0;            // e >= 1
  double hunt_crossley_s_per_m = 0; // b >= 0
  double friction_coefficient = 0;  // mu >= 0
  double slip_velocity_m_s = 1e-3;  // v_s > 0
};

// Throws std::invalid_argument naming the offending value.
void ValidateContactLaw(const ContactLaw& law);

struct NodeForce {
  Vec3 f_W = Vec3::Zero();   // total force on the node side (normal + friction), world
  double normal = 0;         // F_N >= 0
  double stiffness = 0;      // dF_N / d(depth) (N/m)
  double friction = 0;       // |F_T|
  double energy = 0;         // J, elastic energy
  double power_dissipated = 0;  // W, >= 0
};

// depth = -g (> 0), depth_rate = d(depth)/dt, n_W the face normal (points towards the node
// side), v_rel_W the velocity of the node relative to the face's material point, area_weight
// the node's weight (m^2). Inline: the contact elements call it once per contact point
// (docs/performance.md, "node-columns").
inline NodeForce EvaluateContactLaw(const ContactLaw& law, double depth, double depth_rate,
                                    const Vec3& n_W, const Vec3& v_rel_W, double area_weight) {
  NodeForce out;
  if (!(depth > 0)) return out;
  // Elastic part and Hunt-Crossley damping, never pulling.
  const double delta_e = law.exponent == 1.0 ? depth : std::pow(depth, law.exponent);
  const double elastic = area_weight * law.stiffness_per_area * delta_e;
  const double damping = std::max(0.0, 1.0 + law.hunt_crossley_s_per_m * depth_rate);
  const double fn = elastic * damping;
  out.normal = fn;
  out.stiffness = law.exponent * elastic / depth * damping;
  out.energy = elastic * depth / (law.exponent + 1.0);
  out.power_dissipated = (fn - elastic) * depth_rate;
  out.f_W = fn * n_W;
  // Regularized Coulomb friction against the tangential slip.
  if (law.friction_coefficient > 0 && fn > 0) {
    const Vec3 v_t = v_rel_W - v_rel_W.dot(n_W) * n_W;
    const double speed = v_t.norm();
    const double scale = law.friction_coefficient * fn /
                         (speed < law.slip_velocity_m_s ? law.slip_velocity_m_s : speed);
    const Vec3 f_t = -scale * v_t;
    out.f_W += f_t;
    out.friction = scale * speed;
    out.power_dissipated += scale * speed * speed;
  }
  return out;
}

// Derivatives of the node force f (NodeForce::f_W) for Newton's iteration matrix: with x_rel the
// node's position relative to the face point (depth = -n . x_rel + const) and v_rel its velocity,
//   df = -K dx_rel - C dv_rel,
//   K = k_n (n + f_t / F_N) n^T,                 k_n = dF_N/d(depth),
//   C = c_n (n + f_t / F_N) n^T + mu F_N / s P,  c_n = dF_N/d(depth_rate),
// P the tangent-plane projector I - n n^T while sticking (|v_t| < v_s, s = v_s), and the
// projector across the slip direction t, P - t t^T, while sliding (s = |v_t|). The turning of n
// with the surfaces is left out (a term of the order of the force over the curvature radius).
struct NodeForceTangent {
  double k_n = 0;          // dF_N/d(depth) (N/m)
  double c_n = 0;          // dF_N/d(depth rate) (N s/m)
  Vec3 a = Vec3::Zero();   // n + f_t / F_N: where a change of F_N acts
  double slip_damping = 0; // mu F_N / s (N s/m)
  int slip_directions = 0; // 0, 1 (sliding) or 2 (sticking): P = sum of d d^T over them
  Vec3 slip_direction[2] = {Vec3::Zero(), Vec3::Zero()};
  // The dense 3 x 3 forms (the accumulation in contact_tangents.h keeps the rank-1 terms).
  Mat3 K(const Vec3& n_W) const { return k_n * a * n_W.transpose(); }
  Mat3 C(const Vec3& n_W) const {
    Mat3 c = c_n * a * n_W.transpose();
    for (int i = 0; i < slip_directions; ++i)
      c += slip_damping * slip_direction[i] * slip_direction[i].transpose();
    return c;
  }
};
NodeForceTangent EvaluateContactLawTangent(const ContactLaw& law, double depth, double depth_rate,
                                           const Vec3& n_W, const Vec3& v_rel_W,
                                           double area_weight);

// Lankarani & Nikravesh (1990, J. Mech. Des. 112:369, eq. 20): b = 3 (1 - e_r^2) / (4 v0) for a
// coefficient of restitution e_r at impact speed v0 (derived for e_r near 1).
double HuntCrossleyFactorLankaraniNikravesh(double restitution, double impact_speed_m_s);

}  // namespace orrery::contact

#include "contact/contact_law.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orrery::contact {

void ValidateContactLaw(const ContactLaw& law) {
  auto fail = [](const std::string& what, double value) {
    throw std::invalid_argument("ContactLaw: " + what + ", got " + std::to_string(value));
  };
  if (!(law.stiffness_per_area > 0)) fail("stiffness_per_area must be > 0", law.stiffness_per_area);
  if (!(law.exponent >= 1)) fail("exponent must be >= 1", law.exponent);
  if (!(law.hunt_crossley_s_per_m >= 0)) fail("hunt_crossley_s_per_m must be >= 0", law.hunt_crossley_s_per_m);
  if (!(law.friction_coefficient >= 0)) fail("friction_coefficient must be >= 0", law.friction_coefficient);
  if (!(law.slip_velocity_m_s > 0)) fail("slip_velocity_m_s must be > 0", law.slip_velocity_m_s);
}

NodeForceTangent EvaluateContactLawTangent(const ContactLaw& law, double depth, double depth_rate,
                                           const Vec3& n_W, const Vec3& v_rel_W,
                                           double area_weight) {
  NodeForceTangent out;
  if (!(depth > 0)) return out;
  // F_N = A k delta^e max(0, 1 + b delta_dot) and its two partials.
  const double e = law.exponent;
  const double delta_e = e == 1.0 ? depth : std::pow(depth, e);
  const double elastic = area_weight * law.stiffness_per_area * delta_e;
  const double damping = 1.0 + law.hunt_crossley_s_per_m * depth_rate;
  if (!(damping > 0)) return out;  // clamped: no force, and none nearby
  const double fn = elastic * damping;
  out.k_n = e * elastic / depth * damping;
  out.c_n = elastic * law.hunt_crossley_s_per_m;
  out.a = n_W;
  // Friction's share of the force direction, f_t / F_N, and its slip derivative.
  if (law.friction_coefficient > 0) {
    const Vec3 v_t = v_rel_W - v_rel_W.dot(n_W) * n_W;
    const double speed = v_t.norm();
    // An orthonormal pair across n, the first along the slip when there is one.
    const Vec3 t1 = speed > 0 ? Vec3(v_t / speed) : n_W.unitOrthogonal();
    const Vec3 t2 = n_W.cross(t1);
    if (speed < law.slip_velocity_m_s) {
      out.a -= (law.friction_coefficient / law.slip_velocity_m_s) * v_t;
      out.slip_damping = law.friction_coefficient * fn / law.slip_velocity_m_s;
      out.slip_directions = 2;
      out.slip_direction[0] = t1;
      out.slip_direction[1] = t2;
    } else {
      out.a -= law.friction_coefficient * t1;
      out.slip_damping = law.friction_coefficient * fn / speed;
      out.slip_directions = 1;
      out.slip_direction[0] = t2;
    }
  }
  return out;
}

double HuntCrossleyFactorLankaraniNikravesh(double restitution, double impact_speed_m_s) {
  if (!(restitution > 0 && restitution <= 1))
    throw std::invalid_argument("HuntCrossleyFactorLankaraniNikravesh: restitution must be in "
                                "(0, 1], got " + std::to_string(restitution));
  if (!(impact_speed_m_s > 0))
    throw std::invalid_argument("HuntCrossleyFactorLankaraniNikravesh: impact speed must be > 0, "
                                "got " + std::to_string(impact_speed_m_s));
  return 3.0 * (1.0 - restitution * restitution) / (4.0 * impact_speed_m_s);
}

}  // namespace orrery::contact

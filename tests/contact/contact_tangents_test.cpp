// Analytic contact tangents (contact/contact_tangents.cpp, EvaluateContactLawTangent in
// contact/contact_law.cpp) against differences:
//   - the law's K and C against central differences of EvaluateContactLaw in the relative
//     position and velocity (Hertz exponent with Hunt-Crossley damping, sticking and sliding
//     friction): exact up to the difference error;
//   - a rigid block pressed and sliding on a plane, on a free joint: DaeSystem::Tangents with
//     the element's tangents against forward differences of the whole pipeline through the
//     element (DaeSystem::set_element_tangents(false)). The tangents leave out the turning of the
//     force's direction and point of action with the block, terms of the order of the force
//     times the half-width L against the rotational stiffness k L^2 / 3, so they agree to a
//     relative 3 delta / L (delta the penetration: 1.5e-3 here).
#include "contact/contact_tangents.h"

#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "contact/contact_element.h"
#include "mbd/dae.h"
#include "mbd/model.h"
#include "mbd/state.h"

namespace orrery::contact {
namespace {

// df = -K dx_rel - C dv_rel, depth = depth0 - n . dx_rel, depth rate = -n . v_rel.
void ExpectLawTangentMatchesDifferences(const ContactLaw& law, double depth0, const Vec3& v_rel0) {
  const Vec3 n = Vec3(0.2, -0.3, 1.0).normalized();
  const double area = 2e-6;
  auto force = [&](const Vec3& dx, const Vec3& v) {
    return EvaluateContactLaw(law, depth0 - n.dot(dx), -n.dot(v), n, v, area).f_W;
  };
  const NodeForceTangent t = EvaluateContactLawTangent(law, depth0, -n.dot(v_rel0), n, v_rel0, area);
  Mat3 K_fd, C_fd;
  const double hx = 1e-6 * depth0, hv = 1e-7 * std::max(1e-3, v_rel0.norm());
  for (int j = 0; j < 3; ++j) {
    const Vec3 ex = hx * Vec3::Unit(j), ev = hv * Vec3::Unit(j);
    K_fd.col(j) = -(force(ex, v_rel0) - force(-ex, v_rel0)) / (2 * hx);
    C_fd.col(j) = -(force(Vec3::Zero(), v_rel0 + ev) - force(Vec3::Zero(), v_rel0 - ev)) / (2 * hv);
  }
  EXPECT_LE((t.K(n) - K_fd).norm(), 1e-6 * K_fd.norm()) << "K\n" << t.K(n) << "\nfd\n" << K_fd;
  EXPECT_LE((t.C(n) - C_fd).norm(), 1e-6 * C_fd.norm()) << "C\n" << t.C(n) << "\nfd\n" << C_fd;
}

TEST(ContactTangents, LawTangentMatchesCentralDifferences) {
  // Hertz-type exponent with Hunt-Crossley damping, approaching and sliding, no friction.
  ExpectLawTangentMatchesDifferences(
      {.stiffness_per_area = 1e16, .exponent = 1.5, .hunt_crossley_s_per_m = 0.5}, 3e-6,
      Vec3(0.4, 0.1, -0.02));
  // Linear penalty, sticking (slip 0.4 mm/s below v_s = 1 mm/s) and sliding (0.2 m/s).
  const ContactLaw friction{.stiffness_per_area = 1e14, .hunt_crossley_s_per_m = 0.3,
                            .friction_coefficient = 0.1, .slip_velocity_m_s = 1e-3};
  ExpectLawTangentMatchesDifferences(friction, 2e-6, Vec3(3e-4, -2e-4, -1e-4));
  ExpectLawTangentMatchesDifferences(friction, 2e-6, Vec3(0.15, 0.13, -0.01));
}

// A 20 x 20 mm square of 4 x 4 cells in z = 0, normal -z (the block's bottom) or +z (a plane).
TriangleMesh Square(double half, int cells, double z_offset_cells, bool up) {
  TriangleMesh m;
  const double h = 2 * half / cells, x0 = -half + z_offset_cells * h;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) m.vertices.push_back(Vec3(x0 + i * h, x0 + j * h, 0));
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const int v = j * (cells + 1) + i;
      if (up) {
        m.triangles.push_back({v, v + 1, v + cells + 2});
        m.triangles.push_back({v, v + cells + 2, v + cells + 1});
      } else {
        m.triangles.push_back({v, v + cells + 2, v + 1});
        m.triangles.push_back({v, v + cells + 1, v + cells + 2});
      }
    }
  return m;
}

TEST(ContactTangents, RigidBlockMatchesPipelineDifferences) {
  constexpr double kHalf = 0.01, kDepth = 3e-6;
  auto block = std::make_shared<const ContactSurface>(std::vector{Square(kHalf, 4, 0, false)}, 30e-6);
  auto plane = std::make_shared<const ContactSurface>(std::vector{Square(0.0225, 9, 0.5, true)}, 30e-6);
  ModelBuilder b;
  const BodyIndex body = b.AddBody("block", 0.03, Vec3(0, 0, 0.005), Vec3(1e-6, 1e-6, 2e-6).asDiagonal());
  const JointIndex free = b.AddJoint({.name = "free", .type = JointType::kFree,
                                      .parent = kWorldBody, .child = body});
  // Pressed 3 um at the centre, tilted 1e-4 rad about x (1 to 5 um across), sliding at 0.4 mm/s
  // (sticking friction) and turning.
  const double tilt = 1e-4;
  Eigen::VectorXd q0(7), v0(6);
  q0 << 0, 0, -kDepth + 1e-6, std::cos(tilt / 2), std::sin(tilt / 2), 0, 0;
  v0 << 4e-4, -1e-4, -2e-3, 0.002, -0.001, 0.03;
  b.SetJointPosition(free, q0);
  b.SetJointVelocity(free, v0);
  b.AddExternalForce(std::make_shared<ContactElement>(ContactElementSpec{
      .name = "block_on_plane", .body_a = body, .body_b = kWorldBody, .surface_a = block,
      .surface_b = plane,
      .law = {.stiffness_per_area = 1e14, .hunt_crossley_s_per_m = 0.4,
              .friction_coefficient = 0.2, .slip_velocity_m_s = 1e-3}}));
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  const State s = State::Initial(*model);
  const int nv = model->nv;
  const Eigen::VectorXd vdot = Eigen::VectorXd::Zero(nv), lambda;
  Eigen::MatrixXd K_an(nv, nv), C_an(nv, nv), K_fd(nv, nv), C_fd(nv, nv);
  DaeSystem dae(*model);
  dae.Tangents(0, s.q, s.v, vdot, lambda, K_an, C_an);
  const auto& ws = static_cast<const ContactWorkspace&>(*dae.data().external[0]);
  EXPECT_GT(ws.contact_points, 40);  // all 25 block nodes and the plane nodes under it
  EXPECT_GT(ws.friction_force, 0);
  dae.set_element_tangents(false);
  dae.Tangents(0, s.q, s.v, vdot, lambda, K_fd, C_fd);
  // Left out: the moments of the force F = k delta about the turning points of action, F L,
  // against the rotational stiffness k L^2 / 3 of a square of half-width L: 3 delta / L, with
  // the deepest penetration for delta.
  const double relative = 3 * 5e-6 / kHalf;
  EXPECT_LE((K_an - K_fd).norm(), relative * K_fd.norm()) << "K\n" << K_an << "\nfd\n" << K_fd;
  EXPECT_LE((C_an - C_fd).norm(), relative * C_fd.norm()) << "C\n" << C_an << "\nfd\n" << C_fd;
  std::printf("rigid block: |K - K_fd| / |K_fd| = %.2e, |C - C_fd| / |C_fd| = %.2e (bound %.1e)\n",
              (K_an - K_fd).norm() / K_fd.norm(), (C_an - C_fd).norm() / C_fd.norm(), relative);
}

}  // namespace
}  // namespace orrery::contact

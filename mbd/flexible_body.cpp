// Flexible bodies in the model builder: validation of the reduced data, the body and its node
// frames, and (FinalizeFlexibleBody) the matrices the step uses.
#include "mbd/flexible_body.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mbd/model.h"

namespace orrery {
namespace {

[[noreturn]] void Fail(const std::string& msg) { throw std::invalid_argument(msg); }

// int rho (a x b) from int rho a b^T: (a x b)_i = eps_ijk a_j b_k.
Vec3 Axial(const Mat3& ab) {
  return {ab(1, 2) - ab(2, 1), ab(2, 0) - ab(0, 2), ab(0, 1) - ab(1, 0)};
}

}  // namespace

void ValidateFlexibleBodyModes(const std::string& body, const FlexibleBodyModes& m) {
  const std::string what = "flexible body '" + body + "': ";
  const int n = m.nf;
  if (n < 0) Fail(what + "nf = " + std::to_string(n) + " is negative");
  if (!(m.mass > 0) || !std::isfinite(m.mass))
    Fail(what + "mass must be positive, got " + std::to_string(m.mass));
  auto size = [&](const std::string& field, long rows, long cols, long want_rows, long want_cols) {
    if (rows != want_rows || cols != want_cols) {
      std::ostringstream s;
      s << what << field << " is " << rows << " x " << cols << ", expected " << want_rows << " x "
        << want_cols << " for nf = " << n;
      Fail(s.str());
    }
  };
  size("I2", m.I2.rows(), m.I2.cols(), 3, n);
  size("I4", static_cast<long>(m.I4.size()), 1, n, 1);
  size("I5", static_cast<long>(m.I5.size()), 1, static_cast<long>(n) * n, 1);
  size("stiffness", m.stiffness.rows(), m.stiffness.cols(), n, n);
  if (m.damping.size() > 0) size("damping", m.damping.rows(), m.damping.cols(), n, n);
  if (!m.geometric_stiffness.empty()) {
    size("geometric_stiffness (count)", static_cast<long>(m.geometric_stiffness.size()), 1, 6, 1);
    for (const auto& g : m.geometric_stiffness) size("geometric_stiffness", g.rows(), g.cols(), n, n);
  }
  if (!m.I1.allFinite() || !m.I3.allFinite() || !m.I2.allFinite() || !m.stiffness.allFinite())
    Fail(what + "invariants or stiffness are not finite");
  if ((m.stiffness - m.stiffness.transpose()).norm() > 1e-9 * (1 + m.stiffness.norm()))
    Fail(what + "modal stiffness is not symmetric");
  if (n > 0) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m.stiffness);
    if (eig.eigenvalues().minCoeff() < -1e-9 * (1 + eig.eigenvalues().cwiseAbs().maxCoeff()))
      Fail(what + "modal stiffness is not positive semi-definite (smallest eigenvalue " +
           std::to_string(eig.eigenvalues().minCoeff()) + ")");
    Eigen::MatrixXd M(n, n);
    for (int k = 0; k < n; ++k)
      for (int l = 0; l < n; ++l) M(k, l) = m.I5[k * n + l].trace();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> em(0.5 * (M + M.transpose()));
    if (!(em.eigenvalues().minCoeff() > 0))
      Fail(what + "modal mass tr(I5) is not positive definite: the modes are dependent");
  }
  for (size_t i = 0; i < m.nodes.size(); ++i) {
    const auto& node = m.nodes[i];
    if (node.translation_shapes.cols() != n ||
        (node.rotation_shapes.size() > 0 && node.rotation_shapes.cols() != n))
      Fail(what + "node " + std::to_string(node.id) + " has shapes for " +
           std::to_string(node.translation_shapes.cols()) + " modes, expected " + std::to_string(n));
  }
  for (const auto& [name, set] : m.node_sets)
    for (int i : set)
      if (i < 0 || i >= static_cast<int>(m.nodes.size()))
        Fail(what + "node set '" + name + "' refers to node index " + std::to_string(i) +
             " outside the " + std::to_string(m.nodes.size()) + " nodes");
  for (const auto& t : m.surface_triangles)
    for (int i : t)
      if (i < 0 || i >= static_cast<int>(m.nodes.size()))
        Fail(what + "surface triangle refers to node index " + std::to_string(i));
  if (!m.stress_nodes.empty())
    size("stress_modes", m.stress_modes.rows(), m.stress_modes.cols(),
         6 * static_cast<long>(m.stress_nodes.size()), n);
}

BodyIndex ModelBuilder::AddFlexibleBody(const std::string& name,
                                        std::shared_ptr<const FlexibleBodyModes> modes,
                                        const FlexibleBodyOptions& options) {
  if (!modes) Fail("flexible body '" + name + "': no modes given");
  ValidateFlexibleBodyModes(name, *modes);
  const FlexibleBodyModes& m = *modes;
  const std::string what = "flexible body '" + name + "': ";
  if (options.geometric_stiffening && m.geometric_stiffness.empty())
    Fail(what + "geometric stiffening asked for, but the reduced body has no geometric stiffness "
                "(reduce it with geometric stiffness)");
  if (!options.damping_ratios.empty() && options.damping_ratios.size() != 1 &&
      static_cast<int>(options.damping_ratios.size()) != m.nf)
    Fail(what + std::to_string(options.damping_ratios.size()) + " damping ratios for " +
         std::to_string(m.nf) + " modes (give 1 or " + std::to_string(m.nf) + ")");
  for (double z : options.damping_ratios)
    if (!(z >= 0) || !std::isfinite(z)) Fail(what + "damping ratio " + std::to_string(z) + " is not >= 0");
  for (const std::string& set : options.record_node_sets)
    if (!m.node_sets.count(set)) {
      std::string known;
      for (const auto& [name, nodes] : m.node_sets) known += (known.empty() ? "" : ", ") + name;
      Fail(what + "no node set '" + set + "' to record (the reduced body has: " + known + ")");
    }
  if (options.rayleigh_alpha < 0 || options.rayleigh_beta < 0)
    Fail(what + "Rayleigh coefficients must be >= 0");
  // Undeformed mass properties: com = I1 / m, inertia about B's origin tr(I3) 1 - I3.
  const Vec3 com = m.I1 / m.mass;
  Mat3 J0 = -m.I3;
  J0.diagonal().array() += m.I3.trace();
  Mat3 Jc = J0 - m.mass * (com.squaredNorm() * Mat3::Identity() - com * com.transpose());
  Jc = 0.5 * (Jc + Jc.transpose()).eval();
  const BodyIndex b = AddBody(name, m.mass, com, Jc);
  FlexibleBody fb;
  fb.body = b;
  fb.modes = modes;
  fb.options = options;
  model_->bodies[b].flexible = static_cast<int>(model_->flexible_bodies.size());
  model_->flexible_bodies.push_back(std::move(fb));
  modal_q_.emplace_back();
  modal_v_.emplace_back();
  return b;
}

void ModelBuilder::SetModalCoordinates(BodyIndex body, const Eigen::VectorXd& q_f,
                                       const Eigen::VectorXd& v_f) {
  if (body < 0 || body >= num_bodies() || model_->bodies[body].flexible < 0)
    Fail("SetModalCoordinates: body index " + std::to_string(body) + " is not a flexible body");
  const int i = model_->bodies[body].flexible;
  const int n = model_->flexible_bodies[i].modes->nf;
  const std::string& name = model_->bodies[body].name;
  if (q_f.size() != n || v_f.size() != n || !q_f.allFinite() || !v_f.allFinite())
    Fail("flexible body '" + name + "': initial modal coordinates need " + std::to_string(n) +
         " finite values each");
  modal_q_[i] = q_f;
  modal_v_[i] = v_f;
}

FrameIndex ModelBuilder::AddNodeFrame(const std::string& name, BodyIndex body, int node,
                                      const Transform& X_BF) {
  if (body < 0 || body >= num_bodies() || model_->bodies[body].flexible < 0)
    Fail("frame '" + name + "': body index " + std::to_string(body) + " is not a flexible body");
  const FlexibleBodyModes& m = *model_->flexible_bodies[model_->bodies[body].flexible].modes;
  if (node < 0 || node >= static_cast<int>(m.nodes.size()))
    Fail("frame '" + name + "': flexible body '" + model_->bodies[body].name + "' has no node index " +
         std::to_string(node) + " (it has " + std::to_string(m.nodes.size()) + " nodes)");
  const FrameIndex f = AddFrame(name, body, X_BF);
  model_->frames[f].node = node;
  model_->frames[f].is_body_frame = false;
  return f;
}

int ModelBuilder::FindNode(BodyIndex body, int id) const {
  if (body < 0 || body >= num_bodies() || model_->bodies[body].flexible < 0)
    Fail("FindNode: body index " + std::to_string(body) + " is not a flexible body");
  const FlexibleBodyModes& m = *model_->flexible_bodies[model_->bodies[body].flexible].modes;
  for (size_t i = 0; i < m.nodes.size(); ++i)
    if (m.nodes[i].id == id) return static_cast<int>(i);
  Fail("flexible body '" + model_->bodies[body].name + "' has no node with id " + std::to_string(id));
}

void ModelBuilder::AddExternalForce(std::shared_ptr<const ExternalForceElement> element) {
  if (!element) Fail("AddExternalForce: no element given");
  CheckName("external force element", element->name());
  for (const auto& e : model_->external_forces)
    if (e->name() == element->name())
      Fail("external force element '" + element->name() + "': name already used");
  model_->external_forces.push_back(std::move(element));
}

void ModelBuilder::FinalizeFlexibleBodies() {
  Model& model = *model_;
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    FlexibleBody& fb = model.flexible_bodies[i];
    const FlexibleBodyModes& m = *fb.modes;
    const int n = fb.options.frozen ? 0 : m.nf;
    fb.nf = n;
    fb.q_start = model.nq;
    fb.v_start = model.nv;
    model.nq += n;
    model.nv += n;
    fb.mass.resize(n, n);
    for (int k = 0; k < n; ++k)
      for (int l = 0; l < n; ++l) fb.mass(k, l) = m.I5[k * m.nf + l].trace();
    fb.stiffness = m.stiffness.topLeftCorner(n, n);
    if (m.damping.size() > 0) {
      fb.damping = m.damping.topLeftCorner(n, n);
    } else {
      fb.damping = fb.options.rayleigh_alpha * fb.mass + fb.options.rayleigh_beta * fb.stiffness;
      const auto& z = fb.options.damping_ratios;
      for (int k = 0; k < n && !z.empty(); ++k)
        fb.damping(k, k) += 2 * (z.size() == 1 ? z[0] : z[k]) *
                            std::sqrt(std::max(fb.stiffness(k, k), 0.0) * fb.mass(k, k));
    }
    fb.mode_cross.resize(static_cast<size_t>(n) * n);
    for (int a = 0; a < n; ++a)
      for (int l = 0; l < n; ++l) fb.mode_cross[a * n + l] = Axial(m.I5[a * m.nf + l]);
    fb.geometric_stiffening = fb.options.geometric_stiffening && n > 0;
  }
}

}  // namespace orrery

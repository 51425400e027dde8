#include "mbd/flexible_dynamics.h"

#include <cstring>

namespace orrery {
namespace {

// int rho (a x b) from int rho a b^T: (a x b)_i = eps_ijk a_j b_k.
inline Vec3 Axial(const Mat3& ab) {
  return {ab(1, 2) - ab(2, 1), ab(2, 0) - ab(0, 2), ab(0, 1) - ab(1, 0)};
}

// The O(nf^2) sums over the modal coordinates are matrix-vector products over the invariants as
// they are stored: a std::vector<Mat3> (or <Vec3>) holds its entries one after another, each
// column-major, so m.I4 is a 9 x nf matrix (column l = vec I4_l), the I5_kl of one k a column of
// 9 nf entries (column k of a 9 nf x nf matrix with leading dimension 9 N), and fb.mode_cross a
// 3 nf x nf matrix (column k = mode_cross_k0 ... mode_cross_k,nf-1). Data's D (3 x 3 nf) is, in
// memory, vec D_0 ... vec D_nf-1: a 9 x nf matrix.
static_assert(sizeof(Mat3) == 9 * sizeof(double) && sizeof(Vec3) == 3 * sizeof(double),
              "Mat3 and Vec3 hold their entries without padding");
using Nine = Eigen::Matrix<double, 9, 1>;
using NineByN = Eigen::Map<const Eigen::Matrix<double, 9, Eigen::Dynamic>>;

// The same coordinates, bit for bit (a cache's key: -0 and +0 differ, so a cached result is
// always the one the stage would make).
inline bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() &&
         (a.size() == 0 ||
          std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0);
}

// Four doubles as one value (GCC and Clang vector extensions): one AVX register, or two SSE2
// registers in the baseline build. Lane-wise + and * are IEEE operations on each lane.
typedef double Lanes4 __attribute__((vector_size(32)));

// Four doubles from anywhere (unaligned), through memory: a vector is not passed by value
// (its ABI differs between the builds).
__attribute__((always_inline)) inline void Load4(Lanes4* v, const double* p) {
  std::memcpy(v, p, sizeof *v);
}

// Rows [i, i + 4 kVecs) of AddColumnCombination, held in registers across the columns (so A is
// read once and y written once), each lane the plain sequential sum of its row. Inlined into
// each build of the kernel, so it takes that build's vector width.
template <int kVecs>
__attribute__((always_inline)) inline void CombineRows(int i, int cols, const double* A, long lda,
                                                       const double* x, const double* b,
                                                       double* y) {
  Lanes4 acc[kVecs];
  for (int j = 0; j < kVecs; ++j) {
    acc[j] = Lanes4{0, 0, 0, 0};
    if (b) Load4(&acc[j], b + i + 4 * j);
  }
  for (int k = 0; k < cols; ++k) {
    const double* a = A + k * lda + i;
    const Lanes4 xk = {x[k], x[k], x[k], x[k]};
    for (int j = 0; j < kVecs; ++j) {
      Lanes4 column;
      Load4(&column, a + 4 * j);
      acc[j] += column * xk;
    }
  }
  std::memcpy(y + i, acc, sizeof acc);
}

__attribute__((always_inline)) inline void CombineColumns(int rows, int cols, const double* A,
                                                          long lda, const double* x,
                                                          const double* b, double* y) {
  int i = 0;
  for (; i + 16 <= rows; i += 16) CombineRows<4>(i, cols, A, lda, x, b, y);
  if (i + 8 <= rows) CombineRows<2>(i, cols, A, lda, x, b, y), i += 8;
  if (i + 4 <= rows) CombineRows<1>(i, cols, A, lda, x, b, y), i += 4;
  for (; i < rows; ++i) {
    double acc = b ? b[i] : 0.0;
    for (int k = 0; k < cols; ++k) acc += A[k * lda + i] * x[k];
    y[i] = acc;
  }
}

// B's angular velocity, angular acceleration and the acceleration of its origin, in B axes
// (classical vectors from the spatial, world-origin, V_WB and A_WB).
struct FrameMotion {
  Vec3 w, alpha, a;
};
inline FrameMotion MotionInBodyAxes(const Data& data, BodyIndex b) {
  const Transform& X = data.X_WB[b];
  const Vec6& V = data.V_WB[b];
  const Vec6& A = data.A_WB[b];
  const Vec3 w_W = V.head<3>();
  const Vec3 v_o = V.tail<3>() + w_W.cross(X.p);
  const Vec3 a_o = A.tail<3>() + A.head<3>().cross(X.p) + w_W.cross(v_o);
  const Mat3 RT = X.R.transpose();
  return {RT * w_W, RT * A.head<3>(), RT * a_o};
}

}  // namespace

void AddColumnCombinationBaseline(int rows, int cols, const double* A, long lda, const double* x,
                                  const double* b, double* y) {
  CombineColumns(rows, cols, A, lda, x, b, y);
}

#if ORRERY_COLUMN_COMBINATION_AVX
__attribute__((target("avx"))) void AddColumnCombinationAvx(int rows, int cols, const double* A,
                                                            long lda, const double* x,
                                                            const double* b, double* y) {
  CombineColumns(rows, cols, A, lda, x, b, y);
}
#endif

void AddColumnCombination(int rows, int cols, const double* A, long lda, const double* x,
                          const double* b, double* y) {
#if ORRERY_COLUMN_COMBINATION_AVX
  static const bool avx = __builtin_cpu_supports("avx");
  if (avx) return AddColumnCombinationAvx(rows, cols, A, lda, x, b, y);
#endif
  AddColumnCombinationBaseline(rows, cols, A, lda, x, b, y);
}

void CalcFlexibleInertiaTerms(const Model& model, Data& data) {
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    const FlexibleBodyModes& m = *fb.modes;
    Data::FlexibleBodyTerms& T = data.flex[i];
    const int n = fb.nf, N = m.nf;
    // First moment S = I1 + I2 q, D_l = I4_l + sum_k q_k I5_kl (one 9 nf x nf product),
    // U = I3 + sum_l q_l (I4_l^T + D_l), J = tr(U) 1 - U. Made again only at other modal
    // coordinates.
    if (!T.D_made || !SameBits(T.qf, T.qf_of_D)) {
      T.S = m.I1;  // + I2 q below
      Mat3 U = m.I3;
      if (n > 0) {
        AddColumnCombination(3, n, m.I2.data(), 3, T.qf.data(), m.I1.data(), T.S.data());
        AddColumnCombination(9 * n, n, m.I5[0].data(), 9L * N, T.qf.data(), m.I4[0].data(),
                             T.D.data());
        Nine I4q, Dq;
        AddColumnCombination(9, n, m.I4[0].data(), 9, T.qf.data(), nullptr, I4q.data());
        AddColumnCombination(9, n, T.D.data(), 9, T.qf.data(), nullptr, Dq.data());
        U += Eigen::Map<const Mat3>(I4q.data()).transpose() + Eigen::Map<const Mat3>(Dq.data());
        for (int l = 0; l < n; ++l) T.L.col(l) = Axial(T.D.block<3, 3>(0, 3 * l));
      }
      T.J = -U;
      T.J.diagonal().array() += U.trace();
      T.qf_of_D = T.qf;
      T.D_made = true;
    }
    // Deformed spatial inertia about the world origin.
    const Transform& X = data.X_WB[fb.body];
    const Vec3 c = T.S / m.mass;
    const Mat3 Jc = T.J - m.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
    data.I_W[fb.body] = SpatialInertia::FromCentral(m.mass, X * c, X.R * Jc * X.R.transpose());
    // Spatial force on B per unit modal acceleration: (R L_l + p x R I2_l, R I2_l).
    for (int l = 0; l < n; ++l) {
      const Vec3 f = X.R * m.I2.col(l);
      T.F_W.col(l) << X.R * T.L.col(l) + X.p.cross(f), f;
    }
  }
}

void CalcNodeFramePoses(const Model& model, const Eigen::VectorXd& q, Data& data) {
  if (model.flexible_bodies.empty()) return;
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    data.flex[i].qf = q.segment(fb.q_start, fb.nf);
  }
  // Frames on nodes: origin at x_P + Phi_P q + R_theta d, axes R_theta R_BF0, theta = Psi_P q.
  for (size_t f = 0; f < model.frames.size(); ++f) {
    const Frame& frame = model.frames[f];
    if (frame.node < 0) continue;
    const int i = model.bodies[frame.body].flexible;
    const FlexibleBody& fb = model.flexible_bodies[i];
    const FlexibleBodyModes::Node& node = fb.modes->nodes[frame.node];
    const int n = fb.nf;
    const Eigen::VectorXd& qf = data.flex[i].qf;
    const Vec3 u = node.translation_shapes.leftCols(n) * qf;
    const bool rotates = node.rotation_shapes.size() > 0;
    const Vec3 theta = rotates ? Vec3(node.rotation_shapes.leftCols(n) * qf) : Vec3::Zero();
    const double angle = theta.norm();
    const Mat3 R_theta = angle > 0 ? AxisAngle(theta / angle, angle) : Mat3::Identity();
    const Vec3 d = R_theta * (frame.X_BF.p - node.position);
    const Transform X_BF(R_theta * frame.X_BF.R, node.position + u + d);
    const Transform& X_WB = data.X_WB[frame.body];
    data.X_WFrame[f] = X_WB * X_BF;
    const Vec3& p_W = data.X_WFrame[f].p;
    auto& J = data.J_frame_modal[f];
    for (int k = 0; k < n; ++k) {
      const Vec3 psi = rotates ? Vec3(node.rotation_shapes.col(k)) : Vec3::Zero();
      const Vec3 w = X_WB.R * psi;
      const Vec3 v_point = X_WB.R * (node.translation_shapes.col(k) + psi.cross(d));
      J.col(k) << w, v_point + p_W.cross(w);
    }
  }
}

void CalcFrameVelocities(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& v, Data& data) {
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    data.flex[i].qf_dot = v.segment(fb.v_start, fb.nf);
  }
  for (size_t f = 0; f < model.frames.size(); ++f) {
    const Frame& frame = model.frames[f];
    data.V_WFrame[f] = data.V_WB[frame.body];
    if (frame.node >= 0) {
      const int i = model.bodies[frame.body].flexible;
      data.V_WFrame[f].noalias() += data.J_frame_modal[f] * data.flex[i].qf_dot;
    }
  }
}

std::pair<double, double> CalcFlexibleInternalForces(const Model& model, Data& data) {
  double energy = 0, dissipated = 0;
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    const int n = fb.nf;
    if (n == 0) continue;
    Data::FlexibleBodyTerms& T = data.flex[i];
    auto tau = data.tau_applied.segment(fb.v_start, n);
    AddColumnCombination(n, n, fb.stiffness.data(), n, T.qf.data(), nullptr, T.scratch.data());
    energy += 0.5 * T.qf.dot(T.scratch);
    tau -= T.scratch;
    AddColumnCombination(n, n, fb.damping.data(), n, T.qf_dot.data(), nullptr, T.scratch.data());
    dissipated += T.qf_dot.dot(T.scratch);
    tau -= T.scratch;
    if (fb.geometric_stiffening) {
      // K_g = sum_c p_c(omega) G_c with omega in B (flexible_body.h).
      const Vec3 w = data.X_WB[fb.body].R.transpose() * data.V_WB[fb.body].head<3>();
      const double p[6] = {w.x() * w.x(), w.y() * w.y(), w.z() * w.z(),
                           w.x() * w.y(), w.y() * w.z(), w.z() * w.x()};
      const auto& G = fb.modes->geometric_stiffness;
      T.K_geo.setZero();
      for (int c = 0; c < 6; ++c) T.K_geo.noalias() += p[c] * G[c].topLeftCorner(n, n);
      T.scratch.noalias() = T.K_geo * T.qf;
      tau -= T.scratch;
    }
  }
  return {energy, dissipated};
}

Vec6 CalcFlexibleBodyForce(const Model& model, const FlexibleBody& fb,
                           const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data) {
  const int i = model.bodies[fb.body].flexible;
  const FlexibleBodyModes& m = *fb.modes;
  Data::FlexibleBodyTerms& T = data.flex[i];
  const int n = fb.nf;
  const Transform& X = data.X_WB[fb.body];
  const FrameMotion motion = MotionInBodyAxes(data, fb.body);
  const Vec3 &w = motion.w, &alpha = motion.alpha, &a = motion.a;
  const auto qd = T.qf_dot.head(n);
  const auto qdd = vdot.segment(fb.v_start, n);
  const Vec3 Sw = w.cross(T.S);
  Vec3 F = m.mass * a + alpha.cross(T.S) + w.cross(Sw);
  Vec3 N = T.S.cross(a) + T.J * alpha + w.cross(T.J * w);
  if (n > 0) {
    Vec3 I2qd, I2qdd, Lqdd;
    AddColumnCombination(3, n, m.I2.data(), 3, qd.data(), nullptr, I2qd.data());
    AddColumnCombination(3, n, m.I2.data(), 3, qdd.data(), nullptr, I2qdd.data());
    AddColumnCombination(3, n, T.L.data(), 3, qdd.data(), nullptr, Lqdd.data());
    const NineByN D(T.D.data(), 9, n);
    Nine Cv;  // C = sum_l qd_l D_l
    AddColumnCombination(9, n, T.D.data(), 9, qd.data(), nullptr, Cv.data());
    const Eigen::Map<const Mat3> C(Cv.data());
    F.noalias() += 2 * w.cross(I2qd) + I2qdd;
    N.noalias() += 2 * (C.trace() * w - C.transpose() * w) + Lqdd;
    // Modal rows: r_l = M_l qdd + I2_l . a + L_l . alpha + w^T D_l w - |w|^2 tr D_l + 2 w . g_l,
    // the two D_l terms as one product with vec(w w^T - |w|^2 1); g_l made again only at other
    // modal rates.
    if (!T.G_made || !SameBits(T.qf_dot, T.qf_dot_of_G)) {
      AddColumnCombination(3 * n, n, fb.mode_cross[0].data(), 3L * n, T.qf_dot.data(), nullptr,
                           T.G.data());
      T.qf_dot_of_G = T.qf_dot;
      T.G_made = true;
    }
    double* r = data.tau_id.data() + fb.v_start;
    AddColumnCombination(n, n, fb.mass.data(), n, qdd.data(), nullptr, r);
    Mat3 W = w * w.transpose();
    W.diagonal().array() -= w.squaredNorm();
    const Eigen::Map<const Nine> Wv(W.data());
    const Vec3 w2 = 2 * w;
    for (int l = 0; l < n; ++l)
      r[l] += m.I2.col(l).dot(a) + T.L.col(l).dot(alpha) + D.col(l).dot(Wv) + T.G.col(l).dot(w2);
  }
  const Vec3 F_W = X.R * F;
  Vec6 f;
  f << X.R * N + X.p.cross(F_W), F_W;
  return f - data.f_ext[fb.body];
}

void AddFlexibleMassMatrix(const Model& model, Data& data) {
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    const int n = fb.nf;
    if (n == 0) continue;
    const auto& F = data.flex[i].F_W;
    for (JointIndex j = model.bodies[fb.body].parent_joint; j >= 0;
         j = model.bodies[model.joints[j].spec.parent].parent_joint) {
      const Joint& jt = model.joints[j];
      for (int r = 0; r < jt.nv; ++r)
        for (int k = 0; k < n; ++k) {
          const double value = data.S.col(jt.v_start + r).dot(F.col(k));
          data.M(jt.v_start + r, fb.v_start + k) = value;
          data.M(fb.v_start + k, jt.v_start + r) = value;
        }
    }
    data.M.block(fb.v_start, fb.v_start, n, n) = fb.mass;
  }
}

double FlexibleKineticEnergy(const Model& model, const Data& data) {
  double T = 0;
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i) {
    const FlexibleBody& fb = model.flexible_bodies[i];
    if (fb.nf == 0) continue;
    const auto& qd = data.flex[i].qf_dot;
    const Vec6 h = data.flex[i].F_W * qd;  // fixed size: no temporary on the heap
    double modal = 0;
    for (int k = 0; k < fb.nf; ++k) modal += qd(k) * fb.mass.col(k).dot(qd);
    T += data.V_WB[fb.body].dot(h) + 0.5 * modal;
  }
  return T;
}

bool ModalColumnsAreLocal(const Model& model, int i) {
  const BodyIndex body = model.flexible_bodies[i].body;
  for (const Joint& jt : model.joints)
    if (jt.spec.parent == body) return false;
  for (const auto& element : model.external_forces)
    if (!element->HasTangents()) return false;
  // Every frame an element of the model reads (joints read none: their offsets are rigid in B).
  auto on_node = [&](FrameIndex f) {
    return f >= 0 && model.frames[f].body == body && model.frames[f].node >= 0;
  };
  for (const auto& l : model.applied_loads)
    if (on_node(l.frame)) return false;
  for (const auto& s : model.translational_springs)
    if (on_node(s.frame_a) || on_node(s.frame_b)) return false;
  for (const auto& s : model.rotational_springs)
    if (on_node(s.frame_a) || on_node(s.frame_b)) return false;
  for (const auto& s : model.bushings)
    if (on_node(s.frame_a) || on_node(s.frame_b)) return false;
  for (const auto& s : model.bearings)
    if (on_node(s.frame_a) || on_node(s.frame_b)) return false;
  for (const auto& c : model.loop_closures)
    if (on_node(c.frame_a) || on_node(c.frame_b)) return false;
  for (const auto& g : model.gear_meshes)
    if (on_node(g.spec.gear_a) || on_node(g.spec.gear_b) || on_node(g.spec.reference)) return false;
  for (const auto& g : model.gear_constraints)
    if (on_node(g.spec.gear_a) || on_node(g.spec.gear_b) || on_node(g.spec.reference)) return false;
  return true;
}

void SetFlexibleModalTangents(const Model& model, const Data& data, int i,
                              const Eigen::Ref<const Eigen::VectorXd>& vdot,
                              Eigen::Ref<Eigen::MatrixXd> Kq, Eigen::Ref<Eigen::MatrixXd> Cv) {
  const FlexibleBody& fb = model.flexible_bodies[i];
  const FlexibleBodyModes& m = *fb.modes;
  const Data::FlexibleBodyTerms& T = data.flex[i];
  const int n = fb.nf, N = m.nf, v0 = fb.v_start;
  if (n == 0) return;
  const Transform& X = data.X_WB[fb.body];
  const FrameMotion motion = MotionInBodyAxes(data, fb.body);
  const Vec3 &w = motion.w, &alpha = motion.alpha, &a = motion.a;
  const auto qdd = vdot.segment(v0, n);
  // The modal rows' q_f-dependent terms L_l . alpha + D_l : (w w^T - |w|^2 1) are linear in D_l
  // (L_l = axial D_l): d/dq_k = vec(I5_kl) . z with z = vec(w w^T - |w|^2 1) plus alpha's part
  // of the axial vector (ab(1,2) - ab(2,1), ab(2,0) - ab(0,2), ab(0,1) - ab(1,0); column-major
  // vec indices 7 - 5, 2 - 6, 3 - 1).
  Mat3 W = w * w.transpose();
  W.diagonal().array() -= w.squaredNorm();
  Nine z = Eigen::Map<const Nine>(W.data());
  z(7) += alpha.x();
  z(5) -= alpha.x();
  z(2) += alpha.y();
  z(6) -= alpha.y();
  z(3) += alpha.z();
  z(1) -= alpha.z();
  // A column's spatial force (world origin, as CalcFlexibleBodyForce returns it) on the rows of
  // the ancestors' coordinates.
  auto set_ancestor_rows = [&](const Vec3& dN, const Vec3& dF, auto column) {
    const Vec3 F_W = X.R * dF;
    Vec6 f;
    f << X.R * dN + X.p.cross(F_W), F_W;
    for (JointIndex j = model.bodies[fb.body].parent_joint; j >= 0;
         j = model.bodies[model.joints[j].spec.parent].parent_joint) {
      const Joint& jt = model.joints[j];
      for (int r = 0; r < jt.nv; ++r) column(jt.v_start + r) = data.S.col(jt.v_start + r).dot(f);
    }
  };
  for (int k = 0; k < n; ++k) {
    // The I5_kl of this k (l < n) as a 9 x n matrix; its combinations with q_f, q_f-dot and
    // q_f-ddot: sum_l x_l I5_kl.
    const double* I5k = m.I5[static_cast<size_t>(k) * N].data();
    Nine Eq, Eqd, Eqdd;
    AddColumnCombination(9, n, I5k, 9, T.qf.data(), nullptr, Eq.data());
    AddColumnCombination(9, n, I5k, 9, T.qf_dot.data(), nullptr, Eqd.data());
    AddColumnCombination(9, n, I5k, 9, qdd.data(), nullptr, Eqdd.data());
    const Eigen::Map<const Mat3> D_k(T.D.data() + 9 * k);
    const Vec3 I2_k = m.I2.col(k);

    // Position column: dS = I2_k, dU = I4_k^T + D_k + sum_l q_l I5_kl, dJ = tr(dU) 1 - dU,
    // dC = sum_l qd_l I5_kl, d(L qdd) = axial(sum_l qdd_l I5_kl); a, alpha, w do not move.
    const Mat3 dU = m.I4[k].transpose() + D_k + Eigen::Map<const Mat3>(Eq.data());
    Mat3 dJ = -dU;
    dJ.diagonal().array() += dU.trace();
    const Eigen::Map<const Mat3> dC(Eqd.data());
    const Vec3 dF = alpha.cross(I2_k) + w.cross(w.cross(I2_k));
    const Vec3 dN = I2_k.cross(a) + dJ * alpha + w.cross(dJ * w) +
                    2 * (dC.trace() * w - dC.transpose() * w) +
                    Axial(Eigen::Map<const Mat3>(Eqdd.data()));
    auto kq = Kq.col(v0 + k);
    kq.setZero();
    set_ancestor_rows(dN, dF, kq);
    for (int l = 0; l < n; ++l)
      kq(v0 + l) = Eigen::Map<const Nine>(I5k + 9 * l).dot(z) + fb.stiffness(l, k);
    if (fb.geometric_stiffening) kq.segment(v0, n) += T.K_geo.col(k);

    // Rate column: the Coriolis terms 2 w x I2 q_f-dot, 2 (tr C 1 - C^T) w with C = sum_l qd_l D_l,
    // the modal rows' 2 w . sum_m qd_m mode_cross_ml, and the damping.
    auto cv = Cv.col(v0 + k);
    cv.setZero();
    set_ancestor_rows(2 * (D_k.trace() * w - D_k.transpose() * w), 2 * w.cross(I2_k), cv);
    const Vec3* cross_k = fb.mode_cross.data() + static_cast<size_t>(k) * n;
    for (int l = 0; l < n; ++l) cv(v0 + l) = 2 * w.dot(cross_k[l]) + fb.damping(l, k);
  }
}

Vec6 CalcSpatialMomentum(const Model& model, const Data& data) {
  Vec6 h = Vec6::Zero();
  for (BodyIndex b = 1; b < model.nbodies; ++b) h += data.I_W[b] * data.V_WB[b];
  for (size_t i = 0; i < model.flexible_bodies.size(); ++i)
    if (model.flexible_bodies[i].nf > 0) h += data.flex[i].F_W * data.flex[i].qf_dot;
  return h;
}

}  // namespace orrery

#include "mbd/constraints.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "mbd/gear_mesh.h"
#include "mbd/kinematics.h"

namespace orrery {
namespace {

// Adds c . V_body (V = J_body v) to row `row` of G: c^T S_j over the body's ancestor joints.
void AddBodyRow(const Model& model, Data& data, int row, BodyIndex body, const Vec6& c) {
  for (JointIndex j = model.bodies[body].parent_joint; j >= 0;
       j = model.bodies[model.joints[j].spec.parent].parent_joint) {
    const Joint& jt = model.joints[j];
    for (int k = 0; k < jt.nv; ++k) data.G(row, jt.v_start + k) += c.dot(data.S.col(jt.v_start + k));
  }
}

// The same for a frame: its body's row, plus the modal columns of a frame on a flexible-body node.
void AddFrameRow(const Model& model, Data& data, int row, FrameIndex frame, const Vec6& c) {
  const BodyIndex body = model.frames[frame].body;
  AddBodyRow(model, data, row, body, c);
  const auto& J = data.J_frame_modal[frame];
  if (J.cols() == 0) return;
  const FlexibleBody& fb = model.flexible_bodies[model.bodies[body].flexible];
  for (int k = 0; k < fb.nf; ++k) data.G(row, fb.v_start + k) += c.dot(J.col(k));
}

}  // namespace

void CalcConstraints(const Model& model, double t, Data& data) {
  data.G.setZero();
  data.g_t.setZero();
  // Loop closures: rows of point coincidence, perpendicularity and in-plane distance.
  int loop_row = 0;
  for (size_t l = 0; l < model.loop_closures.size(); ++l) {
    const LoopClosureSpec& lc = model.loop_closures[l];
    const Transform& A = data.X_WFrame[lc.frame_a];
    const Transform& B = data.X_WFrame[lc.frame_b];
    int row = model.loop_row_start[l];
    auto emit = [&](double phi, const Vec6& ca, const Vec6& cb) {
      data.phi(row) = phi;
      data.c_rows_a[loop_row] = ca;
      data.c_rows_b[loop_row] = cb;
      AddFrameRow(model, data, row, lc.frame_a, ca);
      AddFrameRow(model, data, row, lc.frame_b, cb);
      ++row;
      ++loop_row;
    };
    auto point = [&]() {  // p_B - p_A = 0 in world axes
      for (int k = 0; k < 3; ++k) {
        const Vec3 e = Vec3::Unit(k);
        Vec6 ca, cb;
        ca << -A.p.cross(e), -e;
        cb << B.p.cross(e), e;
        emit(B.p(k) - A.p(k), ca, cb);
      }
    };
    auto perpendicular = [&](const Vec3& a, const Vec3& b) {  // a (on A) . b (on B) = 0
      Vec6 ca, cb;
      ca << a.cross(b), Vec3::Zero();
      cb << -a.cross(b), Vec3::Zero();
      emit(a.dot(b), ca, cb);
    };
    auto distance = [&](const Vec3& a) {  // (p_B - p_A) . a (on A) = 0
      Vec6 cb;
      cb << B.p.cross(a), a;
      emit((B.p - A.p).dot(a), -cb, cb);
    };
    // The closure type's terms (joint_types.cpp), in table order.
    const JointTypeInfo& info = JointInfo(lc.type);
    for (int t = 0; t < info.n_loop_terms; ++t) {
      const LoopTerm& term = info.loop_terms[t];
      switch (term.kind) {
        case LoopTerm::Kind::kPoint: point(); break;
        case LoopTerm::Kind::kPerpendicular:
          perpendicular(A.R.col(term.axis_a), B.R.col(term.axis_b));
          break;
        case LoopTerm::Kind::kDistance: distance(A.R.col(term.axis_a)); break;
      }
    }
  }
  // Ideal gear meshes: drive-flank deflection = 0; G row = n . (v_a(P) - v_b(P)).
  for (size_t k = 0; k < model.gear_constraints.size(); ++k) {
    const GearConstraint& gc = model.gear_constraints[k];
    const GearConstraintSpec& s = gc.spec;
    const MeshState st = CalcMeshState(gc.geometry, data, s.gear_a, s.gear_b, s.reference,
                                       s.base_radius_a, s.base_radius_b, 0.0);
    const int row = model.gear_constraint_row[k];
    Vec6 ca, cb;
    ca << st.p_a_W.cross(st.n_drive_W), st.n_drive_W;
    cb << -st.p_b_W.cross(st.n_drive_W), -st.n_drive_W;
    data.phi(row) = st.delta_drive;
    data.c_gear_a[k] = ca;
    data.c_gear_b[k] = cb;
    AddFrameRow(model, data, row, s.gear_a, ca);
    AddFrameRow(model, data, row, s.gear_b, cb);
    Vec6 cc;
    cc << -st.KSpin(st.n_drive_W) * st.z_W, Vec3::Zero();
    data.c_gear_c[k] = cc;
    AddFrameRow(model, data, row, s.reference, cc);
  }
  // Drivers: position rows q_k - f(t) (holonomic), speed rows v_k - f(t).
  for (size_t d = 0; d < model.drivers.size(); ++d) {
    const Driver& dr = model.drivers[d];
    const int row = model.driver_row[d];
    data.G(row, dr.v_index) = 1.0;
    if (dr.spec.mode == DriverSpec::Mode::kPosition) {
      data.phi(row) = data.q_normalized(dr.q_index) - dr.spec.function.Value(t);
      data.g_t(row) = -dr.spec.function.Derivative(t);
    } else {
      data.g_t(row) = -dr.spec.function.Value(t);
    }
  }
}

void AddConstraintBodyForces(const Model& model, const Data& data,
                             const Eigen::Ref<const Eigen::VectorXd>& lambda,
                             std::vector<Vec6>& f) {
  for (size_t k = 0; k < model.gear_constraints.size(); ++k) {
    const GearConstraintSpec& s = model.gear_constraints[k].spec;
    const double lam = lambda(model.gear_constraint_row[k]);
    f[model.frames[s.gear_a].body] -= lam * data.c_gear_a[k];
    f[model.frames[s.gear_b].body] -= lam * data.c_gear_b[k];
    f[model.frames[s.reference].body] -= lam * data.c_gear_c[k];
  }
  int loop_row = 0;
  for (size_t l = 0; l < model.loop_closures.size(); ++l) {
    const LoopClosureSpec& lc = model.loop_closures[l];
    const BodyIndex ba = model.frames[lc.frame_a].body, bb = model.frames[lc.frame_b].body;
    for (int r = 0; r < model.loop_rows[l]; ++r, ++loop_row) {
      const double lam = lambda(model.loop_row_start[l] + r);
      f[ba] -= lam * data.c_rows_a[loop_row];
      f[bb] -= lam * data.c_rows_b[loop_row];
    }
  }
}

std::string ConstraintRowName(const Model& model, int row) {
  for (size_t l = 0; l < model.loop_closures.size(); ++l)
    if (row >= model.loop_row_start[l] && row < model.loop_row_start[l] + model.loop_rows[l])
      return "loop closure '" + model.loop_closures[l].name + "' row " +
             std::to_string(row - model.loop_row_start[l]);
  for (size_t k = 0; k < model.gear_constraints.size(); ++k)
    if (model.gear_constraint_row[k] == row)
      return "gear constraint '" + model.gear_constraints[k].spec.name + "'";
  for (size_t d = 0; d < model.drivers.size(); ++d)
    if (model.driver_row[d] == row) return "driver '" + model.drivers[d].spec.name + "'";
  return "row " + std::to_string(row);
}

std::string DependentConstraintRows(const Model& model, const Eigen::MatrixXd& G, double relative_threshold) {
  if (G.rows() == 0 || !G.allFinite()) return "";
  // Singular values of G^T (nv x nc): its right singular vectors live in the rows' space.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(G.transpose(), Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  const double s_max = s.size() > 0 ? s(0) : 0.0;
  const Eigen::Index nc = G.rows();
  // Fewer columns than rows: G^T has nc - nv zero singular values beyond those computed.
  const double s_min = s.size() < nc ? 0.0 : s(nc - 1);
  if (!(s_min <= relative_threshold * s_max)) return "";
  const Eigen::VectorXd y = svd.matrixV().col(nc - 1);
  const double y_max = y.lpNorm<Eigen::Infinity>();
  std::string rows;
  for (Eigen::Index r = 0; r < nc; ++r) {
    if (std::abs(y(r)) < 0.1 * y_max) continue;
    if (!rows.empty()) rows += " and ";
    rows += ConstraintRowName(model, static_cast<int>(r));
  }
  std::ostringstream ratio;
  ratio << "; s_min / s_max = " << std::setprecision(3) << (s_max > 0 ? s_min / s_max : 0.0);
  return rows + ratio.str();
}

void AddConstraintForces(const Eigen::MatrixXd& G, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                         Eigen::Ref<Eigen::VectorXd> out) {
  if (G.rows() == 1) {
    out += lambda(0) * G.row(0).transpose();
    return;
  }
  out.noalias() += G.transpose() * lambda;
}

void AssembleState(const Model& model, State& state, Data& data, double tolerance) {
  NormalizeQuaternions(model, state.q);
  if (model.n_constraints == 0) return;
  const int nh = model.n_holonomic;
  // Rank check on G at the start: redundant rows make the DAE singular.
  CalcPositionKinematics(model, state.q, data);
  CalcConstraints(model, state.t, data);
  {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(data.G.transpose());
    qr.setThreshold(1e-10);
    if (qr.rank() < model.n_constraints) {
      // Name the first row that depends on the ones before it.
      std::string culprit;
      for (int r = 1; r <= model.n_constraints; ++r) {
        Eigen::ColPivHouseholderQR<Eigen::MatrixXd> sub(data.G.topRows(r).transpose());
        sub.setThreshold(1e-10);
        if (sub.rank() < r) {
          culprit = ConstraintRowName(model, r - 1);
          break;
        }
      }
      throw std::runtime_error(
          "constraints are redundant at the initial configuration (" + culprit +
          " depends on the rows before it); use a cut joint with fewer rows, e.g. a spherical "
          "cut with a universal joint in the loop");
    }
  }
  // Positions: q <- q (+) dv with dv the minimum-norm Gauss-Newton step.
  double scale = 1.0;
  for (int k = 0; k < model.nq; ++k) scale = std::max(scale, std::abs(state.q(k)));
  bool converged = nh == 0;
  for (int it = 0; it < 50 && nh > 0; ++it) {
    CalcPositionKinematics(model, state.q, data);
    CalcConstraints(model, state.t, data);
    const double err = data.phi.lpNorm<Eigen::Infinity>();
    if (err <= tolerance * scale) {
      converged = true;
      break;
    }
    const Eigen::MatrixXd Gh = data.G.topRows(nh);
    const Eigen::VectorXd dv = Gh.completeOrthogonalDecomposition().solve(-data.phi);
    IntegratePositions(model, dv, state.q);
  }
  if (!converged) {
    Eigen::Index worst;
    data.phi.cwiseAbs().maxCoeff(&worst);
    throw std::runtime_error("initial assembly did not converge: " +
                             ConstraintRowName(model, static_cast<int>(worst)) + " violated by " +
                             std::to_string(std::abs(data.phi(worst))));
  }
  // Velocities: minimum-norm correction onto G v + g_t = 0.
  CalcPositionKinematics(model, state.q, data);
  CalcConstraints(model, state.t, data);
  const Eigen::VectorXd residual = data.G * state.v + data.g_t;
  state.v -= data.G.completeOrthogonalDecomposition().solve(residual);
}

}  // namespace orrery

#include "contact/flexible_gear_mesh.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include "contact/flexible_contact_element.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "flex/geometric_stiffness.h"
#include "contact/triangle_geometry.h"
#include "models/mesh_stiffness.h"

namespace orrery::contact {

namespace {

constexpr double kPi = 3.14159265358979323846;

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Angle wrapped to (-pi, pi].
double Wrap(double a) { return a - 2 * kPi * std::round(a / (2 * kPi)); }

// Tooth of a gear with z teeth holding the point p (gear frame).
int ToothOf(const Vec3& p, int z) {
  const int k = static_cast<int>(std::lround(std::atan2(p.y(), p.x()) * z / (2 * kPi)));
  return ((k % z) + z) % z;
}

// 8-node serendipity face: corners 0-3 at (xi, eta) = (-1,-1), (1,-1), (1,1), (-1,1), midsides
// 4-7 on the edges 0-1, 1-2, 2-3, 3-0. Shape functions and their derivatives.
void Serendipity(double x, double e, double N[8], double Nx[8], double Ne[8]) {
  static const double cx[4] = {-1, 1, 1, -1}, ce[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    const double a = x * cx[i], b = e * ce[i];
    N[i] = 0.25 * (1 + a) * (1 + b) * (a + b - 1);
    Nx[i] = 0.25 * cx[i] * (1 + b) * (2 * a + b);
    Ne[i] = 0.25 * ce[i] * (1 + a) * (a + 2 * b);
  }
  // Midsides at eta = -1 (4), xi = 1 (5), eta = 1 (6), xi = -1 (7).
  N[4] = 0.5 * (1 - x * x) * (1 - e), Nx[4] = -x * (1 - e), Ne[4] = -0.5 * (1 - x * x);
  N[5] = 0.5 * (1 + x) * (1 - e * e), Nx[5] = 0.5 * (1 - e * e), Ne[5] = -e * (1 + x);
  N[6] = 0.5 * (1 - x * x) * (1 + e), Nx[6] = -x * (1 + e), Ne[6] = 0.5 * (1 - x * x);
  N[7] = 0.5 * (1 - x) * (1 - e * e), Nx[7] = -0.5 * (1 - e * e), Ne[7] = -e * (1 - x);
}

// Boundary faces of a hex20 mesh as 8 node indices in the order of Serendipity() (CalculiX
// hex20: corners 0-7, midsides 8-11 (0-1, 1-2, 2-3, 3-0), 12-15 (4-5, 5-6, 6-7, 7-4), 16-19 (0-4,
// 1-5, 2-6, 3-7)).
std::vector<std::array<int, 8>> BoundaryFaces8(const flex::FeMesh& mesh) {
  static const int faces[6][8] = {{0, 3, 2, 1, 11, 10, 9, 8},     {4, 5, 6, 7, 12, 13, 14, 15},
                                  {0, 1, 5, 4, 8, 17, 12, 16},    {1, 2, 6, 5, 9, 18, 13, 17},
                                  {2, 3, 7, 6, 10, 19, 14, 18},   {3, 0, 4, 7, 11, 16, 15, 19}};
  std::map<std::array<int, 4>, std::pair<int, std::array<int, 8>>> count;
  for (const flex::FeElement& el : mesh.elements()) {
    if (el.type != flex::ElementType::kHex20)
      throw std::invalid_argument("flexible gear mesh: embedded flanks need hex20 elements");
    for (const auto& f : faces) {
      std::array<int, 8> nodes;
      for (int k = 0; k < 8; ++k) nodes[k] = el.nodes[f[k]];
      std::array<int, 4> key = {nodes[0], nodes[1], nodes[2], nodes[3]};
      std::sort(key.begin(), key.end());
      auto& entry = count[key];
      ++entry.first;
      entry.second = nodes;
    }
  }
  std::vector<std::array<int, 8>> out;
  for (const auto& [key, entry] : count)
    if (entry.first == 1) out.push_back(entry.second);
  return out;
}

// Solves (diag(0, kq) + R^T C R) dx = -g for dx = (d0, dq) without forming the n x n matrix:
// Woodbury for the q block H_qq = K + R_q^T C R_q (nc contact rows),
//   H_qq^-1 b = K^-1 b - K^-1 R_q^T (C^-1 + R_q K^-1 R_q^T)^-1 R_q K^-1 b,
// then the Schur complement of the TE entry: d0 = (-g0 + h^T H_qq^-1 g_q) / (h00 - h^T H_qq^-1 h),
// dq = H_qq^-1 (-g_q - h d0), with h = R_q^T C r_0, h00 = sum c r_0^2. Cost O(n nc^2).
Eigen::VectorXd NewtonStep(const Eigen::VectorXd& kq, const std::vector<Eigen::VectorXd>& rows,
                           const std::vector<double>& c, const Eigen::VectorXd& g) {
  const int n = static_cast<int>(g.size()), nc = static_cast<int>(rows.size());
  Eigen::MatrixXd Rq(nc, n - 1);
  Eigen::VectorXd r0(nc), cv(nc);
  for (int i = 0; i < nc; ++i) {
    Rq.row(i) = rows[i].tail(n - 1).transpose();
    r0(i) = rows[i](0);
    cv(i) = c[i];
  }
  const Eigen::VectorXd kinv = kq.cwiseInverse();
  const Eigen::MatrixXd RK = Rq * kinv.asDiagonal();  // R_q K^-1
  Eigen::MatrixXd A = RK * Rq.transpose();
  A.diagonal() += cv.cwiseInverse();
  const Eigen::LDLT<Eigen::MatrixXd> Af(A);
  auto solve_qq = [&](const Eigen::VectorXd& b) -> Eigen::VectorXd {
    return kinv.cwiseProduct(b) - RK.transpose() * Af.solve(RK * b);
  };
  const Eigen::VectorXd h = Rq.transpose() * cv.cwiseProduct(r0);
  const double h00 = cv.dot(r0.cwiseProduct(r0));
  const Eigen::VectorXd gq = g.tail(n - 1);
  const Eigen::VectorXd Hg = solve_qq(gq), Hh = solve_qq(h);
  Eigen::VectorXd dx(n);
  dx(0) = (-g(0) + h.dot(Hg)) / (h00 - h.dot(Hh));
  dx.tail(n - 1) = solve_qq(-gq - h * dx(0));
  return dx;
}

}  // namespace

FlexibleGearBody ReduceGearForContact(const gears::Gear& gear, bool second,
                                      const FlexibleGearMeshOptions& options,
                                      double bore_radius_m) {
  const auto t0 = std::chrono::steady_clock::now();
  gears::GearFeMeshSpec spec = options.fe;
  spec.bore_radius_m = bore_radius_m > 0 ? bore_radius_m : 0.4 * gear.reference_radius_m();
  const flex::FeMesh mesh = gears::MakeGearFeMesh(gear, spec);
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  const std::vector<flex::FeInterface> ifs = {
      flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
  const int z = gear.teeth();
  // Teeth through the mesh zone over one period (see the header), and their loaded flanks: the
  // flank on the positive-angle side of the tooth.
  const int n = options.teeth_each_side;
  FlexibleGearBody body;
  std::vector<int> flank_nodes;
  std::set<int> surface_nodes;
  for (int j = -n - 1; j <= n; ++j) {
    const int k = ((j % z) + z) % z;
    const double centre = 2 * kPi * k / z;
    auto mean_offset = [&](const std::string& set) {
      double s = 0;
      const auto& nodes = mesh.NodeSet(set);
      for (int i : nodes) {
        const auto& p = mesh.positions()[i];
        s += Wrap(std::atan2(p.y(), p.x()) - centre);
      }
      return s / nodes.size();
    };
    const std::string plus = gears::ToothSetName(k, "FLANK_PLUS");
    const std::string minus = gears::ToothSetName(k, "FLANK_MINUS");
    const std::string loaded = mean_offset(plus) > mean_offset(minus) ? plus : minus;
    const std::string tip = gears::ToothSetName(k, "TIP");
    body.teeth.push_back(k);
    body.contact_sets.push_back(loaded);
    body.contact_sets.push_back(tip);
    for (int i : mesh.NodeSet(loaded)) flank_nodes.push_back(i);
    for (const std::string& s : {loaded, tip})
      for (int i : mesh.NodeSet(s)) surface_nodes.insert(i);
  }
  (void)second;
  std::sort(flank_nodes.begin(), flank_nodes.end());
  flank_nodes.erase(std::unique(flank_nodes.begin(), flank_nodes.end()), flank_nodes.end());
  // Attachment columns: unit x and y loads at every loaded-flank node, bore held.
  const int m = static_cast<int>(flank_nodes.size());
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(3 * mesh.num_nodes(), 2 * m);
  for (int c = 0; c < m; ++c) {
    F(3 * flank_nodes[c] + 0, 2 * c) = 1;
    F(3 * flank_nodes[c] + 1, 2 * c + 1) = 1;
  }
  const Eigen::MatrixXd U = flex::SolveStaticsHeldAtInterface(mesh, sys, ifs, 0, F);
  // Reduced stiffness U^T K U = U^T (F + bore reaction) = F^T U (U vanishes on the held bore):
  // the compliance of the loaded DOFs, read off U. Diagonalized, K_r = V Lambda V^T, the modes
  // are Phi = U V (K diagonal; not mass-normalized: the sweep is static), evaluated only at the
  // nodes the contact needs.
  Eigen::MatrixXd Kr(2 * m, 2 * m);
  for (int c = 0; c < m; ++c) {
    Kr.row(2 * c) = U.row(3 * flank_nodes[c] + 0);
    Kr.row(2 * c + 1) = U.row(3 * flank_nodes[c] + 1);
  }
  Kr = 0.5 * (Kr + Kr.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kr);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues().minCoeff() > 0))
    throw std::runtime_error("ReduceGearForContact: the reduced stiffness is not positive definite");
  // Modal coordinates q with u = U V q: K = V^T (U^T K U) V = Lambda.
  const Eigen::MatrixXd& V = eig.eigenvectors();
  auto phi_of = [&](int node) -> Eigen::MatrixXd { return U.middleRows(3 * node, 3) * V; };
  // The modes: surface nodes of the contact sets in the gear frame (B = gear frame; the bore is
  // held, so B's pose is the gear's rigid pose), the contact node sets and triangles.
  auto modes = std::make_shared<FlexibleBodyModes>();
  modes->nf = 2 * m;
  modes->stiffness = eig.eigenvalues().asDiagonal();
  std::vector<int> node_of(mesh.num_nodes(), -1);
  for (int i : surface_nodes) {
    node_of[i] = static_cast<int>(modes->nodes.size());
    FlexibleBodyModes::Node node;
    node.id = mesh.node_ids()[i];
    node.position = mesh.positions()[i];
    node.translation_shapes = phi_of(i);
    node.rotation_shapes = Eigen::MatrixXd::Zero(3, modes->nf);
    modes->nodes.push_back(std::move(node));
  }
  for (const std::string& s : body.contact_sets) {
    auto& set = modes->node_sets[s];
    for (int i : mesh.NodeSet(s)) set.push_back(node_of[i]);
  }
  for (const auto& t : flex::BoundaryTriangles(mesh))
    if (node_of[t[0]] >= 0 && node_of[t[1]] >= 0 && node_of[t[2]] >= 0)
      modes->surface_triangles.push_back({node_of[t[0]], node_of[t[1]], node_of[t[2]]});
  // The analytic loaded flanks and tips on the FE faces of the contact sets.
  if (options.embedded_flanks) {
    std::vector<char> in_sets(mesh.num_nodes(), 0);
    for (const std::string& s : body.contact_sets)
      for (int i : mesh.NodeSet(s)) in_sets[i] = 1;
    std::vector<std::array<int, 8>> faces;
    for (const auto& f : BoundaryFaces8(mesh))
      if (std::all_of(f.begin(), f.end(), [&](int i) { return in_sets[i]; })) faces.push_back(f);
    // Local coordinates of v on face f by Gauss-Newton on |x(xi, eta) - v|; distance or inf.
    auto project = [&](const std::array<int, 8>& f, const Vec3& v, double* xi, double* eta) {
      double x = 0, e = 0, N[8], Nx[8], Ne[8];
      for (int it = 0; it < 30; ++it) {
        Serendipity(x, e, N, Nx, Ne);
        Vec3 p = Vec3::Zero(), px = Vec3::Zero(), pe = Vec3::Zero();
        for (int k = 0; k < 8; ++k) {
          const Vec3 xk = mesh.positions()[f[k]];
          p += N[k] * xk, px += Nx[k] * xk, pe += Ne[k] * xk;
        }
        const Vec3 r = p - v;
        Eigen::Matrix2d A;
        A << px.dot(px), px.dot(pe), pe.dot(px), pe.dot(pe);
        const Eigen::Vector2d d = A.ldlt().solve(-Eigen::Vector2d(px.dot(r), pe.dot(r)));
        x = std::clamp(x + d(0), -1.5, 1.5), e = std::clamp(e + d(1), -1.5, 1.5);
        if (d.norm() < 1e-13) break;
      }
      Serendipity(x, e, N, Nx, Ne);
      Vec3 p = Vec3::Zero();
      for (int k = 0; k < 8; ++k) p += N[k] * mesh.positions()[f[k]];
      *xi = x, *eta = e;
      const double tol = 1e-9;
      if (std::abs(x) > 1 + tol || std::abs(e) > 1 + tol)
        return std::numeric_limits<double>::infinity();
      return (p - v).norm();
    };
    const gears::ProfileResolution res{.root = 1, .fillet = 1,
                                       .involute = options.involute_intervals,
                                       .tip = options.tip_intervals};
    std::vector<Eigen::MatrixXd> part_shapes;
    int total = 0;
    for (int k : body.teeth) {
      const TriangleMesh full = gears::MakeToothSurfaceMesh(gear, k, res, options.face_intervals_per_element * spec.face_divisions);
      // Each vertex on its FE face (closest within the tolerance), or none.
      const int nv = static_cast<int>(full.vertices.size());
      std::vector<int> face_of(nv, -1);
      std::vector<Eigen::Vector2d> local(nv);
      for (int v = 0; v < nv; ++v) {
        double best = options.embed_tolerance_m;
        for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
          double x, e;
          const double d = project(faces[f], full.vertices[v], &x, &e);
          if (d <= best) best = d, face_of[v] = f, local[v] = {x, e};
        }
      }
      TriangleMesh part;
      std::vector<int> index(nv, -1), used;
      for (const auto& t : full.triangles) {
        if (face_of[t[0]] < 0 || face_of[t[1]] < 0 || face_of[t[2]] < 0) continue;
        std::array<int, 3> tri;
        for (int c = 0; c < 3; ++c) {
          if (index[t[c]] < 0) {
            index[t[c]] = static_cast<int>(part.vertices.size());
            part.vertices.push_back(full.vertices[t[c]]);
            used.push_back(t[c]);
          }
          tri[c] = index[t[c]];
        }
        part.triangles.push_back(tri);
      }
      if (part.triangles.empty()) continue;
      Eigen::MatrixXd S = Eigen::MatrixXd::Zero(3 * used.size(), modes->nf);
      for (size_t i = 0; i < used.size(); ++i) {
        double N[8], Nx[8], Ne[8];
        Serendipity(local[used[i]](0), local[used[i]](1), N, Nx, Ne);
        const auto& f = faces[face_of[used[i]]];
        for (int c = 0; c < 8; ++c)
          S.middleRows(3 * i, 3) += N[c] * modes->nodes[node_of[f[c]]].translation_shapes;
      }
      total += static_cast<int>(used.size());
      part_shapes.push_back(std::move(S));
      body.fine_parts.push_back(std::move(part));
    }
    body.fine_shapes.resize(3 * total, modes->nf);
    int row = 0;
    for (const Eigen::MatrixXd& S : part_shapes) {
      body.fine_shapes.middleRows(row, S.rows()) = S;
      row += static_cast<int>(S.rows());
    }
  }
  body.modes = modes;
  body.fe_nodes = mesh.num_nodes();
  body.reduce_seconds = Seconds(t0);
  return body;
}

GearContactCalibration CalibrateFlexibleGearContact(const gears::GearPair& pair,
                                                    const gears::GearMaterial& material,
                                                    double calibration_load_n,
                                                    const FlexiblePairPenalty& penalty) {
  if (!(calibration_load_n > 0))
    throw std::invalid_argument("CalibrateFlexibleGearContact: calibration load must be > 0, got " +
                                std::to_string(calibration_load_n));
  if (!(material.youngs_modulus_pa > 0) || !(material.poisson_ratio > -1 && material.poisson_ratio < 0.5))
    throw std::invalid_argument("CalibrateFlexibleGearContact: invalid material (E " +
                                std::to_string(material.youngs_modulus_pa) + " Pa, nu " +
                                std::to_string(material.poisson_ratio) + ")");
  const double b = pair.face_width_m();
  // Hertz, then the tooth compliance of each rigid gear at its reference circle.
  double compliance = 1 / gears::HertzStiffness(b, material, material);
  auto add_tooth = [&](const gears::Gear& gear, double rim_radius_m) {
    compliance += gears::CalcToothCompliance(gear, gear.reference_radius_m(), b, material,
                                             rim_radius_m).total();
  };
  if (penalty.rigid1) add_tooth(pair.gear1(), penalty.rim_radius1_m);
  if (penalty.rigid2) add_tooth(pair.gear2(), penalty.rim_radius2_m);
  GearContactOptions go;
  go.single_pair_stiffness_n_per_m = 1 / compliance;
  go.calibration_load_n = calibration_load_n;
  return CalibrateGearContact(pair, go);
}

FlexibleMeshSweep SweepFlexibleGearMesh(const gears::GearPair& pair,
                                        const FlexibleGearMeshOptions& options, double load_n,
                                        int points) {
  if (pair.internal())
    throw std::invalid_argument("SweepFlexibleGearMesh: internal pairs are not supported");
  if (!(load_n > 0)) throw std::invalid_argument("SweepFlexibleGearMesh: load must be > 0");
  if (points < 1) throw std::invalid_argument("SweepFlexibleGearMesh: points must be >= 1");
  FlexibleMeshSweep sweep;
  sweep.load_n = load_n;
  // Penalty: the Hertzian line-contact stiffness of the lumped model at the calibration load.
  const gears::GearMaterial mat{.youngs_modulus_pa = options.fe.material.youngs_modulus_pa,
                                .poisson_ratio = options.fe.material.poissons_ratio};
  sweep.hertz_stiffness_n_per_m = gears::HertzStiffness(pair.face_width_m(), mat, mat);
  const GearContactCalibration cal = CalibrateFlexibleGearContact(
      pair, mat, options.calibration_load_n > 0 ? options.calibration_load_n : load_n);
  sweep.stiffness_per_area = cal.stiffness_per_area;
  // Reduced gears and their contact surfaces (one part per tooth).
  const FlexibleGearBody g1 = ReduceGearForContact(pair.gear1(), false, options, options.bore_radius1_m);
  const FlexibleGearBody g2 = ReduceGearForContact(pair.gear2(), true, options, options.bore_radius2_m);
  sweep.reduce_seconds = g1.reduce_seconds + g2.reduce_seconds;
  sweep.fe_nodes1 = g1.fe_nodes, sweep.fe_nodes2 = g2.fe_nodes;
  const int z1 = pair.gear1().teeth(), z2 = pair.gear2().teeth();
  auto surface = [&](const FlexibleGearBody& g, const gears::Gear& gear, int z) {
    const FlexibleContactSurfaceSpec spec{.node_sets = g.contact_sets,
                                          .gap_margin_m = options.gap_margin_m,
                                          .deformation_allowance_m = options.deformation_allowance_m,
                                          .slack_m = 0, .angular_parts = z};
    (void)gear;
    if (options.embedded_flanks)
      return std::make_shared<const FlexibleContactSurface>(g.modes, g.fine_parts, g.fine_shapes,
                                                            spec);
    return std::make_shared<const FlexibleContactSurface>(
        g.modes, FlexibleContactSurfaceSpec{.node_sets = g.contact_sets,
                                            .gap_margin_m = options.gap_margin_m,
                                            .deformation_allowance_m = options.deformation_allowance_m,
                                            .slack_m = 0, .angular_parts = z});
  };
  const FlexibleContactElement element({.name = "flexible_sweep",
                                        .a = {.body = 1, .flexible = surface(g1, pair.gear1(), z1)},
                                        .b = {.body = 2, .flexible = surface(g2, pair.gear2(), z2)},
                                        .law = {.stiffness_per_area = cal.stiffness_per_area}});
  FlexibleContactWorkspace ws(element.spec().a, element.spec().b);
  const FlexibleContactSurface& s1 = *element.spec().a.flexible;
  const FlexibleContactSurface& s2 = *element.spec().b.flexible;
  const int nf1 = s1.nf(), nf2 = s2.nf(), n = 1 + nf1 + nf2;
  sweep.nf1 = nf1, sweep.nf2 = nf2;
  const Eigen::VectorXd k1 = g1.modes->stiffness.diagonal(), k2 = g2.modes->stiffness.diagonal();

  const double rb1 = pair.gear1().base_radius_m();
  const double a = pair.center_distance_m();
  const Vec3 p2(a, 0, 0);
  const auto t0 = std::chrono::steady_clock::now();
  // Unknowns x = (TE, q1, q2); warm-started across roll angles.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  x(0) = load_n / gears::CalcIso6336Stiffness(pair).c_single_n_per_m;
  Eigen::VectorXd q1(nf1), q2(nf2), g(n), dx(n);
  // Gauss-Newton Hessian H = diag(0, K1, K2) + R^T C R, kept as its contact rows R (one per
  // penetrating node) and weights C.
  std::vector<Eigen::VectorXd> rows_R;
  std::vector<double> weights_C;
  Eigen::VectorXd kq(n - 1);
  kq << k1, k2;
  Eigen::VectorXd r(n);
  for (int i = 0; i < points; ++i) {
    MeshSweepPoint pt;
    pt.roll_angle_rad = 2 * kPi / z1 * i / points;
    const double theta2 = kPi + kPi / z2 - double(z1) / z2 * pt.roll_angle_rad;
    const Transform X_W2(AxisAngle(Vec3::UnitZ(), theta2), p2);
    // Contact state at x, and the total potential Pi.
    auto evaluate = [&](const Eigen::VectorXd& xx) {
      q1 = xx.segment(1, nf1);
      q2 = xx.segment(1 + nf1, nf2);
      const Transform X_W1(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + xx(0) / rb1), Vec3::Zero());
      element.Evaluate({.X_WB = X_W1, .q_f = &q1}, {.X_WB = X_W2, .q_f = &q2}, ws);
      ++pt.evaluations;
      return 0.5 * q1.dot(k1.cwiseProduct(q1)) + 0.5 * q2.dot(k2.cwiseProduct(q2)) + ws.energy -
             load_n * xx(0);
    };
    // Gradient and Gauss-Newton Hessian at the last evaluation.
    auto linearize = [&](const Eigen::VectorXd& xx) {
      const Transform X_W1(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + xx(0) / rb1), Vec3::Zero());
      g(0) = -load_n - ws.side_a.f_W(2) / rb1;
      g.segment(1, nf1) = k1.cwiseProduct(xx.segment(1, nf1)) - ws.side_a.modal_force;
      g.segment(1 + nf1, nf2) = k2.cwiseProduct(xx.segment(1 + nf1, nf2)) - ws.side_b.modal_force;
      rows_R.clear();
      weights_C.clear();
      // One row r = d(gap)/dx per penetrating node; nodes of gear 1 (a) or gear 2 (b).
      auto rows = [&](const std::vector<NodeGap>& gaps, bool node_on_1) {
        const FlexibleContactSurface& sn = node_on_1 ? s1 : s2;
        const FlexibleContactSurface& sf = node_on_1 ? s2 : s1;
        const ContactSideBuffers& bf = node_on_1 ? ws.side_b : ws.side_a;
        const Transform& X_WF = node_on_1 ? X_W2 : X_W1;
        const Mat3 R_WN = node_on_1 ? X_W1.R : X_W2.R;
        const int off_n = node_on_1 ? 1 : 1 + nf1, off_f = node_on_1 ? 1 + nf1 : 1;
        for (const NodeGap& gp : gaps) {
          if (!(gp.gap < 0) || !gp.on_surface) continue;
          r.setZero();
          const Vec3 ez = Vec3::UnitZ();
          r(0) = node_on_1 ? gp.n_W.dot(ez.cross(gp.p_W)) / rb1 : -gp.n_W.dot(ez.cross(gp.q_W)) / rb1;
          const Vec3 n_N = R_WN.transpose() * gp.n_W, n_F = X_WF.R.transpose() * gp.n_W;
          r.segment(off_n, sn.nf()).noalias() += sn.shapes().middleRows(3 * gp.node, 3).transpose() * n_N;
          const auto& tri = sf.undeformed().triangles()[gp.face];
          const Vec3 w = Barycentric(X_WF.Inverse() * gp.q_W, bf.vertices[tri[0]],
                                     bf.vertices[tri[1]], bf.vertices[tri[2]]);
          for (int k = 0; k < 3; ++k)
            r.segment(off_f, sf.nf()).noalias() -=
                w(k) * (sf.shapes().middleRows(3 * tri[k], 3).transpose() * n_F);
          const double c = cal.stiffness_per_area * 0.5 * gp.weight * sn.undeformed().vertex_areas()[gp.node];
          rows_R.push_back(r);
          weights_C.push_back(c);
        }
      };
      rows(ws.gaps_a, true);
      rows(ws.gaps_b, false);

    };
    // Newton with backtracking on Pi.
    double pi = evaluate(x);
    bool converged = false;
    for (int it = 0; it < options.max_newton_iterations; ++it) {
      linearize(x);
      if (ws.contact_points == 0) {  // no contact yet: turn gear 1 on
        x(0) += 0.5 * load_n / sweep.hertz_stiffness_n_per_m + 1e-6;
        pi = evaluate(x);
        continue;
      }
      dx = NewtonStep(kq, rows_R, weights_C, g);
      // Converged: the TE step under 1 pm and the moment balanced to 1e-5 of the load.
      if (std::abs(dx(0)) < 1e-12 && std::abs(g(0)) < 1e-5 * load_n) {
        converged = true;
        break;
      }
      const double slope = g.dot(dx);
      double alpha = 1;
      Eigen::VectorXd trial = x + dx;
      double pi_trial = evaluate(trial);
      int k = 0;
      for (; k < 20 && pi_trial > pi + 1e-4 * alpha * slope; ++k) {
        alpha *= 0.5;
        trial = x + alpha * dx;
        pi_trial = evaluate(trial);
      }
      // No descent (a contact on an edge or vertex of a face, where the force along the face
      // normal is not the gradient of the distance-based energy): take the full Newton step.
      if (k == 20) {
        trial = x + dx;
        pi_trial = evaluate(trial);
      }
      x = trial;
      pi = pi_trial;
    }
    pi = evaluate(x);
    if (!converged) {
      linearize(x);
      // Stalled (contacts switching between features at a tip corner): accepted if the moment
      // balances to 1 % of the load, counted and reported; otherwise an error.
      if (std::abs(g(0)) < 1e-2 * load_n) {
        ++sweep.unconverged_points;
        sweep.max_moment_residual = std::max(sweep.max_moment_residual, std::abs(g(0)) / load_n);
        evaluate(x);
      } else
      throw std::runtime_error("SweepFlexibleGearMesh: no equilibrium at roll angle " +
                               std::to_string(pt.roll_angle_rad) + " (moment residual " +
                               std::to_string(std::abs(g(0)) / load_n) + " of the load, TE " +
                               std::to_string(x(0)) + " m)");
    }
    pt.transmission_error_m = x(0);
    pt.stiffness_n_per_m = load_n / x(0);
    pt.normal_force_n = ws.normal_force;
    pt.contact_points = ws.contact_points;
    sweep.max_deformation_m.push_back(
        std::max(ws.side_a.deformation_bound, ws.side_b.deformation_bound));
    // Teeth of gear 1 in contact and their contact extent along the line of action.
    const Transform X_1W =
        Transform(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + x(0) / rb1), Vec3::Zero()).Inverse();
    ContactPattern pattern(pt, X_1W, rb1);
    auto add = [&](int tooth, const Vec3& p_W) { pattern.Add(tooth, p_W); };
    const auto& v1 = s1.undeformed().vertices();
    for (const NodeGap& gp : ws.gaps_a)
      if (gp.gap < 0 && gp.on_surface) add(ToothOf(v1[gp.node], z1), gp.p_W);
    for (const NodeGap& gp : ws.gaps_b)
      if (gp.gap < 0 && gp.on_surface)
        add(ToothOf(v1[s1.undeformed().triangles()[gp.face][0]], z1), gp.q_W);
    int predicted = 0;
    if (pt.teeth_in_contact > 0) {
      const double c = 0.5 * (pt.pattern_min_m[0] + pt.pattern_max_m[0]);
      const double pb = pair.transverse_base_pitch_m();
      for (int j = -3; j <= 3; ++j) {
        const double sj = c + j * pb;
        if (sj >= pair.contact_start_m() && sj <= pair.contact_end_m()) ++predicted;
      }
    }
    sweep.predicted_pairs.push_back(predicted);
    sweep.evaluations += pt.evaluations;
    sweep.points.push_back(pt);
  }
  sweep.sweep_seconds = Seconds(t0);
  sweep.inflation_exceeded = ws.inflation_exceeded;
  double sum = 0, te_min = 1e300, te_max = -1e300;
  for (const MeshSweepPoint& p : sweep.points) {
    sum += p.stiffness_n_per_m;
    te_min = std::min(te_min, p.transmission_error_m);
    te_max = std::max(te_max, p.transmission_error_m);
  }
  sweep.mean_stiffness_n_per_m = sum / points;
  double zone_sum[2] = {0, 0};
  int zone_n[2] = {0, 0};
  for (const MeshSweepPoint& p : sweep.points)
    if (p.teeth_in_contact == 1 || p.teeth_in_contact == 2) {
      zone_sum[p.teeth_in_contact - 1] += p.stiffness_n_per_m;
      ++zone_n[p.teeth_in_contact - 1];
    }
  if (zone_n[0]) sweep.single_zone_stiffness_n_per_m = zone_sum[0] / zone_n[0];
  if (zone_n[1]) sweep.double_zone_stiffness_n_per_m = zone_sum[1] / zone_n[1];
  sweep.te_peak_to_peak_m = te_max - te_min;
  return sweep;
}

}  // namespace orrery::contact

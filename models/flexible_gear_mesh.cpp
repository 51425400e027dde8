#include "models/flexible_gear_mesh.h"

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
#include "flex/fe_element.h"
#include "flex/fe_interface.h"
#include "flex/flexible_body_modes.h"
#include "flex/geometric_stiffness.h"
#include "contact/triangle_geometry.h"
#include "models/mesh_stiffness.h"
#include "models/tooth_fault_geometry.h"

namespace orrery::gears {

// The general contact engine this layer builds on.
using namespace orrery::contact;

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

// Boundary faces of a hex20 mesh as 8 node indices (corners, then midsides: the node order of
// flex::QuadFaceShape8), in the order of their sorted corner nodes.
std::vector<std::array<int, 8>> BoundaryFaces8(const flex::FeMesh& mesh) {
  for (const flex::FeElement& el : mesh.elements())
    if (el.type != flex::ElementType::kHex20)
      throw std::invalid_argument("flexible gear mesh: embedded flanks need hex20 elements");
  std::vector<std::pair<std::array<int, 4>, std::array<int, 8>>> keyed;
  for (const flex::BoundaryFace& f : flex::BoundaryFaces(mesh)) {
    std::array<int, 8> nodes;
    for (int k = 0; k < 4; ++k) nodes[k] = f.corner_nodes[k], nodes[4 + k] = f.midside_nodes[k];
    std::array<int, 4> key = f.corner_nodes;
    std::sort(key.begin(), key.end());
    keyed.emplace_back(key, nodes);
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::array<int, 8>> out;
  for (const auto& [key, nodes] : keyed) out.push_back(nodes);
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

// Stage 1 of ReduceGearForContact: the teeth through the mesh zone over one period (see the
// header) and their contact sets (the loaded flank: the one on the positive-angle side of the
// tooth; the tip; a broken tooth's fracture surface), the loaded-flank nodes (sorted, unique) and
// every node of the sets.
void CollectContactTeeth(const flex::FeMesh& mesh, int z, int centre_tooth, int n, FlexibleGearBody& body,
                         std::vector<int>& flank_nodes, std::set<int>& surface_nodes) {
  for (int j = centre_tooth - n - 1; j <= centre_tooth + n; ++j) {
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
    // A broken tooth's fracture surface can touch too.
    const std::string fracture = gears::ToothSetName(k, "FRACTURE");
    if (mesh.node_sets().count(fracture)) {
      body.contact_sets.push_back(fracture);
      for (int i : mesh.NodeSet(fracture)) {
        flank_nodes.push_back(i);
        surface_nodes.insert(i);
      }
    }
  }
  std::sort(flank_nodes.begin(), flank_nodes.end());
  flank_nodes.erase(std::unique(flank_nodes.begin(), flank_nodes.end()), flank_nodes.end());
}

// Stage 2: static modes at the loaded-flank nodes with the bore held. Unit x and y loads at every
// flank node give the displacements U; the reduced stiffness U^T K U = F^T U (U vanishes on the
// held bore) is the compliance of the loaded DOFs, read off U. Diagonalized, K_r = V Lambda V^T,
// the modes are Phi = U V (K diagonal; not mass-normalized: the sweep is static). Returns them
// as U (3 #nodes x 2m), V (2m x 2m) and Lambda (the mode shape of a node is its 3 rows of U
// times V, formed only for the nodes the contact needs).
void ReduceAtFlankNodes(const flex::FeMesh& mesh, const flex::FeSystem& sys, const std::vector<int>& flank_nodes,
                        Eigen::MatrixXd& U, Eigen::MatrixXd& V, Eigen::VectorXd& stiffness) {
  const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
  const int m = static_cast<int>(flank_nodes.size());
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(3 * mesh.num_nodes(), 2 * m);
  for (int c = 0; c < m; ++c) {
    F(3 * flank_nodes[c] + 0, 2 * c) = 1;
    F(3 * flank_nodes[c] + 1, 2 * c + 1) = 1;
  }
  U = flex::SolveStaticsHeldAtInterface(mesh, sys, ifs, 0, F);
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
  V = eig.eigenvectors();
  stiffness = eig.eigenvalues();
}

// Stage 3: the modes at the surface nodes of the contact sets in the gear frame (B = gear frame;
// the bore is held, so B's pose is the gear's rigid pose), the contact node sets and the surface
// triangles between them. node_of: mesh node -> mode node (-1: not kept).
std::shared_ptr<FlexibleBodyModes> MakeSurfaceModes(const flex::FeMesh& mesh, const FlexibleGearBody& body,
                                                    const std::set<int>& surface_nodes,
                                                    const Eigen::MatrixXd& U, const Eigen::MatrixXd& V,
                                                    const Eigen::VectorXd& stiffness, std::vector<int>& node_of) {
  auto modes = std::make_shared<FlexibleBodyModes>();
  modes->nf = static_cast<int>(stiffness.size());
  modes->stiffness = stiffness.asDiagonal();
  node_of.assign(mesh.num_nodes(), -1);
  for (int i : surface_nodes) {
    node_of[i] = static_cast<int>(modes->nodes.size());
    FlexibleBodyModes::Node node;
    node.id = mesh.node_ids()[i];
    node.position = mesh.positions()[i];
    node.translation_shapes = U.middleRows(3 * i, 3) * V;
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
  return modes;
}

// Local coordinates (xi, eta) of v on the 8-node face f by Gauss-Newton on |x(xi, eta) - v|;
// returns the distance, or inf when the closest point lies outside the face.
double ProjectOnFace(const flex::FeMesh& mesh, const std::array<int, 8>& f, const Vec3& v, double* xi,
                     double* eta) {
  double x = 0, e = 0, N[8], Nx[8], Ne[8];
  for (int it = 0; it < 30; ++it) {
    flex::QuadFaceShape8(x, e, N, Nx, Ne);
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
  flex::QuadFaceShape8(x, e, N, Nx, Ne);
  Vec3 p = Vec3::Zero();
  for (int k = 0; k < 8; ++k) p += N[k] * mesh.positions()[f[k]];
  *xi = x, *eta = e;
  const double tol = 1e-9;
  if (std::abs(x) > 1 + tol || std::abs(e) > 1 + tol) return std::numeric_limits<double>::infinity();
  return (p - v).norm();
}

// One tooth's analytic surface embedded in the FE faces of the contact sets: the part of the
// surface whose vertices lie on a face (within the tolerance, a spall's depth more on a spalled
// tooth) and the shapes of its used vertices from the faces' serendipity functions (3 rows each).
// Returns false when no triangle of the tooth lies on the faces.
bool EmbedToothSurface(const flex::FeMesh& mesh, const std::vector<std::array<int, 8>>& faces,
                       const TriangleMesh& full, double tolerance, const FlexibleBodyModes& modes,
                       const std::vector<int>& node_of, TriangleMesh& part, Eigen::MatrixXd& S) {
  const int nv = static_cast<int>(full.vertices.size());
  std::vector<int> face_of(nv, -1);
  std::vector<Eigen::Vector2d> local(nv);
  for (int v = 0; v < nv; ++v) {
    double best = tolerance;
    for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
      double x, e;
      const double d = ProjectOnFace(mesh, faces[f], full.vertices[v], &x, &e);
      if (d <= best) best = d, face_of[v] = f, local[v] = {x, e};
    }
  }
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
  if (part.triangles.empty()) return false;
  S = Eigen::MatrixXd::Zero(3 * used.size(), modes.nf);
  for (size_t i = 0; i < used.size(); ++i) {
    double N[8], Nx[8], Ne[8];
    flex::QuadFaceShape8(local[used[i]](0), local[used[i]](1), N, Nx, Ne);
    const auto& f = faces[face_of[used[i]]];
    for (int c = 0; c < 8; ++c) S.middleRows(3 * i, 3) += N[c] * modes.nodes[node_of[f[c]]].translation_shapes;
  }
  return true;
}

// Stage 4: the analytic loaded flanks and tips on the FE faces of the contact sets
// (body.fine_parts and body.fine_shapes).
void EmbedAnalyticFlanks(const gears::Gear& gear, const FlexibleGearMeshOptions& options,
                         const gears::GearFeMeshSpec& spec, const flex::FeMesh& mesh,
                         const FlexibleBodyModes& modes, const std::vector<int>& node_of, FlexibleGearBody& body) {
  std::vector<char> in_sets(mesh.num_nodes(), 0);
  for (const std::string& s : body.contact_sets)
    for (int i : mesh.NodeSet(s)) in_sets[i] = 1;
  std::vector<std::array<int, 8>> faces;
  for (const auto& f : BoundaryFaces8(mesh))
    if (std::all_of(f.begin(), f.end(), [&](int i) { return in_sets[i]; })) faces.push_back(f);
  const gears::ProfileResolution res{.root = 1, .fillet = 1,
                                     .involute = options.involute_intervals,
                                     .tip = options.tip_intervals};
  std::vector<Eigen::MatrixXd> part_shapes;
  int total = 0;
  for (int k : body.teeth) {
    const int n_face = options.face_intervals_per_element * spec.face_divisions;
    const TriangleMesh full = gears::MakeFaultyToothSurfaceMesh(gear, k, res, n_face, spec.faults);
    double tolerance = options.embed_tolerance_m;
    for (const gears::ToothFaultSpec& f : spec.faults)
      if (f.tooth == k && f.kind == gears::ToothFaultSpec::Kind::kSpall) tolerance += f.depth_m;
    TriangleMesh part;
    Eigen::MatrixXd S;
    if (!EmbedToothSurface(mesh, faces, full, tolerance, modes, node_of, part, S)) continue;
    total += static_cast<int>(S.rows() / 3);
    part_shapes.push_back(std::move(S));
    body.fine_parts.push_back(std::move(part));
  }
  body.fine_shapes.resize(3 * total, modes.nf);
  int row = 0;
  for (const Eigen::MatrixXd& S : part_shapes) {
    body.fine_shapes.middleRows(row, S.rows()) = S;
    row += static_cast<int>(S.rows());
  }
}

}  // namespace

FlexibleGearBody ReduceGearForContact(const gears::Gear& gear, bool second,
                                      const FlexibleGearMeshOptions& options,
                                      double bore_radius_m, int centre_tooth) {
  const auto t0 = std::chrono::steady_clock::now();
  gears::GearFeMeshSpec spec = options.fe;
  spec.bore_radius_m = bore_radius_m > 0 ? bore_radius_m : 0.4 * gear.reference_radius_m();
  spec.faults = second ? options.faults2 : options.faults1;
  const flex::FeMesh mesh = gears::MakeGearFeMesh(gear, spec);
  const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
  FlexibleGearBody body;
  std::vector<int> flank_nodes;
  std::set<int> surface_nodes;
  CollectContactTeeth(mesh, gear.teeth(), centre_tooth, options.teeth_each_side, body, flank_nodes, surface_nodes);
  Eigen::MatrixXd U, V;
  Eigen::VectorXd stiffness;
  ReduceAtFlankNodes(mesh, sys, flank_nodes, U, V, stiffness);
  std::vector<int> node_of;
  const std::shared_ptr<FlexibleBodyModes> modes = MakeSurfaceModes(mesh, body, surface_nodes, U, V, stiffness, node_of);
  if (options.embedded_flanks) EmbedAnalyticFlanks(gear, options, spec, mesh, *modes, node_of, body);
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

namespace {

// The contact surface of a reduced gear: the embedded analytic flanks, or the FE faces.
std::shared_ptr<const FlexibleContactSurface> SweepSurface(const FlexibleGearBody& g, const FlexibleGearMeshOptions& options,
                                                           int z) {
  const FlexibleContactSurfaceSpec spec{.node_sets = g.contact_sets,
                                        .gap_margin_m = options.gap_margin_m,
                                        .deformation_allowance_m = options.deformation_allowance_m,
                                        .slack_m = 0, .angular_parts = z};
  if (options.embedded_flanks) return std::make_shared<const FlexibleContactSurface>(g.modes, g.fine_parts, g.fine_shapes, spec);
  return std::make_shared<const FlexibleContactSurface>(g.modes, spec);
}

// The quasi-static problem of one sweep point: unknowns x = (TE, q1, q2), total potential
// Pi = q1^T K1 q1 / 2 + q2^T K2 q2 / 2 + contact energy - F TE, gear 1 turned by the roll angle
// plus TE / r_b1, gear 2 at its rigid mesh position.
class SweepProblem {
 public:
  SweepProblem(const FlexibleContactElement& element, FlexibleContactWorkspace& ws, const FlexibleGearBody& g1,
               const FlexibleGearBody& g2, double rb1, double load_n, double stiffness_per_area)
      : element_(element), ws_(ws), s1_(*element.spec().a.flexible), s2_(*element.spec().b.flexible),
        k1_(g1.modes->stiffness.diagonal()), k2_(g2.modes->stiffness.diagonal()), rb1_(rb1), load_n_(load_n),
        stiffness_per_area_(stiffness_per_area) {
    nf1_ = s1_.nf(), nf2_ = s2_.nf();
    const int n = 1 + nf1_ + nf2_;
    q1_.resize(nf1_), q2_.resize(nf2_), g_.resize(n), r_.resize(n), kq_.resize(n - 1);
    kq_ << k1_, k2_;
  }
  int size() const { return 1 + nf1_ + nf2_; }
  void SetPose(double roll_rad, const Transform& X_W2) { roll_rad_ = roll_rad, X_W2_ = X_W2; }
  Transform PoseOfGear1(double te) const {
    return Transform(AxisAngle(Vec3::UnitZ(), roll_rad_ + te / rb1_), Vec3::Zero());
  }
  // Contact state at x, and Pi.
  double Evaluate(const Eigen::VectorXd& x, MeshSweepPoint& pt) {
    q1_ = x.segment(1, nf1_);
    q2_ = x.segment(1 + nf1_, nf2_);
    element_.Evaluate({.X_WB = PoseOfGear1(x(0)), .q_f = &q1_}, {.X_WB = X_W2_, .q_f = &q2_}, ws_);
    ++pt.evaluations;
    return 0.5 * q1_.dot(k1_.cwiseProduct(q1_)) + 0.5 * q2_.dot(k2_.cwiseProduct(q2_)) + ws_.energy - load_n_ * x(0);
  }
  // Gradient g and Gauss-Newton Hessian H = diag(0, K1, K2) + R^T C R (its contact rows R, one per
  // penetrating node, and weights C) at the last evaluation.
  void Linearize(const Eigen::VectorXd& x) {
    g_(0) = -load_n_ - ws_.side_a.f_W(2) / rb1_;
    g_.segment(1, nf1_) = k1_.cwiseProduct(x.segment(1, nf1_)) - ws_.side_a.modal_force;
    g_.segment(1 + nf1_, nf2_) = k2_.cwiseProduct(x.segment(1 + nf1_, nf2_)) - ws_.side_b.modal_force;
    rows_R_.clear();
    weights_C_.clear();
    const Transform X_W1 = PoseOfGear1(x(0));
    AddRows(ws_.gaps_a, true, X_W1);
    AddRows(ws_.gaps_b, false, X_W1);
  }
  Eigen::VectorXd NewtonStepOfLast() const { return NewtonStep(kq_, rows_R_, weights_C_, g_); }
  const Eigen::VectorXd& gradient() const { return g_; }

 private:
  // One row r = d(gap)/dx per penetrating node; nodes of gear 1 (a) or gear 2 (b).
  void AddRows(const std::vector<NodeGap>& gaps, bool node_on_1, const Transform& X_W1) {
    const FlexibleContactSurface& sn = node_on_1 ? s1_ : s2_;
    const FlexibleContactSurface& sf = node_on_1 ? s2_ : s1_;
    const ContactSideBuffers& bf = node_on_1 ? ws_.side_b : ws_.side_a;
    const Transform& X_WF = node_on_1 ? X_W2_ : X_W1;
    const Mat3 R_WN = node_on_1 ? X_W1.R : X_W2_.R;
    const int off_n = node_on_1 ? 1 : 1 + nf1_, off_f = node_on_1 ? 1 + nf1_ : 1;
    for (const NodeGap& gp : gaps) {
      if (!(gp.gap < 0) || !gp.on_surface) continue;
      r_.setZero();
      const Vec3 ez = Vec3::UnitZ();
      r_(0) = node_on_1 ? gp.n_W.dot(ez.cross(gp.p_W)) / rb1_ : -gp.n_W.dot(ez.cross(gp.q_W)) / rb1_;
      const Vec3 n_N = R_WN.transpose() * gp.n_W, n_F = X_WF.R.transpose() * gp.n_W;
      r_.segment(off_n, sn.nf()).noalias() += sn.shapes().middleRows(3 * gp.node, 3).transpose() * n_N;
      const auto& tri = sf.undeformed().triangles()[gp.face];
      const Vec3 w = Barycentric(X_WF.Inverse() * gp.q_W, bf.vertices[tri[0]], bf.vertices[tri[1]], bf.vertices[tri[2]]);
      for (int k = 0; k < 3; ++k)
        r_.segment(off_f, sf.nf()).noalias() -= w(k) * (sf.shapes().middleRows(3 * tri[k], 3).transpose() * n_F);
      rows_R_.push_back(r_);
      weights_C_.push_back(stiffness_per_area_ * 0.5 * gp.weight * sn.undeformed().vertex_areas()[gp.node]);
    }
  }

  const FlexibleContactElement& element_;
  FlexibleContactWorkspace& ws_;
  const FlexibleContactSurface &s1_, &s2_;
  const Eigen::VectorXd k1_, k2_;
  const double rb1_, load_n_, stiffness_per_area_;
  int nf1_ = 0, nf2_ = 0;
  double roll_rad_ = 0;
  Transform X_W2_;
  Eigen::VectorXd q1_, q2_, g_, r_, kq_;
  std::vector<Eigen::VectorXd> rows_R_;
  std::vector<double> weights_C_;
};

// Newton with backtracking on Pi from x (warm start). Converged: the TE step under 1 pm and the
// moment balanced to 1e-5 of the load. Returns whether it converged; x holds the last iterate and
// the problem's state its evaluation.
bool SolveSweepPoint(SweepProblem& problem, const FlexibleContactWorkspace& ws, double load_n, double hertz_stiffness,
                     int max_iterations, Eigen::VectorXd& x, MeshSweepPoint& pt) {
  double pi = problem.Evaluate(x, pt);
  bool converged = false;
  for (int it = 0; it < max_iterations; ++it) {
    problem.Linearize(x);
    if (ws.contact_points == 0) {  // no contact yet: turn gear 1 on
      x(0) += 0.5 * load_n / hertz_stiffness + 1e-6;
      pi = problem.Evaluate(x, pt);
      continue;
    }
    const Eigen::VectorXd dx = problem.NewtonStepOfLast();
    const Eigen::VectorXd& g = problem.gradient();
    if (std::abs(dx(0)) < 1e-12 && std::abs(g(0)) < 1e-5 * load_n) {
      converged = true;
      break;
    }
    const double slope = g.dot(dx);
    double alpha = 1;
    Eigen::VectorXd trial = x + dx;
    double pi_trial = problem.Evaluate(trial, pt);
    int k = 0;
    for (; k < 20 && pi_trial > pi + 1e-4 * alpha * slope; ++k) {
      alpha *= 0.5;
      trial = x + alpha * dx;
      pi_trial = problem.Evaluate(trial, pt);
    }
    // No descent (a contact on an edge or vertex of a face, where the force along the face
    // normal is not the gradient of the distance-based energy): take the full Newton step.
    if (k == 20) {
      trial = x + dx;
      pi_trial = problem.Evaluate(trial, pt);
    }
    x = trial;
    pi = pi_trial;
  }
  problem.Evaluate(x, pt);
  return converged;
}

// Teeth of gear 1 in contact, their contact extent along the line of action, and the number of
// pairs the rigid geometry predicts there (sweep.predicted_pairs).
void RecordContactPattern(const gears::GearPair& pair, const FlexibleContactWorkspace& ws,
                          const FlexibleContactSurface& s1, double rb1, double te, MeshSweepPoint& pt,
                          FlexibleMeshSweep& sweep) {
  const int z1 = pair.gear1().teeth();
  const Transform X_1W = Transform(AxisAngle(Vec3::UnitZ(), pt.roll_angle_rad + te / rb1), Vec3::Zero()).Inverse();
  ContactPattern pattern(pt, X_1W, rb1);
  const auto& v1 = s1.undeformed().vertices();
  for (const NodeGap& gp : ws.gaps_a)
    if (gp.gap < 0 && gp.on_surface) pattern.Add(ToothOf(v1[gp.node], z1), gp.p_W);
  for (const NodeGap& gp : ws.gaps_b)
    if (gp.gap < 0 && gp.on_surface) pattern.Add(ToothOf(v1[s1.undeformed().triangles()[gp.face][0]], z1), gp.q_W);
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
}

// Mean stiffness, single- and double-pair zone means and the TE's peak to peak.
void SummarizeSweep(FlexibleMeshSweep& sweep) {
  double sum = 0, te_min = 1e300, te_max = -1e300;
  double zone_sum[2] = {0, 0};
  int zone_n[2] = {0, 0};
  for (const MeshSweepPoint& p : sweep.points) {
    sum += p.stiffness_n_per_m;
    te_min = std::min(te_min, p.transmission_error_m);
    te_max = std::max(te_max, p.transmission_error_m);
    if (p.teeth_in_contact == 1 || p.teeth_in_contact == 2) {
      zone_sum[p.teeth_in_contact - 1] += p.stiffness_n_per_m;
      ++zone_n[p.teeth_in_contact - 1];
    }
  }
  sweep.mean_stiffness_n_per_m = sum / static_cast<double>(sweep.points.size());
  if (zone_n[0]) sweep.single_zone_stiffness_n_per_m = zone_sum[0] / zone_n[0];
  if (zone_n[1]) sweep.double_zone_stiffness_n_per_m = zone_sum[1] / zone_n[1];
  sweep.te_peak_to_peak_m = te_max - te_min;
}

}  // namespace

FlexibleMeshSweep SweepFlexibleGearMesh(const gears::GearPair& pair,
                                        const FlexibleGearMeshOptions& options, double load_n,
                                        int points, const MeshSweepRange& range) {
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
  // Reduced gears and their contact surfaces (one part per tooth), with attachment modes on the
  // teeth around those in mesh at the middle of the range (gear 1's tooth k meets gear 2's
  // -k - 1: TvmsSweepFrame).
  const int z1 = pair.gear1().teeth(), z2 = pair.gear2().teeth();
  const double span = range.span_rad > 0 ? range.span_rad : 2 * kPi / z1;
  const int centre1 = static_cast<int>(std::lround(-(range.start_rad + 0.5 * span) * z1 / (2 * kPi)));
  const FlexibleGearBody g1 = ReduceGearForContact(pair.gear1(), false, options, options.bore_radius1_m, centre1);
  const FlexibleGearBody g2 = ReduceGearForContact(pair.gear2(), true, options, options.bore_radius2_m, -centre1);
  sweep.reduce_seconds = g1.reduce_seconds + g2.reduce_seconds;
  sweep.fe_nodes1 = g1.fe_nodes, sweep.fe_nodes2 = g2.fe_nodes;
  const FlexibleContactElement element({.name = "flexible_sweep",
                                        .a = {.body = 1, .flexible = SweepSurface(g1, options, z1)},
                                        .b = {.body = 2, .flexible = SweepSurface(g2, options, z2)},
                                        .law = {.stiffness_per_area = cal.stiffness_per_area}});
  FlexibleContactWorkspace ws(element.spec().a, element.spec().b);
  const double rb1 = pair.gear1().base_radius_m();
  SweepProblem problem(element, ws, g1, g2, rb1, load_n, cal.stiffness_per_area);
  sweep.nf1 = element.spec().a.flexible->nf(), sweep.nf2 = element.spec().b.flexible->nf();
  const Vec3 p2(pair.center_distance_m(), 0, 0);
  const auto t0 = std::chrono::steady_clock::now();
  // Unknowns x = (TE, q1, q2); warm-started across roll angles.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(problem.size());
  x(0) = load_n / gears::CalcIso6336Stiffness(pair).c_single_n_per_m;
  for (int i = 0; i < points; ++i) {
    MeshSweepPoint pt;
    pt.roll_angle_rad = range.start_rad + span * i / points;
    const double theta2 = kPi + kPi / z2 - double(z1) / z2 * pt.roll_angle_rad;
    problem.SetPose(pt.roll_angle_rad, Transform(AxisAngle(Vec3::UnitZ(), theta2), p2));
    if (!SolveSweepPoint(problem, ws, load_n, sweep.hertz_stiffness_n_per_m, options.max_newton_iterations, x, pt)) {
      problem.Linearize(x);
      // Stalled (contacts switching between features at a tip corner): accepted if the moment
      // balances to 1 % of the load, counted and reported; otherwise an error.
      const double residual = std::abs(problem.gradient()(0)) / load_n;
      if (!(residual < 1e-2))
        throw std::runtime_error("SweepFlexibleGearMesh: no equilibrium at roll angle " +
                                 std::to_string(pt.roll_angle_rad) + " (moment residual " + std::to_string(residual) +
                                 " of the load, TE " + std::to_string(x(0)) + " m)");
      ++sweep.unconverged_points;
      sweep.max_moment_residual = std::max(sweep.max_moment_residual, residual);
      problem.Evaluate(x, pt);
    }
    pt.transmission_error_m = x(0);
    pt.stiffness_n_per_m = load_n / x(0);
    pt.normal_force_n = ws.normal_force;
    pt.contact_points = ws.contact_points;
    sweep.max_deformation_m.push_back(std::max(ws.side_a.deformation_bound, ws.side_b.deformation_bound));
    RecordContactPattern(pair, ws, *element.spec().a.flexible, rb1, x(0), pt, sweep);
    sweep.evaluations += pt.evaluations;
    sweep.points.push_back(pt);
  }
  sweep.sweep_seconds = Seconds(t0);
  sweep.inflation_exceeded = ws.inflation_exceeded;
  SummarizeSweep(sweep);
  return sweep;
}

}  // namespace orrery::gears

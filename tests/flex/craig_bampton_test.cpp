// Craig-Bampton reduction (flex/craig_bampton.cpp) and interfaces (flex/fe_interface.cpp) on a
// hex20 box bar 1 x 0.1 x 0.15 m (10 x 2 x 2 bricks, E = 210 GPa, nu = 0.3, rho = 7850 kg/m^3),
// interfaces on the end faces XMIN (reference, body frame) and XMAX. Oracles:
//   - frequencies: Rayleigh-Ritz. The reduced elastic eigenvalues are upper bounds of the FE model
//     clamped at the reference master and decrease monotonically as normal modes are added (the
//     bases are nested). With an RBE3 at the free end (no added stiffness) the FE model is the plain
//     cantilever (CalcFeModes with XMIN fixed, no interface code involved); with an RBE2 it is the
//     FE model with the end face rigid (the interface transform, then the sparse eigen solver).
//   - statics: a force and moment on the free master with the reference clamped; Craig-Bampton is
//     exact for interface loads (the constraint modes are the static responses), with any number of
//     normal modes, 0 included. RBE2: the full sparse solve in interface coordinates. RBE3: the plain
//     cantilever loaded by the RBE3 distribution f_s = R^T f, master displacement R u_s.
//   - mass properties: rho V, the box centre, and the box inertia with the parallel-axis term. The
//     consistent hex20 mass integrates a rigid (linear) field exactly, so they agree to rounding.
//   - orthogonality: reduced M identity on the elastic block, K diagonal, no rigid stiffness.
// Tolerances: the Lanczos tolerance (1e-10 on Ritz values) and sparse-solve rounding; the static
// differences observed are 2e-11 (RBE2) and 1e-10 (RBE3) relative against a bound of 1e-8, the
// Rayleigh bounds are checked to 1e-8 relative. Mutations checked by hand: flipping the sign of the
// rotation in G fails the interface, offset-master, mass and rigid-stiffness tests; scaling Psi by
// 0.999 fails every reduction test.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "flex/box_mesher.h"
#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "flex/fe_modes.h"
#include "flex/geometric_stiffness.h"

namespace orrery::flex {
namespace {

constexpr double kRho = 7850;
const Eigen::Vector3d kOrigin(0.2, -0.1, 0.3);
const Eigen::Vector3d kSize(1.0, 0.1, 0.15);

FeMesh Bar() {
  FeMesh mesh = MakeBoxMesh({.origin_m = kOrigin, .size_m = kSize, .divisions = {10, 2, 2}, .type = ElementType::kHex20});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = kRho});
  return mesh;
}

// The bar with the node set "MID": the nodes of its middle cross-section (an interior interface).
FeMesh BarWithMidPlane() {
  FeMesh mesh = Bar();
  const Eigen::Vector3d mid = kOrigin + 0.5 * kSize;
  std::vector<int> plane;
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (std::abs(mesh.positions()[i].x() - mid.x()) < 1e-9) plane.push_back(i);
  mesh.AddToNodeSet("MID", plane);
  return mesh;
}

std::vector<FeInterface> Ends(InterfaceKind xmin, InterfaceKind xmax, const FeMesh& mesh) {
  return {MakeInterface(mesh, "XMIN", xmin), MakeInterface(mesh, "XMAX", xmax)};
}

// Rows and columns `keep` (ascending) of a sparse matrix.
Eigen::SparseMatrix<double> Restrict(const Eigen::SparseMatrix<double>& A, const std::vector<int>& keep) {
  std::vector<int> map(A.rows(), -1);
  for (int i = 0; i < static_cast<int>(keep.size()); ++i) map[keep[i]] = i;
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < A.outerSize(); ++c) {
    if (map[c] < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (map[it.row()] >= 0) t.emplace_back(map[it.row()], map[c], it.value());
  }
  Eigen::SparseMatrix<double> R(keep.size(), keep.size());
  R.setFromTriplets(t.begin(), t.end());
  return R;
}

// Elastic eigenvalues of a reduced model (after the 6 rigid coordinates).
Eigen::VectorXd Elastic(const CraigBamptonModel& cb) { return cb.eigenvalues.tail(cb.num_elastic); }

TEST(CraigBamptonInterface, Rbe3AveragesAndRbe2IsRigid) {
  const FeMesh mesh = Bar();
  FeInterface f = MakeInterface(mesh, "XMAX", InterfaceKind::kRbe3);
  const Eigen::Vector3d p = InterfaceMasterPosition(mesh, f);
  EXPECT_NEAR(p.x(), kOrigin.x() + kSize.x(), 1e-14);
  EXPECT_NEAR(p.y(), kOrigin.y() + kSize.y() / 2, 1e-14);
  const Eigen::MatrixXd G = RigidKinematicMatrix(mesh, f.nodes, p);
  const Eigen::MatrixXd R = Rbe3AveragingMatrix(mesh, f);
  // A rigid slave motion is fitted exactly: R G = I
  EXPECT_LT((R * G - Eigen::MatrixXd::Identity(6, 6)).norm(), 1e-12);
  // The master translation is the mean translation of the slaves
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * f.nodes.size());
  for (std::size_t k = 0; k < f.nodes.size(); ++k) u(3 * k + 1) = static_cast<double>(k % 5);
  EXPECT_NEAR((R * u)(1), u.sum() / f.nodes.size(), 1e-12);
  // Collinear slaves do not fix a rotation
  FeInterface line{.name = "LINE", .kind = InterfaceKind::kRbe3, .nodes = {f.nodes[0], f.nodes[0]}};
  EXPECT_THROW(Rbe3AveragingMatrix(mesh, line), std::invalid_argument);
  // Shared nodes are rejected
  std::vector<FeInterface> both = {f, f};
  EXPECT_THROW(MakeInterfaceTransform(mesh, both), std::invalid_argument);
  // A rigid motion in interface coordinates is rigid at every node (RBE2 and RBE3 ends)
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe3, mesh);
  const InterfaceTransform t = MakeInterfaceTransform(mesh, ifs);
  Eigen::Matrix<double, 6, 1> a;
  a << 1e-3, -2e-3, 5e-4, 0.01, -0.02, 0.03;
  Eigen::VectorXd q(t.T.cols());
  for (int j = 0; j < 2; ++j) {
    // Master motion of interface j under the rigid motion a about master 0: [[I, -skew(d)], [0, I]]
    Eigen::Matrix<double, 6, 6> gamma = Eigen::Matrix<double, 6, 6>::Identity();
    const Eigen::Vector3d d = t.master_positions[j] - t.master_positions[0];
    gamma.block<3, 3>(0, 3) << 0, d.z(), -d.y(), -d.z(), 0, d.x(), d.y(), -d.x(), 0;
    q.segment<6>(6 * j) = gamma * a;
  }
  const std::vector<int> all = mesh.NodeSet("NALL");
  const Eigen::VectorXd rigid = RigidKinematicMatrix(mesh, all, t.master_positions[0]) * a;
  for (std::size_t k = 0; k < t.interior_dofs.size(); ++k) q(t.num_boundary + k) = rigid(t.interior_dofs[k]);
  EXPECT_LT((t.T * q - rigid).norm(), 1e-12 * rigid.norm());
}

// Convergence with 32 fixed-interface modes (cutoff f_c, the highest kept): the relative eigenvalue
// error of each of the first 6 elastic modes is below the usual truncation estimate (f / f_c)^2 and
// below 1/20 of its error with 4 modes (observed here: factors 30 to 1000).
void ExpectConverged(const CraigBamptonModel& cb, const FeModes& exact, const Eigen::VectorXd& errors4,
                     const char* label) {
  const double f_c = EigenvalueToHz(cb.fixed_interface_eigenvalues.tail(1)(0));
  for (int k = 0; k < 6; ++k) {
    const double rel = cb.eigenvalues(6 + k) / exact.eigenvalues(k) - 1;
    std::printf("  %s, 32 modes (f_c %.0f Hz): mode %d  %.6f Hz (FE %.6f Hz), rel. eigenvalue error %.2e (4 modes: %.2e)\n",
                label, f_c, k + 1, cb.frequencies_hz[6 + k], exact.frequencies_hz[k], rel, errors4(k));
    EXPECT_LT(rel, std::pow(exact.frequencies_hz[k] / f_c, 2)) << label << " mode " << k;
    EXPECT_LT(rel, errors4(k) / 20) << label << " mode " << k;
  }
}

// (1) Rayleigh-Ritz: RBE3 free end, against the plain cantilever.
TEST(CraigBampton, FrequenciesConvergeFromAboveRbe3End) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const FeModes exact = CalcFeModes(sys, NodeDofs(mesh.NodeSet("XMIN")), {.num_modes = 12});
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe3, mesh);
  Eigen::VectorXd previous, errors4;
  for (int nm : {0, 2, 4, 8, 16, 32}) {
    const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = nm});
    const Eigen::VectorXd lam = Elastic(cb);
    ASSERT_EQ(lam.size(), 6 + nm);
    const int n = std::min<int>(12, lam.size());
    for (int k = 0; k < n; ++k) {
      EXPECT_GE(lam(k), exact.eigenvalues(k) * (1 - 1e-8)) << "nm " << nm << " mode " << k;
      if (previous.size() > k) {
        EXPECT_LE(lam(k), previous(k) * (1 + 1e-8)) << "nm " << nm << " mode " << k;
      }
    }
    previous = lam;
    if (nm == 4) errors4 = lam.head(6).cwiseQuotient(exact.eigenvalues.head(6)).array() - 1;
    if (nm == 32) ExpectConverged(cb, exact, errors4, "RBE3 end");
  }
}

// (1) Rayleigh-Ritz: RBE2 free end, against the FE model with a rigid end face.
TEST(CraigBampton, FrequenciesConvergeFromAboveRbe2End) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe2, mesh);
  // Full model: interface coordinates, reference master (coordinates 0-5) fixed
  const InterfaceTransform t = MakeInterfaceTransform(mesh, ifs);
  const Eigen::SparseMatrix<double> Kq = t.T.transpose() * sys.K * t.T, Mq = t.T.transpose() * sys.M * t.T;
  const int nq = static_cast<int>(Kq.rows());
  const Eigen::SparseMatrix<double> Kf = Kq.block(6, 6, nq - 6, nq - 6), Mf = Mq.block(6, 6, nq - 6, nq - 6);
  const FeModes exact = SolveLowestModes(Kf, Mf, {.num_modes = 12});
  // The rigid end face stiffens the cantilever (Rayleigh: a constraint raises every eigenvalue)
  const FeModes cantilever = CalcFeModes(sys, NodeDofs(mesh.NodeSet("XMIN")), {.num_modes = 12});
  for (int k = 0; k < 12; ++k) EXPECT_GE(exact.eigenvalues(k), cantilever.eigenvalues(k) * (1 - 1e-8));
  Eigen::VectorXd previous, errors4;
  for (int nm : {0, 2, 4, 8, 16, 32}) {
    const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = nm});
    const Eigen::VectorXd lam = Elastic(cb);
    const int n = std::min<int>(12, lam.size());
    for (int k = 0; k < n; ++k) {
      EXPECT_GE(lam(k), exact.eigenvalues(k) * (1 - 1e-8)) << "nm " << nm << " mode " << k;
      if (previous.size() > k) {
        EXPECT_LE(lam(k), previous(k) * (1 + 1e-8)) << "nm " << nm << " mode " << k;
      }
    }
    previous = lam;
    if (nm == 4) errors4 = lam.head(6).cwiseQuotient(exact.eigenvalues.head(6)).array() - 1;
    if (nm == 32) ExpectConverged(cb, exact, errors4, "RBE2 end");
  }
}

// Reduced master displacement under a master load f: the body is clamped at the reference master,
// so the rigid coordinates stay zero and K_e eta = S_e^T f.
Eigen::Matrix<double, 6, 1> ReducedStatic(const CraigBamptonModel& cb, int interface,
                                          const Eigen::Matrix<double, 6, 1>& f) {
  const Eigen::MatrixXd S = cb.master_shapes.block(6 * interface, 6, 6, cb.num_elastic);
  const Eigen::MatrixXd Ke = cb.K.bottomRightCorner(cb.num_elastic, cb.num_elastic);
  const Eigen::VectorXd eta = Ke.ldlt().solve(S.transpose() * f);
  return S * eta;
}

Eigen::Matrix<double, 6, 1> EndLoad() {
  Eigen::Matrix<double, 6, 1> f;
  f << 2e4, -3e4, 5e4, 1e3, -2e3, 4e3;  // N, N m
  return f;
}

// (2) Statics, RBE2 at both ends: exact with and without normal modes.
TEST(CraigBampton, StaticInterfaceLoadIsExactRbe2) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe2, mesh);
  const InterfaceTransform t = MakeInterfaceTransform(mesh, ifs);
  const Eigen::SparseMatrix<double> Kq = t.T.transpose() * sys.K * t.T;
  const int nq = static_cast<int>(Kq.rows());
  const Eigen::SparseMatrix<double> Kf = Kq.block(6, 6, nq - 6, nq - 6);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nq - 6);
  rhs.head(6) = EndLoad();  // free master = coordinates 6-11, first after the reference
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Kf);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const Eigen::Matrix<double, 6, 1> u_full = ldlt.solve(rhs).head(6);
  for (int nm : {0, 10}) {
    const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = nm});
    const Eigen::Matrix<double, 6, 1> u_cb = ReducedStatic(cb, 1, EndLoad());
    std::printf("  RBE2, %d modes: tip u = (%.6e %.6e %.6e) m, theta = (%.6e %.6e %.6e), rel. diff %.2e\n", nm,
                u_cb(0), u_cb(1), u_cb(2), u_cb(3), u_cb(4), u_cb(5), (u_cb - u_full).norm() / u_full.norm());
    EXPECT_LT((u_cb - u_full).norm(), 1e-8 * u_full.norm()) << "modes " << nm;
  }
}

// (2) Statics, RBE3 free end: against the plain cantilever loaded by the RBE3 distribution.
TEST(CraigBampton, StaticInterfaceLoadIsExactRbe3) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe3, mesh);
  // Cantilever: XMIN DOFs removed, slave forces R^T f at XMAX
  std::vector<bool> fixed(3 * mesh.num_nodes(), false);
  for (int d : NodeDofs(mesh.NodeSet("XMIN"))) fixed[d] = true;
  std::vector<int> free, where(3 * mesh.num_nodes(), -1);
  for (int d = 0; d < 3 * mesh.num_nodes(); ++d)
    if (!fixed[d]) {
      where[d] = static_cast<int>(free.size());
      free.push_back(d);
    }
  const Eigen::MatrixXd R = Rbe3AveragingMatrix(mesh, ifs[1]);
  const Eigen::VectorXd fs = R.transpose() * EndLoad();
  const std::vector<int> sdofs = NodeDofs(ifs[1].nodes);
  // NodeDofs sorts by node index; map the slave order of R explicitly
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(free.size());
  for (std::size_t k = 0; k < ifs[1].nodes.size(); ++k)
    for (int c = 0; c < 3; ++c) rhs(where[3 * ifs[1].nodes[k] + c]) += fs(3 * k + c);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Restrict(sys.K, free));
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const Eigen::VectorXd u = ldlt.solve(rhs);
  Eigen::VectorXd us(3 * ifs[1].nodes.size());
  for (std::size_t k = 0; k < ifs[1].nodes.size(); ++k)
    for (int c = 0; c < 3; ++c) us(3 * k + c) = u(where[3 * ifs[1].nodes[k] + c]);
  const Eigen::Matrix<double, 6, 1> u_full = R * us;
  EXPECT_EQ(sdofs.size(), us.size());
  for (int nm : {0, 10}) {
    const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = nm});
    const Eigen::Matrix<double, 6, 1> u_cb = ReducedStatic(cb, 1, EndLoad());
    std::printf("  RBE3, %d modes: tip u = (%.6e %.6e %.6e) m, theta = (%.6e %.6e %.6e), rel. diff %.2e\n", nm,
                u_cb(0), u_cb(1), u_cb(2), u_cb(3), u_cb(4), u_cb(5), (u_cb - u_full).norm() / u_full.norm());
    EXPECT_LT((u_cb - u_full).norm(), 1e-8 * u_full.norm()) << "modes " << nm;
  }
}

// Weighted RBE3 and the sign convention of G checked against the cross product directly.
TEST(CraigBamptonInterface, WeightedRbe3AndRotationConvention) {
  const FeMesh mesh = Bar();
  FeInterface f = MakeInterface(mesh, "XMAX", InterfaceKind::kRbe3);
  const int ns = static_cast<int>(f.nodes.size());
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * ns);
  double wsum = 0, wu = 0;
  for (int k = 0; k < ns; ++k) {
    f.weights.push_back(1.0 + (k % 3));
    u(3 * k + 2) = std::sin(1.0 + k);
    wsum += f.weights.back();
    wu += f.weights.back() * u(3 * k + 2);
  }
  // Master at the weighted centroid: the master translation is the weighted mean
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int k = 0; k < ns; ++k) c += f.weights[k] * mesh.positions()[f.nodes[k]];
  f.master_position_m = c / wsum;
  const Eigen::MatrixXd R = Rbe3AveragingMatrix(mesh, f);
  EXPECT_NEAR((R * u)(2), wu / wsum, 1e-12);
  // Loads reach the slaves statically equivalent: sum f_s = F, sum r x f_s = M
  Eigen::Matrix<double, 6, 1> load;
  load << 1, 2, 3, 4, 5, 6;
  const Eigen::VectorXd fs = R.transpose() * load;
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), Mo = Eigen::Vector3d::Zero();
  for (int k = 0; k < ns; ++k) {
    F += fs.segment<3>(3 * k);
    Mo += (mesh.positions()[f.nodes[k]] - *f.master_position_m).cross(Eigen::Vector3d(fs.segment<3>(3 * k)));
  }
  EXPECT_LT((F - load.head(3)).norm(), 1e-12);
  EXPECT_LT((Mo - load.tail(3)).norm(), 1e-12);
  // G: u_s = u_m + theta x r
  const Eigen::Vector3d p(0.3, -0.2, 0.5), theta(0.01, -0.03, 0.02), um(1e-3, 2e-3, -1e-3);
  const std::vector<int> one = {f.nodes[3]};
  Eigen::Matrix<double, 6, 1> m6;
  m6 << um, theta;
  const Eigen::Vector3d expected = um + theta.cross(mesh.positions()[one[0]] - p);
  EXPECT_LT((RigidKinematicMatrix(mesh, one, p) * m6 - expected).norm(), 1e-15);
}

// (2) Statics with an offset master: a force F at a master offset by d from the face centroid
// equals F and the moment d x F at the centroid; the offset master moves by u_c + theta_c x d.
TEST(CraigBampton, OffsetMasterTransfersMomentArm) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  for (InterfaceKind kind : {InterfaceKind::kRbe2, InterfaceKind::kRbe3}) {
    auto ifs = Ends(InterfaceKind::kRbe2, kind, mesh);
    const CraigBamptonModel centred = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 4});
    const Eigen::Vector3d d(0.2, 0.05, -0.1);
    ifs[1].master_position_m = centred.master_positions_m[1] + d;
    const CraigBamptonModel offset = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 4});
    const Eigen::Vector3d F(1e4, -2e4, 3e4);
    Eigen::Matrix<double, 6, 1> f_off, f_c;
    f_off << F, Eigen::Vector3d::Zero();
    f_c << F, d.cross(F);
    const Eigen::Matrix<double, 6, 1> u_off = ReducedStatic(offset, 1, f_off), u_c = ReducedStatic(centred, 1, f_c);
    const Eigen::Vector3d expected = u_c.head<3>() + u_c.tail<3>().cross(d);
    EXPECT_LT((u_off.head<3>() - expected).norm(), 1e-8 * expected.norm()) << static_cast<int>(kind);
    EXPECT_LT((u_off.tail<3>() - u_c.tail<3>()).norm(), 1e-8 * u_c.tail<3>().norm()) << static_cast<int>(kind);
  }
}

// One interface: the elastic modes are exactly the fixed-interface modes; RBE3 as the only
// interface (weighted mean motion held) also holds the body.
TEST(CraigBampton, SingleInterfaceGivesTheFixedInterfaceModes) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  for (InterfaceKind kind : {InterfaceKind::kRbe2, InterfaceKind::kRbe3}) {
    const std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", kind)};
    const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 8});
    ASSERT_EQ(cb.num_elastic, 8);
    for (int k = 0; k < 8; ++k)
      EXPECT_NEAR(cb.eigenvalues(6 + k), cb.fixed_interface_eigenvalues(k), 1e-9 * cb.fixed_interface_eigenvalues(k));
  }
  // The RBE2 clamp is the cantilever
  const FeModes cantilever = CalcFeModes(sys, NodeDofs(mesh.NodeSet("XMIN")), {.num_modes = 8});
  const std::vector<FeInterface> clamp = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2)};
  const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, clamp, {.num_modes = 8});
  for (int k = 0; k < 8; ++k)
    EXPECT_NEAR(cb.eigenvalues(6 + k), cantilever.eigenvalues(k), 1e-8 * cantilever.eigenvalues(k));
}

// The reduction's held statics under the six inertial load cases (block elimination of the free
// masters through K_ii's factorization, craig_bampton.cpp) against an independent solve: a
// factorization of the stiffness with only the reference master held (SolveStaticsHeldAtInterface).
// Both are exact solutions of the same system: they differ by the rounding of the two sparse
// solves (observed 5e-12 with RBE2, up to 1.3e-10 with RBE3 ends, relative) against a bound of
// 1e-9 (a solve that ignores the free masters is off by 1.0); with three interfaces (the middle one
// on a node set of the mid-plane) two masters are eliminated.
// InterfaceCoordinatesMatrix against Eigen's sparse product T^T A T (the oracle: the same terms
// summed in another order), K and M, with an RBE2, a weighted RBE3 and an RBE2 in the middle so
// that RBE3 rows (a dependent DOF reads every independent slave DOF) meet RBE2 rows. Bound: two
// sums of the same m products differ by at most 2 gamma_(m+2) = 2 (m + 2) eps / (1 - (m + 2) eps)
// times the sum of the products' magnitudes, (|T|^T |A| |T|)(a, b) (Higham, Accuracy and
// Stability of Numerical Algorithms, 2002, sec. 3.1; two roundings per product); m per entry is
// the same product of the matrices' patterns with ones. Measured: 0.077 (K) and 0.095 (M) of the
// bound at most (2.0e-17 and 1.5e-17 of the largest entry). The columns must come out sorted, and
// the upper triangle alone (upper_only) is the full result's to the bit.
TEST(CraigBamptonInterface, InterfaceCoordinatesMatrixIsTheProductTtAT) {
  const FeMesh mesh = BarWithMidPlane();
  const FeSystem sys = AssembleFeSystem(mesh);
  FeInterface rbe3 = MakeInterface(mesh, "XMAX", InterfaceKind::kRbe3);
  for (std::size_t k = 0; k < rbe3.nodes.size(); ++k)
    rbe3.weights.push_back(1.0 + 0.1 * double(k % 7));
  const std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2),
                                        MakeInterface(mesh, "MID", InterfaceKind::kRbe2), rbe3};
  const InterfaceTransform t = MakeInterfaceTransform(mesh, ifs);
  auto ones = [](const Eigen::SparseMatrix<double>& A) {
    return A.unaryExpr([](double) { return 1.0; });
  };
  const Eigen::SparseMatrix<double> absT = t.T.cwiseAbs(), patT = ones(t.T);
  const double eps = std::numeric_limits<double>::epsilon();
  for (const Eigen::SparseMatrix<double>* A : {&sys.K, &sys.M}) {
    const Eigen::MatrixXd fast = Eigen::MatrixXd(InterfaceCoordinatesMatrix(t, *A));
    const Eigen::MatrixXd eigen =
        Eigen::MatrixXd(Eigen::SparseMatrix<double>(t.T.transpose() * *A * t.T));
    const Eigen::ArrayXXd magnitude =
        Eigen::MatrixXd(Eigen::SparseMatrix<double>(absT.transpose() * A->cwiseAbs() * absT))
            .array();
    const Eigen::ArrayXXd m =
        Eigen::MatrixXd(Eigen::SparseMatrix<double>(patT.transpose() * ones(*A) * patT)).array() +
        2;
    ASSERT_EQ(fast.rows(), eigen.rows());
    ASSERT_EQ(fast.cols(), eigen.cols());
    ASSERT_TRUE(fast.allFinite());
    const Eigen::ArrayXXd bound = 2 * m * eps / (1 - m * eps) * magnitude;
    const Eigen::ArrayXXd difference = (fast - eigen).cwiseAbs().array();
    EXPECT_TRUE((difference <= bound).all())
        << (A == &sys.K ? "K" : "M") << ": largest difference over its bound "
        << (difference / bound.max(1e-300)).maxCoeff();
  }
  const Eigen::SparseMatrix<double> K = InterfaceCoordinatesMatrix(t, sys.K);
  for (Eigen::Index j = 0; j < K.outerSize(); ++j) {
    Eigen::Index previous = -1;
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it) {
      ASSERT_GT(it.row(), previous) << "column " << j << " not sorted";
      previous = it.row();
    }
  }
  // The upper triangle alone: the same sums, to the bit
  const Eigen::MatrixXd upper =
      Eigen::MatrixXd(InterfaceCoordinatesMatrix(t, sys.K, /*upper_only=*/true));
  const Eigen::MatrixXd full_upper = Eigen::MatrixXd(K).triangularView<Eigen::Upper>();
  EXPECT_EQ((upper - full_upper).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_THROW(InterfaceCoordinatesMatrix(t, Eigen::SparseMatrix<double>(3, 3)),
               std::invalid_argument);
}

TEST(CraigBampton, HeldInertialStaticsMatchAnIndependentSolve) {
  const FeMesh mesh = BarWithMidPlane();
  const FeSystem sys = AssembleFeSystem(mesh);
  for (InterfaceKind kind : {InterfaceKind::kRbe2, InterfaceKind::kRbe3}) {
    const std::vector<FeInterface> ifs = {MakeInterface(mesh, "XMIN", InterfaceKind::kRbe2),
                                          MakeInterface(mesh, "MID", kind), MakeInterface(mesh, "XMAX", kind)};
    for (int ref : {0, 2}) {
      const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 4, .reference_interface = ref});
      const Eigen::MatrixXd F = InertialLoadCases(mesh, sys, cb.master_positions_m[ref]);
      const Eigen::MatrixXd U = SolveStaticsHeldAtInterface(mesh, sys, ifs, ref, F);
      ASSERT_EQ(cb.inertial_load_statics.rows(), U.rows());
      ASSERT_EQ(cb.inertial_load_statics.cols(), 6);
      EXPECT_LT((cb.inertial_load_statics - U).norm(), 1e-9 * U.norm()) << "reference " << ref;
    }
  }
}

// (3) Mass properties of the rigid block: rho V, box centre, box inertia about the reference master.
TEST(CraigBampton, RigidBlockHasTheMassPropertiesOfTheMesh) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const double m = kRho * kSize.prod();
  const Eigen::Vector3d c = kOrigin + kSize / 2;
  Eigen::Matrix3d Ic = Eigen::Matrix3d::Zero();
  Ic(0, 0) = m / 12 * (kSize.y() * kSize.y() + kSize.z() * kSize.z());
  Ic(1, 1) = m / 12 * (kSize.x() * kSize.x() + kSize.z() * kSize.z());
  Ic(2, 2) = m / 12 * (kSize.x() * kSize.x() + kSize.y() * kSize.y());
  for (InterfaceKind kind : {InterfaceKind::kRbe2, InterfaceKind::kRbe3})
    for (int ref : {0, 1}) {
      const auto ifs = Ends(kind, InterfaceKind::kRbe2, mesh);
      const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 6, .reference_interface = ref});
      const Eigen::Vector3d d = c - cb.master_positions_m[ref];
      const Eigen::Matrix3d I_Ro = Ic + m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
      EXPECT_NEAR(cb.mass_kg, m, 1e-12 * m);
      EXPECT_NEAR(sys.mass_kg, m, 1e-12 * m);
      EXPECT_LT((cb.p_RoCm_m - d).norm(), 1e-12);
      EXPECT_LT((cb.I_Ro_kgm2 - I_Ro).norm(), 1e-11 * I_Ro.norm()) << "kind " << static_cast<int>(kind) << " ref " << ref;
      // Translational block is m I exactly
      EXPECT_LT((cb.M.topLeftCorner(3, 3) - m * Eigen::Matrix3d::Identity()).norm(), 1e-11 * m);
    }
}

// (4) Orthogonality and separation of the rigid coordinates.
TEST(CraigBampton, ReducedMatricesAreDiagonalOnElasticModes) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe3, mesh);
  const CraigBamptonModel cb = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 12});
  const int ne = cb.num_elastic;
  ASSERT_EQ(ne, 18);
  ASSERT_EQ(cb.K.rows(), 24);
  const Eigen::MatrixXd Me = cb.M.bottomRightCorner(ne, ne), Ke = cb.K.bottomRightCorner(ne, ne);
  EXPECT_LT((Me - Eigen::MatrixXd::Identity(ne, ne)).cwiseAbs().maxCoeff(), 1e-10);
  const double kmax = Ke.diagonal().maxCoeff();
  Eigen::MatrixXd off = Ke;
  off.diagonal().setZero();
  EXPECT_LT(off.cwiseAbs().maxCoeff(), 1e-10 * kmax);
  for (int k = 0; k < ne; ++k) {
    EXPECT_NEAR(Ke(k, k), cb.eigenvalues(6 + k), 1e-10 * kmax);
    EXPECT_GT(cb.eigenvalues(6 + k), 0);
    if (k > 0) {
      EXPECT_GE(cb.eigenvalues(6 + k), cb.eigenvalues(5 + k));
    }
  }
  // Rigid coordinates carry no strain energy: K's rigid rows vanish (relative to K's scale)
  EXPECT_LT(cb.K.topRows(6).cwiseAbs().maxCoeff(), 1e-8 * kmax);
  // The body is clamped at the reference master: elastic shapes vanish at its RBE2 nodes, the
  // rigid shapes are the rigid field there
  const std::vector<int> dofs = NodeDofs(ifs[0].nodes);
  for (int d : dofs) EXPECT_LT(cb.shapes.row(d).tail(ne).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((cb.master_shapes.topLeftCorner(6, 6) - Eigen::MatrixXd::Identity(6, 6)).norm(), 1e-12);
  EXPECT_LT(cb.master_shapes.topRightCorner(6, ne).cwiseAbs().maxCoeff(), 1e-12);
  // The full reduced eigenproblem has 6 zero eigenvalues and the elastic ones
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(cb.K, cb.M);
  for (int k = 0; k < 6; ++k) EXPECT_LT(std::abs(ges.eigenvalues()(k)), 1e-8 * kmax);
}

// Truncation by cutoff frequency keeps exactly the fixed-interface modes below it.
TEST(CraigBampton, CutoffFrequencyKeepsModesBelowIt) {
  const FeMesh mesh = Bar();
  const FeSystem sys = AssembleFeSystem(mesh);
  const auto ifs = Ends(InterfaceKind::kRbe2, InterfaceKind::kRbe2, mesh);
  const CraigBamptonModel all = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 10});
  const double cutoff = 0.5 * (EigenvalueToHz(all.fixed_interface_eigenvalues(3)) +
                               EigenvalueToHz(all.fixed_interface_eigenvalues(4)));
  const CraigBamptonModel cut = ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 10, .cutoff_hz = cutoff});
  EXPECT_EQ(cut.fixed_interface_eigenvalues.size(), 4);
  EXPECT_TRUE(cut.cutoff_reached);
  EXPECT_EQ(cut.num_elastic, 6 + 4);
  EXPECT_THROW(ReduceCraigBampton(mesh, sys, ifs, {.reference_interface = 2}), std::invalid_argument);
  EXPECT_THROW(ReduceCraigBampton(mesh, sys, ifs, {.num_modes = -1}), std::invalid_argument);
}

}  // namespace
}  // namespace orrery::flex

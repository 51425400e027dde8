// CHOLMOD supernodal Cholesky (flex/cholmod_factor.cpp) and its use in the shift-invert operator
// (flex/sparse_ldlt_shift_invert.cpp): on a clamped hex20 box, the eigenvalues of
// K phi = w^2 M phi obtained through (K - sigma M)^-1 with CHOLMOD equal those through the
// simplicial LDL^T (relative 1e-10) and those of CalcFeModes (whose default operator uses
// CHOLMOD); above the lowest eigenvalue the operator falls back to LDL^T and counts the
// eigenvalues below the shift; the symbolic analysis is reused across shifts.
// The eigenvalues through an operator are computed densely: F = (K - sigma M)^-1 column by
// column, M = L L^T, eigenvalues nu of L^T F L, w^2 = sigma + 1 / nu.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "flex/blas_kernels.h"
#include "flex/box_mesher.h"
#include "flex/cholmod_factor.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"
#include "flex/sparse_ldlt_shift_invert.h"

namespace orrery::flex {
namespace {

struct Clamped {
  FeSystem system;
  std::vector<int> fixed;
  Eigen::SparseMatrix<double> K, M;  // free DOFs only
};

Clamped MakeClampedBox() {
  FeMesh mesh = MakeBoxMesh({.size_m = {0.4, 0.1, 0.08}, .divisions = {4, 2, 1}, .type = ElementType::kHex20});
  mesh.AssignMaterialToAll({.name = "STEEL", .youngs_modulus_pa = 210e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850});
  Clamped c{.system = AssembleFeSystem(mesh), .fixed = NodeDofs(mesh.NodeSet("XMIN"))};
  const int ndof = static_cast<int>(c.system.K.rows());
  std::vector<int> map(ndof, 0);
  for (int d : c.fixed) map[d] = -1;
  int n = 0;
  for (int d = 0; d < ndof; ++d)
    if (map[d] == 0) map[d] = n++;
    else map[d] = -1;
  const auto restrict = [&](const Eigen::SparseMatrix<double>& A) {
    std::vector<Eigen::Triplet<double>> t;
    for (int col = 0; col < A.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, col); it; ++it)
        if (map[it.row()] >= 0 && map[col] >= 0) t.emplace_back(map[it.row()], map[col], it.value());
    Eigen::SparseMatrix<double> R(n, n);
    R.setFromTriplets(t.begin(), t.end());
    return R;
  };
  c.K = restrict(c.system.K);
  c.M = restrict(c.system.M);
  return c;
}

// F = (K - sigma M)^-1 through the operator's perform_op.
Eigen::MatrixXd InverseThrough(const SparseLdltShiftInvert& op) {
  const Eigen::Index n = op.rows();
  Eigen::MatrixXd F(n, n);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    e(j) = 1;
    op.perform_op(e.data(), F.col(j).data());
    e(j) = 0;
  }
  return F;
}

// Ascending eigenvalues w^2 of K x = w^2 M x from F = (K - sigma M)^-1 (sigma below all of them).
Eigen::VectorXd EigenvaluesThrough(const SparseLdltShiftInvert& op, const Eigen::SparseMatrix<double>& M) {
  const Eigen::MatrixXd F = InverseThrough(op);
  const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(Eigen::MatrixXd(M)).matrixL();
  const Eigen::MatrixXd C = L.transpose() * (0.5 * (F + F.transpose())) * L;
  const Eigen::VectorXd nu = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C, Eigen::EigenvaluesOnly).eigenvalues();
  Eigen::VectorXd w2(nu.size());
  for (Eigen::Index i = 0; i < nu.size(); ++i) w2(i) = op.shift() + 1 / nu(nu.size() - 1 - i);  // largest nu first
  return w2;
}

double NegativeShift(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M) {
  return -1e-6 * K.diagonal().sum() / M.diagonal().sum();  // fe_modes.cpp's default
}

TEST(CholmodFactorTest, CholeskyEigenvaluesEqualLdlt) {
  const Clamped c = MakeClampedBox();
  const double sigma = NegativeShift(c.K, c.M);
  SparseLdltShiftInvert chol(c.K, c.M, ShiftInvertMethod::kCholesky), ldlt(c.K, c.M, ShiftInvertMethod::kLdlt);
  chol.set_shift(sigma);
  ldlt.set_shift(sigma);
  ASSERT_TRUE(chol.uses_cholesky());
  ASSERT_FALSE(ldlt.uses_cholesky());
  EXPECT_EQ(chol.num_eigenvalues_below_shift(), 0);
  EXPECT_EQ(ldlt.num_eigenvalues_below_shift(), 0);
  EXPECT_GT(chol.factor_nonzeros(), c.K.rows());
  const Eigen::VectorXd a = EigenvaluesThrough(chol, c.M), b = EigenvaluesThrough(ldlt, c.M);
  ASSERT_GT(a.size(), 100);
  for (int i = 0; i < 30; ++i) {
    EXPECT_GT(a(i), 0) << i;
    EXPECT_NEAR(a(i), b(i), 1e-10 * b(i)) << "mode " << i;
  }
  // CalcFeModes uses the default operator (Cholesky at its negative shift)
  const FeModes modes = CalcFeModes(c.system, c.fixed, {.num_modes = 30});
  EXPECT_EQ(modes.num_rigid_body_modes, 0);
  for (int i = 0; i < 30; ++i) EXPECT_NEAR(modes.eigenvalues(i), b(i), 1e-10 * b(i)) << "mode " << i;
}

TEST(CholmodFactorTest, FallsBackToLdltAboveLowestEigenvalueAndReusesAnalysis) {
  const Clamped c = MakeClampedBox();
  const double sigma = NegativeShift(c.K, c.M);
  SparseLdltShiftInvert reference(c.K, c.M, ShiftInvertMethod::kLdlt);
  reference.set_shift(sigma);
  const Eigen::VectorXd w2 = EigenvaluesThrough(reference, c.M);
  // A shift between the 3rd and 4th eigenvalues: indefinite
  const double above = 0.5 * (w2(2) + w2(3));
  SparseLdltShiftInvert op(c.K, c.M);  // kAuto
  op.set_shift(above);
  EXPECT_FALSE(op.uses_cholesky());
  EXPECT_EQ(op.num_eigenvalues_below_shift(), 3);
  SparseLdltShiftInvert strict(c.K, c.M, ShiftInvertMethod::kCholesky);
  EXPECT_THROW(strict.set_shift(above), std::runtime_error);
  // Back below the spectrum: Cholesky again, same operator as LDL^T
  for (SparseLdltShiftInvert* o : {&op, &strict}) {
    o->set_shift(sigma);
    EXPECT_TRUE(o->uses_cholesky());
    EXPECT_EQ(o->num_eigenvalues_below_shift(), 0);
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(c.K.rows(), -1, 2);
    Eigen::VectorXd y(x.size()), z(x.size());
    o->perform_op(x.data(), y.data());
    reference.perform_op(x.data(), z.data());
    EXPECT_LT((y - z).norm(), 1e-10 * z.norm());
  }
}

TEST(CholmodFactorTest, FactorizeAndSolve) {
  // 1-D Laplacian plus shift: SPD; minus a large shift: indefinite
  const int n = 50;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0);
    if (i > 0) t.emplace_back(i, i - 1, -1.0), t.emplace_back(i - 1, i, -1.0);
  }
  Eigen::SparseMatrix<double> S(n, n), I(n, n);
  S.setFromTriplets(t.begin(), t.end());
  I.setIdentity();
  CholmodCholesky chol;
  EXPECT_THROW(chol.solve(nullptr, nullptr), std::logic_error);
  ASSERT_TRUE(chol.factorize(S));
  EXPECT_EQ(chol.rows(), n);
  EXPECT_EQ(chol.factor_nonzeros(), 2 * n - 1);  // tridiagonal: no fill
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1, 3);
  Eigen::VectorXd x(n);
  chol.solve(b.data(), x.data());
  EXPECT_LT((S * x - b).norm(), 1e-12 * b.norm() * n * n);
  const Eigen::SparseMatrix<double> indefinite = S - 1.0 * I;
  EXPECT_FALSE(chol.factorize(indefinite));
  EXPECT_FALSE(chol.factorized());
  const Eigen::SparseMatrix<double> shifted = S + 1.0 * I;
  ASSERT_TRUE(chol.factorize(shifted));
  chol.solve(b.data(), x.data());
  EXPECT_LT((shifted * x - b).norm(), 1e-13 * b.norm() * n);
  Eigen::SparseMatrix<double> wrong(n + 1, n + 1);
  wrong.setIdentity();
  EXPECT_THROW(chol.factorize(wrong), std::invalid_argument);
}

// The halves of a solve (S = P^T L L^T P), checked against the whole solve and S itself on the
// clamped hex20 box, whose fill-reducing ordering is not the identity: Y = L^-1 P B has
// Y^T Y = B^T S^-1 B, and X = P^T L^-T Y solves S X = B.
TEST(CholmodFactorTest, ForwardAndBackwardHalvesComposeTheSolve) {
  const Clamped c = MakeClampedBox();
  const Eigen::Index n = c.K.rows();
  CholmodCholesky chol;
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 3);
  Eigen::MatrixXd Y(n, 3), X(n, 3), Xs(n, 3);
  EXPECT_THROW(chol.solve_forward(B.data(), Y.data(), 3), std::logic_error);
  EXPECT_THROW(chol.solve_backward(B.data(), Y.data(), 3), std::logic_error);
  ASSERT_TRUE(chol.factorize(c.K));
  chol.solve(B.data(), Xs.data(), 3);
  chol.solve_forward(B.data(), Y.data(), 3);
  const Eigen::MatrixXd gram = Y.transpose() * Y, expected = B.transpose() * Xs;
  EXPECT_LT((gram - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());
  chol.solve_backward(Y.data(), X.data(), 3);
  EXPECT_LT((X - Xs).cwiseAbs().maxCoeff(), 1e-10 * Xs.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd residual = c.K.selfadjointView<Eigen::Upper>() * X - B;
  EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-8 * B.cwiseAbs().maxCoeff());
  EXPECT_THROW(chol.solve_forward(B.data(), Y.data(), 0), std::invalid_argument);
}

// factorize(S&&) frees S before the numeric factorization and gives the same factor as
// factorize(const S&) (same solves to the bit); both agree with Eigen's simplicial LL^T (an
// independent factorization with its own ordering) on the clamped box, whose ordering permutes;
// a second factorization of another matrix of the same pattern (K - sigma M) reuses the analysis.
TEST(CholmodFactorTest, ReleasingFactorizationIsTheSameFactor) {
  const Clamped c = MakeClampedBox();
  const Eigen::Index n = c.K.rows();
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 2);
  Eigen::MatrixXd X(n, 2), Xr(n, 2);
  CholmodCholesky kept, released;
  ASSERT_TRUE(kept.factorize(c.K));
  Eigen::SparseMatrix<double> S = c.K;
  ASSERT_TRUE(released.factorize(std::move(S)));
  EXPECT_EQ(S.data().allocatedSize(), 0);  // NOLINT(bugprone-use-after-move): released by contract
  EXPECT_EQ(released.factor_nonzeros(), kept.factor_nonzeros());
  kept.solve(B.data(), X.data(), 2);
  released.solve(B.data(), Xr.data(), 2);
  EXPECT_EQ((X - Xr).cwiseAbs().maxCoeff(), 0.0);
  const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Upper> llt(c.K);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Eigen::MatrixXd Xe = llt.solve(B);
  EXPECT_LT((X - Xe).cwiseAbs().maxCoeff(), 1e-10 * Xe.cwiseAbs().maxCoeff());
  // Same pattern, other values: the analysis is kept
  const double sigma = -1e3;
  ASSERT_TRUE(released.factorize(UpperShifted(c.K, c.M, sigma)));
  released.solve(B.data(), Xr.data(), 2);
  const Eigen::SparseMatrix<double> Ss = UpperShifted(c.K, c.M, sigma);
  const Eigen::MatrixXd residual = Ss.selfadjointView<Eigen::Upper>() * Xr - B;
  EXPECT_LT(residual.cwiseAbs().maxCoeff(), 1e-8 * B.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace orrery::flex

// The BLAS note of `orrery fe-modes` / `orrery reduce` (flex/blas_kernels.h): it names a kernel
// set only when OpenBLAS runs a generic one, and never once the user has chosen one.
TEST(BlasKernels, AdviceOnlyForGenericOpenBlasKernelsAndNeverOnceTheUserChose) {
  const std::string name = orrery::flex::BlasKernelName();
  const std::string advice = orrery::flex::BlasKernelAdvice();
  const bool generic = name == "Prescott" || name == "Core2" || name == "Nehalem";
  if (!generic) {
    EXPECT_TRUE(advice.empty()) << name << ": " << advice;
  }
  if (!advice.empty()) {
    EXPECT_NE(advice.find("'" + name + "'"), std::string::npos) << advice;
    EXPECT_NE(advice.find("OPENBLAS_CORETYPE="), std::string::npos) << advice;
  }
  const char* before = std::getenv("OPENBLAS_CORETYPE");
  const std::string saved = before ? before : "";
  setenv("OPENBLAS_CORETYPE", "Haswell", 1);
  EXPECT_EQ(orrery::flex::BlasKernelAdvice(), "");
  if (before) {
    setenv("OPENBLAS_CORETYPE", saved.c_str(), 1);
  } else {
    unsetenv("OPENBLAS_CORETYPE");
  }
}

#include "flex/cholmod_factor.h"

#include <cholmod.h>

#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace orrery::flex {

struct CholmodCholesky::Impl {
  cholmod_common common;
  cholmod_factor* L = nullptr;
  double lnz = 0;
  // Solve workspace (cholmod_solve2): solution and two scratch matrices, kept between solves
  cholmod_dense* X = nullptr;
  cholmod_dense* Y = nullptr;
  cholmod_dense* E = nullptr;
  // Permuted right-hand sides of solve_forward (n x columns), kept between solves
  mutable std::vector<double> permuted;

  Impl() {
    cholmod_start(&common);
    common.print = 0;                        // report through return values, not stdout
    common.supernodal = CHOLMOD_SUPERNODAL;  // always supernodal (BLAS-3 on dense blocks)
    common.final_ll = 1;                     // keep L L^T (no conversion to LDL^T)
    common.quick_return_if_not_posdef = 1;   // an indefinite matrix is rejected, not finished
  }
  ~Impl() {
    for (cholmod_dense** d : {&X, &Y, &E})
      if (*d) cholmod_free_dense(d, &common);
    if (L) cholmod_free_factor(&L, &common);
    cholmod_finish(&common);
  }
};

namespace {

// A view of an Eigen column-major compressed sparse matrix as a CHOLMOD sparse matrix (no copy);
// stype = 1: only the upper triangle is used.
cholmod_sparse View(const Eigen::SparseMatrix<double>& S) {
  cholmod_sparse A{};
  A.nrow = static_cast<std::size_t>(S.rows());
  A.ncol = static_cast<std::size_t>(S.cols());
  A.nzmax = static_cast<std::size_t>(S.nonZeros());
  A.p = const_cast<int*>(S.outerIndexPtr());
  A.i = const_cast<int*>(S.innerIndexPtr());
  A.nz = nullptr;
  A.x = const_cast<double*>(S.valuePtr());
  A.z = nullptr;
  A.stype = 1;
  A.itype = CHOLMOD_INT;
  A.xtype = CHOLMOD_REAL;
  A.dtype = CHOLMOD_DOUBLE;
  A.sorted = 1;
  A.packed = 1;
  return A;
}

std::string Status(const cholmod_common& c) { return "CHOLMOD status " + std::to_string(c.status); }

}  // namespace

CholmodCholesky::CholmodCholesky() : impl_(std::make_unique<Impl>()) {}

CholmodCholesky::~CholmodCholesky() = default;

bool CholmodCholesky::factorize(const Eigen::SparseMatrix<double>& S) {
  if (S.rows() != S.cols()) throw std::invalid_argument("CholmodCholesky: matrix must be square");
  if (!S.isCompressed()) throw std::invalid_argument("CholmodCholesky: matrix must be compressed");
  if (impl_->L && S.rows() != n_)
    throw std::invalid_argument("CholmodCholesky: size " + std::to_string(S.rows()) + " differs from the analysed " +
                                std::to_string(n_));
  cholmod_sparse A = View(S);
  cholmod_common& c = impl_->common;
  factorized_ = false;
  if (!impl_->L) {
    impl_->L = cholmod_analyze(&A, &c);
    if (!impl_->L || c.status < CHOLMOD_OK)
      throw std::runtime_error("CholmodCholesky: symbolic analysis failed (" + Status(c) + ")");
    n_ = S.rows();
    impl_->lnz = c.lnz;
  }
  const int ok = cholmod_factorize(&A, impl_->L, &c);
  if (c.status == CHOLMOD_NOT_POSDEF) return false;
  if (!ok || c.status < CHOLMOD_OK)
    throw std::runtime_error("CholmodCholesky: numeric factorization failed (" + Status(c) + ")");
  if (impl_->L->minor < impl_->L->n) return false;
  factorized_ = true;
  return true;
}

namespace {

// A view of n x k column-major values as a CHOLMOD dense matrix (no copy).
cholmod_dense DenseView(const double* B, std::size_t n, std::size_t k) {
  cholmod_dense b{};
  b.nrow = n;
  b.ncol = k;
  b.nzmax = n * k;
  b.d = n;
  b.x = const_cast<double*>(B);
  b.z = nullptr;
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  return b;
}

}  // namespace

// sys: CHOLMOD_A (S^-1 B), CHOLMOD_L or CHOLMOD_Lt (no permutation); the result in impl->X.
void CholmodCholesky::SolveSystem(int sys, const double* B, int columns, const char* name) const {
  if (!factorized_) throw std::logic_error(std::string("CholmodCholesky::") + name + " without a successful factorize()");
  if (columns < 1) throw std::invalid_argument(std::string("CholmodCholesky::") + name + ": columns must be >= 1");
  cholmod_common& c = impl_->common;
  cholmod_dense b = DenseView(B, static_cast<std::size_t>(n_), static_cast<std::size_t>(columns));
  // cholmod_solve2 reuses X, Y and E when their sizes fit (no allocation after the first call)
  if (!cholmod_solve2(sys, impl_->L, &b, nullptr, &impl_->X, nullptr, &impl_->Y, &impl_->E, &c))
    throw std::runtime_error(std::string("CholmodCholesky: ") + name + " failed (" + Status(c) + ")");
}

void CholmodCholesky::solve(const double* B, double* X, int columns) const {
  SolveSystem(CHOLMOD_A, B, columns, "solve");
  std::memcpy(X, impl_->X->x, sizeof(double) * static_cast<std::size_t>(n_) * columns);
}

// (P B)(i) = B(Perm(i)): row i of P S P^T is row Perm(i) of S (CHOLMOD's convention).
void CholmodCholesky::solve_forward(const double* B, double* X, int columns) const {
  if (!factorized_) throw std::logic_error("CholmodCholesky::solve_forward without a successful factorize()");
  if (columns < 1) throw std::invalid_argument("CholmodCholesky::solve_forward: columns must be >= 1");
  const std::size_t n = static_cast<std::size_t>(n_);
  std::vector<double>& pb = impl_->permuted;
  pb.resize(n * columns);
  const int* perm = static_cast<const int*>(impl_->L->Perm);
  for (int j = 0; j < columns; ++j)
    for (std::size_t i = 0; i < n; ++i) pb[j * n + i] = B[j * n + perm[i]];
  SolveSystem(CHOLMOD_L, pb.data(), columns, "solve_forward");
  std::memcpy(X, impl_->X->x, sizeof(double) * n * columns);
}

void CholmodCholesky::solve_backward(const double* B, double* X, int columns) const {
  SolveSystem(CHOLMOD_Lt, B, columns, "solve_backward");
  const std::size_t n = static_cast<std::size_t>(n_);
  const int* perm = static_cast<const int*>(impl_->L->Perm);
  const double* y = static_cast<const double*>(impl_->X->x);
  for (int j = 0; j < columns; ++j)
    for (std::size_t i = 0; i < n; ++i) X[j * n + perm[i]] = y[j * n + i];
}

Eigen::Index CholmodCholesky::factor_nonzeros() const { return static_cast<Eigen::Index>(impl_->lnz); }

}  // namespace orrery::flex

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
  // Factor of B = P S P^T, analysed with the natural ordering (see factorize); P from the first
  // analysis of S (METIS or AMD, postordered): (P b)(i) = b(perm[i])
  cholmod_factor* L = nullptr;
  std::vector<int> perm;
  double lnz = 0;
  // Solve workspace (cholmod_solve2): solution and two scratch matrices, kept between solves
  cholmod_dense* X = nullptr;
  cholmod_dense* Y = nullptr;
  cholmod_dense* E = nullptr;
  // Permuted right-hand sides (n x columns), kept between solves
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

bool CholmodCholesky::factorize(const Eigen::SparseMatrix<double>& S) { return Factorize(S, nullptr); }

bool CholmodCholesky::factorize(Eigen::SparseMatrix<double>&& S) { return Factorize(S, &S); }

// The fill-reducing permutation of S, from CHOLMOD's default analysis (AMD, METIS where AMD fills
// in much; postordered), into impl.perm; the nonzeros of L into impl.lnz.
void CholmodCholesky::Order(cholmod_sparse& A) {
  cholmod_common& c = impl_->common;
  cholmod_factor* L0 = cholmod_analyze(&A, &c);
  if (!L0 || c.status < CHOLMOD_OK) {
    if (L0) cholmod_free_factor(&L0, &c);
    throw std::runtime_error("CholmodCholesky: symbolic analysis failed (" + Status(c) + ")");
  }
  const int* p = static_cast<const int*>(L0->Perm);
  impl_->perm.assign(p, p + L0->n);
  impl_->lnz = c.lnz;
  cholmod_free_factor(&L0, &c);
}

// The supernodal analysis of the permuted matrix B with the natural ordering: B's elimination
// tree is already postordered (P includes the postorder), so the supernodes are those of the
// analysis of S, and cholmod_factorize then works on B itself (a natural ordering with a lower
// triangle is the one case in which it makes no permuted copy).
void CholmodCholesky::AnalyzePermuted(cholmod_sparse& B) {
  cholmod_common& c = impl_->common;
  const int nmethods = c.nmethods, ordering = c.method[0].ordering, postorder = c.postorder;
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_NATURAL;
  c.postorder = 0;
  impl_->L = cholmod_analyze(&B, &c);
  c.nmethods = nmethods;
  c.method[0].ordering = ordering;
  c.postorder = postorder;
  if (!impl_->L || c.status < CHOLMOD_OK)
    throw std::runtime_error("CholmodCholesky: symbolic analysis of the permuted matrix failed (" + Status(c) + ")");
  if (impl_->L->ordering != CHOLMOD_NATURAL || !impl_->L->is_super)
    throw std::logic_error("CholmodCholesky: the permuted matrix was not analysed as supernodal in natural order");
}

// Factorizes S: B = lower triangle of P S P^T (CHOLMOD's own permuted copy, which
// cholmod_factorize would otherwise make and hold next to S), S's storage released into
// `release` if given, then L L^T = B.
bool CholmodCholesky::Factorize(const Eigen::SparseMatrix<double>& S, Eigen::SparseMatrix<double>* release) {
  if (S.rows() != S.cols()) throw std::invalid_argument("CholmodCholesky: matrix must be square");
  if (!S.isCompressed()) throw std::invalid_argument("CholmodCholesky: matrix must be compressed");
  if (impl_->L && S.rows() != n_)
    throw std::invalid_argument("CholmodCholesky: size " + std::to_string(S.rows()) + " differs from the analysed " +
                                std::to_string(n_));
  cholmod_sparse A = View(S);
  cholmod_common& c = impl_->common;
  factorized_ = false;
  if (!impl_->L) Order(A);
  cholmod_sparse* B = cholmod_ptranspose(&A, 2, impl_->perm.data(), nullptr, 0, &c);
  if (!B || c.status < CHOLMOD_OK) throw std::runtime_error("CholmodCholesky: permuting the matrix failed (" + Status(c) + ")");
  if (release) Eigen::SparseMatrix<double>().swap(*release);
  try {
    if (!impl_->L) {
      AnalyzePermuted(*B);
      n_ = static_cast<Eigen::Index>(impl_->perm.size());
    }
  } catch (...) {
    cholmod_free_sparse(&B, &c);
    throw;
  }
  const int ok = cholmod_factorize(B, impl_->L, &c);
  cholmod_free_sparse(&B, &c);
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

// sys: CHOLMOD_A, CHOLMOD_L or CHOLMOD_Lt of the permuted factor (L has the natural ordering:
// no permutation inside CHOLMOD); the result in impl->X.
void CholmodCholesky::SolveSystem(int sys, const double* B, int columns, const char* name) const {
  if (!factorized_) throw std::logic_error(std::string("CholmodCholesky::") + name + " without a successful factorize()");
  if (columns < 1) throw std::invalid_argument(std::string("CholmodCholesky::") + name + ": columns must be >= 1");
  cholmod_common& c = impl_->common;
  cholmod_dense b = DenseView(B, static_cast<std::size_t>(n_), static_cast<std::size_t>(columns));
  // cholmod_solve2 reuses X, Y and E when their sizes fit (no allocation after the first call)
  if (!cholmod_solve2(sys, impl_->L, &b, nullptr, &impl_->X, nullptr, &impl_->Y, &impl_->E, &c))
    throw std::runtime_error(std::string("CholmodCholesky: ") + name + " failed (" + Status(c) + ")");
}

// (P B)(i) = B(perm(i)) into impl->permuted: row i of P S P^T is row perm(i) of S (CHOLMOD's
// convention).
const double* CholmodCholesky::Permuted(const double* B, int columns, const char* name) const {
  if (!factorized_) throw std::logic_error(std::string("CholmodCholesky::") + name + " without a successful factorize()");
  if (columns < 1) throw std::invalid_argument(std::string("CholmodCholesky::") + name + ": columns must be >= 1");
  const std::size_t n = static_cast<std::size_t>(n_);
  std::vector<double>& pb = impl_->permuted;
  pb.resize(n * columns);
  const int* perm = impl_->perm.data();
  for (int j = 0; j < columns; ++j)
    for (std::size_t i = 0; i < n; ++i) pb[j * n + i] = B[j * n + perm[i]];
  return pb.data();
}

// X = P^T Y for the solution Y in impl->X.
void CholmodCholesky::Unpermute(double* X, int columns) const {
  const std::size_t n = static_cast<std::size_t>(n_);
  const int* perm = impl_->perm.data();
  const double* y = static_cast<const double*>(impl_->X->x);
  for (int j = 0; j < columns; ++j)
    for (std::size_t i = 0; i < n; ++i) X[j * n + perm[i]] = y[j * n + i];
}

// S^-1 B = P^T (L L^T)^-1 P B
void CholmodCholesky::solve(const double* B, double* X, int columns) const {
  SolveSystem(CHOLMOD_A, Permuted(B, columns, "solve"), columns, "solve");
  Unpermute(X, columns);
}

void CholmodCholesky::solve_forward(const double* B, double* X, int columns) const {
  SolveSystem(CHOLMOD_L, Permuted(B, columns, "solve_forward"), columns, "solve_forward");
  std::memcpy(X, impl_->X->x, sizeof(double) * static_cast<std::size_t>(n_) * columns);
}

void CholmodCholesky::solve_backward(const double* B, double* X, int columns) const {
  SolveSystem(CHOLMOD_Lt, B, columns, "solve_backward");
  Unpermute(X, columns);
}

Eigen::Index CholmodCholesky::factor_nonzeros() const { return static_cast<Eigen::Index>(impl_->lnz); }

}  // namespace orrery::flex

#include "flex/cholmod_factor.h"

#include <cholmod.h>

#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

namespace orrery::flex {

struct CholmodCholesky::Impl {
  cholmod_common common;
  cholmod_factor* L = nullptr;
  double lnz = 0;

  Impl() {
    cholmod_start(&common);
    common.print = 0;                        // report through return values, not stdout
    common.supernodal = CHOLMOD_SUPERNODAL;  // always supernodal (BLAS-3 on dense blocks)
    common.final_ll = 1;                     // keep L L^T (no conversion to LDL^T)
    common.quick_return_if_not_posdef = 1;   // an indefinite matrix is rejected, not finished
  }
  ~Impl() {
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

void CholmodCholesky::solve(const double* b, double* x) const {
  if (!factorized_) throw std::logic_error("CholmodCholesky::solve without a successful factorize()");
  cholmod_common& c = impl_->common;
  cholmod_dense B{};
  B.nrow = static_cast<std::size_t>(n_);
  B.ncol = 1;
  B.nzmax = static_cast<std::size_t>(n_);
  B.d = static_cast<std::size_t>(n_);
  B.x = const_cast<double*>(b);
  B.z = nullptr;
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* X = cholmod_solve(CHOLMOD_A, impl_->L, &B, &c);
  if (!X) throw std::runtime_error("CholmodCholesky: solve failed (" + Status(c) + ")");
  std::memcpy(x, X->x, sizeof(double) * static_cast<std::size_t>(n_));
  cholmod_free_dense(&X, &c);
}

Eigen::Index CholmodCholesky::factor_nonzeros() const { return static_cast<Eigen::Index>(impl_->lnz); }

}  // namespace orrery::flex

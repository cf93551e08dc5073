#include "phiq/min_norm_solver.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace phiq {

struct MinNormSolver::Impl {
  cholmod_common cc;
  cholmod_factor* L = nullptr;
  cholmod_sparse A;  // a view of the pattern and the caller's values: CHOLMOD reads, never owns, these arrays
  Impl() { cholmod_l_start(&cc); }
  ~Impl() {
    if (L) cholmod_l_free_factor(&L, &cc);
    cholmod_l_finish(&cc);
  }
};

namespace {
void make_view(cholmod_sparse& A, const CscPattern& p, const double* values) {
  std::memset(&A, 0, sizeof A);
  A.nrow = static_cast<std::size_t>(p.rows);
  A.ncol = static_cast<std::size_t>(p.cols);
  A.nzmax = static_cast<std::size_t>(p.nnz());
  A.p = const_cast<Index*>(p.col_ptr.data());
  A.i = const_cast<Index*>(p.row_idx.data());
  A.x = const_cast<double*>(values);
  A.stype = 0;  // unsymmetric: CHOLMOD analyses and factorises A Aᵀ
  A.itype = CHOLMOD_LONG;
  A.xtype = values ? CHOLMOD_REAL : CHOLMOD_PATTERN;
  A.dtype = CHOLMOD_DOUBLE;
  A.sorted = 1;
  A.packed = 1;
}
}  // namespace

MinNormSolver::MinNormSolver(std::shared_ptr<const CscPattern> pattern)
    : pattern_(std::move(pattern)), impl_(std::make_unique<Impl>()) {
  // Singular A Aᵀ is an outcome (a status), not an error to print.
  impl_->cc.print = 0;
  impl_->cc.error_handler = nullptr;
  make_view(impl_->A, *pattern_, nullptr);
  impl_->L = cholmod_l_analyze(&impl_->A, &impl_->cc);
  if (!impl_->L) throw Error("CHOLMOD could not analyse the pattern (status " + std::to_string(impl_->cc.status) + ")");
}

MinNormSolver::~MinNormSolver() = default;

FactorStatus MinNormSolver::factorize(const double* values, double beta) {
  values_ = nullptr;
  rcond_ = 0.0;
  make_view(impl_->A, *pattern_, values);
  double b[2] = {beta, 0.0};
  const int ok = cholmod_l_factorize_p(&impl_->A, b, nullptr, 0, impl_->L, &impl_->cc);
  if (!ok || impl_->cc.status < CHOLMOD_OK) {
    message_ = "CHOLMOD factorisation failed (status " + std::to_string(impl_->cc.status) + ")";
    return FactorStatus::kFailed;
  }
  if (impl_->cc.status == CHOLMOD_NOT_POSDEF || impl_->L->minor < impl_->L->n) {
    message_ = "A Aᵀ is not positive definite: the rows of A are linearly dependent";
    return FactorStatus::kSingular;
  }
  rcond_ = cholmod_l_rcond(impl_->L, &impl_->cc);
  values_ = values;
  return FactorStatus::kOk;
}

bool MinNormSolver::solve(const double* b, double* y) {
  if (!values_) return false;
  const std::size_t r = static_cast<std::size_t>(pattern_->rows);
  cholmod_dense B;
  std::memset(&B, 0, sizeof B);
  B.nrow = B.d = r;
  B.ncol = 1;
  B.nzmax = r;
  B.x = const_cast<double*>(b);
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* Y = cholmod_l_solve(CHOLMOD_A, impl_->L, &B, &impl_->cc);
  if (!Y) {
    message_ = "CHOLMOD solve failed (status " + std::to_string(impl_->cc.status) + ")";
    return false;
  }
  std::copy_n(static_cast<const double*>(Y->x), r, y);
  cholmod_l_free_dense(&Y, &impl_->cc);
  return true;
}

void MinNormSolver::multiply_transposed(const double* y, double* x) const {
  const CscPattern& p = *pattern_;
  for (Index j = 0; j < p.cols; ++j) {
    double s = 0.0;
    for (Index k = p.col_ptr[j]; k < p.col_ptr[j + 1]; ++k) s += values_[k] * y[p.row_idx[k]];
    x[j] = s;
  }
}

bool MinNormSolver::min_norm(const double* b, double* x) {
  std::vector<double> y(static_cast<std::size_t>(pattern_->rows));
  if (!solve(b, y.data())) return false;
  multiply_transposed(y.data(), x);
  return true;
}

}  // namespace phiq

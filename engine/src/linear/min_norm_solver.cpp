#include "phiq/min_norm_solver.hpp"

#include "linear/cholmod_view.hpp"
#include "linear/pattern_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace phiq {

struct MinNormSolver::Impl {
  detail::CholmodCommon common;
  cholmod_common& cc = common.cc;
  cholmod_factor* L = nullptr;
  cholmod_sparse A;       // a view of the pattern and the caller's values
  std::vector<double> y;  // solve scratch for min_norm(): no allocation per iteration
  // cholmod_l_solve2's solution and workspace, kept from one solve to the next (allocated once)
  cholmod_dense *X = nullptr, *Y = nullptr, *E = nullptr;
  ~Impl() {
    for (cholmod_dense** d : {&X, &Y, &E})
      if (*d) cholmod_l_free_dense(d, &cc);
    if (L) cholmod_l_free_factor(&L, &cc);
  }
};

MinNormSolver::MinNormSolver(std::shared_ptr<const CscPattern> pattern)
    : pattern_(std::move(pattern)), impl_(std::make_unique<Impl>()) {
  impl_->A = detail::csc_view(*pattern_, nullptr);
  impl_->L = cholmod_l_analyze(&impl_->A, &impl_->cc);
  if (!impl_->L)
    throw Error("minimum-norm solver (CHOLMOD): " +
                detail::unusable_pattern(*pattern_, "cannot be analysed", impl_->cc.status == CHOLMOD_OUT_OF_MEMORY));
}

MinNormSolver::~MinNormSolver() = default;

FactorStatus MinNormSolver::factorize(const double* values, double beta) {
  values_ = nullptr;
  rcond_ = 0.0;
  impl_->A = detail::csc_view(*pattern_, values);
  double b[2] = {beta, 0.0};
  const int ok = cholmod_l_factorize_p(&impl_->A, b, nullptr, 0, impl_->L, &impl_->cc);
  if (!ok || impl_->cc.status < CHOLMOD_OK) {
    message_ = "minimum-norm solver (CHOLMOD): " +
               detail::unusable_pattern(*pattern_, "cannot be factorised", impl_->cc.status == CHOLMOD_OUT_OF_MEMORY);
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
  Impl& im = *impl_;
  if (!cholmod_l_solve2(CHOLMOD_A, im.L, &B, nullptr, &im.X, nullptr, &im.Y, &im.E, &im.cc)) {
    message_ =
        std::string("minimum-norm solver (CHOLMOD): ") +
        (im.cc.status == CHOLMOD_OUT_OF_MEMORY ? "out of memory in the solve" : "the solve with the factors failed");
    return false;
  }
  std::copy_n(static_cast<const double*>(im.X->x), r, y);
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

void MinNormSolver::multiply_add(const double* x, double* y) const {
  const CscPattern& p = *pattern_;
  for (Index j = 0; j < p.cols; ++j)
    for (Index k = p.col_ptr[j]; k < p.col_ptr[j + 1]; ++k) y[p.row_idx[k]] += values_[k] * x[j];
}

bool MinNormSolver::min_norm(const double* b, double* x) {
  std::vector<double>& y = impl_->y;
  y.resize(static_cast<std::size_t>(pattern_->rows));
  if (!solve(b, y.data())) return false;
  multiply_transposed(y.data(), x);
  return true;
}

}  // namespace phiq

#include "phiq/linear_solver.hpp"

#include "linear/klu_lu.hpp"
#include "linear/pattern_messages.hpp"

#include <umfpack.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace phiq {

const char* to_string(FactorStatus s) {
  switch (s) {
    case FactorStatus::kOk:
      return "ok";
    case FactorStatus::kSingular:
      return "singular";
    case FactorStatus::kFailed:
      return "failed";
  }
  return "?";
}

const char* to_string(LinearSolverKind k) {
  switch (k) {
    case LinearSolverKind::kUmfpack:
      return "umfpack";
    case LinearSolverKind::kKlu:
      return "klu";
    case LinearSolverKind::kDense:
      return "dense";
  }
  return "?";
}

namespace {

std::string umfpack_status_text(int status) {
  switch (status) {
    case UMFPACK_OK:
      return "ok";
    case UMFPACK_WARNING_singular_matrix:
      return "singular matrix";
    case UMFPACK_ERROR_out_of_memory:
      return "out of memory";
    case UMFPACK_ERROR_invalid_matrix:
      return "invalid matrix";
    case UMFPACK_ERROR_different_pattern:
      return "pattern changed since the symbolic analysis";
    case UMFPACK_ERROR_invalid_Symbolic_object:
      return "invalid symbolic object";
    case UMFPACK_ERROR_invalid_Numeric_object:
      return "invalid numeric object";
    default:
      return "sparse LU (UMFPACK) failed (an error it does not name)";
  }
}

// ---- UMFPACK ------------------------------------------------------------------------------------------------

class UmfpackSymbolic;

class UmfpackNumeric final : public SparseLuNumeric {
 public:
  explicit UmfpackNumeric(std::shared_ptr<const UmfpackSymbolic> sym);
  ~UmfpackNumeric() override {
    if (numeric_) umfpack_dl_free_numeric(&numeric_);
  }
  FactorStatus factorize(const double* values) override;
  bool solve(const double* b, double* x) override { return solve_system(UMFPACK_A, b, x); }
  bool solve_transposed(const double* b, double* x) override { return solve_system(UMFPACK_At, b, x); }
  double rcond() const override { return rcond_; }
  int determinant_sign() const override {
    if (!numeric_ || rcond_ == 0.0) return 0;
    // mantissa and exponent apart: the determinant itself under- or overflows a double on large models (a
    // 24 270-coordinate lattice gave 0, which read as singular)
    double mx = 0.0, ex = 0.0;
    if (umfpack_dl_get_determinant(&mx, &ex, numeric_, nullptr) != UMFPACK_OK) return 0;
    return (mx > 0) - (mx < 0);
  }
  std::string last_message() const override { return message_; }
  std::int64_t pivoting_factorizations() const override { return factorizations_; }
  std::size_t memory_bytes() const override {
    SuiteSparse_long lnz = 0, unz = 0, nr = 0, nc = 0, nzud = 0;
    if (!numeric_ || umfpack_dl_get_lunz(&lnz, &unz, &nr, &nc, &nzud, numeric_) != UMFPACK_OK) return 0;
    return static_cast<std::size_t>(lnz + unz) * (sizeof(double) + sizeof(SuiteSparse_long));
  }

 private:
  bool solve_system(int sys, const double* b, double* x);
  std::int64_t factorizations_ = 0;
  std::shared_ptr<const UmfpackSymbolic> keep_;  // co-owns the symbolic analysis it factorises with
  const UmfpackSymbolic& sym_;
  void* numeric_ = nullptr;
  const double* values_ = nullptr;  // refinement in solve() reads the matrix the factors came from
  double control_[UMFPACK_CONTROL];
  double info_[UMFPACK_INFO];
  std::vector<SuiteSparse_long> wi_;  // solve workspace: no allocation per solve
  std::vector<double> w_;
  double rcond_ = 0.0;
  std::string message_;
};

class UmfpackSymbolic final : public SparseLuSymbolic, public std::enable_shared_from_this<UmfpackSymbolic> {
 public:
  explicit UmfpackSymbolic(std::shared_ptr<const CscPattern> pattern) : pattern_(std::move(pattern)) {
    const CscPattern& p = *pattern_;
    umfpack_dl_defaults(control_);
    // No iterative refinement: Newton corrects its own steps, and for velocity/acceleration on a non-singular Φq
    // the direct solve is accurate to cond·eps. Refinement (the default, up to 2 steps) cost ~25 % of a sweep step
    // on nfourbar (bench/README.md) and changed no test result.
    control_[UMFPACK_IRSTEP] = 0;
    double info[UMFPACK_INFO];
    // Pattern-only analysis (Ax = NULL): the column pre-ordering depends on the pattern, which is fixed per model;
    // the numeric factorisation still pivots on the values of every iteration.
    int status =
        umfpack_dl_symbolic(p.rows, p.cols, p.col_ptr.data(), p.row_idx.data(), nullptr, &symbolic_, control_, info);
    if (status != UMFPACK_OK)
      throw Error("sparse LU (UMFPACK): " +
                  detail::unusable_pattern(p, "cannot be analysed", status == UMFPACK_ERROR_out_of_memory));
  }
  ~UmfpackSymbolic() override {
    if (symbolic_) umfpack_dl_free_symbolic(&symbolic_);
  }
  LinearSolverKind kind() const override { return LinearSolverKind::kUmfpack; }
  std::unique_ptr<SparseLuNumeric> make_numeric() const override {
    return std::make_unique<UmfpackNumeric>(shared_from_this());
  }

  std::shared_ptr<const CscPattern> pattern_;  // shared with the Model
  void* symbolic_ = nullptr;                   // read-only after construction: shared by all numeric objects
  double control_[UMFPACK_CONTROL];
};

UmfpackNumeric::UmfpackNumeric(std::shared_ptr<const UmfpackSymbolic> sym) : keep_(std::move(sym)), sym_(*keep_) {
  std::copy(sym_.control_, sym_.control_ + UMFPACK_CONTROL, control_);
  wi_.resize(static_cast<std::size_t>(sym_.pattern_->cols));
  w_.resize(5 * static_cast<std::size_t>(sym_.pattern_->cols));
}

FactorStatus UmfpackNumeric::factorize(const double* values) {
  if (numeric_) umfpack_dl_free_numeric(&numeric_);
  values_ = values;
  ++factorizations_;
  const CscPattern& p = *sym_.pattern_;
  int status =
      umfpack_dl_numeric(p.col_ptr.data(), p.row_idx.data(), values, sym_.symbolic_, &numeric_, control_, info_);
  rcond_ = info_[UMFPACK_RCOND];
  if (status == UMFPACK_OK) {
    message_.clear();
    return FactorStatus::kOk;
  }
  message_ = umfpack_status_text(status);
  if (status == UMFPACK_WARNING_singular_matrix) return FactorStatus::kSingular;  // factors exist, but U has a 0
  if (numeric_) umfpack_dl_free_numeric(&numeric_);
  return FactorStatus::kFailed;
}

bool UmfpackNumeric::solve_system(int sys, const double* b, double* x) {
  if (!numeric_) {
    message_ = "solve before a successful factorisation";
    return false;
  }
  const CscPattern& p = *sym_.pattern_;
  int status = umfpack_dl_wsolve(sys, p.col_ptr.data(), p.row_idx.data(), values_, x, b, numeric_, control_, info_,
                                 wi_.data(), w_.data());
  if (status != UMFPACK_OK) {
    message_ = umfpack_status_text(status);
    return false;
  }
  return true;
}

// ---- Dense reference (Eigen partial-pivoting LU) -------------------------------------------------------------

class DenseSymbolic;

class DenseNumeric final : public SparseLuNumeric {
 public:
  explicit DenseNumeric(std::shared_ptr<const CscPattern> p) : p_(*p), keep_(std::move(p)), a_(p_.rows, p_.cols) {}
  FactorStatus factorize(const double* values) override {
    ++factorizations_;
    a_.setZero();
    for (Index c = 0; c < p_.cols; ++c)
      for (Index k = p_.col_ptr[c]; k < p_.col_ptr[c + 1]; ++k) a_(p_.row_idx[k], c) = values[k];
    lu_.compute(a_);
    // PartialPivLU does not report singularity; judge it from U's diagonal like UMFPACK does. The determinant's
    // sign from the signs of that diagonal and of the row permutation: the determinant itself, their product,
    // underflows a double (60 rows scaled by 10⁻⁹ scale it by 10⁻⁵⁴⁰) and its sign then reads 0, singular.
    const auto diag = lu_.matrixLU().diagonal();
    auto d = diag.cwiseAbs();
    double mx = d.size() ? d.maxCoeff() : 0.0, mn = d.size() ? d.minCoeff() : 0.0;
    rcond_ = mx > 0 ? mn / mx : 0.0;
    sign_ = static_cast<int>(lu_.permutationP().determinant());
    for (Index i = 0; i < diag.size(); ++i) sign_ = diag(i) < 0 ? -sign_ : sign_;
    if (!std::isfinite(mx)) return FactorStatus::kFailed;
    return mn == 0.0 ? FactorStatus::kSingular : FactorStatus::kOk;
  }
  bool solve(const double* b, double* x) override {
    Eigen::Map<const Eigen::VectorXd> bb(b, p_.rows);
    Eigen::Map<Eigen::VectorXd>(x, p_.cols) = lu_.solve(bb);
    return true;
  }
  bool solve_transposed(const double* b, double* x) override {
    Eigen::Map<const Eigen::VectorXd> bb(b, p_.cols);
    Eigen::Map<Eigen::VectorXd>(x, p_.rows) = lu_.transpose().solve(bb);
    return true;
  }
  double rcond() const override { return rcond_; }
  int determinant_sign() const override { return rcond_ == 0.0 ? 0 : sign_; }
  std::string last_message() const override { return rcond_ == 0.0 ? "singular matrix" : ""; }
  std::int64_t pivoting_factorizations() const override { return factorizations_; }
  std::size_t memory_bytes() const override { return static_cast<std::size_t>(a_.size()) * sizeof(double); }

 private:
  const CscPattern& p_;
  std::shared_ptr<const CscPattern> keep_;
  Eigen::MatrixXd a_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  double rcond_ = 0.0;
  int sign_ = 0;  // of det A, from the last factorisation (determinant_sign())
  std::int64_t factorizations_ = 0;
};

class DenseSymbolic final : public SparseLuSymbolic {
 public:
  explicit DenseSymbolic(std::shared_ptr<const CscPattern> p) : p_(std::move(p)) {}
  LinearSolverKind kind() const override { return LinearSolverKind::kDense; }
  std::unique_ptr<SparseLuNumeric> make_numeric() const override { return std::make_unique<DenseNumeric>(p_); }

 private:
  std::shared_ptr<const CscPattern> p_;
};

}  // namespace

std::shared_ptr<const SparseLuSymbolic> analyse(LinearSolverKind kind, std::shared_ptr<const CscPattern> pattern) {
  if (!pattern) throw Error("analyse: null pattern");
  if (pattern->rows != pattern->cols)
    throw Error("sparse LU needs a square matrix, got " + std::to_string(pattern->rows) + " x " +
                std::to_string(pattern->cols));
  switch (kind) {
    case LinearSolverKind::kUmfpack:
      return std::make_shared<UmfpackSymbolic>(pattern);
    case LinearSolverKind::kKlu:
      return detail::analyse_klu(std::move(pattern));
    case LinearSolverKind::kDense:
      return std::make_shared<DenseSymbolic>(pattern);
  }
  throw Error("unknown linear solver kind");
}

}  // namespace phiq

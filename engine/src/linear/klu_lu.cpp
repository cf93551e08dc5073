// KLU (SuiteSparse) behind the sparse LU interface: analysis once per pattern, refactorisation with the old pivot
// order while the pivots hold, a pivot search again when they degrade.
//
// Two choices on top of KLU's defaults, both measured on the generated models (bench/README.md, "Sparse LU at
// scale"):
// - 32-bit indices (klu_*) whenever the matrix and the estimated factors fit them, 64-bit (klu_l_*) otherwise:
//   every entry of L and U carries its row index, so the factors take a quarter less memory, and refactorisations
//   and solves, which stream them, a quarter less memory traffic.
// - The blocks of the block triangular form in an order that follows the pattern's own where that is more local
//   than the order KLU finds them in (resequence_blocks, klu_blocks.hpp).
#include "linear/klu_lu.hpp"
#include "linear/klu_blocks.hpp"
#include "linear/pattern_messages.hpp"

#include <klu.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <type_traits>
#include <string>
#include <utility>
#include <vector>

namespace phiq::detail {
namespace {

template <class Int>
class KluSymbolic;

template <class Int>
class KluNumeric final : public SparseLuNumeric {
 public:
  using Api = Klu<Int>;
  explicit KluNumeric(std::shared_ptr<const KluSymbolic<Int>> sym) : keep_(std::move(sym)), sym_(*keep_) {
    Api::defaults(&common_);
  }
  ~KluNumeric() override {
    if (numeric_ && numeric_ != pinned_.numeric) Api::free_numeric(&numeric_, &common_);
    if (pinned_.numeric) Api::free_numeric(&pinned_.numeric, &common_);
  }
  FactorStatus factorize(const double* values) override;
  bool solve(const double* b, double* x) override { return solve_system(false, b, x); }
  bool solve_transposed(const double* b, double* x) override { return solve_system(true, b, x); }
  double rcond() const override { return rcond_; }
  int determinant_sign() const override;
  std::uint64_t block_signs() const override { return block_signs_; }
  std::string last_message() const override { return message_; }
  std::int64_t pivoting_factorizations() const override { return pivoting_; }
  void forget_pivot_order() override { forget_pivots_ = true; }
  bool pin_pivot_order() override;
  bool restore_pinned_pivot_order() override;
  void unpin_pivot_order() override;
  // the last pivot search's peak, factorising and what was kept aside included (factor_with_pivoting)
  std::size_t memory_bytes() const override { return numeric_ ? common_.mempeak : 0; }

  // A refactorisation keeps the pivot order of the last pivoting factorisation; when its reciprocal pivot ratio
  // falls below this fraction of the one measured right after pivoting, the pivots have degraded (the matrix moved
  // far from the one they were chosen for) and the matrix is factorised again with a pivot search.
  static constexpr double kDegradation = 1e-3;
  // Nor is a refactorisation taken as it is when its ratio falls below this and tenfold below the one right after
  // pivoting (tenfold: not at every small drift of a ratio that is low by nature, 2.5e-7 at any angle for a chain of
  // 10⁶ loops). A pivot search may have been made where the matrix was poor (KLU keeps diagonal pivots down to 1e-3
  // of their column), and the old order then lets a pivot run to zero that the matrix does not need — a body's
  // Euler parameter crossing zero gave 5e-9 where a pivot search gives 0.49 — and the sweep would report a
  // near-singular position (its warning is at 1e-7) that is not there. Below it a pivot search measures again;
  // where the matrix really is that close to singular, the search's own ratio becomes the new reference.
  static constexpr double kCheckedBelow = 1e-6;

 private:
  FactorStatus factor_with_pivoting(const double* values);
  double scan_diagonal();  // KLU's rcond of the factors (of the row-scaled matrix), and u_sign_
  void keep_row_scale();   // inverse_row_scale_ from KLU's Rs, once after a pivot search
  bool solve_system(bool transposed, const double* b, double* x);
  std::shared_ptr<const KluSymbolic<Int>> keep_;
  const KluSymbolic<Int>& sym_;
  mutable typename Api::Common common_;
  typename Api::Numeric* numeric_ = nullptr;
  double rcond_ = 0.0, rcond_at_pivoting_ = 0.0;
  std::int64_t pivoting_ = 0;
  bool forget_pivots_ = false;  // forget_pivot_order(): the next factorize() searches for pivots
  std::string message_;
  int p_sign_ = 1;  // parity of the row permutation Pnum of the last pivoting factorisation
  int u_sign_ = 1;  // sign of the product of U's diagonal (0: a zero pivot)
  // Per block: the parity of the pivot order's rows and the fixed columns (block_parities of Pnum and Q, xor-ed),
  // of the last pivoting factorisation; empty for a single block (block_signs() is then 0).
  std::vector<unsigned char> block_parity_;
  std::uint64_t block_signs_ = 0;        // block_signs() of the last factorisation (scan_diagonal)
  unsigned negative_parity_offset_ = 0;  // xor of block_parity_: taken out of the blocks' product again for u_sign_
  // The reciprocals of the row scale factors of the last pivoting factorisation, in pivot order (KLU's Rs, the
  // largest |entry| of each row); empty while the factors are of the scaled matrix (right after pivoting), used
  // by scan_diagonal() once refactorisations work on the unscaled one.
  std::vector<double> inverse_row_scale_;
  // A pinned pivot order (pin_pivot_order()): its factors object, refactorised in place while it is the current
  // one (numeric_), kept aside while a pivot search has replaced it, and what describes its order.
  struct Pinned {
    typename Api::Numeric* numeric = nullptr;
    double rcond_at_pivoting = 0.0;
    int p_sign = 1;
    std::vector<unsigned char> block_parity;
    unsigned negative_parity_offset = 0;
    std::vector<double> inverse_row_scale;
  } pinned_;
};

// The interface of both widths' analyses that describe_klu reads.
class KluSymbolicBase : public SparseLuSymbolic {
 public:
  KluAnalysis analysis;
};

template <class Int>
class KluSymbolic final : public KluSymbolicBase, public std::enable_shared_from_this<KluSymbolic<Int>> {
 public:
  using Api = Klu<Int>;
  explicit KluSymbolic(std::shared_ptr<const CscPattern> pattern) : pattern_(std::move(pattern)) {
    const CscPattern& p = *pattern_;
    if constexpr (std::is_same_v<Int, SuiteSparse_long>) {
      static_assert(sizeof(SuiteSparse_long) == sizeof(Index));
      ap_ = const_cast<Int*>(reinterpret_cast<const Int*>(p.col_ptr.data()));
      ai_ = const_cast<Int*>(reinterpret_cast<const Int*>(p.row_idx.data()));
    } else {  // KLU reads the pattern at every factorisation: a copy in its own index type
      ap32_.assign(p.col_ptr.begin(), p.col_ptr.end());
      ai32_.assign(p.row_idx.begin(), p.row_idx.end());
      ap_ = ap32_.data(), ai_ = ai32_.data();
    }
    // BTF + AMD on the pattern only: the orderings are fixed per model.
    symbolic_ = analyze_bounded(static_cast<Int>(p.cols));
    if (!symbolic_)
      throw Error("sparse LU (KLU): " + unusable_pattern(p, "cannot be analysed", last_status_ == KLU_OUT_OF_MEMORY));
    analysis = resequence_blocks<Int>(ap_, ai_, symbolic_);
    analysis.transversal = transversal_;
    q_sign_ = permutation_sign(symbolic_->Q, p.cols);
    if (symbolic_->nblocks > 1) q_block_parity_ = block_parities(symbolic_->Q, symbolic_->R, symbolic_->nblocks);
  }
  ~KluSymbolic() override {
    typename Api::Common common;
    Api::defaults(&common);
    Api::free_symbolic(&symbolic_, &common);
  }
  LinearSolverKind kind() const override { return LinearSolverKind::kKlu; }
  std::unique_ptr<SparseLuNumeric> make_numeric() const override {
    return std::make_unique<KluNumeric<Int>>(this->shared_from_this());
  }
  // BTF's maximum transversal (a depth-first search for a zero-free diagonal) is at most about nnz(Φq) of work on
  // the generated models in their own column order, except the reference-point grid: 42 nnz at 10⁴ cells, 115 at
  // 10⁵ (2.2 s, 70 % of its loading), growing like N^1.8, where the same search over the columns in reverse order
  // takes 0.04 nnz. The search depends on the order it meets the columns in, so the analysis bounds it at
  // kTransversalWork · nnz; past the bound it analyses the pattern with its columns reversed (KLU's Q is then
  // mapped back: the numeric objects factorise the pattern as it is), and past it again, in the model's order
  // without a bound, as before. Everything else KLU analyses (blocks, their AMD orderings) is the same pattern's.
  static constexpr double kTransversalWork = 8.0;
  typename Api::Symbolic* analyze_bounded(Int n) {
    typename Api::Common common;
    Api::defaults(&common);
    common.maxwork = kTransversalWork;
    typename Api::Symbolic* s = Api::analyze(n, ap_, ai_, &common);
    if (common.work >= 0.0) return last_status_ = common.status, s;
    Api::free_symbolic(&s, &common);
    std::vector<Int> rap(static_cast<std::size_t>(n) + 1), rai(static_cast<std::size_t>(ap_[n]));
    rap[0] = 0;
    for (Int c = 0; c < n; ++c) {  // column c of the reversed pattern is column n − 1 − c of the model's
      const Int j = n - 1 - c;
      std::copy(ai_ + ap_[j], ai_ + ap_[j + 1], rai.begin() + rap[static_cast<std::size_t>(c)]);
      rap[static_cast<std::size_t>(c) + 1] = rap[static_cast<std::size_t>(c)] + (ap_[j + 1] - ap_[j]);
    }
    s = Api::analyze(n, rap.data(), rai.data(), &common);
    if (common.work >= 0.0 && s) {
      for (Int k = 0; k < n; ++k) s->Q[k] = n - 1 - s->Q[k];
      transversal_ = 1;
      return last_status_ = common.status, s;
    }
    Api::free_symbolic(&s, &common);
    common.maxwork = 0.0;
    s = Api::analyze(n, ap_, ai_, &common);
    transversal_ = 2;
    last_status_ = common.status;
    return s;
  }
  int last_status_ = 0;  // KLU's status after the analysis
  int transversal_ = 0;  // KluAnalysis::transversal

  // Entries of L and U that the analysis expects, and those of the off-diagonal blocks.
  double estimated_entries() const { return symbolic_->lnz + symbolic_->unz + static_cast<double>(symbolic_->nzoff); }

  std::shared_ptr<const CscPattern> pattern_;
  std::vector<int> ap32_, ai32_;  // the pattern with 32-bit indices (Int = int only)
  Int* ap_ = nullptr;             // the pattern as KLU reads it
  Int* ai_ = nullptr;
  typename Api::Symbolic* symbolic_ = nullptr;  // read-only after construction: shared by all numeric objects
  int q_sign_ = 1;                              // parity of the fixed column permutation Q
  std::vector<unsigned char> q_block_parity_;   // block_parities of Q (empty for a single block)
};

// P R⁻¹ A Q = L U with L unit lower triangular and R > 0 (KLU's row scaling): sign det A = sign P · sign Q ·
// Π sign U_ii. The final row permutation Pnum changes only with a pivoting factorisation (p_sign_).
template <class Int>
int KluNumeric<Int>::determinant_sign() const {
  if (!numeric_ || rcond_ == 0.0) return 0;
  return sym_.q_sign_ * p_sign_ * u_sign_;
}

// One pass over U's diagonal for what klu_rcond computes (min |U_ii| / max |U_ii|, 0 for a zero or NaN pivot) and
// the sign of Π U_ii, which determinant_sign() needs: a sweep asks for both at every row, and on large models each
// pass over the diagonal is a pass over memory.
template <class Int>
double KluNumeric<Int>::scan_diagonal() {
  const Index n = sym_.pattern_->cols;
  const double* u = static_cast<const double*>(numeric_->Udiag);
  const double* rs = inverse_row_scale_.empty() ? nullptr : inverse_row_scale_.data();
  double lo = INFINITY, hi = 0.0;
  // Block by block (a block's sign is its pivots' times its rows' and columns' parity); a matrix factorised whole
  // is one block of parity 0, with no fingerprint.
  const bool blocked = !block_parity_.empty();
  const Int whole[2] = {0, static_cast<Int>(n)};
  static constexpr unsigned char kEven = 0;
  const Int* R = blocked ? sym_.symbolic_->R : whole;
  const unsigned char* parity = blocked ? block_parity_.data() : &kEven;
  const Index nb = blocked ? static_cast<Index>(block_parity_.size()) : 1;
  std::uint64_t signs = 0;
  unsigned negative = 0;
  bool zero = false;
  auto blocks = [&](auto scaled) {  // the loop twice, with and without scale factors (no test per entry)
    for (Index b = 0; b < nb; ++b) {
      unsigned block_negative = parity[b];
      for (Index i = R[b], end = R[b + 1]; i < end; ++i) {
        const double a = scaled ? std::fabs(u[i]) * rs[i] : std::fabs(u[i]);
        lo = a < lo ? a : lo;
        hi = a > hi ? a : hi;
        block_negative ^= u[i] < 0.0;
        zero |= !(a > 0.0);  // zero or NaN
      }
      signs ^= block_key(static_cast<std::uint64_t>(b)) & (0 - static_cast<std::uint64_t>(block_negative));
      negative ^= block_negative;
    }
  };
  if (rs)
    blocks(std::true_type{});
  else
    blocks(std::false_type{});
  if (zero) return u_sign_ = 0, 0.0;
  if (blocked) {
    negative ^= negative_parity_offset_;  // undo the blocks' parities: u_sign_ is Π sign U_ii alone
    block_signs_ = signs;
  }
  u_sign_ = negative ? -1 : 1;
  const double r = n > 0 ? lo / hi : 0.0;
  return std::isfinite(r) ? r : 0.0;
}

template <class Int>
void KluNumeric<Int>::keep_row_scale() {
  if (!inverse_row_scale_.empty() || !numeric_ || !numeric_->Rs) return;
  const double* rs = static_cast<const double*>(numeric_->Rs);  // (> 0: an empty row has scale 1)
  inverse_row_scale_.resize(static_cast<std::size_t>(sym_.pattern_->cols));
  for (std::size_t i = 0; i < inverse_row_scale_.size(); ++i) inverse_row_scale_[i] = 1.0 / rs[i];
}

template <class Int>
bool KluNumeric<Int>::pin_pivot_order() {
  unpin_pivot_order();
  if (!numeric_) return false;
  keep_row_scale();
  if (inverse_row_scale_.empty()) return false;
  pinned_ = {numeric_, rcond_at_pivoting_, p_sign_, block_parity_, negative_parity_offset_, inverse_row_scale_};
  return true;
}

template <class Int>
void KluNumeric<Int>::unpin_pivot_order() {
  if (pinned_.numeric && pinned_.numeric != numeric_) Api::free_numeric(&pinned_.numeric, &common_);
  pinned_ = Pinned{};
}

// Back to the pinned order's factors object and what describes its order, so that the next factorize()
// refactorises with it exactly as it would right after pinning (its values are overwritten; only the order and the
// reference ratio matter).
template <class Int>
bool KluNumeric<Int>::restore_pinned_pivot_order() {
  if (!pinned_.numeric) return false;
  if (numeric_ && numeric_ != pinned_.numeric) Api::free_numeric(&numeric_, &common_);
  numeric_ = pinned_.numeric;
  forget_pivots_ = false;
  rcond_at_pivoting_ = pinned_.rcond_at_pivoting;
  p_sign_ = pinned_.p_sign;
  block_parity_ = pinned_.block_parity;
  negative_parity_offset_ = pinned_.negative_parity_offset;
  inverse_row_scale_ = pinned_.inverse_row_scale;
  return true;
}

template <class Int>
FactorStatus KluNumeric<Int>::factor_with_pivoting(const double* values) {
  // (the pinned factors are kept for restore_pinned_pivot_order(); a search builds a new object beside them)
  if (numeric_ && numeric_ != pinned_.numeric) Api::free_numeric(&numeric_, &common_);
  numeric_ = nullptr;
  forget_pivots_ = false;
  ++pivoting_;
  inverse_row_scale_.clear();
  common_.scale = 2;  // pivots chosen on rows scaled by their largest entries (KLU's default)
  // memory_bytes() from here: what is live (a pinned order's factors kept aside) and this factorisation's peak, the
  // same in every workspace that factorises the same matrix (not the peak of whatever it factorised before, which
  // a parallel sweep's decision to pin must not depend on)
  common_.mempeak = common_.memusage;
  numeric_ = Api::factor(sym_.ap_, sym_.ai_, const_cast<double*>(values), sym_.symbolic_, &common_);
  if (!numeric_) {
    rcond_ = 0.0;
    // halt_if_singular (the default): a zero pivot frees the factors and reports KLU_SINGULAR
    if (common_.status == KLU_SINGULAR) {
      message_ = "singular matrix";
      return FactorStatus::kSingular;
    }
    message_ = common_.status == KLU_TOO_LARGE
                   ? std::string("KLU factorisation failed: the factors outgrew its index type")
                   : unusable_pattern(*sym_.pattern_, "cannot be factorised", common_.status == KLU_OUT_OF_MEMORY);
    return FactorStatus::kFailed;
  }
  // the row permutation is fixed until the next pivot search: its parity once here, not per determinant_sign()
  p_sign_ = permutation_sign(numeric_->Pnum, sym_.pattern_->cols);
  if (!sym_.q_block_parity_.empty()) {
    block_parity_ = block_parities(numeric_->Pnum, sym_.symbolic_->R, sym_.symbolic_->nblocks);
    negative_parity_offset_ = 0;
    for (std::size_t b = 0; b < block_parity_.size(); ++b)
      negative_parity_offset_ ^= block_parity_[b] ^= sym_.q_block_parity_[b];
  }
  rcond_ = rcond_at_pivoting_ = scan_diagonal();
  message_.clear();
  return FactorStatus::kOk;
}

// A refactorisation keeps the pivot order and works on the unscaled matrix (KLU's scale −1: no pass over the
// values for their row maxima, no division of each entry, no scaling of each right-hand side). Row scaling only
// matters for choosing pivots: with the order fixed, elimination on D⁻¹A and on A differ by the diagonal D alone
// (P A Q = (D L D⁻¹)(D U), D > 0), so the factors are equally accurate. The reciprocal pivot ratio is still measured
// on the scaled rows, with the scale factors of the pivoting factorisation (the values move little between the
// two), so that its thresholds and the degradation test keep their meaning on badly scaled models.
template <class Int>
FactorStatus KluNumeric<Int>::factorize(const double* values) {
  if (numeric_ && !forget_pivots_) {
    keep_row_scale();    // first refactorisation after a pivot search: keep KLU's scales
    common_.scale = -1;  // KLU frees its Rs: the factors and the solves are of the unscaled matrix
    const bool ok =
        !inverse_row_scale_.empty() &&
        Api::refactor(sym_.ap_, sym_.ai_, const_cast<double*>(values), sym_.symbolic_, numeric_, &common_) &&
        common_.status == KLU_OK;
    if (ok) {
      const double rc = scan_diagonal();
      if (rc >= kDegradation * rcond_at_pivoting_ && !(rc < kCheckedBelow && rc < 0.1 * rcond_at_pivoting_)) {
        rcond_ = rc;
        message_.clear();
        return FactorStatus::kOk;
      }
    }
    // refactorisation failed, hit a zero pivot, or its pivots degraded: search for pivots again
  }
  return factor_with_pivoting(values);
}

template <class Int>
bool KluNumeric<Int>::solve_system(bool transposed, const double* b, double* x) {
  if (!numeric_) {
    message_ = "solve before a successful factorisation";
    return false;
  }
  const Int n = static_cast<Int>(sym_.pattern_->cols);
  std::copy(b, b + n, x);
  const bool ok = transposed ? Api::tsolve(sym_.symbolic_, numeric_, n, x, &common_)
                             : Api::solve(sym_.symbolic_, numeric_, n, x, &common_);
  if (!ok) {
    message_ = common_.status == KLU_OUT_OF_MEMORY ? "sparse LU (KLU): out of memory in the solve with the Jacobian"
                                                   : "sparse LU (KLU): the solve with the Jacobian's factors failed";
    return false;
  }
  return true;
}

// 32-bit KLU up to this many expected entries of L, U and the off-diagonal blocks: each block's factors are
// addressed by int offsets into its own array of 8-byte units (an entry takes 1.5 units), so 2^28 entries leave
// room for four times the fill the analysis expects before the offsets could overflow.
constexpr double kInt32Entries = 268435456.0;

}  // namespace

std::shared_ptr<const SparseLuSymbolic> analyse_klu(std::shared_ptr<const CscPattern> pattern, KluIndexWidth width) {
  const bool fits = pattern->cols < INT_MAX / 2 && pattern->nnz() < INT_MAX / 2;
  if (width == KluIndexWidth::k32 && !fits) throw Error("KLU: the pattern is too large for 32-bit indices");
  if (width != KluIndexWidth::k64 && fits) {
    auto narrow = std::make_shared<KluSymbolic<int>>(pattern);
    if (width == KluIndexWidth::k32 || narrow->estimated_entries() < kInt32Entries) return narrow;
  }
  return std::make_shared<KluSymbolic<SuiteSparse_long>>(std::move(pattern));
}

KluAnalysis describe_klu(const SparseLuSymbolic& s) {
  const auto* k = dynamic_cast<const KluSymbolicBase*>(&s);
  if (!k) throw Error("describe_klu: not a KLU analysis");
  return k->analysis;
}

}  // namespace phiq::detail

/// @file
/// Sparse LU behind one interface, in SuiteSparse's vocabulary: analyse (pattern, once per model) → factorise
/// (values, every Newton iteration) → solve.
///
/// The symbolic object is immutable after analyse() and may be shared by any number of threads; each thread owns
/// its numeric object (make_numeric()), which co-owns the symbolic object it was made from. UMFPACK's "singular matrix"
/// warning is reported as kSingular, distinct from a failure of the library (kFailed: out of memory, invalid data).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "phiq/sparse_pattern.hpp"

namespace phiq {

/// Outcome of a numeric factorisation.
enum class FactorStatus {
  kOk,        ///< factors computed, the matrix is non-singular
  kSingular,  ///< factors computed but U has a zero pivot (UMFPACK's warning): solves are not meaningful
  kFailed,    ///< the library failed (out of memory, invalid data): no factors
};
/// "ok", "singular" or "failed".
const char* to_string(FactorStatus s);

/// Which sparse LU to use for the square driven system.
enum class LinearSolverKind {
  kUmfpack,  ///< SuiteSparse UMFPACK: multifrontal LU, pivot search at every factorisation
  kKlu,      ///< SuiteSparse KLU: refactorisation with the previous pivot order, re-pivoting when pivots degrade
  kDense,    ///< Eigen's dense partial-pivoting LU of the same matrix: a reference for tests and small models
};
/// "umfpack", "klu" or "dense".
const char* to_string(LinearSolverKind k);

/// Numeric factors of one matrix with an analysed pattern. One per thread (not thread-safe).
class SparseLuNumeric {
 public:
  virtual ~SparseLuNumeric() = default;  ///< frees the factors
  /// Numeric factorisation of the matrix with the analysed pattern and these CSC values.
  virtual FactorStatus factorize(const double* values) = 0;
  /// x = A⁻¹ b with the last successful factorisation. x and b must not alias. Returns false on failure.
  virtual bool solve(const double* b, double* x) = 0;
  /// x = A⁻ᵀ b with the last successful factorisation (same rules as solve()). Used for diagnostics: inverse
  /// iteration on Aᵀ finds which equations are nearly dependent at a near-singular position.
  virtual bool solve_transposed(const double* b, double* x) = 0;
  /// Reciprocal condition estimate of the last factorisation (UMFPACK: min|U_ii| / max|U_ii|).
  virtual double rcond() const = 0;
  /// Sign of det A from the last successful factorisation: +1 or −1, 0 when there are no factors or U has a
  /// zero pivot. Along a branch of a driven motion det Φq changes sign exactly where the branch passes a singular
  /// position (a bifurcation or a dead point), which is how a sweep notices one between two steps. O(n).
  virtual int determinant_sign() const = 0;
  /// A fingerprint of the signs of the determinants of A's diagonal blocks, for a library that factorises A's
  /// block triangular form (KLU: a chain of loops has one block per loop); 0 for one that factorises A whole. Two
  /// factorisations of matrices of this pattern give the same value when every block's determinant has the same
  /// sign, and different values (but for a 2⁻⁶⁴ coincidence) when any differs. det A keeps its sign when an even
  /// number of blocks change theirs at once (nfourbar of even N through its flat position, all loops singular
  /// together); a sweep compares both to notice such a crossing. Valid when determinant_sign() is ±1.
  virtual std::uint64_t block_signs() const { return 0; }
  /// Detail of the last failure, for diagnostics.
  virtual std::string last_message() const = 0;
  /// The next factorize() searches for pivots as the first one does, instead of keeping the pivot order of an
  /// earlier factorisation (KLU): its factors then depend on the matrix alone, not on which matrices this object
  /// factorised before (Workspace::start_afresh). No-op for libraries that always pivot.
  virtual void forget_pivot_order() {}
  /// Keeps the pivot order of the last factorisation (true), for restore_pinned_pivot_order(). Returns false,
  /// pinning nothing, when the last factorisation failed, and for libraries that always pivot. The pinned factors
  /// are kept (memory_bytes() counts them) until unpin_pivot_order() or destruction.
  virtual bool pin_pivot_order() { return false; }
  /// The next factorize() refactorises with the pinned pivot order (and searches only where it has degraded, as
  /// always), whatever was factorised since it was pinned: its factors then depend on the matrix and the pinned
  /// order alone (a parallel sweep's chunks: the same bits on any thread, without a pivot search per chunk).
  /// Returns false, changing nothing, when no order is pinned.
  virtual bool restore_pinned_pivot_order() { return false; }
  /// Forgets a pinned pivot order; the current factors stay usable.
  virtual void unpin_pivot_order() {}
  /// Factorisations so far that searched for pivots (for KLU: not a refactorisation with the old pivot order).
  /// Equal to the number of factorize() calls for libraries that always pivot.
  virtual std::int64_t pivoting_factorizations() const = 0;
  /// Bytes the factors take (KLU: its memory in use; UMFPACK: the entries of L and U; dense: n²), 0 before the
  /// first factorisation. What a parallel sweep counts per thread when it fits its threads to the memory.
  virtual std::size_t memory_bytes() const = 0;
};

/// Symbolic analysis of a pattern (orderings, once per model). Immutable and thread-safe: share it.
class SparseLuSymbolic {
 public:
  virtual ~SparseLuSymbolic() = default;  ///< frees the analysis once no numeric object uses it
  /// The library behind it.
  virtual LinearSolverKind kind() const = 0;
  /// A new numeric object for this pattern (co-owns this analysis). Thread-safe.
  virtual std::unique_ptr<SparseLuNumeric> make_numeric() const = 0;
};

/// Symbolic analysis of a square pattern. Throws phiq::Error when the pattern is not square or the library fails.
std::shared_ptr<const SparseLuSymbolic> analyse(LinearSolverKind kind, std::shared_ptr<const CscPattern> pattern);

}  // namespace phiq

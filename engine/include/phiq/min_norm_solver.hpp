/// @file
/// Minimum-norm solves of under-determined linear systems A x = b (A of full row rank, r ≤ n), through a sparse
/// Cholesky factorisation of A Aᵀ by CHOLMOD: x = Aᵀ (A Aᵀ)⁻¹ b is the solution of least 2-norm. Used by the
/// assembly (Gauss-Newton steps that move the rough placement as little as possible onto Φ = 0) and by the rank
/// analysis (which rows a redundant row is a combination of).
///
/// SuiteSparse vocabulary: the pattern of A is analysed once (fill-reducing ordering of A Aᵀ, in the constructor),
/// then factorise(values) every iteration, then solve. Not thread-safe: one object per thread.
#pragma once

#include <memory>
#include <string>

#include "phiq/linear_solver.hpp"
#include "phiq/sparse_pattern.hpp"

namespace phiq {

/// CHOLMOD's L Lᵀ = A Aᵀ + β I for a fixed pattern of A (r × n), and the minimum-norm solve with it.
class MinNormSolver {
 public:
  /// Analyses the pattern of A (once). Throws phiq::Error when CHOLMOD fails (out of memory, invalid pattern).
  explicit MinNormSolver(std::shared_ptr<const CscPattern> pattern);
  ~MinNormSolver();  ///< frees the factor and CHOLMOD's workspace
  MinNormSolver(const MinNormSolver&) = delete;
  MinNormSolver& operator=(const MinNormSolver&) = delete;

  /// The pattern of A.
  const CscPattern& pattern() const { return *pattern_; }
  /// Factorises A Aᵀ + beta I with A's values in pattern order (kept by pointer until the next factorise: solve()
  /// and min_norm() read A). kSingular when A Aᵀ + β I is not numerically positive definite (A rank deficient and
  /// β = 0); kFailed when CHOLMOD fails.
  FactorStatus factorize(const double* values, double beta = 0.0);
  /// y = (A Aᵀ + β I)⁻¹ b (b and y have r entries). Returns false when there is no valid factorisation.
  bool solve(const double* b, double* y);
  /// x = Aᵀ (A Aᵀ + β I)⁻¹ b (b has r entries, x has n): the minimum-norm solution of A x = b when β = 0.
  bool min_norm(const double* b, double* x);
  /// x = Aᵀ y (y has r entries, x has n), with the values of the last successful factorize().
  void multiply_transposed(const double* y, double* x) const;
  /// y += A x (x has n entries, y has r), with the values of the last successful factorize().
  void multiply_add(const double* x, double* y) const;
  /// CHOLMOD's reciprocal condition estimate of A Aᵀ + β I (min/max of the diagonal of L, squared): a cheap,
  /// rough figure; about rcond(A)².
  double rcond() const { return rcond_; }
  /// Detail of the last failure.
  const std::string& last_message() const { return message_; }

 private:
  struct Impl;
  std::shared_ptr<const CscPattern> pattern_;
  std::unique_ptr<Impl> impl_;
  const double* values_ = nullptr;
  double rcond_ = 0.0;
  std::string message_;
};

}  // namespace phiq

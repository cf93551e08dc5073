// KLU behind the SparseLuSymbolic / SparseLuNumeric interface (linear_solver.hpp): internal to the engine.
#pragma once

#include <memory>

#include "phiq/linear_solver.hpp"

namespace phiq::detail {

/// Which of KLU's index types to use: kAuto takes 32-bit indices when the matrix and the factors the analysis
/// expects fit them (tests force either).
enum class KluIndexWidth { kAuto, k32, k64 };

/// KLU's symbolic analysis of a square pattern: BTF + AMD, the blocks then put in an order that follows the
/// pattern's own where that is more local (klu_lu.cpp). Throws phiq::Error when KLU fails.
std::shared_ptr<const SparseLuSymbolic> analyse_klu(std::shared_ptr<const CscPattern> pattern,
                                                    KluIndexWidth width = KluIndexWidth::kAuto);

/// What analyse_klu chose, for tests and diagnostics.
struct KluAnalysis {
  int index_bits = 0;        ///< 32 or 64
  Index blocks = 0;          ///< diagonal blocks of the block triangular form
  bool resequenced = false;  ///< the blocks follow the pattern's order instead of KLU's
  double klu_jump = 0.0;     ///< mean distance between consecutive columns in KLU's own order
  double jump = 0.0;         ///< the same in the order used
  /// The column order BTF's maximum transversal searched (klu_lu.cpp, KluSymbolic::analyze_bounded): 0 the
  /// pattern's, within its bound; 1 reversed, the pattern's having exceeded it; 2 the pattern's without a bound,
  /// both having exceeded it.
  int transversal = 0;
};
/// Throws phiq::Error when `s` is not a KLU analysis.
KluAnalysis describe_klu(const SparseLuSymbolic& s);

}  // namespace phiq::detail

/// @file
/// The fixed compressed-sparse-column pattern of Φq, built once per model from the constraints' triplets.
#pragma once

#include <vector>

#include "phiq/types.hpp"

namespace phiq {

/// A sparsity pattern in compressed sparse columns (the layout UMFPACK, KLU and CHOLMOD take). Values live
/// elsewhere (in a Workspace), in the same order as row_idx.
struct CscPattern {
  Index rows = 0;              ///< number of rows (equations)
  Index cols = 0;              ///< number of columns (coordinates)
  std::vector<Index> col_ptr;  ///< size cols + 1
  std::vector<Index> row_idx;  ///< size nnz, ascending within each column, no duplicates
  /// Number of stored entries.
  Index nnz() const { return static_cast<Index>(row_idx.size()); }
};

/// Builds the CSC pattern of the triplets (trip_rows[k], trip_cols[k]) and, in slot_of_triplet[k], the position of
/// triplet k in the CSC value array. Duplicated (row, col) pairs share one slot, so values are accumulated into it.
/// O(nnz + rows + cols), by two counting sorts; no comparison sort. Throws phiq::Error if a triplet is out of
/// range or the lists differ in length. Thread-safe.
CscPattern build_csc_pattern(Index rows, Index cols, const std::vector<Index>& trip_rows,
                             const std::vector<Index>& trip_cols, std::vector<Index>* slot_of_triplet);

/// The pattern of Aᵀ (A.cols × A.rows) and, in source_entry[k], the position in A's value array of Aᵀ's entry k, so
/// that Aᵀ's values are a gather of A's: tv[k] = av[source_entry[k]] (null when only the pattern is wanted, e.g. A by
/// rows). O(nnz + rows + cols). Thread-safe.
CscPattern transpose_pattern(const CscPattern& a, std::vector<Index>* source_entry);

}  // namespace phiq

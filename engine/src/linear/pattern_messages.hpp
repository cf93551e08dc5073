// Why a factorisation library refused the Jacobian, in the model's terms. KLU, UMFPACK and CHOLMOD report a pattern
// they cannot use by a status number (KLU -3, UMFPACK -5, CHOLMOD -4 for the same empty matrix); a user acts on
// what the pattern lacks — an equation that involves no coordinate (an empty row), a coordinate that no equation
// involves (an empty column) — so the solvers' messages say that, and never the library's status.
#pragma once

#include <string>
#include <vector>

#include "phiq/sparse_pattern.hpp"

namespace phiq::detail {

// "the Jacobian (3 x 3, 5 entries) has an equation that involves no coordinate (2 empty rows) and ...": what the
// pattern lacks, or that it is structurally singular when it lacks no row nor column. `what` is the step that
// failed ("cannot be analysed"); `out_of_memory` says so instead.
inline std::string unusable_pattern(const CscPattern& p, const std::string& what, bool out_of_memory = false) {
  const std::string size = "the Jacobian (" + std::to_string(p.rows) + " x " + std::to_string(p.cols) + ", " +
                           std::to_string(p.nnz()) + " entries)";
  if (out_of_memory) return size + " " + what + ": out of memory";
  std::vector<char> row_used(static_cast<std::size_t>(p.rows), 0);
  for (Index r : p.row_idx) row_used[static_cast<std::size_t>(r)] = 1;
  Index empty_rows = 0, empty_cols = 0;
  for (char u : row_used) empty_rows += u ? 0 : 1;
  for (Index j = 0; j + 1 < static_cast<Index>(p.col_ptr.size()); ++j)
    empty_cols += p.col_ptr[static_cast<std::size_t>(j + 1)] == p.col_ptr[static_cast<std::size_t>(j)] ? 1 : 0;
  std::string why;
  if (empty_rows)
    why = std::to_string(empty_rows) + " equation" + (empty_rows == 1 ? "" : "s") + " that involve" +
          (empty_rows == 1 ? "s" : "") + " no coordinate (empty rows)";
  if (empty_cols)
    why += (why.empty() ? "" : " and ") + std::to_string(empty_cols) + " coordinate" + (empty_cols == 1 ? "" : "s") +
           " that no equation involves (empty columns)";
  if (why.empty())
    return size + " " + what + ": it is structurally singular (no pivot order makes its diagonal non-zero)";
  return size + " " + what + ": it has " + why;
}

}  // namespace phiq::detail

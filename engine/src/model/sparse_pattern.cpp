#include "phiq/sparse_pattern.hpp"

namespace phiq {

CscPattern build_csc_pattern(Index rows, Index cols, const std::vector<Index>& trip_rows,
                             const std::vector<Index>& trip_cols, std::vector<Index>* slot_of_triplet) {
  if (trip_rows.size() != trip_cols.size()) throw Error("build_csc_pattern: row and column lists differ in size");
  const std::size_t nt = trip_rows.size();
  for (std::size_t k = 0; k < nt; ++k)
    if (trip_rows[k] < 0 || trip_rows[k] >= rows || trip_cols[k] < 0 || trip_cols[k] >= cols)
      throw Error("build_csc_pattern: triplet " + std::to_string(k) + " out of range");

  // Counting sort by row, then a stable counting sort by column: triplets end up ordered by (col, row).
  std::vector<Index> by_row(nt), count(static_cast<std::size_t>(std::max(rows, cols)) + 1, 0);
  for (std::size_t k = 0; k < nt; ++k) ++count[static_cast<std::size_t>(trip_rows[k]) + 1];
  for (Index r = 0; r < rows; ++r) count[r + 1] += count[r];
  for (std::size_t k = 0; k < nt; ++k) by_row[static_cast<std::size_t>(count[trip_rows[k]]++)] = static_cast<Index>(k);

  std::vector<Index> col_start(static_cast<std::size_t>(cols) + 1, 0), order(nt);
  for (std::size_t k = 0; k < nt; ++k) ++col_start[static_cast<std::size_t>(trip_cols[k]) + 1];
  for (Index c = 0; c < cols; ++c) col_start[c + 1] += col_start[c];
  std::vector<Index> next(col_start.begin(), col_start.end() - 1);
  for (Index k : by_row) order[static_cast<std::size_t>(next[trip_cols[k]]++)] = k;

  CscPattern p;
  p.rows = rows;
  p.cols = cols;
  p.col_ptr.assign(static_cast<std::size_t>(cols) + 1, 0);
  p.row_idx.reserve(nt);
  slot_of_triplet->assign(nt, -1);
  for (Index c = 0; c < cols; ++c) {
    Index last_row = -1;
    for (Index i = col_start[c]; i < col_start[c + 1]; ++i) {
      Index k = order[static_cast<std::size_t>(i)];
      if (trip_rows[k] != last_row) {
        p.row_idx.push_back(trip_rows[k]);
        last_row = trip_rows[k];
      }
      (*slot_of_triplet)[static_cast<std::size_t>(k)] = static_cast<Index>(p.row_idx.size()) - 1;
    }
    p.col_ptr[c + 1] = static_cast<Index>(p.row_idx.size());
  }
  return p;
}

CscPattern transpose_pattern(const CscPattern& a, std::vector<Index>* source_entry) {
  CscPattern t;
  t.rows = a.cols;
  t.cols = a.rows;
  t.col_ptr.assign(static_cast<std::size_t>(a.rows) + 1, 0);
  for (Index r : a.row_idx) ++t.col_ptr[static_cast<std::size_t>(r) + 1];
  for (Index i = 0; i < a.rows; ++i)
    t.col_ptr[static_cast<std::size_t>(i) + 1] += t.col_ptr[static_cast<std::size_t>(i)];
  t.row_idx.assign(static_cast<std::size_t>(a.nnz()), 0);
  if (source_entry) source_entry->assign(static_cast<std::size_t>(a.nnz()), 0);
  std::vector<Index> next(t.col_ptr.begin(), t.col_ptr.end() - 1);
  for (Index j = 0; j < a.cols; ++j)
    for (Index k = a.col_ptr[static_cast<std::size_t>(j)]; k < a.col_ptr[static_cast<std::size_t>(j) + 1]; ++k) {
      const Index d = next[static_cast<std::size_t>(a.row_idx[static_cast<std::size_t>(k)])]++;
      t.row_idx[static_cast<std::size_t>(d)] = j;
      if (source_entry) (*source_entry)[static_cast<std::size_t>(d)] = k;
    }
  return t;
}

}  // namespace phiq

// Internal: CHOLMOD's workspace as an RAII object, and a CscPattern with values seen as a cholmod_sparse without
// copying (CHOLMOD reads, never owns, the arrays). Shared by the minimum-norm solver and the rank analysis. Not
// installed.
#pragma once

#include <cholmod.h>

#include <algorithm>
#include <cstring>

#include "phiq/sparse_pattern.hpp"

namespace phiq::detail {

// cholmod_l_start / cholmod_l_finish, quiet: singular matrices are statuses to act on, not messages to print.
struct CholmodCommon {
  cholmod_common cc;
  CholmodCommon() {
    cholmod_l_start(&cc);
    cc.print = 0;
    cc.error_handler = nullptr;
  }
  ~CholmodCommon() { cholmod_l_finish(&cc); }
  CholmodCommon(const CholmodCommon&) = delete;
  CholmodCommon& operator=(const CholmodCommon&) = delete;
};

// `p` with `values` (nullptr: the pattern only) as an unsymmetric cholmod_sparse (stype 0: CHOLMOD's analyse and
// factorise then work on A Aᵀ).
inline cholmod_sparse csc_view(const CscPattern& p, const double* values) {
  cholmod_sparse a;
  std::memset(&a, 0, sizeof a);
  a.nrow = static_cast<std::size_t>(p.rows);
  a.ncol = static_cast<std::size_t>(p.cols);
  a.nzmax = static_cast<std::size_t>(std::max<Index>(p.nnz(), 1));
  a.p = const_cast<Index*>(p.col_ptr.data());
  a.i = const_cast<Index*>(p.row_idx.data());
  a.x = const_cast<double*>(values);
  a.stype = 0;
  a.itype = CHOLMOD_LONG;
  a.xtype = values ? CHOLMOD_REAL : CHOLMOD_PATTERN;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

}  // namespace phiq::detail

// Streaming stores for the rows a parallel chunk holds until they are delivered: a copy whose stores bypass the
// caches (SSE2), and the fence that completes them. Apart from parallel_sweep.cpp because they are the processor-
// specific part of it; inline, since the chunks copy every row with them.
#pragma once

#include <algorithm>
#include <cstdint>

#include <Eigen/Core>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "phiq/types.hpp"

namespace phiq::detail {

// to = from (to has from's size), with stores that bypass the caches where the processor has them (SSE2): a
// parallel chunk's rows are read again only when they are delivered, long after, and writing them through the
// caches evicted the chunk's own LU factors and constraints (nfourbar N = 10⁴, 2 threads: 2–3 % of the sweep).
inline void stream_copy(const Eigen::VectorXd& from, Eigen::VectorXd& to) {
  const Index n = from.size();
  const double* src = from.data();
  double* dst = to.data();
#if defined(__SSE2__)
  Index i = 0;
  if (n > 0 && reinterpret_cast<std::uintptr_t>(dst) % 16 != 0) dst[0] = src[0], i = 1;  // (Eigen aligns to 16)
  for (; i + 2 <= n; i += 2) _mm_stream_pd(dst + i, _mm_loadu_pd(src + i));
  for (; i < n; ++i) dst[i] = src[i];
#else
  std::copy(src, src + n, dst);
#endif
}

// Orders the stores of every stream_copy before it ahead of the stores after it. Once per chunk, not per row: a
// fence waits until the streamed stores have reached memory, which the computation otherwise overlaps (nfourbar
// N = 10³, 2 threads: 0.5 % of the sweep).
inline void stream_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace phiq::detail

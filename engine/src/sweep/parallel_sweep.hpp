// The chunked sweep: the drive steps in chunks on one or more threads, each chunk started from a seed that a
// positions-only pass finds ahead of it, accepted where the chunk before, continued one step (its seam), arrives at
// its first row, and delivered in order on the caller's thread (chunked_sweep.hpp). run_sweep.cpp chooses it, and
// the chunk size, from what a row takes to hold (HeldRows) and the resources (resources.hpp).
#pragma once

#include <algorithm>
#include <cstddef>

#include "phiq/sweep.hpp"
#include "sweep/sweep_run.hpp"
#include "sweep/sweeper.hpp"

namespace phiq::detail {

// The rows a parallel chunk holds until they are delivered in order.
struct HeldRows {
  bool caller_reads_rows = false;  // run_sweep has an on_step or a RowWriter: every row is delivered
  double row_bytes = 0.0;          // what a row takes: q, q̇, q̈ as solved, then Φ, rcond and point motions as asked
  // At most what a row takes encoded, when the chunks encode their rows (Run::chunks_encode()); else 0
  double encoded_row_bytes = 0.0;
  // Which of a chunk's `rows` rows keep their vectors: all of them for a caller that reads the rows as vectors.
  // Otherwise (rows encoded by the chunk, or a sweep for its summary and last state), only what the parallel sweep
  // reads again itself: the first row's q (the seam check) and the last row (the state an ordered continuation
  // starts from). Copying the rows in between was 3 % of a 2-thread sweep of nfourbar N = 10³ that nobody read.
  bool keeps_vectors(std::size_t rows, std::size_t i) const {
    return (caller_reads_rows && encoded_row_bytes == 0.0) || i == 0 || i + 1 == rows;
  }
  // What a chunk of `rows` rows holds until it is delivered (keeps_vectors, and the encoded rows).
  double held_bytes(Index rows) const {
    const bool all = caller_reads_rows && encoded_row_bytes == 0.0;
    return row_bytes * static_cast<double>(all ? rows : std::min<Index>(rows, 2)) +
           encoded_row_bytes * static_cast<double>(rows);
  }
};
// `encoded_row_bytes`: RowWriter::max_row_bytes() when the chunks encode their rows, else 0.
HeldRows held_rows(const Model& model, const SweepOptions& opt, bool caller_reads_rows,
                   std::size_t encoded_row_bytes = 0);

// The drive steps 1 … opt.steps of the sweep `run`, whose row 0 the caller's sweeper `sw` has delivered (its state is
// moved out: `sw` is not used after this), in `n_chunks` chunks of `chunk` steps on `threads` threads (1: one after
// the other, with the same seeds, so the same rows, as on any other count), with the rows held as `layout` says;
// what the chunks do not deliver runs in order at the end. Work done in other workspaces is added to `others`; the
// caller's workspace's counters at the start and the end of the parallel part are left in `counted_begin` and
// `counted_end` (the work between them is the chunks' and seeds', in `others` already). Status, message and
// warnings go to run.sum; the caller's workspace ends at the last delivered row. Rethrows an exception of the
// caller's on_step (or RowWriter) once every thread has stopped.
void parallel_sweep(const Model& model, const SweepOptions& opt, Workspace& ws, Run& run, Sweeper& sw,
                    const HeldRows& layout, Index chunk, Index n_chunks, int threads, WorkCounters& others,
                    WorkCounters& counted_begin, WorkCounters& counted_end);

}  // namespace phiq::detail

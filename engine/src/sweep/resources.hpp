// What a sweep may use of the machine: how many threads fit in memory (each needs a workspace), and how many steps
// a parallel chunk takes when SweepOptions::chunk_steps is 0. Read once per sweep, before the drive steps
// (run_sweep.cpp); the memory probes behind them are in resources.cpp.
#pragma once

#include <vector>

#include "phiq/sweep.hpp"

namespace phiq::detail {

// All cores (threads = 0), as many as fit: each thread beyond the first needs a workspace like the caller's `ws`
// (which has factorised at row 0; the caller's own serves one thread, and the seeding pass shares them), beside the
// rows held for delivery (SweepOptions::row_buffer_bytes at most). memory_budget is the whole process's: what it
// holds already (the model, the caller's workspace) is spent. Fewer threads than `threads` come with a
// "threads_reduced" warning at `t0`.
int threads_that_fit(const SweepOptions& opt, const Workspace& ws, int threads, double t0,
                     std::vector<SweepWarning>& warnings);

// SweepOptions::chunk_steps = 0: the chunk of a parallel sweep on `threads` threads whose rows take `row_bytes`
// each (held until delivered when `caller_reads_rows`). 64 steps (a chunk costs a seed, a start from it and a seam
// step), but at least 4 chunks per thread, down to 16 steps (so a sweep of 16 steps or fewer runs in order): the
// seed of a chunk is one step over the chunk's whole span, and on a large model long spans are expensive (Newton
// from far away, sub-steps). Measured, 100 steps on 2 threads against 1 thread: chain3d N = 10⁴ positions only 1.5×
// with 9 chunks of 12 steps, 0.9–1.0× with 2 of 50; nfourbar N = 10³ with q̇, q̈ 1.45× either way. More chunks also
// balance more threads (tools/simulate_schedule.py). Fewer steps when the rows a chunk per thread holds would
// exceed row_buffer_bytes, and none below kMinChunkSteps: `threads` is then lowered to as many as have room for
// such chunks, the rest of the cores left to the model's parallel evaluation (1: in order), with a
// "threads_reduced" warning at `t0` (only where the sweep could run in parallel chunks: `parallel`).
Index automatic_chunk_steps(const SweepOptions& opt, double row_bytes, bool caller_reads_rows, bool parallel,
                            double t0, int& threads, std::vector<SweepWarning>& warnings);

}  // namespace phiq::detail

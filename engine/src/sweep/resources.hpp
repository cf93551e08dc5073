// What a sweep may use of the machine: how many threads fit in memory (each needs a workspace), and how many steps
// a parallel chunk takes when SweepOptions::chunk_steps is 0. Read once per sweep, before the drive steps
// (run_sweep.cpp); the memory probes behind them are in resources.cpp.
#pragma once

#include <vector>

#include "phiq/sweep.hpp"

namespace phiq::detail {

// The largest thread count the engine takes (SweepOptions::threads, run_batch(), ModesOptions::threads), as phiq's
// --threads: phiq::Error above it, rather than a TBB task arena of that many slots (10⁷ from Python: SIGSEGV).
inline constexpr int kMaxThreads = 1000000;

// All cores (threads = 0), as many as fit: each thread beyond the first needs a workspace like the caller's `ws`
// (which has factorised at row 0; the caller's own serves one thread, and the seeding pass shares them), beside the
// rows held for delivery (SweepOptions::row_buffer_bytes at most). memory_budget is the whole process's: what it
// holds already (the model, the caller's workspace) is spent. Fewer threads than `threads` come with a
// "threads_reduced" warning at `t0`.
int threads_that_fit(const SweepOptions& opt, const Workspace& ws, int threads, double t0,
                     std::vector<SweepWarning>& warnings);

// SweepOptions::chunk_steps = 0: the steps per chunk, from the scene and the options only — never from the thread
// count, the machine or the time — so that every thread count cuts the sweep alike and computes the same rows, to the
// bit. 64 steps (a chunk costs a seed, a start from it and a seam step: about 3 steps of 64), fewer for short
// sweeps so that there are 16 chunks to share among threads, down to 16 steps (a sweep of 16 steps or fewer is one
// chunk: in order). Measured, 100 steps on 2 threads against 1 thread: chain3d N = 10⁴ positions only 1.5× with 9
// chunks of 12 steps, 0.9–1.0× with 2 of 50 (tools/simulate_schedule.py for more threads). When the caller reads
// the rows (`caller_reads_rows`), a chunk holds no more rows than row_buffer_bytes has room for, and none below
// kMinChunkSteps: a sweep whose rows are wider runs as one chunk, in order.
Index automatic_chunk_steps(const SweepOptions& opt, double row_bytes, bool caller_reads_rows);

// The threads among `threads` that have room for a chunk's rows each (`chunk_bytes`: HeldRows::held_bytes(chunk),
// the rows as a chunk holds them, `row_bytes` a row's vectors) in row_buffer_bytes (all of them when the
// caller reads no rows: two are held per chunk); fewer come with a "threads_reduced" warning at `t0`. Only the
// schedule changes with it, never the rows.
int threads_with_room_for_rows(const SweepOptions& opt, double row_bytes, double chunk_bytes, bool caller_reads_rows,
                               Index chunk, int threads, double t0, std::vector<SweepWarning>& warnings);

}  // namespace phiq::detail

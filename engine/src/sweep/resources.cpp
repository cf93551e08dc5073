// The memory a sweep may use (/proc probes: MemAvailable, the process's resident memory, and what a workspace
// takes), and from it the threads that fit and the automatic chunk size (resources.hpp).
#include "sweep/resources.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include <unistd.h>

namespace phiq::detail {

namespace {

// The shortest chunk the automatic choice makes. A chunk costs about three steps besides its own (its seed, the
// start from it, the seam step), so shorter chunks cost more than a second thread gains: 10⁶ scissor stages, 100
// steps on 2 threads, ran slower in chunks of 5 rows (solve 82 s) than in order, and took 12 GB in chunks of 1
// (q, q̇, q̈: rows of 144 MB); chunks of 12 steps still gave 1.5× (chain3d N = 10⁴). Where the rows held for
// delivery leave room for fewer steps per chunk than this, the sweep runs on fewer threads, or in order.
constexpr Index kMinChunkSteps = 8;

// What one more thread of a parallel sweep of `ws`'s model takes: the LU (measured, ws has factorised: KLU's peak),
// Φq's values, and the vectors of a workspace and of a sweeper's predictor history, about 16 of n and 4 of m.
// (10⁶ scissor stages: 2.2 GB measured per extra thread; this says 10 × its 0.22 GB at 10⁵.)
double workspace_bytes(const Workspace& ws) {
  const double n = static_cast<double>(ws.q.size()), m = static_cast<double>(ws.phi.size());
  const double lu = ws.lu ? static_cast<double>(ws.lu->memory_bytes()) : 0.0;
  return lu + 8.0 * (static_cast<double>(ws.jacobian_values.size() + ws.solve_values.size()) + 16.0 * n + 4.0 * m);
}

// The memory the system reports available (Linux: MemAvailable), 0 when it reports none.
double available_memory() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return 0.0;
  char line[256];
  double kb = 0.0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "MemAvailable: %lf kB", &kb) == 1) break;
  std::fclose(f);
  return 1024.0 * kb;
}

// The process's resident memory (Linux: /proc/self/statm), 0 when unknown.
double resident_memory() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0.0;
  double size = 0.0, resident = 0.0;
  const bool ok = std::fscanf(f, "%lf %lf", &size, &resident) == 2;
  std::fclose(f);
  return ok ? resident * static_cast<double>(sysconf(_SC_PAGESIZE)) : 0.0;
}

}  // namespace

int threads_that_fit(const SweepOptions& opt, const Workspace& ws, int threads, double t0,
                     std::vector<SweepWarning>& warnings) {
  const double budget =
      opt.memory_budget > 0 ? static_cast<double>(opt.memory_budget) - resident_memory() : available_memory();
  const double per = workspace_bytes(ws);
  if (!(budget > 0.0 || opt.memory_budget > 0) || !(per > 0.0)) return threads;
  const double room =
      std::floor((budget - static_cast<double>(opt.row_buffer_bytes)) / per) + 1.0;  // the caller's is one of them
  if (room >= threads) return threads;
  const int fit = std::max(1, static_cast<int>(std::max(room, 1.0)));
  std::ostringstream m;
  m.precision(3);
  m << "the drive steps run on " << fit << (fit == 1 ? " thread" : " threads") << " instead of " << threads
    << ": each needs a workspace of " << per / 1e9 << " GB (its LU of Φq and its vectors), and ";
  if (opt.memory_budget > 0)
    m << "the budget of " << static_cast<double>(opt.memory_budget) / 1e9 << " GB (memory_budget) leaves "
      << std::max(budget, 0.0) / 1e9 << " GB beside what the run holds";
  else
    m << budget / 1e9 << " GB are available";
  warnings.push_back({t0, "threads_reduced", m.str()});
  return fit;
}

Index automatic_chunk_steps(const SweepOptions& opt, double row_bytes, bool caller_reads_rows) {
  Index chunk = std::min<Index>(64, std::max<Index>(16, opt.steps / 16));
  if (!caller_reads_rows) return chunk;
  const double rows_fit = static_cast<double>(opt.row_buffer_bytes) / row_bytes;  // rows the buffer holds
  if (rows_fit >= static_cast<double>(chunk)) return chunk;
  return rows_fit >= kMinChunkSteps ? static_cast<Index>(rows_fit) : std::max<Index>(opt.steps, 1);
}

int threads_with_room_for_rows(const SweepOptions& opt, double row_bytes, double chunk_bytes, bool caller_reads_rows,
                               Index chunk, int threads, double t0, std::vector<SweepWarning>& warnings) {
  if (!caller_reads_rows || threads <= 1) return threads;
  const bool one_chunk = chunk >= opt.steps;
  // (one chunk by choice — a short sweep, or chunk_steps — runs in order without a word)
  if (one_chunk &&
      (static_cast<double>(opt.row_buffer_bytes) / row_bytes >= kMinChunkSteps || opt.steps <= kMinChunkSteps))
    return threads;
  // a thread's chunk holds its rows as it keeps them until delivery: encoded text or doubles where the chunks
  // encode them (CSV rows are about three times their doubles), else the vectors
  row_bytes = chunk_bytes / static_cast<double>(std::max<Index>(chunk, 1));
  const double rows_fit = static_cast<double>(opt.row_buffer_bytes) / row_bytes;
  const int room =
      one_chunk ? 1 : static_cast<int>(std::min<double>(threads, std::floor(rows_fit / static_cast<double>(chunk))));
  if (room >= threads) return threads;
  std::ostringstream msg;
  msg.precision(3);
  msg << "the drive steps run "
      << (one_chunk ? std::string("in order, not in chunks,")
                    : "on " + std::to_string(std::max(room, 1)) + (room > 1 ? " threads" : " thread"))
      << " instead of on " << threads << " threads: a row of the outputs is " << row_bytes / 1e6
      << " MB, and the rows held for delivery in order (SweepOptions::row_buffer_bytes, "
      << static_cast<double>(opt.row_buffer_bytes) / 1e6 << " MB) hold " << static_cast<long long>(rows_fit)
      << " rows: "
      << (one_chunk ? "fewer than the " + std::to_string(kMinChunkSteps) + " steps that pay for a chunk's seed"
                    : "chunks of " + std::to_string(chunk) + " steps for " + std::to_string(std::max(room, 1)) +
                          (room > 1 ? " threads" : " thread"))
      << "; the other threads still serve the model's parallel evaluation";
  warnings.push_back({t0, "threads_reduced", msg.str()});
  return std::max(room, 1);
}

}  // namespace phiq::detail

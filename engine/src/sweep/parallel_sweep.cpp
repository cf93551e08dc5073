// The parallel sweep (parallel_sweep.hpp): the schedule of seeds and chunks on the task arena's threads, a chunk's
// rows from its seed with its seam step, the seam check that accepts a chunk as the sequential sweep's continuation,
// and the delivery in order on the caller's thread, falling back to the sweep in order after a chunk that does not
// continue it. The rows a chunk computes are held in buffers recycled through the workspace (Workspace::spare_rows).
#include "sweep/parallel_sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "phiq/text.hpp"
#include "sweep/streamed_rows.hpp"

namespace phiq::detail {

namespace {

// Two solutions of the same position problem are the same one if they differ by less than `limit` tolerances in
// every coordinate (each is within about one of the exact root, or of its rounding level; another branch is a
// finite distance away).
bool same_solution(const Model& model, const Eigen::VectorXd& a, const double* b, double tol, double limit) {
  return detail::scaled_distance(model, a.data(), b, a.data(), tol) <= limit;
}

// Sub-steps of a positions-only sweep's first seed (see seed_one).
constexpr int kFirstSeedParts = 4;

// A row computed by a parallel chunk, held until it is delivered in order. Its vectors are delivered as they are
// (no copy into the caller's state per row: on a model whose steps are cheap, copying rows in and out cost a fifth
// of a chunk's time).
struct Row {
  Eigen::VectorXd q, qd, qdd, phi;  // q̇, q̈ as solved, Φ when asked (only what is read again: HeldRows::keeps_vectors)
  double rcond = 0.0;
  Orientation det_sign{0, 0};
  double det_sign_t = 0.0;  // where det_sign holds (Sweeper::det_sign_time())
  std::vector<PointMotion> points;
};

// One parallel chunk: rows k0 … k1 computed from a seed at t_k0 (chunk 0: from row 0), then the sweep continued
// in order one step further (the seam), which the next chunk's first row must match.
struct Chunk {
  Index k0 = 0, k1 = 0;
  std::vector<Row> rows;     // rows k0 … k1
  SweepSummary sum;          // status, message, warnings, subdivisions, rcond and work of this chunk
  bool ok = false;
  bool has_seam = false;
  Eigen::VectorXd seam_q;    // the position at t_{k1+1} reached by continuing in order
  double rounding = 0.0;  // largest rounding level (Sweeper::take_rounding_level) of its solves, seed included
};

}  // namespace

HeldRows held_rows(const Model& model, const SweepOptions& opt, bool caller_reads_rows) {
  const Index n = model.num_coordinates();
  // Rows keep q̇ whenever it is solved (q̈ needs it, and so does an ordered continuation's predictor).
  const bool need_v = opt.velocities || opt.accelerations, need_a = opt.accelerations;
  // a row's layout in the chunk buffers: q, q̇, q̈ as solved, then Φ, rcond and the point motions as asked
  const Index m = model.num_equations();
  const Index n_phi = opt.residuals ? m : 0, n_rcond = opt.condition ? 1 : 0;
  const Index n_points = static_cast<Index>(opt.points.size());
  constexpr Index kMotionDoubles = static_cast<Index>(sizeof(PointMotion) / sizeof(double));
  static_assert(sizeof(PointMotion) == 9 * sizeof(double), "PointMotion is stored as 9 doubles in chunk rows");
  const Index width = n * (1 + (need_v ? 1 : 0) + (need_a ? 1 : 0)) + n_phi + n_rcond + n_points * kMotionDoubles + 1;
  return {caller_reads_rows, 8.0 * static_cast<double>(std::max<Index>(width, 1))};
}

void parallel_sweep(const Model& model, const SweepOptions& opt, Workspace& ws, Run& run, Sweeper& sw,
                    const HeldRows& layout, Index chunk, Index n_chunks, int threads, WorkCounters& others,
                    WorkCounters& counted_begin, WorkCounters& counted_end) {
  SweepSummary& sum = run.sum;
  // Rows keep q̇ whenever it is solved (q̈ needs it, and so does an ordered continuation's predictor).
  const bool need_v = opt.velocities || opt.accelerations, need_a = opt.accelerations;
  const Index n_phi = opt.residuals ? model.num_equations() : 0;
  const Index n_points = static_cast<Index>(opt.points.size());
  sum.threads = threads;
  auto first_row = [&](Index c) { return 1 + c * chunk; };
  auto last_row = [&](Index c) { return std::min(opt.steps, (c + 1) * chunk); };

  // Workspaces, taken from a pool for the time of one chunk or one seed: the caller's own (idle otherwise) and as
  // many more as are in use at once, one per thread, since the seeding pass takes one only while it finds a seed.
  // On large models a workspace is mostly the LU of Φq (10⁶ scissor stages: 1.5 GB), so that is what the memory
  // of a parallel sweep grows by per thread. Not one per thread index: a thread waiting inside a nested parallel
  // evaluation (large models) may start other work meanwhile, which then needs a workspace of its own. The work
  // done in each is counted with the chunk or seed that did it; the caller's workspace's share is taken out of its
  // own count at the end (ws_in_parallel).
  std::vector<std::unique_ptr<Workspace>> owned;
  std::vector<Workspace*> pool{&ws};
  std::mutex pool_mutex;
  auto acquire = [&] {
    std::lock_guard<std::mutex> lock(pool_mutex);
    if (pool.empty()) {
      owned.push_back(std::make_unique<Workspace>(model));
      return owned.back().get();
    }
    Workspace* w = pool.back();
    pool.pop_back();
    w->newton_contraction = -1.0;  // measured by its last user, on other steps
    return w;
  };
  auto release = [&](Workspace* w) {
    std::lock_guard<std::mutex> lock(pool_mutex);
    pool.push_back(w);
  };
  counted_begin = ws.counters;

  // The last delivered row (the state an ordered continuation starts from) and the position the sweep reaches
  // one step after it when continued in order (the previous chunk's seam), if known. The caller's sweeper is not
  // used again: its state moves here and its history is freed.
  Index resume = 1;
  State row0 = sw.take_state();
  Eigen::VectorXd last_q = std::move(row0.q), last_qd = need_v ? std::move(row0.qd) : ws.qd,
                  last_qdd = need_a ? std::move(row0.qdd) : ws.qdd;
  bool seam_known = false;
  Eigen::VectorXd seam_q;
  double seam_rounding = 0.0;
  std::vector<Eigen::VectorXd> seeds(static_cast<std::size_t>(n_chunks));  // seeds[c]: chunk c's first row (not 0)
  std::vector<double> seed_rounding(static_cast<std::size_t>(n_chunks), 0.0);  // the seeder's rounding level there
  std::vector<double> seed_error(static_cast<std::size_t>(n_chunks), INFINITY);  // and its error estimate

  // Buffers for the rows' q, q̇, q̈: those of delivered rows, and those the workspace kept from its last parallel
  // sweep (Workspace::spare_rows), so that the rows are written into memory the process has already touched.
  std::mutex spare_mutex;
  std::vector<Eigen::VectorXd> spare;
  spare.swap(ws.spare_rows);
  const Index n_coords = model.num_coordinates();
  std::erase_if(spare, [&](const Eigen::VectorXd& v) { return v.size() != n_coords; });
  auto take_buffers = [&](std::vector<Row>& rows) {
    std::lock_guard<std::mutex> lock(spare_mutex);
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (Eigen::VectorXd* v : {&rows[i].q, need_v ? &rows[i].qd : nullptr, need_a ? &rows[i].qdd : nullptr}) {
        if (!v || !layout.keeps_vectors(rows.size(), i)) continue;
        if (spare.empty()) {
          v->resize(n_coords);
        } else {
          v->swap(spare.back());
          spare.pop_back();
        }
      }
  };
  auto give_buffers = [&](std::vector<Row>& rows) {
    std::lock_guard<std::mutex> lock(spare_mutex);
    for (Row& r : rows)
      for (Eigen::VectorXd* v : {&r.q, &r.qd, &r.qdd})
        if (v->size() == n_coords) spare.push_back(std::move(*v));
  };
  // Chunk c: its rows from its seed (chunk 0: in order from row 0), then the seam step.
  auto run_chunk = [&](Index c, Chunk& ch) {
    Workspace* held = acquire();
    Workspace& w = *held;
    const WorkCounters w0 = w.counters;
    ch.k0 = first_row(c), ch.k1 = last_row(c);
    Sweeper s(model, opt, w, ch.sum);
    ch.rows.resize(static_cast<std::size_t>(ch.k1 - ch.k0 + 1));
    take_buffers(ch.rows);
    std::size_t kept = 0;
    auto keep = [&] {
      const State& st = s.state();
      Row& r = ch.rows[kept];
      s.row_outputs();
      r.det_sign = s.det_sign(), r.det_sign_t = s.det_sign_time();  // (the bifurcation check reads every row's)
      if (!layout.keeps_vectors(ch.rows.size(), kept++)) return;
      stream_copy(st.q, r.q);
      if (need_v) stream_copy(st.qd, r.qd);
      if (need_a) stream_copy(st.qdd, r.qdd);
      if (n_phi) r.phi = w.phi;
      r.rcond = s.rcond();
      if (n_points) r.points.assign(s.point_motions(), s.point_motions() + n_points);
    };
    if (c == 0) {  // continues row 0 in order: the sequential sweep itself
      w.q = last_q, w.qd = last_qd, w.qdd = last_qdd;
      s.adopt(run.time_of(0));
      ch.ok = s.advance(run.time_of(ch.k0), 0);
    } else {
      ch.ok = s.start_from(run.time_of(ch.k0), seeds[static_cast<std::size_t>(c)],
                           seed_error[static_cast<std::size_t>(c)]);
    }
    if (ch.ok) keep();
    for (Index k = ch.k0 + 1; ch.ok && k <= ch.k1; ++k)
      if ((ch.ok = s.advance(run.time_of(k), 0))) keep();
    if (ch.ok && ch.k1 < opt.steps) {
      // the seam row belongs to the next chunk: its warnings and sub-steps are counted there
      const SweepSummary kept = ch.sum;
      if (s.advance_position(run.time_of(ch.k1 + 1))) {
        ch.has_seam = true;
        ch.seam_q = s.state().q;
      }
      ch.sum.warnings = kept.warnings;
      ch.sum.subdivisions = kept.subdivisions;
      ch.sum.singular_positions = kept.singular_positions;
      ch.sum.status = kept.status, ch.sum.message = kept.message;
      ch.sum.min_rcond = kept.min_rcond, ch.sum.min_rcond_time = kept.min_rcond_time;
    }
    ch.rounding = std::max(s.take_rounding_level(), c > 0 ? seed_rounding[static_cast<std::size_t>(c)] : 0.0);
    add_counters(ch.sum.counters, w.counters, w0);
    release(held);
    stream_fence();  // the chunk's streamed rows are complete before it is marked done for the delivering thread
  };

  // Accepts and delivers a computed chunk: 0 delivered, 1 rejected (the rest runs in order), 2 stopped by the
  // caller. A chunk is the sequential sweep's continuation if it starts where the sweep, continued in order from
  // the last delivered row, arrives (chunk 0 is that continuation by construction).
  auto deliver_chunk = [&](Chunk& ch) {
    add_counters(others, ch.sum.counters, WorkCounters{});
    // Two solutions of the same problem agree to 100 tolerances, or, where Newton stopped at the rounding level
    // (a long chain), to 10× how well that stop says q is known: another branch is a finite distance away.
    const double limit = std::max(100.0, 10.0 * std::max(seam_rounding, ch.rounding));
    const bool accept = ch.ok && (ch.k0 == 1 || (seam_known && same_solution(model, seam_q, ch.rows[0].q.data(),
                                                                             opt.newton.tolerance, limit)));
    if (!accept) return 1;
    for (Index k = ch.k0; k <= ch.k1; ++k) {
      const Row& r = ch.rows[static_cast<std::size_t>(k - ch.k0)];
      if (!run.deliver(k, r.q, r.qd, r.qdd, n_points ? r.points.data() : nullptr, r.phi, r.rcond, r.det_sign,
                       r.det_sign_t)) {
        last_q = r.q, last_qd = need_v ? r.qd : last_qd, last_qdd = need_a ? r.qdd : last_qdd;  // where it stopped
        return 2;
      }
    }
    // the state an ordered continuation starts from: the chunk's last row (it is freed once delivered)
    Row& last = ch.rows.back();
    last_q.swap(last.q);
    if (need_v) last_qd.swap(last.qd);
    if (need_a) last_qdd.swap(last.qdd);
    resume = ch.k1 + 1;
    seam_known = ch.has_seam;
    if (seam_known) seam_q.swap(ch.seam_q), seam_rounding = ch.rounding;
    sum.subdivisions += ch.sum.subdivisions;
    sum.singular_positions += ch.sum.singular_positions;
    sum.warnings.insert(sum.warnings.end(), ch.sum.warnings.begin(), ch.sum.warnings.end());
    if (ch.sum.min_rcond > 0.0 && (sum.min_rcond == 0.0 || ch.sum.min_rcond < sum.min_rcond))
      sum.min_rcond = ch.sum.min_rcond, sum.min_rcond_time = ch.sum.min_rcond_time;
    ++sum.parallel_chunks;
    return 0;
  };

  // How far the work may run ahead of the delivery: chunks seeded beyond the next one to deliver. As many as the
  // row buffer allows, at least one per thread, and at most 16 per thread so that rows are delivered (and Ctrl-C
  // seen) every few thousand steps however long the sweep.
  const Index ahead = std::max<Index>(
      threads,
      std::min<Index>(16 * threads,
                      static_cast<Index>(static_cast<double>(opt.row_buffer_bytes) / layout.held_bytes(chunk))));

  // Seeds: the position at each chunk's first row, found in order with the chunk's span as the step (positions
  // only, the parabolic predictor over the seeds before, subdivision on failure), one at a time, just ahead of the
  // chunks that need them.
  // A failure ends the seeding; the chunks after it run in order below, where the failure is reported as the
  // sequential sweep reports it.
  SweepOptions seed_options = opt;
  seed_options.velocities = seed_options.accelerations = false;
  seed_options.predictor = Predictor::kParabolic;
  seed_options.points.clear(), seed_options.residuals = seed_options.condition = false;  // seeds deliver no rows
  SweepSummary seed_summary;
  WorkCounters seed_work;  // done in pool workspaces by the seeding pass
  Workspace* sws = acquire();
  sws->q = last_q;
  Sweeper seeder(model, seed_options, *sws, seed_summary);
  seeder.adopt(run.time_of(0));
  release(sws);

  // The schedule. `threads` loops run the work as it becomes ready: the seeding (in order, one thread at a time,
  // first whenever fewer chunks are ready than threads, so that it stays ahead) and the seeded chunks (lowest
  // first). A chunk starts as soon as its seed is known, not in waves, so no thread waits for a wave's slowest
  // chunk. The calling thread alone delivers, in order, each chunk as soon as it and all before it are done: the
  // caller's on_step runs on the caller's thread, as in a sequential sweep, overlapped with the other threads'
  // chunks.
  std::mutex mutex;
  std::condition_variable wake;
  std::vector<Chunk> chunks(static_cast<std::size_t>(n_chunks));
  std::vector<char> chunk_done(static_cast<std::size_t>(n_chunks), 0);
  Index seeded = 1;            // chunks 0 … seeded − 1 have their seed (chunk 0 starts from row 0)
  Index claimed = 0;           // chunks 0 … claimed − 1 have been taken by a thread
  Index delivered = 0;         // chunks 0 … delivered − 1 have been delivered
  bool seeding_busy = false;   // a thread is finding a seed
  bool seeding_over = n_chunks <= 1;  // every seed found, or the seeding failed
  bool stop = false;           // a chunk was rejected (fallback) or the caller stopped the sweep
  bool cancelled = false;
  bool fallback = false;
  const std::thread::id caller = std::this_thread::get_id();

  auto seed_one = [&] {  // finds seed `seeded` (the lock is not held)
    const auto seed_start = std::chrono::steady_clock::now();
    const Index c = seeded;  // only the thread holding seeding_busy changes it
    Workspace* w = acquire();
    const WorkCounters w0 = w->counters;
    seeder.bind(*w);
    // Without derivatives at row 0 (positions only), the first seed is the one extrapolated from a single position
    // over a whole chunk's span: from that constant prediction its Newton failed on nfourbar N = 10⁵ and took 0.57 s
    // of a 1.66 s sweep. In sub-steps it gives the parabola through the seeds its first rows: 1.35 s.
    const int parts = c == 1 && !need_v ? kFirstSeedParts : 1;
    const double t0 = seeder.state().t, t1 = run.time_of(first_row(c));
    bool ok = true;
    for (int i = 1; ok && i <= parts; ++i)
      ok = seeder.advance(i == parts ? t1 : t0 + (t1 - t0) * static_cast<double>(i) / parts, 0);
    add_counters(seed_work, w->counters, w0);
    release(w);
    if (ok) {
      seeds[static_cast<std::size_t>(c)] = seeder.state().q;
      seed_error[static_cast<std::size_t>(c)] = seeder.state_error();
      seed_rounding[static_cast<std::size_t>(c)] = seeder.take_rounding_level();
    }
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - seed_start).count();
    std::lock_guard<std::mutex> lock(mutex);
    sum.seed_seconds += took;
    if (ok) ++seeded;
    seeding_over = !ok || seeded == n_chunks;
    seeding_busy = false;
    wake.notify_all();
  };
  // The caller's deliveries: every chunk done in order (the lock is held on entry and on return).
  auto deliver_ready = [&](std::unique_lock<std::mutex>& lock) {
    while (!stop && delivered < claimed && chunk_done[static_cast<std::size_t>(delivered)]) {
      Chunk& ch = chunks[static_cast<std::size_t>(delivered)];
      lock.unlock();
      const int d = deliver_chunk(ch);
      give_buffers(ch.rows);
      ch.rows = std::vector<Row>();  // delivered: free
      seeds[static_cast<std::size_t>(delivered)] = Eigen::VectorXd();
      lock.lock();
      if (d != 0) {
        stop = true, cancelled = d == 2, fallback = d == 1;
      } else {
        ++delivered;
      }
      wake.notify_all();
    }
  };
  auto work_loop = [&] {
    const bool is_caller = std::this_thread::get_id() == caller;
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      if (is_caller) deliver_ready(lock);
      if (stop) return;
      const Index ready = seeded - claimed;
      const bool can_seed = !seeding_busy && !seeding_over && seeded < std::min(n_chunks, delivered + ahead + 1);
      if (can_seed && ready < threads) {  // (with no chunk ready, always: threads ≥ 2 here)
        seeding_busy = true;
        lock.unlock();
        tbb::this_task_arena::isolate(seed_one);  // nested evaluations wait only for their own tasks
        lock.lock();
      } else if (ready > 0) {
        const Index c = claimed++;
        lock.unlock();
        tbb::this_task_arena::isolate([&] { run_chunk(c, chunks[static_cast<std::size_t>(c)]); });
        lock.lock();
        chunk_done[static_cast<std::size_t>(c)] = 1;
        wake.notify_all();
      } else if (seeding_over && !seeding_busy && claimed == seeded && (!is_caller || delivered == claimed)) {
        return;  // nothing more will become ready (the caller: and everything done is delivered)
      } else {
        wake.wait(lock);  // for a seed, a finished chunk (the caller) or a delivery (the window)
      }
    }
  };
  // An exception (the caller's on_step may throw) stops every loop, so that none waits for the thrower, and is
  // rethrown once they have all returned.
  std::exception_ptr failure;
  auto work = [&] {
    try {
      work_loop();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
      if (!failure) failure = std::current_exception();
      wake.notify_all();
    }
  };
  tbb::parallel_for(
      tbb::blocked_range<int>(0, threads, 1),
      [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k < r.end(); ++k) work();
      },
      tbb::simple_partitioner());
  // the row buffers go back to the workspace for its next parallel sweep, up to Workspace::kSpareRowBytes
  const std::size_t keep = static_cast<std::size_t>(Workspace::kSpareRowBytes / (8.0 * std::max<Index>(n_coords, 1)));
  if (spare.size() > keep) spare.resize(keep);
  ws.spare_rows.swap(spare);
  if (failure) std::rethrow_exception(failure);
  // chunks computed but not delivered (after a rejected one): their work was done all the same
  for (Index c = delivered + (stop ? 1 : 0); c < claimed; ++c)
    add_counters(others, chunks[static_cast<std::size_t>(c)].sum.counters, WorkCounters{});
  add_counters(others, seed_work, WorkCounters{});
  counted_end = ws.counters;  // the caller's workspace's work so far is the chunks' and seeds'
  // The caller's workspace ends at the last delivered row, as after a sequential sweep.
  ws.q = last_q;
  if (need_v) ws.qd = last_qd;
  if (need_a) ws.qdd = last_qdd;
  if (cancelled) return;
  if (resume <= opt.steps) {
    // In order from the last delivered row: the unseeded chunks, or everything after a chunk that did not
    // continue the sweep's branch or failed (the failure is then found, and reported, in order).
    if (fallback)
      sum.warnings.push_back({run.time_of(resume), "parallel_fallback",
                              "the parallel chunk starting at t = " + format_time(run.time_of(resume)) +
                                  " did not continue the sweep in order (another branch, or a failure); the "
                                  "remaining steps ran in order"});
    Sweeper rest(model, opt, ws, sum);
    rest.adopt(run.time_of(resume - 1));
    run.sequential(rest, ws, resume);
    rest.leave_state_in_workspace();
  }
}

}  // namespace phiq::detail

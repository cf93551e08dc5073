// The schedule of a parallel sweep (chunked_sweep.hpp): the seeding pass, the threads' loop that seeds and runs
// chunks and, on the caller's thread, delivers them in order, and the steps no chunk delivered, run in order at
// the end. Also parallel_sweep() and held_rows() (parallel_sweep.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "phiq/text.hpp"
#include "sweep/chunked_sweep.hpp"
#include "sweep/parallel_sweep.hpp"

namespace phiq::detail {

ChunkedSweep::ChunkedSweep(const Model& model, const SweepOptions& opt, Workspace& ws, Run& run, Sweeper& sw,
                           const HeldRows& layout, Index chunk, Index n_chunks, int threads, WorkCounters& others,
                           WorkCounters& counted_begin)
    : model_(model),
      opt_(opt),
      ws_(ws),
      run_(run),
      row0_sweeper_(sw),
      layout_(layout),
      n_chunks_(n_chunks),
      threads_(threads),
      others_(others),
      need_v_(opt.solves_velocities()),
      need_a_(opt.solves_accelerations()),
      encode_(run.chunks_encode()),
      first_(static_cast<std::size_t>(n_chunks) + 1),
      max_shift_(chunk / 2),
      pool_(model, ws, sw.state().q, run.time_of(0)),
      buffers_(ws, layout, need_v_, need_a_),
      seeds_(n_chunks),
      seed_options_(opt),
      euler_signs_(model),
      chunks_(static_cast<std::size_t>(n_chunks)) {
  for (Index c = 0; c < n_chunks; ++c) first_[static_cast<std::size_t>(c)] = 1 + c * chunk;
  first_[static_cast<std::size_t>(n_chunks)] = opt.steps + 1;
  sched_.chunk_done.assign(static_cast<std::size_t>(n_chunks), 0);
  sched_.seeding_over = n_chunks <= 1;
  // The caller's sweeper is not used again: its state moves here and its history is freed.
  State row0 = sw.take_state();
  at_.q = std::move(row0.q), at_.qd = need_v_ ? std::move(row0.qd) : ws.qd;
  at_.qdd = need_a_ ? std::move(row0.qdd) : ws.qdd;

  // How far the work may run ahead of the delivery: chunks seeded beyond the next one to deliver. As many as the
  // row buffer allows, at least one per thread, and at most 16 per thread so that rows are delivered (and Ctrl-C
  // seen) every few thousand steps however long the sweep.
  ahead_ = std::max<Index>(threads,
                           std::min<Index>(16 * threads, static_cast<Index>(static_cast<double>(opt.row_buffer_bytes) /
                                                                            layout.held_bytes(chunk + max_shift_))));

  // Seeds: the position at each chunk's first row, found in order with the chunk's span as the step (positions
  // only, the parabolic predictor over the seeds before, subdivision on failure), one at a time, just ahead of the
  // chunks that need them. A failure ends the seeding; the chunks after it run in order (finish_in_order), where
  // the failure is reported as the sequential sweep reports it.
  seed_options_.velocities = seed_options_.accelerations = false;
  seed_options_.predictor = Predictor::kParabolic;
  seed_options_.points.clear(), seed_options_.residuals = seed_options_.condition = false;  // seeds deliver no rows
  seed_options_.efforts = OutputEfforts{};
  counted_begin = ws.counters;  // (the work of the seeds and chunks, in pool workspaces, is counted with them)
  Workspace* sws = pool_.acquire();
  sws->q = at_.q;
  seeder_ = std::make_unique<Sweeper>(model, seed_options_, *sws, seed_summary_);
  seeder_->adopt(run.time_of(0));
  // row 0's rates for the first seed's sign, solved here where the sweep does not (as the seeds' are: seed_one; not
  // counted)
  Eigen::VectorXd qd0 = need_v_ ? at_.qd : Eigen::VectorXd(), qdd0 = need_a_ ? at_.qdd : Eigen::VectorXd();
  if (!euler_signs_.empty() && !need_a_) {
    sws->q = at_.q;
    if (need_v_) sws->qd = at_.qd;
    if (need_v_ || solve_velocity(model, run.time_of(0), *sws) == SolveStatus::kSuccess) {
      qd0 = sws->qd;
      if (solve_acceleration(model, run.time_of(0), *sws) == SolveStatus::kSuccess) qdd0 = sws->qdd;
    }
  }
  pool_.release(sws);
  euler_signs_.start(run.time_of(0), at_.q, qd0, qdd0);
}

// Finds seed sched_.seeded (the lock is not held; only the thread holding seeding_busy changes seeded).
void ChunkedSweep::seed_one() {
  const auto seed_start = std::chrono::steady_clock::now();
  const Index c = sched_.seeded;
  Workspace* w = pool_.acquire();
  const WorkCounters w0 = w->counters;
  Sweeper& seeder = *seeder_;
  seeder.bind(*w);
  // Without derivatives at row 0 (positions only), the first seed is the one extrapolated from a single position
  // over a whole chunk's span: from that constant prediction its Newton failed on nfourbar N = 10⁵ and took 0.57 s
  // of a 1.66 s sweep. In sub-steps it gives the parabola through the seeds its first rows: 1.35 s.
  int parts = c == 1 && !need_v_ ? kFirstSeedParts : 1;
  Index row = first_row(c);
  const double t0 = seeder.state().t, t1 = run_.time_of(row);
  // A body that may turn a quarter turn or more over the span, by the last seed's rates: sub-steps of less than a
  // quarter turn each, so that the seeder follows its Euler parameters' sign as the sweep in order does (in one
  // step it may land on −e, which align() turns back only where its extrapolation is sure: a harmonic screw's nut,
  // three turns a second and slowing, was refused at its seam)
  if (!euler_signs_.empty())
    if (const double turn = euler_signs_.largest_turn(t1 - t0); std::isfinite(turn))
      parts = std::max(parts, static_cast<int>(std::min(std::ceil(turn / (0.5 * M_PI)), 64.0)));
  bool ok = true;
  for (int i = 1; ok && i <= parts; ++i)
    ok = seeder.advance(i == parts ? t1 : t0 + (t1 - t0) * static_cast<double>(i) / parts, 0);
  // at or next to a singular position (Φq near-singular at the seed): the chunk starts a row later
  for (const Index last = std::min(row + max_shift_, opt_.steps); ok && row < last && seeder.near_singular();)
    ok = seeder.advance(run_.time_of(++row), 0);
  const auto at = static_cast<std::size_t>(c);
  add_counters(seeds_.work[at], w->counters, w0);
  // The seed's velocity and acceleration, for the sign of the next seed's Euler parameters (euler_signs.hpp), in a
  // model with free ones where a body may turn a quarter turn over a chunk span (else the constant-rate
  // extrapolation is right, and their solves are saved): with the seeding's own factors, not counted (the summary
  // counts the rows' solves; these steer the seeds' signs alone, and no bit of a seed)
  Eigen::VectorXd seed_qd, seed_qdd;
  if (ok && !euler_signs_.empty() && euler_signs_.turns_far(run_.time_of(row) - t0)) {
    w->q = seeder.state().q;
    const double t = run_.time_of(row);
    if (solve_velocity(model_, t, *w) == SolveStatus::kSuccess) {
      seed_qd = w->qd;
      if (solve_acceleration(model_, t, *w) == SolveStatus::kSuccess) seed_qdd = w->qdd;
    }
  }
  pool_.release(w);
  if (ok) {
    first_[at] = row;  // (chunk c − 1, which ends here, is not claimed before: ready)
    seeds_.q[at] = seeder.state().q;
    seeds_.error[at] = seeder.state_error();
    // (a seed turned to −e is checked by a Newton step, as an unknown one is)
    if (euler_signs_.align(run_.time_of(row), seeds_.q[at], seed_qd, seed_qdd)) seeds_.error[at] = INFINITY;
    seeds_.rounding[at] = seeder.take_rounding_level();
  }
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - seed_start).count();
  std::lock_guard<std::mutex> lock(sched_.mutex);
  run_.sum.seed_seconds += took;
  if (ok) ++sched_.seeded;
  sched_.seeding_over = !ok || sched_.seeded == n_chunks_;
  sched_.seeding_busy = false;
  sched_.wake.notify_all();
}

// What a chunk's delivery says for the schedule (the lock is held): delivered, or the parallel part stops.
void ChunkedSweep::settle(int d) {
  if (d != kDelivered) {
    sched_.stop = true, sched_.cancelled = d == kStopped, sched_.fallback = d == kRejected;
  } else {
    ++sched_.delivered;
  }
  sched_.wake.notify_all();
}

// The caller's deliveries: every chunk done, in order (the lock is held on entry and on return).
void ChunkedSweep::deliver_ready(std::unique_lock<std::mutex>& lock) {
  while (!sched_.stop && sched_.delivered < sched_.claimed &&
         sched_.chunk_done[static_cast<std::size_t>(sched_.delivered)]) {
    const auto c = static_cast<std::size_t>(sched_.delivered);
    Chunk& ch = chunks_[c];
    lock.unlock();
    const int d = deliver_chunk(ch);
    buffers_.give(ch.rows, ch.encoded);
    ch.rows = std::vector<Row>();  // delivered: free
    seeds_.q[c] = Eigen::VectorXd();
    lock.lock();
    settle(d);
  }
}

// The schedule. `threads` loops run the work as it becomes ready: the seeding (in order, one thread at a time,
// first whenever fewer chunks are ready than threads, so that it stays ahead) and the seeded chunks (lowest
// first). A chunk starts as soon as its seed is known, not in waves, so no thread waits for a wave's slowest
// chunk. The calling thread alone delivers, in order, each chunk as soon as it and all before it are done: the
// caller's on_step (or RowWriter::write) runs on the caller's thread, as in a sequential sweep, overlapped with the
// other threads' chunks.
void ChunkedSweep::work_loop() {
  const bool is_caller = std::this_thread::get_id() == caller_;
  Schedule& s = sched_;
  std::unique_lock<std::mutex> lock(s.mutex);
  for (;;) {
    if (is_caller) deliver_ready(lock);
    if (s.stop) return;
    // chunks whose seed and end (the next seed, or the end of the seeding) are known, and not taken yet
    const Index ready = (s.seeding_over ? s.seeded : s.seeded - 1) - s.claimed;
    const bool can_seed =
        !s.seeding_busy && !s.seeding_over && s.seeded < std::min(n_chunks_, s.delivered + ahead_ + 1);
    if (can_seed && ready < threads_) {  // (with no chunk ready, always)
      s.seeding_busy = true;
      lock.unlock();
      tbb::this_task_arena::isolate([&] { seed_one(); });  // nested evaluations wait only for their own tasks
      lock.lock();
    } else if (ready > 0) {
      const Index c = s.claimed++;
      // the caller, with every chunk before this one delivered, delivers its rows as it computes them
      const bool stream = is_caller && c == s.delivered;
      lock.unlock();
      int d = kDelivered;
      tbb::this_task_arena::isolate([&] { d = run_chunk(c, chunks_[static_cast<std::size_t>(c)], stream); });
      lock.lock();
      s.chunk_done[static_cast<std::size_t>(c)] = 1;
      if (stream) {
        seeds_.q[static_cast<std::size_t>(c)] = Eigen::VectorXd();
        settle(d);
      }
      s.wake.notify_all();
    } else if (s.seeding_over && !s.seeding_busy && s.claimed == s.seeded && (!is_caller || s.delivered == s.claimed)) {
      return;  // nothing more will become ready (the caller: and everything done is delivered)
    } else {
      s.wake.wait(lock);  // for a seed, a finished chunk (the caller) or a delivery (the window)
    }
  }
}

void ChunkedSweep::run(WorkCounters& counted_end) {
  // An exception (the caller's on_step may throw) stops every loop, so that none waits for the thrower, and is
  // rethrown once they have all returned.
  auto work = [&] {
    try {
      work_loop();
    } catch (...) {
      std::lock_guard<std::mutex> lock(sched_.mutex);
      sched_.stop = true;
      if (!sched_.failure) sched_.failure = std::current_exception();
      sched_.wake.notify_all();
    }
  };
  tbb::parallel_for(
      tbb::blocked_range<int>(0, threads_, 1),
      [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k < r.end(); ++k) work();
      },
      tbb::simple_partitioner());
  if (sched_.failure) std::rethrow_exception(sched_.failure);
  // The work counted is the same for every thread count: that of the chunks whose rows were delivered (a rejected
  // chunk, or one the caller stopped, ran further when held than when streamed: not counted), and of the seeds
  // needed to run every chunk examined (its own and the next, which ends it; a seed that failed included). Chunks
  // and seeds computed further ahead are left out, as they would not have been computed on fewer threads.
  const Index seeds_counted = std::min(sched_.stop ? sched_.delivered + 1 : sched_.delivered, n_chunks_ - 1);
  for (Index c = 1; c <= seeds_counted; ++c)
    add_counters(others_, seeds_.work[static_cast<std::size_t>(c)], WorkCounters{});
  counted_end = ws_.counters;  // the caller's workspace's work so far is the chunks' and seeds'
  // The caller's workspace ends at the last delivered row, as after a sequential sweep.
  ws_.q = at_.q;
  if (need_v_) ws_.qd = at_.qd;
  if (need_a_) ws_.qdd = at_.qdd;
  if (!sched_.cancelled && at_.resume <= opt_.steps) finish_in_order();
}

// In order from the last delivered row: the unseeded chunks, or everything after a chunk that did not continue
// the sweep's branch or failed (the failure is then found, and reported, in order).
void ChunkedSweep::finish_in_order() {
  const double t = run_.time_of(at_.resume);
  if (sched_.fallback)
    run_.sum.warnings.push_back({t, "parallel_fallback",
                                 "the parallel chunk starting at t = " + format_time(t) +
                                     " did not continue the sweep in order: " + fallback_cause_ +
                                     "; the remaining steps ran in order"});
  ws_.start_afresh();  // as a chunk starts: from the row alone, whatever the workspace solved last
  Sweeper rest(model_, opt_, ws_, run_.sum, &row0_sweeper_);
  rest.adopt(run_.time_of(at_.resume - 1));
  run_.sequential(rest, ws_, at_.resume);
  rest.leave_state_in_workspace();
}

HeldRows held_rows(const Model& model, const SweepOptions& opt, bool caller_reads_rows, std::size_t encoded_row_bytes) {
  const Index n = model.num_coordinates();
  // Rows keep q̇ whenever it is solved (q̈ needs it, and so does an ordered continuation's predictor).
  const bool need_v = opt.solves_velocities(), need_a = opt.solves_accelerations();
  // a row's layout in the chunk buffers: q, q̇, q̈ as solved, then Φ, rcond, the point motions and the
  // sensitivities and efforts as asked
  const Index m = model.num_equations();
  const Index n_phi = opt.residuals ? m : 0, n_rcond = opt.condition ? 1 : 0;
  const Index n_points = static_cast<Index>(opt.points.size());
  constexpr Index kMotionDoubles = static_cast<Index>(sizeof(PointMotion) / sizeof(double));
  static_assert(sizeof(PointMotion) == 9 * sizeof(double), "PointMotion is stored as 9 doubles in chunk rows");
  const Index n_sensitivities = SensitivityLayout{n}.size(opt.sensitivities.size());
  const Index width = n * (1 + (need_v ? 1 : 0) + (need_a ? 1 : 0)) + n_phi + n_rcond + n_points * kMotionDoubles +
                      n_sensitivities + effort_values(opt.efforts, opt.sensitivities.size()) + 1;
  return {caller_reads_rows, 8.0 * static_cast<double>(std::max<Index>(width, 1)),
          static_cast<double>(encoded_row_bytes)};
}

void parallel_sweep(const Model& model, const SweepOptions& opt, Workspace& ws, Run& run, Sweeper& sw,
                    const HeldRows& layout, Index chunk, Index n_chunks, int threads, WorkCounters& others,
                    WorkCounters& counted_begin, WorkCounters& counted_end) {
  run.sum.threads = threads;
  ChunkedSweep(model, opt, ws, run, sw, layout, chunk, n_chunks, threads, others, counted_begin).run(counted_end);
}

}  // namespace phiq::detail

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
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "phiq/text.hpp"
#include "solve/factorisation.hpp"
#include "sweep/euler_signs.hpp"
#include "sweep/streamed_rows.hpp"

namespace phiq::detail {

namespace {

// Two solutions of the same position problem are the same one if they differ by less than `limit` tolerances in
// every coordinate (each is within about one of the exact root, or of its rounding level; another branch is a
// finite distance away).
bool same_solution(const Model& model, const Eigen::VectorXd& a, const double* b, double tol, double limit) {
  return detail::scaled_distance(model, a.data(), b, a.data(), tol) <= limit;
}

// Why a parallel chunk's first row q0 (null: it did not converge, `failure` saying why) is not where the sweep in
// order arrives, seam_q (null: unknown), beyond `limit` tolerances: the parallel_fallback warning's cause.
std::string rejection_cause(const Model& model, const std::string& failure, const Eigen::VectorXd* seam_q,
                            const double* q0, double tol, double limit) {
  if (!q0) return "its first row did not converge from its seed (" + failure + ")";
  if (!seam_q) return "the chunk before it did not reach the chunk's first time point (its seam step failed)";
  Eigen::VectorXd turned = Eigen::Map<const Eigen::VectorXd>(q0, seam_q->size());
  if (EulerSeedSigns(model).turn_like(seam_q->data(), turned) &&
      same_solution(model, *seam_q, turned.data(), tol, limit))
    return "its first row has the other sign of a body's Euler parameters (e and −e: one orientation) than the "
           "sweep in order";
  std::ostringstream m;
  m.precision(3);
  m << "its first row is another branch: " << detail::scaled_distance(model, seam_q->data(), q0, seam_q->data(), tol)
    << " tolerances from where the sweep in order arrives";
  return m.str();
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
  RowQuality quality;       // its class and estimated error (SweepSummary::accuracy)
  std::vector<PointMotion> points;
  std::vector<JointMotion> joints;              // every row's (the delivery unwraps the angles row by row)
  std::vector<OrientationMotion> orientations;  // with the vectors
  std::vector<double> sensitivities;            // with the vectors (SensitivityLayout)
  RowMotions motions() const {
    return {points.empty() ? nullptr : points.data(), joints.empty() ? nullptr : joints.data(),
            orientations.empty() ? nullptr : orientations.data(),
            sensitivities.empty() ? nullptr : sensitivities.data()};
  }
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
  double first_rounding = 0.0;  // that of its seed and first row (what the seam check allows for)
  Index good = 0;         // rows k0 … k0 + good − 1 converged (all of them when ok)
  State end;              // the last good row's state (streamed chunks, and held ones that failed after some)
};

}  // namespace

HeldRows held_rows(const Model& model, const SweepOptions& opt, bool caller_reads_rows) {
  const Index n = model.num_coordinates();
  // Rows keep q̇ whenever it is solved (q̈ needs it, and so does an ordered continuation's predictor).
  const bool need_v = opt.velocities || opt.accelerations, need_a = opt.accelerations;
  // a row's layout in the chunk buffers: q, q̇, q̈ as solved, then Φ, rcond, the point motions and the
  // sensitivities as asked
  const Index m = model.num_equations();
  const Index n_phi = opt.residuals ? m : 0, n_rcond = opt.condition ? 1 : 0;
  const Index n_points = static_cast<Index>(opt.points.size());
  constexpr Index kMotionDoubles = static_cast<Index>(sizeof(PointMotion) / sizeof(double));
  static_assert(sizeof(PointMotion) == 9 * sizeof(double), "PointMotion is stored as 9 doubles in chunk rows");
  const Index n_sensitivities = SensitivityLayout{n}.size(opt.sensitivities.size());
  const Index width = n * (1 + (need_v ? 1 : 0) + (need_a ? 1 : 0)) + n_phi + n_rcond + n_points * kMotionDoubles +
                      n_sensitivities + 1;
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
  // Chunk c's rows: first[c] … first[c + 1] − 1. A chunk starts at row 1 + c·chunk, or a few rows later where its
  // seed there is at or next to a singular position (seed_one): a chunk started there would start as a sweep
  // starting on a singular position does, from an assembly, with the branch and the derivatives less well known
  // (nfourbar through its flat positions: the row's q̇ extrapolated from one side, and the chunk rejected at its
  // seam), while the chunk before passes it in order, as a sequential sweep does. The seeds decide it, in order,
  // so the layout is the same on every thread count; a chunk is run once its end (the next seed) is known.
  std::vector<Index> first(static_cast<std::size_t>(n_chunks) + 1);
  for (Index c = 0; c < n_chunks; ++c) first[static_cast<std::size_t>(c)] = 1 + c * chunk;
  first[static_cast<std::size_t>(n_chunks)] = opt.steps + 1;
  auto first_row = [&](Index c) { return first[static_cast<std::size_t>(c)]; };
  auto last_row = [&](Index c) { return first[static_cast<std::size_t>(c) + 1] - 1; };
  const Index max_shift = chunk / 2;  // how far a chunk's start moves at most (its chunk then holds 1.5 chunks)

  // Workspaces, taken from a pool for the time of one chunk or one seed: the caller's own (idle otherwise) and as
  // many more as are in use at once, one per thread, since the seeding pass takes one only while it finds a seed.
  // On large models a workspace is mostly the LU of Φq (10⁶ scissor stages: 1.5 GB), so that is what the memory
  // of a parallel sweep grows by per thread. Not one per thread index: a thread waiting inside a nested parallel
  // evaluation (large models) may start other work meanwhile, which then needs a workspace of its own. The work
  // done in each is counted with the chunk or seed that did it; the caller's workspace's share is taken out of its
  // own count at the end (ws_in_parallel).
  //
  // A chunk or a seed computes the same bits whichever workspace it gets: nothing its last user left (a
  // factorisation, a measured contraction) is carried into it, and every workspace refactorises with one pivot
  // order, that of Φq at row 0, pinned in each the first time it is taken (pin_pivot_order_at). A pivot search per
  // chunk and per seed instead cost 7–17 % of a 2-thread sweep of nfourbar N = 10³ (bench/README.md, "What the
  // same bits on every thread count cost"). Where nothing can be pinned (Φq singular at row 0, factors over
  // kMaxPinnedBytes) each searches afresh — in every workspace alike, since that depends on row 0 alone.
  std::vector<std::unique_ptr<Workspace>> owned;
  std::vector<Workspace*> pool{&ws};
  std::vector<const Workspace*> pinned;  // workspaces that had their order pinned (or tried to)
  std::mutex pool_mutex;
  const Eigen::VectorXd pin_q = sw.state().q;
  const double pin_t = run.time_of(0);
  struct Unpin {  // the caller's workspace does not keep the sweep's pinned order (its next calls start afresh)
    Workspace& w;
    ~Unpin() {
      if (w.lu) w.lu->unpin_pivot_order();
    }
  } unpin{ws};
  auto acquire = [&] {
    Workspace* w = nullptr;
    bool pin = false;
    {
      std::lock_guard<std::mutex> lock(pool_mutex);
      if (pool.empty()) {
        owned.push_back(std::make_unique<Workspace>(model));
        w = owned.back().get();
      } else {
        w = pool.back();
        pool.pop_back();
      }
      pin = std::find(pinned.begin(), pinned.end(), w) == pinned.end();
      if (pin) pinned.push_back(w);
    }
    if (pin) pin_pivot_order_at(model, *w, pin_q, pin_t);  // (a factorisation: outside the lock)
    w->start_afresh();
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
  Sweeper& row0_sweeper = sw;  // (chunk 0 takes its branch tangent, if row 0 is a singular start)
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
  // Whether a chunk whose first row is at q0 continues the sweep in order: chunk 0 does by construction; another
  // must start where the sweep, continued in order from the last delivered row, arrives (the previous chunk's
  // seam). Two solutions of the same problem agree to 100 tolerances, or, where Newton stopped at the rounding level
  // (a long chain), to 10× how well that stop says q is known: another branch is a finite distance away.
  auto seam_limit = [&](const Chunk& ch) { return std::max(100.0, 10.0 * std::max(seam_rounding, ch.first_rounding)); };
  auto continues = [&](const Chunk& ch, const double* q0) {
    return ch.k0 == 1 || (seam_known && same_solution(model, seam_q, q0, opt.newton.tolerance, seam_limit(ch)));
  };
  // Why a chunk whose first row is q0 (null: it has none) does not continue the sweep, for the parallel_fallback
  // warning (set by the caller's thread, which alone delivers).
  std::string fallback_cause;
  auto not_continued = [&](const Chunk& ch, const double* q0) {
    fallback_cause = rejection_cause(model, ch.sum.message, seam_known ? &seam_q : nullptr, q0, opt.newton.tolerance,
                                     seam_limit(ch));
  };
  // A chunk delivered (its first `good` rows): the state an ordered continuation starts from, its seam, and its
  // summary, up to its last good row. Returns 0 when every row was good, 3 when it failed after them (the rest
  // then runs in order from its last good row, where the failure is found and reported as a sequential sweep's).
  auto finish = [&](Chunk& ch, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) {
    last_q.swap(q);
    if (need_v) last_qd.swap(qd);
    if (need_a) last_qdd.swap(qdd);
    resume = ch.k0 + ch.good;
    seam_known = ch.ok && ch.has_seam;
    if (seam_known) seam_q.swap(ch.seam_q), seam_rounding = ch.rounding;
    sum.subdivisions += ch.sum.subdivisions;
    sum.singular_positions += ch.sum.singular_positions;
    sum.warnings.insert(sum.warnings.end(), ch.sum.warnings.begin(), ch.sum.warnings.end());
    if (ch.sum.min_rcond > 0.0 && (sum.min_rcond == 0.0 || ch.sum.min_rcond < sum.min_rcond))
      sum.min_rcond = ch.sum.min_rcond, sum.min_rcond_time = ch.sum.min_rcond_time;
    ++sum.parallel_chunks;
    return ch.ok ? 0 : 3;
  };

  // Chunk c: its rows from its seed (chunk 0: in order from row 0), then the seam step. `stream`: the caller's
  // thread runs the chunk next to be delivered, and delivers each row as it is computed instead of holding it
  // (one thread always does): the same rows, the same checks, no buffers. Returns, when streaming, what
  // deliver_chunk returns.
  auto run_chunk = [&](Index c, Chunk& ch, bool stream) {
    Workspace* held = acquire();
    Workspace& w = *held;
    const WorkCounters w0 = w.counters;
    ch.k0 = first_row(c), ch.k1 = last_row(c);
    Sweeper s(model, opt, w, ch.sum);
    if (!stream) {
      ch.rows.resize(static_cast<std::size_t>(ch.k1 - ch.k0 + 1));
      take_buffers(ch.rows);
    }
    int outcome = 0;
    // The summary up to the last good row: what is delivered of it (sub-steps, warnings and the condition of a
    // failed step or of the seam step belong to the sweep that runs them next).
    SweepSummary good_sum;
    auto keep = [&] {  // false: stop the chunk (streaming: rejected or stopped by the caller)
      const State& st = s.state();
      const Index k = ch.k0 + ch.good;
      s.row_outputs(k);
      if (ch.good == 0) ch.first_rounding = std::max(s.take_rounding_level(), ch.first_rounding);
      good_sum.warnings = ch.sum.warnings, good_sum.subdivisions = ch.sum.subdivisions;
      good_sum.singular_positions = ch.sum.singular_positions;
      good_sum.min_rcond = ch.sum.min_rcond, good_sum.min_rcond_time = ch.sum.min_rcond_time;
      if (stream) {
        if (ch.good == 0 && !continues(ch, st.q.data())) return not_continued(ch, st.q.data()), outcome = 1, false;
        ++ch.good;
        if (!run.deliver(k, st.q, st.qd, st.qdd, s.motions(), w.phi, s.rcond(), s.det_sign(),
                         s.det_sign_time(), s.row_quality())) {
          last_q = st.q, last_qd = need_v ? st.qd : last_qd, last_qdd = need_a ? st.qdd : last_qdd;
          return outcome = 2, false;
        }
        return true;
      }
      Row& r = ch.rows[static_cast<std::size_t>(ch.good)];
      r.det_sign = s.det_sign(), r.det_sign_t = s.det_sign_time();  // (the bifurcation check reads every row's)
      r.quality = s.row_quality();  // (and the summary's accuracy)
      const RowMotions rm = s.motions();
      if (rm.joints) r.joints.assign(rm.joints, rm.joints + opt.joints.size());
      if (layout.keeps_vectors(ch.rows.size(), static_cast<std::size_t>(ch.good++))) {
        stream_copy(st.q, r.q);
        if (need_v) stream_copy(st.qd, r.qd);
        if (need_a) stream_copy(st.qdd, r.qdd);
        if (n_phi) r.phi = w.phi;
        r.rcond = s.rcond();
        if (n_points) r.points.assign(s.point_motions(), s.point_motions() + n_points);
        if (rm.orientations) r.orientations.assign(rm.orientations, rm.orientations + opt.orientations.size());
        if (rm.sensitivities)
          r.sensitivities.assign(rm.sensitivities,
                                 rm.sensitivities + SensitivityLayout{model.num_coordinates()}.size(opt.sensitivities.size()));
      }
      return true;
    };
    if (c > 0) ch.first_rounding = seed_rounding[static_cast<std::size_t>(c)];
    if (c == 0) {  // continues row 0 in order: the sequential sweep itself
      w.q = last_q, w.qd = last_qd, w.qdd = last_qdd;
      s.adopt(run.time_of(0));
      s.take_branch_tangent(row0_sweeper);
      ch.ok = s.advance(run.time_of(ch.k0), 0);
    } else {
      ch.ok = s.start_from(run.time_of(ch.k0), seeds[static_cast<std::size_t>(c)],
                           seed_error[static_cast<std::size_t>(c)]);
    }
    bool going = ch.ok && keep();
    for (Index k = ch.k0 + 1; going && k <= ch.k1; ++k) going = (ch.ok = s.advance(run.time_of(k), 0)) && keep();
    // The last good row's state, where an ordered continuation starts (before the seam step moves the stepper on):
    // a streamed chunk holds no rows, and a held one that failed kept only its ends' vectors.
    if ((stream || !ch.ok) && ch.good > 0) ch.end = s.state();
    if (going && ch.k1 < opt.steps && s.advance_position(run.time_of(ch.k1 + 1))) {
      ch.has_seam = true;  // the seam row belongs to the next chunk
      ch.seam_q = s.state().q;
    }
    ch.rounding = std::max(s.take_rounding_level(), ch.first_rounding);
    ch.sum.warnings.swap(good_sum.warnings);
    ch.sum.subdivisions = good_sum.subdivisions, ch.sum.singular_positions = good_sum.singular_positions;
    ch.sum.min_rcond = good_sum.min_rcond, ch.sum.min_rcond_time = good_sum.min_rcond_time;
    add_counters(ch.sum.counters, w.counters, w0);
    if (stream && outcome == 0) {
      if (ch.good == 0) {
        outcome = 1;  // no first row: rejected, the rest runs in order
        not_continued(ch, nullptr);
      } else {
        add_counters(others, ch.sum.counters, WorkCounters{});
        outcome = finish(ch, ch.end.q, ch.end.qd, ch.end.qdd);
      }
    }
    release(held);
    if (!stream) stream_fence();  // the chunk's streamed rows are complete before it is marked done for the caller
    return outcome;
  };

  // Accepts and delivers a chunk computed ahead: 0 delivered, 1 rejected (the rest runs in order), 2 stopped by the
  // caller, 3 failed after its first rows, which are delivered (the rest runs in order from there).
  auto deliver_chunk = [&](Chunk& ch) {
    if (ch.good == 0 || !continues(ch, ch.rows[0].q.data()))
      return not_continued(ch, ch.good == 0 ? nullptr : ch.rows[0].q.data()), 1;
    for (Index k = ch.k0; k < ch.k0 + ch.good; ++k) {
      const Row& r = ch.rows[static_cast<std::size_t>(k - ch.k0)];
      if (!run.deliver(k, r.q, r.qd, r.qdd, r.motions(), r.phi, r.rcond, r.det_sign,
                       r.det_sign_t, r.quality)) {
        last_q = r.q, last_qd = need_v ? r.qd : last_qd, last_qdd = need_a ? r.qdd : last_qdd;  // where it stopped
        return 2;
      }
    }
    add_counters(others, ch.sum.counters, WorkCounters{});
    // the state an ordered continuation starts from: the chunk's last good row (freed once delivered)
    if (!ch.ok) return finish(ch, ch.end.q, ch.end.qd, ch.end.qdd);
    Row& last = ch.rows.back();
    return finish(ch, last.q, last.qd, last.qdd);
  };

  // How far the work may run ahead of the delivery: chunks seeded beyond the next one to deliver. As many as the
  // row buffer allows, at least one per thread, and at most 16 per thread so that rows are delivered (and Ctrl-C
  // seen) every few thousand steps however long the sweep.
  const Index ahead = std::max<Index>(
      threads,
      std::min<Index>(16 * threads,
                      static_cast<Index>(static_cast<double>(opt.row_buffer_bytes) /
                                         layout.held_bytes(chunk + max_shift))));

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
  // Done in pool workspaces by the seeding pass, per seed: the summary counts the seeds the result needed, not the
  // ones found ahead of a rejected chunk (how far ahead depends on the threads: the counts must not).
  std::vector<WorkCounters> seed_work(static_cast<std::size_t>(n_chunks));
  Workspace* sws = acquire();
  sws->q = last_q;
  Sweeper seeder(model, seed_options, *sws, seed_summary);
  seeder.adopt(run.time_of(0));
  release(sws);
  EulerSeedSigns euler_signs(model);  // each seed on the sign of Euler parameters the sweep in order continues with
  euler_signs.start(run.time_of(0), last_q, need_v ? last_qd : Eigen::VectorXd());

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
    Index row = first_row(c);
    const double t0 = seeder.state().t, t1 = run.time_of(row);
    bool ok = true;
    for (int i = 1; ok && i <= parts; ++i)
      ok = seeder.advance(i == parts ? t1 : t0 + (t1 - t0) * static_cast<double>(i) / parts, 0);
    // at or next to a singular position (Φq near-singular at the seed): the chunk starts a row later
    for (const Index last = std::min(row + max_shift, opt.steps); ok && row < last && seeder.near_singular();)
      ok = seeder.advance(run.time_of(++row), 0);
    add_counters(seed_work[static_cast<std::size_t>(c)], w->counters, w0);
    release(w);
    if (ok) {
      first[static_cast<std::size_t>(c)] = row;  // (chunk c − 1, which ends here, is not claimed before: ready)
      seeds[static_cast<std::size_t>(c)] = seeder.state().q;
      seed_error[static_cast<std::size_t>(c)] = seeder.state_error();
      // (a seed turned to −e is checked by a Newton step, as an unknown one is)
      if (euler_signs.align(run.time_of(row), seeds[static_cast<std::size_t>(c)]))
        seed_error[static_cast<std::size_t>(c)] = INFINITY;
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
  // What a chunk's delivery says for the schedule (the lock is held): delivered, or the parallel part stops.
  auto settle = [&](int d) {
    if (d != 0) {
      stop = true, cancelled = d == 2, fallback = d == 1;
    } else {
      ++delivered;
    }
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
      settle(d);
    }
  };
  auto work_loop = [&] {
    const bool is_caller = std::this_thread::get_id() == caller;
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      if (is_caller) deliver_ready(lock);
      if (stop) return;
      // chunks whose seed and end (the next seed, or the end of the seeding) are known, and not taken yet
      const Index ready = (seeding_over ? seeded : seeded - 1) - claimed;
      const bool can_seed = !seeding_busy && !seeding_over && seeded < std::min(n_chunks, delivered + ahead + 1);
      if (can_seed && ready < threads) {  // (with no chunk ready, always)
        seeding_busy = true;
        lock.unlock();
        tbb::this_task_arena::isolate(seed_one);  // nested evaluations wait only for their own tasks
        lock.lock();
      } else if (ready > 0) {
        const Index c = claimed++;
        // the caller, with every chunk before this one delivered, delivers its rows as it computes them
        const bool stream = is_caller && c == delivered;
        lock.unlock();
        int d = 0;
        tbb::this_task_arena::isolate([&] { d = run_chunk(c, chunks[static_cast<std::size_t>(c)], stream); });
        lock.lock();
        chunk_done[static_cast<std::size_t>(c)] = 1;
        if (stream) {
          seeds[static_cast<std::size_t>(c)] = Eigen::VectorXd();
          settle(d);
        }
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
  // The work counted is the same for every thread count: that of the chunks whose rows were delivered (a rejected
  // chunk, or one the caller stopped, ran further when held than when streamed: not counted), and of the seeds
  // needed to run every chunk examined (its own and the next, which ends it; a seed that failed included). Chunks
  // and seeds computed further ahead are left out, as they would not have been computed on fewer threads.
  const Index seeds_counted = std::min(stop ? delivered + 1 : delivered, n_chunks - 1);
  for (Index c = 1; c <= seeds_counted; ++c) add_counters(others, seed_work[static_cast<std::size_t>(c)], WorkCounters{});
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
                                  " did not continue the sweep in order: " + fallback_cause +
                                  "; the remaining steps ran in order"});
    ws.start_afresh();  // as a chunk starts: from the row alone, whatever the workspace solved last
    Sweeper rest(model, opt, ws, sum);
    rest.adopt(run.time_of(resume - 1));
    run.sequential(rest, ws, resume);
    rest.leave_state_in_workspace();
  }
}

}  // namespace phiq::detail

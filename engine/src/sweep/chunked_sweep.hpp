// A parallel sweep (parallel_sweep.hpp) and its parts: a row a chunk holds until it is delivered, the chunk itself,
// the pool of workspaces the chunks and seeds solve in, the buffers their rows are recycled through, the seeds, the
// delivery's state and the schedule the threads share. The chunks are computed and delivered in
// parallel_sweep.cpp, seeded and scheduled in chunk_schedule.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "solve/factorisation.hpp"
#include "sweep/euler_signs.hpp"
#include "sweep/parallel_sweep.hpp"

namespace phiq::detail {

// A row computed by a parallel chunk, held until it is delivered in order. Its vectors are delivered as they are
// (no copy into the caller's state per row: on a model whose steps are cheap, copying rows in and out cost a fifth
// of a chunk's time).
struct Row {
  // q̇, q̈ as solved, Φ when asked (only what is read again: HeldRows::keeps_vectors)
  Eigen::VectorXd q, qd, qdd, phi;
  double rcond = 0.0;
  Orientation det_sign{0, 0};
  double det_sign_t = 0.0;  // where det_sign holds (Sweeper::det_sign_time())
  RowQuality quality;       // its class and estimated error (SweepSummary::accuracy)
  std::vector<PointMotion> points;
  std::vector<JointMotion> joints;              // every row's (the delivery unwraps the angles row by row)
  std::vector<OrientationMotion> orientations;  // with the vectors
  std::vector<double> sensitivities;            // with the vectors (SensitivityLayout)
  std::vector<double> efforts;                  // with the vectors (effort_values())
  RowMotions motions() const {
    return {points.empty() ? nullptr : points.data(), joints.empty() ? nullptr : joints.data(),
            orientations.empty() ? nullptr : orientations.data(),
            sensitivities.empty() ? nullptr : sensitivities.data(), efforts.empty() ? nullptr : efforts.data()};
  }
};

// One parallel chunk: rows k0 … k1 computed from a seed at t_k0 (chunk 0: from row 0), then the sweep continued
// in order one step further (the seam), which the next chunk's first row must match.
struct Chunk {
  Index k0 = 0, k1 = 0;
  std::vector<Row> rows;  // rows k0 … k1
  // The written rows among them, encoded by the thread that computed them (Run::chunks_encode()): their count and
  // the last one's time point
  std::string encoded;
  Index encoded_rows = 0, last_encoded = -1;
  SweepSummary sum;  // status, message, warnings, subdivisions, rcond and work of this chunk
  bool ok = false;
  bool has_seam = false;
  Eigen::VectorXd seam_q;       // the position at t_{k1+1} reached by continuing in order
  double rounding = 0.0;        // largest rounding level (Sweeper::take_rounding_level) of its solves, seed included
  double first_rounding = 0.0;  // that of its seed and first row (what the seam check allows for)
  Index good = 0;               // rows k0 … k0 + good − 1 converged (all of them when ok)
  State end;                    // the last good row's state (streamed chunks, and held ones that failed after some)
};

// Workspaces, taken from a pool for the time of one chunk or one seed: the caller's own (idle otherwise) and as
// many more as are in use at once, one per thread, since the seeding pass takes one only while it finds a seed.
// On large models a workspace is mostly the LU of Φq (10⁶ scissor stages: 1.5 GB), so that is what the memory
// of a parallel sweep grows by per thread. Not one per thread index: a thread waiting inside a nested parallel
// evaluation (large models) may start other work meanwhile, which then needs a workspace of its own.
//
// A chunk or a seed computes the same bits whichever workspace it gets: nothing its last user left (a
// factorisation, a measured contraction) is carried into it, and every workspace refactorises with one pivot
// order, that of Φq at row 0, pinned in each the first time it is taken (pin_pivot_order_at). A pivot search per
// chunk and per seed instead cost 7–17 % of a 2-thread sweep of nfourbar N = 10³ (bench/README.md, "What the
// same bits on every thread count cost"). Where nothing can be pinned (Φq singular at row 0, factors over
// kMaxPinnedBytes) each searches afresh — in every workspace alike, since that depends on row 0 alone.
class WorkspacePool {
 public:
  // `caller`: the caller's workspace; the pivot order pinned is that of Φq at row 0 (q0, t0).
  WorkspacePool(const Model& model, Workspace& caller, const Eigen::VectorXd& q0, double t0)
      : model_(model), caller_(caller), pool_{&caller}, pin_q_(q0), pin_t_(t0) {}
  // The caller's workspace does not keep the sweep's pinned order (its next calls start afresh).
  ~WorkspacePool() {
    if (caller_.lu) caller_.lu->unpin_pivot_order();
  }
  WorkspacePool(const WorkspacePool&) = delete;
  WorkspacePool& operator=(const WorkspacePool&) = delete;

  Workspace* acquire() {
    Workspace* w = nullptr;
    bool pin = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pool_.empty()) {
        owned_.push_back(std::make_unique<Workspace>(model_));
        w = owned_.back().get();
      } else {
        w = pool_.back();
        pool_.pop_back();
      }
      pin = std::find(pinned_.begin(), pinned_.end(), w) == pinned_.end();
      if (pin) pinned_.push_back(w);
    }
    if (pin) pin_pivot_order_at(model_, *w, pin_q_, pin_t_);  // (a factorisation: outside the lock)
    w->start_afresh();
    return w;
  }
  void release(Workspace* w) {
    std::lock_guard<std::mutex> lock(mutex_);
    pool_.push_back(w);
  }

 private:
  const Model& model_;
  Workspace& caller_;
  std::vector<std::unique_ptr<Workspace>> owned_;
  std::vector<Workspace*> pool_;
  std::vector<const Workspace*> pinned_;  // workspaces that had their order pinned (or tried to)
  std::mutex mutex_;
  const Eigen::VectorXd pin_q_;
  const double pin_t_;
};

// Buffers for the rows' q, q̇, q̈ and for the chunks' encoded rows: those of delivered chunks, and those the
// workspace kept from its last parallel sweep (Workspace::spare_rows), so that the rows are written into memory
// the process has already touched.
class RowBuffers {
 public:
  RowBuffers(Workspace& ws, const HeldRows& layout, bool need_v, bool need_a)
      : ws_(ws), layout_(layout), n_(ws.model().num_coordinates()), need_v_(need_v), need_a_(need_a) {
    spare_.swap(ws.spare_rows);
    std::erase_if(spare_, [&](const Eigen::VectorXd& v) { return v.size() != n_; });
  }
  // The row buffers go back to the workspace for its next parallel sweep, up to Workspace::kSpareRowBytes.
  ~RowBuffers() {
    const auto keep = static_cast<std::size_t>(Workspace::kSpareRowBytes / (8.0 * std::max<Index>(n_, 1)));
    if (spare_.size() > keep) spare_.resize(keep);
    ws_.spare_rows.swap(spare_);
  }
  RowBuffers(const RowBuffers&) = delete;
  RowBuffers& operator=(const RowBuffers&) = delete;

  // Sizes the vectors of `rows` that keep them (HeldRows::keeps_vectors); `text`: the chunk's encoded rows.
  void take(std::vector<Row>& rows, std::string& text, std::size_t text_bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (Eigen::VectorXd* v : {&rows[i].q, need_v_ ? &rows[i].qd : nullptr, need_a_ ? &rows[i].qdd : nullptr}) {
        if (!v || !layout_.keeps_vectors(rows.size(), i)) continue;
        if (spare_.empty()) {
          v->resize(n_);
        } else {
          v->swap(spare_.back());
          spare_.pop_back();
        }
      }
    if (text_bytes == 0) return;
    if (!spare_text_.empty()) text.swap(spare_text_.back()), spare_text_.pop_back();
    text.reserve(text_bytes);
  }
  void give(std::vector<Row>& rows, std::string& text) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (Row& r : rows)
      for (Eigen::VectorXd* v : {&r.q, &r.qd, &r.qdd})
        if (v->size() == n_) spare_.push_back(std::move(*v));
    if (text.capacity() > 0) {
      text.clear();
      spare_text_.push_back(std::move(text));
      text = std::string();
    }
  }

 private:
  Workspace& ws_;
  const HeldRows& layout_;
  const Index n_;
  const bool need_v_, need_a_;
  std::mutex mutex_;
  std::vector<Eigen::VectorXd> spare_;
  std::vector<std::string> spare_text_;  // as many as chunks were held at once: the window bounds them
};

// Sub-steps of a positions-only sweep's first seed (see seed_one).
constexpr int kFirstSeedParts = 4;

// What a chunk's delivery, or a streamed chunk, says for the schedule.
enum ChunkOutcome { kDelivered = 0, kRejected = 1, kStopped = 2, kFailedAfterSome = 3 };

// The seeds: the position at each chunk's first row (not chunk 0's), found in order by one seeding pass.
struct Seeds {
  explicit Seeds(Index n_chunks)
      : q(static_cast<std::size_t>(n_chunks)),
        rounding(static_cast<std::size_t>(n_chunks), 0.0),
        error(static_cast<std::size_t>(n_chunks), INFINITY),
        work(static_cast<std::size_t>(n_chunks)) {}
  std::vector<Eigen::VectorXd> q;
  std::vector<double> rounding;  // the seeder's rounding level there
  std::vector<double> error;     // and its error estimate
  // Done in pool workspaces by the seeding pass, per seed: the summary counts the seeds the result needed, not the
  // ones found ahead of a rejected chunk (how far ahead depends on the threads: the counts must not).
  std::vector<WorkCounters> work;
};

// The last delivered row (the state an ordered continuation starts from) and the position the sweep reaches one
// step after it when continued in order (the previous chunk's seam), if known.
struct Delivery {
  Index resume = 1;
  Eigen::VectorXd q, qd, qdd;
  bool seam_known = false;
  Eigen::VectorXd seam_q;
  double seam_rounding = 0.0;
};

// What the threads share, under `mutex`.
struct Schedule {
  std::mutex mutex;
  std::condition_variable wake;
  std::vector<char> chunk_done;
  Index seeded = 1;           // chunks 0 … seeded − 1 have their seed (chunk 0 starts from row 0)
  Index claimed = 0;          // chunks 0 … claimed − 1 have been taken by a thread
  Index delivered = 0;        // chunks 0 … delivered − 1 have been delivered
  bool seeding_busy = false;  // a thread is finding a seed
  bool seeding_over = false;  // every seed found, or the seeding failed
  bool stop = false;          // a chunk was rejected (fallback) or the caller stopped the sweep
  bool cancelled = false;
  bool fallback = false;
  std::exception_ptr failure;  // the first exception of any thread (the caller's on_step may throw)
};

// One parallel sweep: parallel_sweep()'s arguments, and the parts above.
class ChunkedSweep {
 public:
  ChunkedSweep(const Model& model, const SweepOptions& opt, Workspace& ws, Run& run, Sweeper& sw,
               const HeldRows& layout, Index chunk, Index n_chunks, int threads, WorkCounters& others,
               WorkCounters& counted_begin);
  // The schedule on `threads` threads; then the counts, the caller's workspace at the last delivered row, and the
  // steps no chunk delivered, in order (parallel_sweep()).
  void run(WorkCounters& counted_end);

 private:
  Index first_row(Index c) const { return first_[static_cast<std::size_t>(c)]; }
  Index last_row(Index c) const { return first_[static_cast<std::size_t>(c) + 1] - 1; }
  double seam_limit(const Chunk& ch) const;
  bool continues(const Chunk& ch, const double* q0) const;
  void not_continued(const Chunk& ch, const double* q0);
  int accept(Chunk& ch, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd);
  void stopped_at(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd);
  struct ChunkRun;
  bool keep_row(ChunkRun& cr);
  void hold_row(ChunkRun& cr);
  int run_chunk(Index c, Chunk& ch, bool stream);
  int deliver_chunk(Chunk& ch);
  void seed_one();
  void settle(int d);
  void deliver_ready(std::unique_lock<std::mutex>& lock);
  void work_loop();
  void finish_in_order();

  const Model& model_;
  const SweepOptions& opt_;
  Workspace& ws_;
  Run& run_;
  Sweeper& row0_sweeper_;  // (chunk 0 takes its branch tangent, if row 0 is a singular start)
  const HeldRows& layout_;
  const Index n_chunks_;
  const int threads_;
  WorkCounters& others_;
  // Rows keep q̇ whenever it is solved (q̈ needs it, and so does an ordered continuation's predictor).
  const bool need_v_, need_a_;
  const bool encode_;  // the chunks encode their rows (Run::chunks_encode())
  // Chunk c's rows: first_[c] … first_[c + 1] − 1. A chunk starts at row 1 + c·chunk, or a few rows later where
  // its seed there is at or next to a singular position (seed_one): a chunk started there would start as a sweep
  // starting on a singular position does, from an assembly, with the branch and the derivatives less well known
  // (nfourbar through its flat positions: the row's q̇ extrapolated from one side, and the chunk rejected at its
  // seam), while the chunk before passes it in order, as a sequential sweep does. The seeds decide it, in order,
  // so the layout is the same on every thread count; a chunk is run once its end (the next seed) is known.
  std::vector<Index> first_;
  const Index max_shift_;  // how far a chunk's start moves at most (its chunk then holds 1.5 chunks)
  WorkspacePool pool_;
  RowBuffers buffers_;
  Delivery at_;
  Seeds seeds_;
  SweepOptions seed_options_;  // positions only, parabolic, no outputs
  SweepSummary seed_summary_;
  std::unique_ptr<Sweeper> seeder_;
  EulerSeedSigns euler_signs_;  // each seed on the sign of Euler parameters the sweep in order continues with
  // Why the chunk that ended the parallel part did not continue the sweep (not_continued(): the caller's thread,
  // which alone delivers), for the parallel_fallback warning.
  std::string fallback_cause_;
  Index ahead_ = 0;  // chunks seeded beyond the next one to deliver, at most
  std::vector<Chunk> chunks_;
  Schedule sched_;
  const std::thread::id caller_ = std::this_thread::get_id();
};

}  // namespace phiq::detail

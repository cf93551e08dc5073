// run_sweep in parallel chunks (parallel drive steps): the rows, failures, warnings and work of the sequential
// sweep whatever the threads and chunks, the row buffers held and recycled, delivery on the calling thread, and
// how many threads the memory allows. Separate from test_sweep.cpp, which tests the sweep in order.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <thread>

#include <tbb/info.h>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// The same sweep in order and on `threads` threads in chunks of `chunk` steps.
struct InOrderAndParallel {
  test::Trace seq, par;
  SweepSummary ss, ps;
  SolveStatus seq_status, par_status;
};
// In order: one chunk (the chunks of a default sweep are cut alike on every thread count, one thread included).
SweepOptions in_order(SweepOptions opt) {
  opt.threads = 1;
  opt.chunk_steps = std::max<Index>(opt.steps, 1);
  return opt;
}
InOrderAndParallel sweep_both(const Model& m, SweepOptions opt, int threads, Index chunk) {
  InOrderAndParallel r;
  r.seq_status = test::sweep(m, in_order(opt), &r.seq, &r.ss);
  opt.threads = threads;
  opt.chunk_steps = chunk;
  r.par_status = test::sweep(m, opt, &r.par, &r.ps);
  return r;
}

// A sweep in chunks delivers the same rows as the sweep in order, to the solver tolerance, whatever the chunk size;
// every chunk is accepted on this regular motion. For a given chunk size the rows are the same bits on any thread
// count (test_sweep_determinism.cpp).
TEST(ParallelSweep, EqualsTheSequentialSweepForAnyThreadCount) {
  Model m = test::nfourbar_model(40, M_PI / 4, M_PI / 2);  // a quarter turn, away from singular positions
  SweepOptions opt;
  opt.steps = 300;
  test::Trace seq;
  SweepSummary ss;
  ASSERT_EQ(test::sweep(m, in_order(opt), &seq, &ss), SolveStatus::kSuccess) << ss.message;
  EXPECT_EQ(ss.threads, 1);
  EXPECT_EQ(ss.parallel_chunks, 0);
  for (int threads : {1, 2, 3, 4}) {
    for (Index chunk : {Index{1}, Index{7}, Index{64}}) {
      opt.threads = threads;
      opt.chunk_steps = chunk;
      test::Trace par;
      SweepSummary ps;
      ASSERT_EQ(test::sweep(m, opt, &par, &ps), SolveStatus::kSuccess) << ps.message;
      EXPECT_EQ(ps.threads, threads);
      EXPECT_EQ(ps.parallel_chunks, (opt.steps + chunk - 1) / chunk) << threads << " threads, chunks of " << chunk;
      EXPECT_EQ(ps.steps_completed, opt.steps + 1);
      // positions to 1e-10 × scale each; velocities and accelerations inherit it (|q̇| ~ 1.6, |q̈| ~ 2.5)
      EXPECT_LT(test::max_difference(seq, par, 0), 1e-9) << threads << " threads, chunks of " << chunk;
      EXPECT_LT(test::max_difference(seq, par, 1), 1e-8) << threads << " threads, chunks of " << chunk;
      EXPECT_LT(test::max_difference(seq, par, 2), 1e-8) << threads << " threads, chunks of " << chunk;
      EXPECT_TRUE(ps.warnings.empty());
      EXPECT_EQ(ps.counters.velocity_solves, ss.counters.velocity_solves)
          << "each chunk but the last solves one step more, the seam its successor's first row is checked against, "
             "for its position only; seeds are positions only";
    }
  }
}

// A parallel sweep writes its held rows into recycled buffers and leaves them in the workspace for the next one
// (Workspace::spare_rows): a second sweep with the same workspace, reusing them, still delivers the sequential
// sweep's rows; buffers of another size left there are dropped, not used.
TEST(ParallelSweep, RowBuffersAreRecycledAndKeptInTheWorkspace) {
  Model m = test::nfourbar_model(40, M_PI / 4, M_PI / 2);
  const Index n = m.num_coordinates();
  SweepOptions opt;
  opt.steps = 200;
  test::Trace seq;
  ASSERT_EQ(test::sweep(m, opt, &seq), SolveStatus::kSuccess);
  opt.threads = 2;
  opt.chunk_steps = 16;
  Workspace ws(m);
  ws.spare_rows.emplace_back(Eigen::VectorXd::Constant(3, 7.0));  // not a row of this model
  test::Trace first;
  for (int run = 0; run < 2; ++run) {
    ws.q = m.initial_positions();
    test::Trace par;
    SweepSummary ps;
    ASSERT_EQ(test::sweep(m, opt, &par, &ps, &ws), SolveStatus::kSuccess) << ps.message;
    EXPECT_EQ(ps.parallel_chunks, 13) << "run " << run;
    EXPECT_LT(test::max_difference(seq, par, 0), 1e-9) << "run " << run;
    EXPECT_LT(test::max_difference(seq, par, 1), 1e-8) << "run " << run;
    EXPECT_LT(test::max_difference(seq, par, 2), 1e-8) << "run " << run;
    // every held row's q, q̇, q̈ went back to the pool (how many were held depends on which thread ran which chunk:
    // the caller streams the chunk next to deliver), never more than the bound, all of the model's size; the
    // recycled buffers change no bit of the rows
    if (run == 0) first = par;
    EXPECT_EQ(test::max_difference(first, par, 0), 0.0) << "run " << run;
    EXPECT_EQ(test::max_difference(first, par, 2), 0.0) << "run " << run;
    EXPECT_LE(static_cast<double>(ws.spare_rows.size()) * 8.0 * static_cast<double>(n), Workspace::kSpareRowBytes);
    for (const Eigen::VectorXd& v : ws.spare_rows) ASSERT_EQ(v.size(), n) << "run " << run;
  }
}

// Through singular positions (a full turn of the N four-bar: the cranks are horizontal twice, where the dof jumps),
// the result must still be the sequential sweep's, however the seeds behave there.
TEST(ParallelSweep, ThroughSingularPositionsMatchesTheSequentialSweep) {
  Model m = test::nfourbar_model(10, 0.1, 2 * M_PI);
  SweepOptions opt;
  opt.steps = 400;
  const InOrderAndParallel r = sweep_both(m, opt, 2, 25);
  const test::Trace &seq = r.seq, &par = r.par;
  const SweepSummary& ps = r.ps;
  ASSERT_EQ(r.seq_status, SolveStatus::kSuccess) << r.ss.message;
  ASSERT_EQ(r.par_status, SolveStatus::kSuccess) << ps.message;
  EXPECT_GT(ps.parallel_chunks, 0);
  EXPECT_LT(test::max_difference(seq, par, 0), 1e-8);
  // near the singular positions Φq is ill-conditioned (rcond ~1e-5 a step away), which amplifies the 1e-10
  // differences of q into q̇ and q̈
  EXPECT_LT(test::max_difference(seq, par, 1), 1e-5);
  EXPECT_LT(test::max_difference(seq, par, 2), 1e-3);
  // and both stay on the parallelogram branch
  for (std::size_t k = 0; k < par.t.size(); ++k) {
    const double th = par.q[k](22);
    for (Index i = 0; i <= 10; ++i) EXPECT_NEAR(par.q[k](2 * i + 1), std::sin(th), 1e-8) << "row " << k;
  }
}

// A parallel sweep that nobody reads row by row (no callback: a sweep for its summary and its last state) keeps
// only the rows it reads again itself, each chunk's first and last, and still reports what a read sweep reports:
// the same warnings at the same times (they come from every row's sign of det Φq, through singular positions
// here), the same solves, and the sequential sweep's last state in the workspace.
TEST(ParallelSweep, WithoutACallbackOnlyEachChunksFirstAndLastRowsAreKept) {
  Model m = test::nfourbar_model(10, 0.1, 2 * M_PI);
  SweepOptions opt;
  opt.steps = 400;
  const InOrderAndParallel r = sweep_both(m, opt, 2, 50);
  ASSERT_EQ(r.par_status, SolveStatus::kSuccess) << r.ps.message;
  ASSERT_FALSE(r.ps.warnings.empty()) << "the full turn passes singular positions";
  opt.threads = 2;
  opt.chunk_steps = 50;
  Workspace ws(m);
  SweepSummary sum;
  ASSERT_EQ(run_sweep(m, opt, ws, nullptr, &sum), SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(sum.parallel_chunks, 8);
  EXPECT_EQ(sum.steps_completed, opt.steps + 1);
  ASSERT_EQ(sum.warnings.size(), r.ps.warnings.size());
  for (std::size_t i = 0; i < sum.warnings.size(); ++i) {
    EXPECT_EQ(sum.warnings[i].kind, r.ps.warnings[i].kind) << i;
    EXPECT_EQ(sum.warnings[i].t, r.ps.warnings[i].t) << i;
  }
  EXPECT_EQ(sum.counters.velocity_solves, r.ps.counters.velocity_solves);
  EXPECT_LT((ws.q - r.seq.q.back()).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((ws.qd - r.seq.qd.back()).lpNorm<Eigen::Infinity>(), 1e-5);
  EXPECT_LT((ws.qdd - r.seq.qdd.back()).lpNorm<Eigen::Infinity>(), 1e-3);
  // q, q̇, q̈ of two rows per chunk went through the pool (of the chunks computed ahead: those the caller's thread
  // runs as the next to deliver are streamed, never held, so how many come back depends on who ran which)
  EXPECT_LE(ws.spare_rows.size(), 2u * 3u * 8u);
}

// Rows too wide for the row buffer: a chunk holds no more rows than row_buffer_bytes has room for (the layout, the
// same on every thread count), and the threads are as many as have room for a chunk each, with a warning that says
// why (10⁶ scissor stages with q, q̇, q̈ ran 100 chunks of one row and held 12 GB); below room for 8 rows, the fewest
// that pay for a chunk's seed, the sweep is one chunk, in order. A sweep without a callback holds two rows per chunk
// and keeps its usual chunks.
TEST(ParallelSweep, RowsTooWideForChunksOfEightStepsRunOnFewerThreadsOrInOrder) {
  Model m = test::nfourbar_model(100, M_PI / 4, M_PI / 2);
  const double row_bytes = 8.0 * static_cast<double>(3 * m.num_coordinates() + 1);  // q, q̇, q̈ and the time
  SweepOptions opt;
  opt.steps = 300;  // chunks of max(16, 300 / 16) = 18 steps
  test::Trace seq;
  ASSERT_EQ(test::sweep(m, in_order(opt), &seq), SolveStatus::kSuccess);
  struct Run {
    test::Trace tr;
    SweepSummary sum;
  };
  // on `threads` threads with room for `rows` rows, expecting it to run on `ran` threads in `chunks` chunks
  auto run = [&](int threads, double rows, int ran, Index chunks) {
    Run r;
    opt.threads = threads;
    opt.row_buffer_bytes = static_cast<std::size_t>(rows * row_bytes);
    EXPECT_EQ(test::sweep(m, opt, &r.tr, &r.sum), SolveStatus::kSuccess) << r.sum.message;
    EXPECT_EQ(r.sum.threads, ran) << threads << " threads, " << rows << " rows";
    EXPECT_EQ(r.sum.parallel_chunks, chunks) << threads << " threads, " << rows << " rows";
    EXPECT_LT(test::max_difference(seq, r.tr, 0), 1e-9) << threads << " threads, " << rows << " rows";
    return r;
  };
  const Run s7 = run(2, 7.5, 1, 0);  // room for 7 rows: in order
  ASSERT_EQ(s7.sum.warnings.size(), 1u);
  EXPECT_EQ(s7.sum.warnings[0].kind, "threads_reduced");
  EXPECT_EQ(s7.sum.warnings[0].t, 0.0);
  EXPECT_HAS(s7.sum.warnings[0].message, "run in order, not in chunks, instead of on 2 threads");
  EXPECT_HAS(s7.sum.warnings[0].message, "hold 7 rows: fewer than the 8 steps that pay for a chunk's seed");
  EXPECT_HAS(s7.sum.warnings[0].message, "row_buffer_bytes");
  EXPECT_EQ(test::max_difference(seq, s7.tr, 0), 0.0);  // the sweep in order itself
  EXPECT_EQ(test::max_difference(seq, s7.tr, 2), 0.0);

  const Run s15 = run(2, 15.5, 1, 20);  // room for 15 rows: chunks of 15, on one thread
  ASSERT_EQ(s15.sum.warnings.size(), 1u);
  EXPECT_HAS(s15.sum.warnings[0].message, "run on 1 thread instead of on 2 threads");
  EXPECT_HAS(s15.sum.warnings[0].message, "hold 15 rows: chunks of 15 steps for 1 thread");
  const Run s15_one = run(1, 15.5, 1, 20);  // the same chunks, the same bits
  EXPECT_TRUE(s15_one.sum.warnings.empty());
  EXPECT_EQ(test::max_difference(s15.tr, s15_one.tr, 0), 0.0);
  EXPECT_EQ(test::max_difference(s15.tr, s15_one.tr, 2), 0.0);

  EXPECT_TRUE(run(2, 40.5, 2, 17).sum.warnings.empty());  // room for two chunks of 18

  const Run s4 = run(4, 40.5, 2, 17);  // on 4 threads, room for 40 rows: chunks of 18 on 2 of them
  ASSERT_EQ(s4.sum.warnings.size(), 1u);
  EXPECT_HAS(s4.sum.warnings[0].message, "run on 2 threads instead of on 4 threads");
  EXPECT_HAS(s4.sum.warnings[0].message, "hold 40 rows: chunks of 18 steps for 2 threads");

  opt.threads = 2;
  opt.row_buffer_bytes = static_cast<std::size_t>(7.5 * row_bytes);
  Workspace ws(m);
  SweepSummary unread;
  ASSERT_EQ(run_sweep(m, opt, ws, nullptr, &unread), SolveStatus::kSuccess) << unread.message;
  EXPECT_EQ(unread.parallel_chunks, 17);  // its usual chunks of 18 steps
  EXPECT_TRUE(unread.warnings.empty());

  opt.row_buffer_bytes = 0;
  EXPECT_THROW((void)run_sweep(m, opt, ws, nullptr, nullptr), Error);
}

// A drive that leaves the reachable range: the parallel sweep reports the same failure, at the same step, as the
// sequential one, after delivering the same rows.
TEST(ParallelSweep, AFailureIsReportedAsInTheSequentialSweep) {
  // slider driven: the crank-slider with L2 = 0.3, L3 = 1 reaches x_B only in [0.7, 1.3]
  ModelBuilder b;
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  Index th = b.add_coordinate("theta2", 0.5), xa = b.add_coordinate("xA", 0.26), ya = b.add_coordinate("yA", 0.14),
        xb = b.add_coordinate("xB", 1.2);
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("slider", xb, MotionLaw::linear(1.2, 0.3));  // x_B = 1.2 + 0.3 t passes 1.3 at t = 1/3
  Model m = std::move(b).build();
  SweepOptions opt;
  opt.steps = 200;
  test::Trace seq, par;
  SweepSummary ss, ps;
  EXPECT_NE(test::sweep(m, opt, &seq, &ss), SolveStatus::kSuccess);
  opt.threads = 2;
  opt.chunk_steps = 10;
  EXPECT_EQ(test::sweep(m, opt, &par, &ps), ss.status);
  EXPECT_EQ(ps.message, ss.message);
  EXPECT_EQ(ps.failed_step, ss.failed_step);
  EXPECT_EQ(par.t.size(), seq.t.size());
  EXPECT_GT(ps.parallel_chunks, 0);
  EXPECT_LT(test::max_difference(seq, par, 0), 1e-9);
  EXPECT_LT(test::max_difference(seq, par, 1), 1e-6);  // approaching the dead point, q̇ grows as 1/sin
}

// The rows reach on_step on the calling thread, in order, however many threads compute them (the caller of an
// embedding simulator may keep thread-local state there); and a caller that stops the sweep gets exactly the rows
// up to the one it stopped at.
TEST(ParallelSweep, DeliversOnTheCallingThreadInOrderAndStopsWhereTheCallerSays) {
  Model m = test::nfourbar_model(20, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 240;
  opt.threads = 2;
  opt.chunk_steps = 8;
  const std::thread::id me = std::this_thread::get_id();
  for (Index stop_at : {Index{-1}, Index{0}, Index{5}, Index{8}, Index{9}, Index{100}}) {
    Workspace ws(m);
    std::vector<Index> seen;
    bool foreign_thread = false;
    SweepSummary sum;
    const SolveStatus st = run_sweep(
        m, opt, ws,
        [&](const StepView& v) {
          seen.push_back(v.step);
          foreign_thread = foreign_thread || std::this_thread::get_id() != me;
          return v.step != stop_at;
        },
        &sum);
    EXPECT_FALSE(foreign_thread) << "stop at " << stop_at;
    const Index last = stop_at < 0 ? opt.steps : stop_at;
    ASSERT_EQ(static_cast<Index>(seen.size()), last + 1) << "stop at " << stop_at;
    for (Index k = 0; k <= last; ++k) EXPECT_EQ(seen[static_cast<std::size_t>(k)], k);
    EXPECT_EQ(st, stop_at < 0 ? SolveStatus::kSuccess : SolveStatus::kCancelled) << sum.message;
    EXPECT_EQ(sum.steps_completed, last + 1);
  }
}

// A model large enough to be evaluated in parallel itself (more than 65536 constraints), swept in parallel chunks:
// the evaluation's tasks run inside the chunks' threads without deadlock, and the rows are the sequential ones.
TEST(ParallelSweep, LargeModelsEvaluatedInParallelInsideParallelChunks) {
  Model m = test::nfourbar_model(33000, M_PI / 4, M_PI / 2);
  ASSERT_GT(m.num_equations(), 65536);  // one row per constraint but the angle
  SweepOptions opt;
  opt.steps = 6;
  opt.t_end = 0.01;
  const InOrderAndParallel r = sweep_both(m, opt, 2, 1);
  ASSERT_EQ(r.seq_status, SolveStatus::kSuccess) << r.ss.message;
  ASSERT_EQ(r.par_status, SolveStatus::kSuccess) << r.ps.message;
  EXPECT_EQ(r.ps.parallel_chunks, 6);
  EXPECT_LT(test::max_difference(r.seq, r.par, 0), 1e-9 * 33000);  // lengths up to 3.3·10⁴ m
  EXPECT_LT(test::max_difference(r.seq, r.par, 1), 1e-7);
}

// A step callback that throws ends a parallel sweep with its exception, whatever the other threads were doing (none
// is left waiting for the thrower), and the same model sweeps again afterwards.
TEST(ParallelSweep, AnExceptionFromTheCallbackPropagates) {
  Model m = test::nfourbar_model(20, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 400;
  opt.threads = 2;
  opt.chunk_steps = 5;
  for (Index throw_at : {Index{0}, Index{3}, Index{57}, Index{400}}) {
    Workspace ws(m);
    Index seen = 0;
    EXPECT_THROW((void)run_sweep(
                     m, opt, ws,
                     [&](const StepView& v) {
                       if (v.step == throw_at) throw std::runtime_error("stop here");
                       ++seen;
                       return true;
                     },
                     nullptr),
                 std::runtime_error);
    EXPECT_EQ(seen, throw_at);
  }
  test::Trace tr;
  EXPECT_EQ(test::sweep(m, opt, &tr), SolveStatus::kSuccess);
  EXPECT_EQ(static_cast<Index>(tr.t.size()), opt.steps + 1);
}

// threads = 0 runs on all cores, as many as the memory allows: below the room for two more workspaces the sweep runs
// its chunks on one thread, with a warning that says why; with room, on every core; an explicit thread count is kept
// whatever the budget. The rows are the same bits in every case.
TEST(ParallelSweep, AllCoresAsManyAsTheMemoryAllows) {
  Model m = test::nfourbar_model(200, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.steps = 200;
  opt.threads = 0;
  opt.memory_budget = 1;  // far too little for a second workspace
  test::Trace tight, roomy, forced;
  SweepSummary st, sr, sf;
  ASSERT_EQ(test::sweep(m, opt, &tight, &st), SolveStatus::kSuccess) << st.message;
  const int cores = tbb::info::default_concurrency();
  auto reduced = [](const SweepSummary& s) {
    for (const SweepWarning& w : s.warnings)
      if (w.kind == "threads_reduced") return w.message;
    return std::string();
  };
  if (cores > 1) {
    EXPECT_EQ(st.threads, 1);
    EXPECT_EQ(st.parallel_chunks, 13);  // the chunks of every thread count: 200 steps in 13 of 16 steps
    EXPECT_NE(reduced(st).find("instead of " + std::to_string(cores)), std::string::npos) << reduced(st);
  }
  opt.memory_budget = std::size_t{1} << 40;
  ASSERT_EQ(test::sweep(m, opt, &roomy, &sr), SolveStatus::kSuccess) << sr.message;
  EXPECT_EQ(reduced(sr), "");
  if (cores > 1) {
    EXPECT_EQ(sr.threads, cores);
  }
  opt.threads = 2;
  opt.memory_budget = 1;
  ASSERT_EQ(test::sweep(m, opt, &forced, &sf), SolveStatus::kSuccess) << sf.message;
  EXPECT_EQ(sf.threads, 2);
  EXPECT_EQ(reduced(sf), "");
  EXPECT_EQ(test::max_difference(tight, roomy, 0), 0.0);  // the same chunks: the same bits
  EXPECT_EQ(test::max_difference(tight, forced, 0), 0.0);
  EXPECT_EQ(test::max_difference(tight, forced, 2), 0.0);
}

}  // namespace
}  // namespace phiq

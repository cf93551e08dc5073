// Whole sweeps of nfourbar: parallel drive steps (1 thread against 2, with the machine's own ceiling for two
// threads), what the output lists cost per step, and formatting the result CSV against solving it. Part of
// phiq_bench (BENCHMARK_MAIN is in bench_kinematics.cpp); separate from the kernel and engine costs measured there.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <thread>
#include <tuple>
#include <vector>

#include <tbb/task_arena.h>

#include "bench_kinematics_timing.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::Clock;
using phiq_bench::nfourbar;
using phiq_bench::seconds_since;

// One sweep of `m` from its initial positions, timed: its wall time in seconds (the summary in *sum).
double timed_sweep(const Model& m, const SweepOptions& opt, Workspace& ws,
                   const std::function<bool(const StepView&)>& on_step, SweepSummary* sum) {
  ws.q = m.initial_positions();
  const auto t0 = Clock::now();
  (void)run_sweep(m, opt, ws, on_step, sum);  // its status is sum->status, the caller's to check
  return seconds_since(t0);
}

// Parallel drive steps: a 1000-step sweep (q, q̇, q̈) on 1 thread and on 2, interleaved; speedup = t1 / t2, and
// the share of the 2-thread run spent in the sequential seeding pass (for the projection to more cores in
// bench/README.md). In the same loop, the machine's own ceiling for this work: two independent copies of the
// 1-thread sweep run at once on two threads (own model, own workspace, nothing shared), pair_throughput =
// 2 t1 / t_pair. A machine whose two cores are fully available gives 2; the engine's schedule is judged by
// schedule_efficiency = speedup / pair_throughput (1 when splitting one sweep costs nothing over running two).
// The machine is shared: a burst of load on the host stalls a 2-thread sweep more than a 1-thread one, and one
// such burst moves a mean of three. So the three ratios are the medians of their per-iteration values over 9
// iterations; speedup_of_totals is the ratio of the summed times (the speedup as reported before the medians).
// These sweeps have no callback, so the parallel one holds only the rows it reads again itself. A caller that reads
// every row (a writer) makes it hold them all until their turn: speedup_rows_read is the same ratio with a callback
// that reads every value of q, q̇ and q̈ on both sides (median too).
// The 1-thread sweep runs the very chunks of the 2-thread one (the same bits on every thread count): what that costs
// on one thread against the sweep in order (one chunk: no seeds, no seam steps, no fresh factorisation per chunk)
// is chunking_cost_one_thread = t1 / t_in_order (median).
void BM_NFourBarParallelSweep(benchmark::State& state) {
  const Index n = state.range(0);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Model m_copy = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m), ws_copy(m_copy);
  SweepOptions one, two, in_order;
  one.steps = two.steps = in_order.steps = 1000;
  two.threads = 2;
  in_order.chunk_steps = in_order.steps;
  double t1 = 0, t2 = 0, pair = 0, seed = 0;
  std::vector<double> speedups, pairs, efficiencies, read_speedups, chunking_costs;  // per iteration
  double checksum = 0;
  auto read = [&](const StepView& s) {  // every value of the row, as a writer reads them
    checksum += s.q.sum() + s.qd->sum() + s.qdd->sum();
    return true;
  };
  for (auto _ : state) {
    SweepSummary sum;
    const double e1 = timed_sweep(m, one, ws, nullptr, &sum);
    t1 += e1;
    const double e = timed_sweep(m, two, ws, nullptr, &sum);
    t2 += e, seed += sum.seed_seconds;
    if (sum.parallel_chunks == 0) state.SkipWithError("no parallel chunks");
    state.SetIterationTime(e);
    ws.q = m.initial_positions();
    ws_copy.q = m_copy.initial_positions();
    const auto t0 = Clock::now();
    std::thread other([&] {
      SweepSummary s2;
      (void)run_sweep(m_copy, one, ws_copy, nullptr, &s2);  // the sweep timed alone above, and checked there
    });
    SweepSummary s1;
    (void)run_sweep(m, one, ws, nullptr, &s1);  // the sweep timed alone above, and checked there
    other.join();
    const double ep = seconds_since(t0);
    pair += ep;
    speedups.push_back(e1 / e), pairs.push_back(2.0 * e1 / ep), efficiencies.push_back((e1 / e) / (2.0 * e1 / ep));
    const double r1 = timed_sweep(m, one, ws, read, &sum);
    read_speedups.push_back(r1 / timed_sweep(m, two, ws, read, &sum));
    chunking_costs.push_back(e1 / timed_sweep(m, in_order, ws, nullptr, &sum));
  }
  benchmark::DoNotOptimize(checksum);
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  state.counters["one_thread_ms"] = 1e3 * t1 / static_cast<double>(state.iterations());
  state.counters["two_threads_ms"] = 1e3 * t2 / static_cast<double>(state.iterations());
  state.counters["speedup"] = median(speedups);
  state.counters["speedup_of_totals"] = t1 / t2;
  state.counters["seed_share"] = seed / t2;
  state.counters["pair_throughput"] = median(pairs);
  state.counters["schedule_efficiency"] = median(efficiencies);
  state.counters["speedup_rows_read"] = median(read_speedups);
  state.counters["chunking_cost_one_thread"] = median(chunking_costs);
}
BENCHMARK(BM_NFourBarParallelSweep)
    ->ArgName("N")
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(9);

// Parallel drive steps of a positions-only sweep of 100 steps (chunks of 16, 7 of them): the short sweep of a large
// model, where a chunk's start-up is a larger share than in the 1000-step sweep above and where the first seed,
// without derivatives at row 0, is extrapolated from one position over a whole chunk (found in
// sub-steps). 1 thread and 2, interleaved; speedup is the median of the per-iteration ratios.
void BM_NFourBarParallelPositions(benchmark::State& state) {
  const Index n = state.range(0);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  SweepOptions one, two;
  one.steps = two.steps = 100;
  one.velocities = one.accelerations = two.velocities = two.accelerations = false;
  two.threads = 2;
  double t1 = 0, t2 = 0, seed = 0;
  std::vector<double> speedups;
  for (auto _ : state) {
    SweepSummary sum;
    const double e1 = timed_sweep(m, one, ws, nullptr, &sum);
    const double e2 = timed_sweep(m, two, ws, nullptr, &sum);
    if (sum.parallel_chunks == 0) state.SkipWithError("no parallel chunks");
    state.SetIterationTime(e2);
    t1 += e1, t2 += e2, seed += sum.seed_seconds;
    speedups.push_back(e1 / e2);
  }
  std::sort(speedups.begin(), speedups.end());
  state.counters["one_thread_ms"] = 1e3 * t1 / static_cast<double>(state.iterations());
  state.counters["two_threads_ms"] = 1e3 * t2 / static_cast<double>(state.iterations());
  state.counters["speedup"] = speedups[speedups.size() / 2];
  state.counters["seed_share"] = seed / t2;
}
BENCHMARK(BM_NFourBarParallelPositions)
    ->ArgName("N")
    ->Arg(10)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(5);

// What outputs cost (issue 5, section 3): the same nfourbar sweep (a quarter turn in 200 steps) with the output
// lists a scene can have, timed interleaved in one loop, per step. The engine plans the work from the list, so the
// positions-only sweep solves no q̇ or q̈, and asking for residuals and rcond adds nothing but copying what the
// solve has. With the default (auto) predictor, derivatives also buy a better start for Newton: the `secant`
// variant is q, q̇, q̈ with the positions-only predictor, for the cost of the derivatives alone.
void BM_NFourBarOutputCost(benchmark::State& state) {
  const Index n = state.range(0), steps = 200;
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  struct Variant {
    const char* name;
    SweepOptions opt;
    double seconds = 0;
    Index newton = 0;
    std::vector<double> per_q;  // this variant's time ÷ the positions-only time, per iteration
  };
  auto make = [&](bool v, bool a) {
    SweepOptions o;
    o.steps = steps;
    o.velocities = v, o.accelerations = a;
    return o;
  };
  std::vector<Variant> variants;
  for (const auto& [name, v, a] : {std::tuple{"q", false, false},
                                   {"q_res_rcond", false, false},
                                   {"qv", true, false},
                                   {"qva", true, true},
                                   {"qva_points", true, true},
                                   {"qva_secant", true, true}})
    variants.push_back(Variant{name, make(v, a), 0.0, 0, {}});
  variants[1].opt.residuals = variants[1].opt.condition = true;
  for (Index i = 0; i <= n; ++i)  // every crank tip: an upper bound of what points cost
    variants[4].opt.points.push_back(
        planar_point(phiq_bench::indexed("P", i), Point2{Slot::coordinate(2 * i), Slot::coordinate(2 * i + 1)}));
  variants[5].opt.predictor = Predictor::kSecant;
  double checksum = 0;
  auto consume = [&](const StepView& s) {  // reads what was delivered, as a writer would
    checksum += s.q(0) + (s.points ? s.points[0].r[0] : 0.0) + (s.phi ? (*s.phi)(0) : 0.0) + s.rcond;
    return true;
  };
  // The machine is shared and noisy: all variants run back to back in every iteration, in an order rotated from one
  // iteration to the next, and the ratios reported are the medians of the per-iteration ratios.
  std::size_t rotation = 0;
  for (auto _ : state) {
    double total = 0;
    std::vector<double> t(variants.size());
    for (std::size_t r = 0; r < variants.size(); ++r) {
      const std::size_t k = (r + rotation) % variants.size();
      Variant& v = variants[k];
      SweepSummary sum;
      ws.q = m.initial_positions();
      ws.has_factorization = false;
      const auto t0 = Clock::now();
      (void)run_sweep(m, v.opt, ws, consume, &sum);  // its status is sum.status, checked below
      const double e = seconds_since(t0);
      if (sum.status != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
      v.seconds += e, total += e, t[k] = e;
      v.newton += sum.counters.newton_iterations;
    }
    ++rotation;
    for (std::size_t k = 0; k < variants.size(); ++k) variants[k].per_q.push_back(t[k] / t[0]);
    state.SetIterationTime(total);
  }
  benchmark::DoNotOptimize(checksum);
  const double it = static_cast<double>(state.iterations()), rows = static_cast<double>(steps + 1);
  for (Variant& v : variants) {
    state.counters[std::string(v.name) + "_us"] = 1e6 * v.seconds / (it * rows);
    state.counters[std::string(v.name) + "_newton"] = static_cast<double>(v.newton) / (it * rows);
    if (&v == &variants[0]) continue;
    std::sort(v.per_q.begin(), v.per_q.end());
    state.counters[std::string(v.name) + "_per_q"] = v.per_q[v.per_q.size() / 2];
  }
}
BENCHMARK(BM_NFourBarOutputCost)
    ->ArgName("N")
    ->Arg(10)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(7);

// Writing the result CSV (issue 4: a wide CSV must not dominate a large run): one row of q, q̇, q̈ of nfourbar formatted
// by CsvFormat::append_row (shortest round-trip text), in a task arena of 1 thread and of 2, interleaved, against the
// time of one drive step of the same model on one thread (a 200-step sweep, q, q̇, q̈). format_per_step_1t > 1 means
// that one thread writing the rows would take longer than one thread solving them.
void BM_CsvRowFormatting(benchmark::State& state) {
  const Index n = state.range(0), steps = 200;
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  SweepOptions o;
  o.steps = steps;
  o.threads = 1;
  Eigen::VectorXd q, qd, qdd;  // the last row: values as a run writes them
  const auto s0 = Clock::now();
  if (run_sweep(
          m, o, ws,
          [&](const StepView& s) {
            if (s.step == steps) q = s.q, qd = *s.qd, qdd = *s.qdd;
            return true;
          },
          nullptr) != SolveStatus::kSuccess)
    state.SkipWithError("the sweep failed");
  const double step_s = seconds_since(s0) / static_cast<double>(steps);
  std::vector<Index> columns(static_cast<std::size_t>(m.num_coordinates()));
  for (std::size_t j = 0; j < columns.size(); ++j) columns[j] = static_cast<Index>(j);
  const CsvFormat csv(m, columns, true, true);
  const StepView row{steps, 1.0, q, &qd, &qdd};
  tbb::task_arena one(1), two(2);
  const int rows = std::max<int>(1, static_cast<int>(1000000 / (3 * n)));  // about 10⁶ numbers per pass
  std::string out;
  double t1 = 0, t2 = 0;
  std::size_t bytes = 0;
  auto pass = [&](tbb::task_arena& arena) {
    const auto t0 = Clock::now();
    arena.execute([&] {
      for (int r = 0; r < rows; ++r) {
        out.clear();
        csv.append_row(row, out);
      }
    });
    bytes = out.size();
    return seconds_since(t0);
  };
  for (auto _ : state) {
    t1 += pass(one);
    const double e = pass(two);
    t2 += e;
    state.SetIterationTime(e);
  }
  const double values = 3.0 * static_cast<double>(m.num_coordinates()) + 1.0;
  const double per_row_1 = t1 / (static_cast<double>(state.iterations()) * rows);
  const double per_row_2 = t2 / (static_cast<double>(state.iterations()) * rows);
  state.counters["ns_per_value_1t"] = 1e9 * per_row_1 / values;
  state.counters["ns_per_value_2t"] = 1e9 * per_row_2 / values;
  state.counters["speedup"] = t1 / t2;
  state.counters["bytes_per_value"] = static_cast<double>(bytes) / values;
  state.counters["step_us"] = 1e6 * step_s;
  state.counters["format_per_step_1t"] = per_row_1 / step_s;
  state.counters["format_per_step_2t"] = per_row_2 / step_s;
}
BENCHMARK(BM_CsvRowFormatting)
    ->ArgName("N")
    ->Arg(10)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(5);

}  // namespace

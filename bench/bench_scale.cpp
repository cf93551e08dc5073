// Time per drive step (position + velocity + acceleration) of the generated models — nfourbar, scissor, grid,
// chain3d — from 10^2 to 10^6 coordinates, through the whole public path: `phiq generate` text → scene loader →
// run_sweep.
//
//   ./build/bench/phiq_bench_scale --benchmark_out=bench/results/scale.json --benchmark_out_format=json
//
// Generation, loading, the assembly of the initial position (chain3d starts from a rough placement; the others
// on the solution) and a first sweep on the fresh workspace are outside the timed region (load_s reports the
// loading, first_sweep_ms that sweep's time per row). Arguments: N (the generator's size)
// and coords (0 natural, 1 reference-point). Counters kernel_ms (a step's bare kernel: one KLU refactorisation and
// two solves) and stream_ms (one triad over vectors of the model's size), measured in the same loop, give the
// machine's own slopes beside the step's (bench/README.md).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

#include <klu.h>

#include "generate.hpp"
#include "generate_linkages.hpp"
#include "linear/klu_lu.hpp"
#include "phiq/phiq.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void run(benchmark::State& state, const char* kind) {
  phiq::tools::GenerateOptions g;
  g.kind = kind;
  g.n = state.range(0);
  g.coords = state.range(1) == 0 ? "natural" : "reference-point";
  // a short sweep per iteration: 10 steps of the generator's default range over 1000 steps (the step size of
  // the default scene), so that every size sees the same step
  g.steps = 1000;
  if (auto r = phiq::tools::kind_default_range(kind)) g.from = r->from, g.to = r->to;
  const auto l0 = Clock::now();
  phiq::Scene scene = phiq::parse_scene(phiq::tools::generate_scene(g), std::string(kind) + ".yaml");
  const double load_s = seconds_since(l0);
  const phiq::Model& m = *scene.model;
  phiq::SweepOptions opt = scene.sweep;
  opt.steps = 10;
  opt.t_end = opt.t_begin + 10 * (scene.sweep.t_end - scene.sweep.t_begin) / 1000.0;
  opt.threads = 1;
  phiq::Workspace ws(m);
  ws.q = m.initial_positions();
  if (phiq::solve_position(m, opt.t_begin, opt.assembly, ws) != phiq::SolveStatus::kSuccess)
    return state.SkipWithError("no assembly at the first time");
  const Eigen::VectorXd start = ws.q;
  phiq::SweepSummary sum;
  // One sweep before the timed ones, timed apart (first_sweep_ms): a fresh workspace's first sweep also pays KLU's
  // pivot search and the first touch of its factors and buffers (at 10⁶ scissor stages 1.5 s of factorisation and
  // 1.4 GB of pages mapped in). Those are paid once per workspace, not per step; left in the loop they landed in
  // the one iteration the 10⁶ sizes run, and were spread over hundreds at 10⁴.
  const auto w0 = Clock::now();
  (void)phiq::run_sweep(m, opt, ws, nullptr, &sum);  // its status is sum.status, checked below
  const double first_sweep_s = seconds_since(w0);
  if (sum.status != phiq::SolveStatus::kSuccess) return state.SkipWithError(sum.message.c_str());
  // In the same loop, for the slope of what a step is made of on this machine: the bare kernel of a step (one
  // refactorisation and two solves of Φq at the first position, with a numeric object of its own on the model's
  // symbolic analysis) and a pure stream over memory of the model's size (a triad over three vectors of n doubles:
  // what any O(n) pass costs once the vectors no longer fit in the caches).
  std::unique_ptr<phiq::SparseLuNumeric> lu = m.symbolic()->make_numeric();
  std::vector<double> values(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  m.jacobian(start.data(), opt.t_begin, values.data());
  lu->factorize(values.data());
  Eigen::VectorXd b = Eigen::VectorXd::Ones(m.num_coordinates()), x(m.num_coordinates()), y(m.num_coordinates());
  double kernel_s = 0, stream_s = 0;
  for (auto _ : state) {
    ws.q = start;
    const auto t0 = Clock::now();
    (void)phiq::run_sweep(m, opt, ws, nullptr, &sum);  // its status is sum.status, checked below
    const double e = seconds_since(t0);
    state.SetIterationTime(e / static_cast<double>(opt.steps + 1));
    if (sum.status != phiq::SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    const auto k0 = Clock::now();
    lu->factorize(values.data());
    lu->solve(b.data(), x.data());
    lu->solve(x.data(), y.data());
    kernel_s += seconds_since(k0);
    benchmark::DoNotOptimize(y.data());
    const auto s0 = Clock::now();
    x = b + 0.5 * y;
    stream_s += seconds_since(s0);
    benchmark::DoNotOptimize(x.data());
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["kernel_ms"] = 1e3 * kernel_s / it;
  state.counters["stream_ms"] = 1e3 * stream_s / it;
  state.counters["coordinates"] = static_cast<double>(m.num_coordinates());
  state.counters["load_s"] = load_s;
  state.counters["first_sweep_ms"] = 1e3 * first_sweep_s / static_cast<double>(opt.steps + 1);
  state.counters["newton_per_step"] = static_cast<double>(sum.counters.newton_iterations) / (opt.steps + 1);
  state.counters["factorizations_per_step"] = static_cast<double>(sum.counters.factorizations) / (opt.steps + 1);
  state.counters["warnings"] = static_cast<double>(sum.warnings.size());
}

void sizes(benchmark::internal::Benchmark* b) {
  b->ArgNames({"N", "coords"});
  for (int64_t n = 100; n <= 1000000; n *= 10) b->Args({n, 0});
  for (int64_t n = 100; n <= 100000; n *= 10) b->Args({n, 1});
}

// KLU as phiq analyses it (32-bit indices where the factors fit, its blocks in the model's own order: klu_lu.cpp)
// against KLU as it comes (klu_l_*, 64-bit, the blocks as its depth-first search orders them), on the same Jacobian
// (the generated model's at its first position),
// in one loop: one refactorisation and one solve each. Counters: phiq_refactor_ms, klu_refactor_ms, phiq_solve_ms,
// klu_solve_ms, their ratios (klu ÷ phiq: the speed-up), the peak memory of factorising (KLU's mempeak) of each,
// and the mean jump between consecutive columns of each order (klu_lu.hpp).
void klu_at_scale(benchmark::State& state, const char* kind) {
  phiq::tools::GenerateOptions g;
  g.kind = kind;
  g.n = state.range(0);
  if (auto r = phiq::tools::kind_default_range(kind)) g.from = r->from, g.to = r->to;
  phiq::Scene scene = phiq::parse_scene(phiq::tools::generate_scene(g), std::string(kind) + ".yaml");
  const phiq::Model& m = *scene.model;
  phiq::Workspace ws(m);
  if (phiq::solve_position(m, scene.sweep.t_begin, scene.sweep.assembly, ws) != phiq::SolveStatus::kSuccess)
    return state.SkipWithError("no assembly at the first time");
  const phiq::CscPattern& p = m.jacobian_pattern();
  std::vector<double> values(static_cast<std::size_t>(p.nnz()));
  m.jacobian(ws.q.data(), scene.sweep.t_begin, values.data());
  const SuiteSparse_long n = p.cols;
  std::vector<SuiteSparse_long> ap(p.col_ptr.begin(), p.col_ptr.end()), ai(p.row_idx.begin(), p.row_idx.end());
  klu_l_common c;
  klu_l_defaults(&c);
  klu_l_symbolic* sym = klu_l_analyze(n, ap.data(), ai.data(), &c);
  klu_l_numeric* num = sym ? klu_l_factor(ap.data(), ai.data(), values.data(), sym, &c) : nullptr;
  if (!num) return state.SkipWithError("KLU failed");
  std::unique_ptr<phiq::SparseLuNumeric> lu = m.symbolic()->make_numeric();
  lu->factorize(values.data());
  Eigen::VectorXd b = Eigen::VectorXd::Ones(n), x(n);
  double phiq_f = 0, klu_f = 0, phiq_s = 0, klu_s = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    lu->factorize(values.data());
    phiq_f += seconds_since(t0);
    t0 = Clock::now();
    lu->solve(b.data(), x.data());
    phiq_s += seconds_since(t0);
    t0 = Clock::now();
    klu_l_refactor(ap.data(), ai.data(), values.data(), sym, num, &c);
    klu_f += seconds_since(t0);
    x = b;
    t0 = Clock::now();
    klu_l_solve(sym, num, n, 1, x.data(), &c);
    klu_s += seconds_since(t0);
    benchmark::DoNotOptimize(x.data());
    state.SetIterationTime(seconds_since(t0));
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["phiq_refactor_ms"] = 1e3 * phiq_f / it;
  state.counters["klu_refactor_ms"] = 1e3 * klu_f / it;
  state.counters["phiq_solve_ms"] = 1e3 * phiq_s / it;
  state.counters["klu_solve_ms"] = 1e3 * klu_s / it;
  state.counters["refactor_speedup"] = klu_f / phiq_f;
  state.counters["solve_speedup"] = klu_s / phiq_s;
  state.counters["phiq_peak_mb"] = static_cast<double>(lu->memory_bytes()) / 1e6;
  state.counters["klu_peak_mb"] = static_cast<double>(c.mempeak) / 1e6;
  const phiq::detail::KluAnalysis a = phiq::detail::describe_klu(*m.symbolic());
  state.counters["index_bits"] = a.index_bits;
  state.counters["klu_jump"] = a.klu_jump;
  state.counters["phiq_jump"] = a.jump;
  state.counters["coordinates"] = static_cast<double>(n);
  klu_l_free_numeric(&num, &c);
  klu_l_free_symbolic(&sym, &c);
}
// Each figure's minimum measured time; 0.01 s in ctest's smoke run (PHIQ_BENCH_SMOKE set). A benchmark's own MinTime
// overrides --benchmark_min_time, and these timed laps are a small part of each iteration (the rest prepares it), so
// the smoke run took 45 s at its smallest size.
double min_time(double seconds) { return std::getenv("PHIQ_BENCH_SMOKE") ? 0.01 : seconds; }

void BM_KluAtScaleGrid(benchmark::State& s) { klu_at_scale(s, "grid"); }
void BM_KluAtScaleNFourBar(benchmark::State& s) { klu_at_scale(s, "nfourbar"); }
void BM_KluAtScaleScissor(benchmark::State& s) { klu_at_scale(s, "scissor"); }
void klu_sizes(benchmark::internal::Benchmark* b) {
  b->ArgName("N");
  for (int64_t n = 100; n <= 1000000; n *= 10) b->Arg(n);
}
BENCHMARK(BM_KluAtScaleGrid)->Apply(klu_sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(min_time(0.5));
BENCHMARK(BM_KluAtScaleNFourBar)
    ->Apply(klu_sizes)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->MinTime(min_time(0.5));
BENCHMARK(BM_KluAtScaleScissor)
    ->Apply(klu_sizes)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->MinTime(min_time(0.5));

void BM_NFourBarStep(benchmark::State& s) { run(s, "nfourbar"); }
void BM_ScissorStep(benchmark::State& s) { run(s, "scissor"); }
void BM_GridStep(benchmark::State& s) { run(s, "grid"); }
void BM_Chain3dStep(benchmark::State& s) { run(s, "chain3d"); }
BENCHMARK(BM_NFourBarStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(min_time(0.2));
BENCHMARK(BM_ScissorStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(min_time(0.2));
BENCHMARK(BM_GridStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(min_time(0.2));
BENCHMARK(BM_Chain3dStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(min_time(0.2));

}  // namespace

BENCHMARK_MAIN();

// Time per drive step (position + velocity + acceleration) of the generated models — nfourbar, scissor, grid,
// chain3d — from 10^2 to 10^6 coordinates, through the whole public path: `phiq generate` text → scene loader →
// run_sweep.
//
//   ./build/bench/phiq_bench_scale --benchmark_out=bench/results/scale.json --benchmark_out_format=json
//
// Generation, loading and the assembly of the initial position (chain3d starts from a rough placement; the others
// on the solution) are outside the timed region (load_s reports the loading). Arguments: N (the generator's size)
// and coords (0 natural, 1 reference-point). Counters kernel_ms (a step's bare kernel: one KLU refactorisation and
// two solves) and stream_ms (one triad over vectors of the model's size), measured in the same loop, give the
// machine's own slopes beside the step's (bench/README.md).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "generate.hpp"
#include "generate_linkages.hpp"
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
    phiq::run_sweep(m, opt, ws, nullptr, &sum);
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
  state.counters["newton_per_step"] = static_cast<double>(sum.counters.newton_iterations) / (opt.steps + 1);
  state.counters["factorizations_per_step"] = static_cast<double>(sum.counters.factorizations) / (opt.steps + 1);
  state.counters["warnings"] = static_cast<double>(sum.warnings.size());
}

void sizes(benchmark::internal::Benchmark* b) {
  b->ArgNames({"N", "coords"});
  for (int64_t n = 100; n <= 1000000; n *= 10) b->Args({n, 0});
  for (int64_t n = 100; n <= 100000; n *= 10) b->Args({n, 1});
}

void BM_NFourBarStep(benchmark::State& s) { run(s, "nfourbar"); }
void BM_ScissorStep(benchmark::State& s) { run(s, "scissor"); }
void BM_GridStep(benchmark::State& s) { run(s, "grid"); }
void BM_Chain3dStep(benchmark::State& s) { run(s, "chain3d"); }
BENCHMARK(BM_NFourBarStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(0.2);
BENCHMARK(BM_ScissorStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(0.2);
BENCHMARK(BM_GridStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(0.2);
BENCHMARK(BM_Chain3dStep)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime()->MinTime(0.2);

}  // namespace

BENCHMARK_MAIN();

// Time per drive step (position + velocity + acceleration) and the cost of the engine around the sparse kernel:
// the step against one bare factorise+solve, a Newton iteration against KLU as phiq configures it and as it comes,
// the model's passes over its constraints, and symbolic reuse. The other benchmarks of phiq_bench are
// bench_kinematics_bare_loop.cpp (the hand-written loop) and bench_kinematics_sweeps.cpp (parallel drive
// steps, what outputs cost).
//
//   ./build/bench/phiq_bench --benchmark_format=console
//
// Models are built in code (no scene loading in the timed region).
#include <benchmark/benchmark.h>

#include <klu.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "bench_kinematics_timing.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::Clock;
using phiq_bench::nfourbar;
using phiq_bench::seconds_since;

Model crank_slider() {
  ModelBuilder b;
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3), ya = b.add_coordinate("yA", 0.0),
        xb = b.add_coordinate("xB", 1.3);
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("motor", th, MotionLaw::linear(0.0, 2.0));
  return std::move(b).build();
}

// The bare kernel: one numeric factorisation + solve of the Jacobian at ws.q with a separate numeric object (same
// symbolic analysis). Timed by the caller right next to the engine work, so that their ratio is measured in one
// run on this shared, noisy machine.
struct Kernel {
  explicit Kernel(const Model& m)
      : lu(m.symbolic()->make_numeric()),
        values(m.jacobian_pattern().nnz()),
        b(m.num_equations()),
        x(m.num_coordinates()) {
    b.setOnes();
  }
  double time_one(const Model& m, const Eigen::VectorXd& q) {
    m.jacobian(q.data(), 0.0, values.data());
    const auto t0 = Clock::now();
    lu->factorize(values.data());
    lu->solve(b.data(), x.data());
    benchmark::DoNotOptimize(x.data());
    return seconds_since(t0);
  }
  std::unique_ptr<SparseLuNumeric> lu;
  std::vector<double> values;
  Eigen::VectorXd b, x;
};

// Sweeps `steps` steps per benchmark iteration (manual time: the sweep only); reports the time per step, the work
// per step, and step_per_kernel = time per step / one bare factorise+solve at the same states, interleaved.
void run_steps(benchmark::State& state, const Model& m, Index steps, double t_end) {
  SweepOptions opt;
  opt.t_begin = 0.0;
  opt.t_end = t_end;
  opt.steps = steps;
  Workspace ws(m);
  Kernel kernel(m);
  SweepSummary sum;
  Index rows = 0;
  double sweep_s = 0.0, kernel_s = 0.0;
  Index kernels = 0;
  for (auto _ : state) {
    ws.q = m.initial_positions();
    const auto t0 = Clock::now();
    double in_kernel = 0.0;
    (void)run_sweep(
        m, opt, ws,
        [&](const StepView& s) {  // its status is sum.status, checked below
          // every 10th row, one bare kernel at this very state (its time is taken out of the sweep's)
          if (s.step % 10 == 0) {
            const auto k0 = Clock::now();
            kernel_s += kernel.time_one(m, s.q), ++kernels;
            in_kernel += seconds_since(k0);
          }
          return true;
        },
        &sum);
    const double t = seconds_since(t0) - in_kernel;
    state.SetIterationTime(t);
    sweep_s += t;
    if (sum.status != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    rows += sum.steps_completed;
  }
  state.SetItemsProcessed(rows);
  state.counters["us_per_step"] = 1e6 * sweep_s / static_cast<double>(rows);
  state.counters["step_per_kernel"] = (sweep_s / static_cast<double>(rows)) / (kernel_s / static_cast<double>(kernels));
  state.counters["newton_per_step"] = static_cast<double>(sum.counters.newton_iterations) / (steps + 1);
  state.counters["factorizations_per_step"] = static_cast<double>(sum.counters.factorizations) / (steps + 1);
  state.counters["pivoting_per_step"] =
      static_cast<double>(ws.lu->pivoting_factorizations()) / static_cast<double>(state.iterations() * (steps + 1));
  state.counters["coordinates"] = static_cast<double>(m.num_coordinates());
}

void BM_CrankSliderSweepStep(benchmark::State& state) {
  Model m = crank_slider();
  run_steps(state, m, 180, M_PI);
}
BENCHMARK(BM_CrankSliderSweepStep)->UseManualTime();

// Second benchmark argument: the sparse LU.
LinearSolverKind kind_arg(const benchmark::State& state) { return static_cast<LinearSolverKind>(state.range(1)); }
void solver_args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"N", "lu"});
  for (int64_t n = 10; n <= 100000; n *= 10)
    for (LinearSolverKind k : {LinearSolverKind::kKlu, LinearSolverKind::kUmfpack})
      b->Args({n, static_cast<int64_t>(k)});
}

// nfourbar, a quarter turn (π/4 → 3π/4) in 50 steps per iteration. lu: 0 UMFPACK, 1 KLU.
void BM_NFourBarSweepStep(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2, kind_arg(state));
  run_steps(state, m, 50, 1.0);
}
BENCHMARK(BM_NFourBarSweepStep)->Apply(solver_args)->Unit(benchmark::kMillisecond)->UseManualTime();

// KLU as it comes: klu_analyze, klu_factor once, then each time klu_refactor + klu_solve with KLU's defaults (its
// row scaling at every refactorisation), 32-bit, on the same matrix. The kernel a user calling the library gets,
// beside the one phiq configures (Kernel: refactorisations without scaling, its rcond and sign scan).
struct KluAsItComes {
  explicit KluAsItComes(const Model& m)
      : ap(m.jacobian_pattern().col_ptr.begin(), m.jacobian_pattern().col_ptr.end()),
        ai(m.jacobian_pattern().row_idx.begin(), m.jacobian_pattern().row_idx.end()),
        values(static_cast<std::size_t>(m.jacobian_pattern().nnz())),
        b(m.num_equations()),
        x(m.num_coordinates()) {
    klu_defaults(&common);
    symbolic = klu_analyze(static_cast<int>(x.size()), ap.data(), ai.data(), &common);
    b.setOnes();
  }
  ~KluAsItComes() {
    if (numeric) klu_free_numeric(&numeric, &common);
    klu_free_symbolic(&symbolic, &common);
  }
  double time_one(const Model& m, const Eigen::VectorXd& q) {
    m.jacobian(q.data(), 0.0, values.data());
    if (!numeric) numeric = klu_factor(ap.data(), ai.data(), values.data(), symbolic, &common);
    x = b;
    const auto t0 = Clock::now();
    klu_refactor(ap.data(), ai.data(), values.data(), symbolic, numeric, &common);
    klu_solve(symbolic, numeric, static_cast<int>(x.size()), 1, x.data(), &common);
    benchmark::DoNotOptimize(x.data());
    return seconds_since(t0);
  }
  std::vector<int> ap, ai;
  std::vector<double> values;
  Eigen::VectorXd b, x;
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
};

// Engine cost around the kernel: the engine's time per full-Newton iteration (Jacobian in place, factorise,
// solve, residual, convergence tests, line search) over a solve that takes several iterations from a perturbed
// start, against one bare factorise+solve of the same matrix, interleaved in the same loop. Reports both times and
// iteration_per_kernel; with KLU also the ratio to KLU as it comes (iteration_per_klu_defaults).
void BM_NFourBarNewtonIterationVsKernel(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2, kind_arg(state));
  Workspace ws(m);
  Kernel kernel(m);
  const bool klu = kind_arg(state) == LinearSolverKind::kKlu;
  KluAsItComes bare(m);
  Eigen::VectorXd start = m.initial_positions();
  for (Index j = 0; j < start.size(); ++j) start(j) += 1e-4 * std::sin(1.7 * static_cast<double>(j));
  NewtonOptions full;  // every iteration factorises (JacobianUpdate::kEveryIteration)
  double engine_s = 0.0, kernel_s = 0.0, bare_s = 0.0;
  Index iterations = 0;
  for (auto _ : state) {
    ws.q = start;
    ws.has_factorization = false;
    PositionSummary ps;
    const auto t0 = Clock::now();
    if (solve_position(m, 0.0, full, ws, &ps) != SolveStatus::kSuccess) state.SkipWithError(ps.message.c_str());
    const double e = seconds_since(t0);
    engine_s += e;
    iterations += ps.iterations;
    kernel_s += kernel.time_one(m, start);
    if (klu) bare_s += bare.time_one(m, start);
    state.SetIterationTime(e / std::max(1, ps.iterations));
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["newton_iterations"] = static_cast<double>(iterations) / it;
  state.counters["iteration_us"] = 1e6 * engine_s / static_cast<double>(iterations);
  state.counters["kernel_us"] = 1e6 * kernel_s / it;
  state.counters["iteration_per_kernel"] = (engine_s / static_cast<double>(iterations)) / (kernel_s / it);
  if (klu) {
    state.counters["klu_defaults_us"] = 1e6 * bare_s / it;
    state.counters["iteration_per_klu_defaults"] = (engine_s / static_cast<double>(iterations)) / (bare_s / it);
  }
}
BENCHMARK(BM_NFourBarNewtonIterationVsKernel)->Apply(solver_args)->Unit(benchmark::kMicrosecond)->UseManualTime();

// The model's passes over its constraints, as the Newton loop makes them: Φ and Φq fused (each iterate that will be
// factorised), Φ alone (the last trial point), Φq alone (a factorisation where no Φ is needed). cold 1: before each
// pass a 16 MB buffer is written, which evicts the constraints from the caches as a factorisation does between two
// iterates; cold 0: the passes run back to back on cached data. Reports each pass's time per call and per row.
void BM_NFourBarConstraintPasses(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2);
  const bool cold = state.range(1) != 0;
  const Eigen::VectorXd q = m.initial_positions();
  Eigen::VectorXd phi(m.num_equations());
  std::vector<double> values(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  std::vector<double> evict(std::size_t{1} << 21, 1.0);
  auto flush = [&] {
    if (!cold) return;
    for (double& x : evict) x += 1.0;
    benchmark::DoNotOptimize(evict.data());
  };
  double fused_s = 0.0, residual_s = 0.0, jacobian_s = 0.0;
  for (auto _ : state) {
    flush();
    auto t0 = Clock::now();
    m.residual_and_jacobian(q.data(), 0.0, phi.data(), values.data());
    const double f = seconds_since(t0);
    flush();
    t0 = Clock::now();
    m.residual(q.data(), 0.0, phi.data());
    const double r = seconds_since(t0);
    flush();
    t0 = Clock::now();
    m.jacobian(q.data(), 0.0, values.data());
    const double j = seconds_since(t0);
    benchmark::DoNotOptimize(phi.data());
    benchmark::DoNotOptimize(values.data());
    fused_s += f, residual_s += r, jacobian_s += j;
    state.SetIterationTime(f);
  }
  const double it = static_cast<double>(state.iterations()), rows = static_cast<double>(m.num_equations());
  state.counters["fused_us"] = 1e6 * fused_s / it;
  state.counters["residual_us"] = 1e6 * residual_s / it;
  state.counters["jacobian_us"] = 1e6 * jacobian_s / it;
  state.counters["fused_ns_per_row"] = 1e9 * fused_s / it / rows;
}
BENCHMARK(BM_NFourBarConstraintPasses)
    ->ArgsProduct({{10, 1000, 10000, 100000}, {0, 1}})  // 10: the CI smoke size
    ->ArgNames({"N", "cold"})
    ->Unit(benchmark::kMicrosecond)
    ->UseManualTime();

// Symbolic reuse: one factorisation as phiq does it (refactor with the pivots of the once-analysed pattern) against
// re-analysing the pattern and factorising with pivoting, at the same matrix, interleaved. The sweep needs
// `factorizations_per_step` of them per step (measured), so re-analysing would cost (reanalyse − refactor) ×
// that per step more: reported as step_speedup = (step + extra) / step.
void BM_NFourBarSymbolicReuse(benchmark::State& state) {
  const Index n = state.range(0);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  SweepOptions opt;
  opt.steps = 50;
  SweepSummary sum;
  const auto s0 = Clock::now();
  if (run_sweep(m, opt, ws, nullptr, &sum) != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
  const double step_s = seconds_since(s0) / static_cast<double>(opt.steps + 1);
  const double fact_per_step = static_cast<double>(sum.counters.factorizations) / static_cast<double>(opt.steps + 1);
  std::vector<double> values(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  m.jacobian(ws.q.data(), 1.0, values.data());
  auto reuse = m.symbolic()->make_numeric();
  reuse->factorize(values.data());
  double reuse_s = 0, fresh_s = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    reuse->factorize(values.data());
    reuse_s += seconds_since(t0);
    t0 = Clock::now();
    auto sym = analyse(LinearSolverKind::kKlu, std::make_shared<CscPattern>(m.jacobian_pattern()));
    auto num = sym->make_numeric();
    num->factorize(values.data());
    const double f = seconds_since(t0);
    fresh_s += f;
    state.SetIterationTime(f);
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["refactor_us"] = 1e6 * reuse_s / it;
  state.counters["analyse_factor_us"] = 1e6 * fresh_s / it;
  state.counters["factor_ratio"] = fresh_s / reuse_s;
  state.counters["step_us"] = 1e6 * step_s;
  state.counters["step_speedup"] = (step_s + fact_per_step * (fresh_s - reuse_s) / it) / step_s;
}
BENCHMARK(BM_NFourBarSymbolicReuse)
    ->ArgName("N")
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMicrosecond)
    ->UseManualTime();

}  // namespace

BENCHMARK_MAIN();

// Time per drive step (position + velocity + acceleration) and the cost of the engine around the sparse kernel.
//
//   ./build/bench/phiq_bench --benchmark_format=console
//
// Models are built in code (no scene loading in the timed region).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>

#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::nfourbar;

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

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The bare kernel: one numeric factorisation + solve of the Jacobian at ws.q with a separate numeric object (same
// symbolic analysis). Timed by the caller right next to the engine work, so that their ratio is measured in one
// run on this shared, noisy machine.
struct Kernel {
  explicit Kernel(const Model& m)
      : lu(m.symbolic()->make_numeric()), values(m.jacobian_pattern().nnz()), b(m.num_equations()),
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
    run_sweep(m, opt, ws, [&](const StepView& s) {
      // every 10th row, one bare kernel at this very state (its time is taken out of the sweep's)
      if (s.step % 10 == 0) {
        const auto k0 = Clock::now();
        kernel_s += kernel.time_one(m, s.q), ++kernels;
        in_kernel += seconds_since(k0);
      }
      return true;
    }, &sum);
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
  state.counters["pivoting_per_step"] = static_cast<double>(ws.lu->pivoting_factorizations()) /
                                        static_cast<double>(state.iterations() * (steps + 1));
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
    for (LinearSolverKind k : {LinearSolverKind::kKlu, LinearSolverKind::kUmfpack}) b->Args({n, static_cast<int64_t>(k)});
}

// nfourbar, a quarter turn (π/4 → 3π/4) in 50 steps per iteration. lu: 0 UMFPACK, 1 KLU.
void BM_NFourBarSweepStep(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2, kind_arg(state));
  run_steps(state, m, 50, 1.0);
}
BENCHMARK(BM_NFourBarSweepStep)->Apply(solver_args)->Unit(benchmark::kMillisecond)->UseManualTime();

// Engine cost around the kernel: one engine Newton iteration (residual, Jacobian in place, factorise, solve,
// line-search residual, convergence tests) against one bare factorise+solve of the same matrix, interleaved in
// the same loop. Reports both times and iteration_per_kernel.
void BM_NFourBarNewtonIterationVsKernel(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2, kind_arg(state));
  Workspace ws(m);
  Kernel kernel(m);
  const Eigen::VectorXd start = m.initial_positions() + Eigen::VectorXd::Constant(m.num_coordinates(), 1e-3);
  NewtonOptions one;
  one.max_iterations = 1;
  double engine_s = 0.0, kernel_s = 0.0;
  for (auto _ : state) {
    ws.q = start;
    ws.has_factorization = false;
    const auto t0 = Clock::now();
    solve_position(m, 0.0, one, ws);
    const double e = seconds_since(t0);
    engine_s += e;
    kernel_s += kernel.time_one(m, start);
    state.SetIterationTime(e);
  }
  state.counters["iteration_us"] = 1e6 * engine_s / static_cast<double>(state.iterations());
  state.counters["kernel_us"] = 1e6 * kernel_s / static_cast<double>(state.iterations());
  state.counters["iteration_per_kernel"] = engine_s / kernel_s;
}
BENCHMARK(BM_NFourBarNewtonIterationVsKernel)->Apply(solver_args)->Unit(benchmark::kMicrosecond)->UseManualTime();

}  // namespace

BENCHMARK_MAIN();

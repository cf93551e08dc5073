// Time per drive step (position + velocity + acceleration) and the cost of the engine around the sparse kernel.
//
//   ./build/bench/phiq_bench --benchmark_format=console
//
// Models are built in code (no scene loading in the timed region).
#include <benchmark/benchmark.h>

#include <cmath>

#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

// IFToMM-style N four-bar in natural coordinates: cranks of length 1 pinned at (i, 0), i = 0..N, tips P_i joined by
// N couplers of length 1; crank 0 carries the angle coordinate theta that is driven. Starts on the parallelogram
// solution P_i = (i + cos θ, sin θ). 2N + 3 coordinates.
Model nfourbar(Index n, double theta0, double rate) {
  ModelBuilder b;
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  std::vector<Point2> tip;
  for (Index i = 0; i <= n; ++i) {
    Index x = b.add_coordinate("x" + std::to_string(i), static_cast<double>(i) + std::cos(theta0));
    Index y = b.add_coordinate("y" + std::to_string(i), std::sin(theta0));
    tip.push_back({S(x), S(y)});
  }
  Index th = b.add_coordinate("theta", theta0);
  for (Index i = 0; i <= n; ++i)
    b.add("crank" + std::to_string(i), DistanceSpec{{C(static_cast<double>(i)), C(0)}, tip[i], 1.0});
  for (Index i = 0; i < n; ++i) b.add("coupler" + std::to_string(i), DistanceSpec{tip[i], tip[i + 1], 1.0});
  b.add("crank0_angle", SegmentAngleSpec{{C(0), C(0)}, tip[0], S(th)});
  b.add_driver("motor", th, MotionLaw::linear(theta0, rate));
  return std::move(b).build();
}

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

// Sweeps `steps` steps per benchmark iteration; reports time per step and the work per step.
void run_steps(benchmark::State& state, const Model& m, Index steps, double t_end) {
  SweepOptions opt;
  opt.t_begin = 0.0;
  opt.t_end = t_end;
  opt.steps = steps;
  Workspace ws(m);
  SweepSummary sum;
  Index rows = 0;
  for (auto _ : state) {
    ws.q = m.initial_positions();
    run_sweep(m, opt, ws, [&](const StepView& s) {
      benchmark::DoNotOptimize(s.q.data());
      return true;
    }, &sum);
    if (sum.status != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    rows += sum.steps_completed;
  }
  state.SetItemsProcessed(rows);
  state.counters["newton_per_step"] = static_cast<double>(sum.counters.newton_iterations) / (steps + 1);
  state.counters["factorizations_per_step"] = static_cast<double>(sum.counters.factorizations) / (steps + 1);
  state.counters["coordinates"] = static_cast<double>(m.num_coordinates());
}

void BM_CrankSliderSweepStep(benchmark::State& state) {
  Model m = crank_slider();
  run_steps(state, m, 180, M_PI);
}
BENCHMARK(BM_CrankSliderSweepStep);

// nfourbar, a quarter turn (π/4 → 3π/4) in 50 steps per iteration.
void BM_NFourBarSweepStep(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2);
  run_steps(state, m, 50, 1.0);
}
BENCHMARK(BM_NFourBarSweepStep)->RangeMultiplier(10)->Range(10, 100000)->Unit(benchmark::kMicrosecond);

// The kernel alone: one UMFPACK numeric factorisation + solve of the same Jacobian, symbolic analysis reused.
void BM_NFourBarKernelFactorSolve(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2);
  Workspace ws(m);
  ws.q(m.coordinate_index("x0")) += 1e-3;  // values away from the exact solution, as inside Newton
  m.jacobian(ws.q.data(), 0.1, ws.jacobian_values.data());
  Eigen::VectorXd rhs = Eigen::VectorXd::Ones(m.num_equations()), x(m.num_coordinates());
  for (auto _ : state) {
    if (ws.lu->factorize(ws.jacobian_values.data()) != FactorStatus::kOk) state.SkipWithError("factorize");
    ws.lu->solve(rhs.data(), x.data());
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(BM_NFourBarKernelFactorSolve)->RangeMultiplier(10)->Range(10, 100000)->Unit(benchmark::kMicrosecond);

// One engine Newton iteration on the same matrix: residual + Jacobian + factorise + solve + line-search residual.
void BM_NFourBarNewtonIteration(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2);
  Workspace ws(m);
  const Eigen::VectorXd start = m.initial_positions() + Eigen::VectorXd::Constant(m.num_coordinates(), 1e-3);
  NewtonOptions one;
  one.max_iterations = 1;
  for (auto _ : state) {
    ws.q = start;
    ws.has_factorization = false;
    solve_position(m, 0.0, one, ws);
    benchmark::DoNotOptimize(ws.q.data());
  }
}
BENCHMARK(BM_NFourBarNewtonIteration)->RangeMultiplier(10)->Range(10, 100000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

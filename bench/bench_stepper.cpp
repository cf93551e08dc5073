// What embedding costs: the caller's clock stepped with a Stepper against run_sweep over the same times, and the
// hand loop of solve_position / solve_velocity / solve_acceleration that an embedder wrote before the Stepper. Part
// of phiq_bench (BENCHMARK_MAIN is in bench_kinematics.cpp).
#include <benchmark/benchmark.h>

#include <cmath>

#include "bench_kinematics_timing.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::Clock;
using phiq_bench::nfourbar;
using phiq_bench::seconds_since;

// nfourbar, a quarter turn (π/4 → 3π/4) in 100 steps (q, q̇, q̈), the three ways interleaved in each iteration:
// run_sweep in order on one thread, a Stepper asked the same 101 times (restarted from the initial positions, so that it
// assembles as the sweep does; made once, as a simulator makes it), and the hand loop (a workspace kept across
// iterations, q reset). Manual time: the stepper's. Counters: µs per step of each, stepper_per_sweep (the
// embedding's cost: 1 when stepping costs what the sweep does) and the Newton iterations and factorisations per step
// of each.
void BM_StepperVsSweep(benchmark::State& state) {
  const Index n = state.range(0), steps = 100;
  const Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  SweepOptions opt;
  opt.t_begin = 0.0, opt.t_end = 1.0, opt.steps = steps, opt.threads = 1;
  opt.chunk_steps = steps;  // in order, as the stepper steps
  StepperOptions so;
  static_cast<SolverSettings&>(so) = opt;
  Workspace sweep_ws(m), hand_ws(m);
  Stepper stepper(m, so);
  double sweep_s = 0, stepper_s = 0, hand_s = 0;
  WorkCounters sweep_work, stepper_work, hand_work;
  for (auto _ : state) {
    sweep_ws.q = m.initial_positions();
    SweepSummary sum;
    auto t0 = Clock::now();
    const SolveStatus swept = run_sweep(m, opt, sweep_ws, nullptr, &sum);
    sweep_s += seconds_since(t0);
    if (swept != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    sweep_work = sum.counters;

    const WorkCounters before = stepper.workspace().counters;
    t0 = Clock::now();
    stepper.restart(m.initial_positions());
    for (Index k = 0; k <= steps; ++k)
      if (stepper.step(opt.time_of(k)) != SolveStatus::kSuccess) state.SkipWithError(stepper.summary().message.c_str());
    const double e = seconds_since(t0);
    stepper_s += e;
    state.SetIterationTime(e);
    stepper_work.newton_iterations = stepper.workspace().counters.newton_iterations - before.newton_iterations;
    stepper_work.factorizations = stepper.workspace().counters.factorizations - before.factorizations;

    hand_ws.q = m.initial_positions();
    const WorkCounters hand_before = hand_ws.counters;
    t0 = Clock::now();
    for (Index k = 0; k <= steps; ++k) {
      const double t = opt.time_of(k);
      if (solve_position(m, t, NewtonOptions{}, hand_ws) != SolveStatus::kSuccess ||
          solve_velocity(m, t, hand_ws) != SolveStatus::kSuccess ||
          solve_acceleration(m, t, hand_ws) != SolveStatus::kSuccess)
        state.SkipWithError("the hand loop failed");
    }
    hand_s += seconds_since(t0);
    hand_work.newton_iterations = hand_ws.counters.newton_iterations - hand_before.newton_iterations;
    hand_work.factorizations = hand_ws.counters.factorizations - hand_before.factorizations;
  }
  const double rows = static_cast<double>(state.iterations() * (steps + 1));
  state.counters["sweep_us_per_step"] = 1e6 * sweep_s / rows;
  state.counters["stepper_us_per_step"] = 1e6 * stepper_s / rows;
  state.counters["hand_loop_us_per_step"] = 1e6 * hand_s / rows;
  state.counters["stepper_per_sweep"] = stepper_s / sweep_s;
  state.counters["hand_loop_per_sweep"] = hand_s / sweep_s;
  const double r = static_cast<double>(steps + 1);
  state.counters["sweep_newton_per_step"] = static_cast<double>(sweep_work.newton_iterations) / r;
  state.counters["stepper_newton_per_step"] = static_cast<double>(stepper_work.newton_iterations) / r;
  state.counters["hand_newton_per_step"] = static_cast<double>(hand_work.newton_iterations) / r;
  state.counters["sweep_factorizations_per_step"] = static_cast<double>(sweep_work.factorizations) / r;
  state.counters["stepper_factorizations_per_step"] = static_cast<double>(stepper_work.factorizations) / r;
  state.counters["hand_factorizations_per_step"] = static_cast<double>(hand_work.factorizations) / r;
}
BENCHMARK(BM_StepperVsSweep)->ArgName("N")->Arg(10)->Arg(1000)->Unit(benchmark::kMillisecond)->UseManualTime();

}  // namespace

// What embedding costs: the caller's clock stepped with a Stepper against run_sweep over the same times, and the
// hand loop of solve_position / solve_velocity / solve_acceleration that an embedder wrote before the Stepper. Part
// of phiq_bench (BENCHMARK_MAIN is in bench_kinematics.cpp).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "bench_kinematics_timing.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::Clock;
using phiq_bench::nfourbar;
using phiq_bench::seconds_since;

// nfourbar, a quarter turn (π/4 → 3π/4) in 100 steps (q, q̇, q̈), three ways in each iteration: run_sweep in order
// on one thread, a Stepper asked the same 101 times (restarted from the initial positions, so that it assembles as
// the sweep does; made once, as a simulator makes it), and the hand loop (a workspace kept across iterations, q
// reset). Whichever of the sweep and the stepper runs second in an iteration is faster by some 10 % at N = 10³ (the
// caches the first left warm: measured 1.09 stepper first, 0.83 sweep first), so they take turns:
// stepper_per_sweep (the embedding's cost: 1 when stepping costs what the sweep does) is the geometric mean of the
// medians of the per-iteration ratios of each order (medians: a burst of load on this shared machine moves a mean
// by 15 %). hand_loop_per_sweep: the hand loop, run third, against that iteration's sweep (median). Manual time: the
// stepper's. Also µs per step of each, and the Newton iterations and factorisations per step of each.
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
  // per iteration, against that iteration's sweep: the stepper run first, run second; the hand loop
  std::vector<double> stepper_first, stepper_second, hand_ratios;
  WorkCounters sweep_work, stepper_work, hand_work;
  // Each returns its wall time and leaves its work in *_work.
  auto sweep = [&] {
    sweep_ws.q = m.initial_positions();
    SweepSummary sum;
    const auto t0 = Clock::now();
    const SolveStatus st = run_sweep(m, opt, sweep_ws, nullptr, &sum);
    const double e = seconds_since(t0);
    if (st != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    sweep_work = sum.counters;
    return e;
  };
  auto step = [&] {
    const WorkCounters before = stepper.workspace().counters;
    const auto t0 = Clock::now();
    stepper.restart(m.initial_positions());
    for (Index k = 0; k <= steps; ++k)
      if (stepper.step(opt.time_of(k)) != SolveStatus::kSuccess) state.SkipWithError(stepper.summary().message.c_str());
    const double e = seconds_since(t0);
    stepper_work.newton_iterations = stepper.workspace().counters.newton_iterations - before.newton_iterations;
    stepper_work.factorizations = stepper.workspace().counters.factorizations - before.factorizations;
    return e;
  };
  auto hand_loop = [&] {
    hand_ws.q = m.initial_positions();
    const WorkCounters before = hand_ws.counters;
    const auto t0 = Clock::now();
    for (Index k = 0; k <= steps; ++k) {
      const double t = opt.time_of(k);
      if (solve_position(m, t, NewtonOptions{}, hand_ws) != SolveStatus::kSuccess ||
          solve_velocity(m, t, hand_ws) != SolveStatus::kSuccess ||
          solve_acceleration(m, t, hand_ws) != SolveStatus::kSuccess)
        state.SkipWithError("the hand loop failed");
    }
    const double e = seconds_since(t0);
    hand_work.newton_iterations = hand_ws.counters.newton_iterations - before.newton_iterations;
    hand_work.factorizations = hand_ws.counters.factorizations - before.factorizations;
    return e;
  };
  for (auto _ : state) {
    const bool first = stepper_first.size() <= stepper_second.size();
    double e_sweep, e_step;
    if (first)
      e_step = step(), e_sweep = sweep();
    else
      e_sweep = sweep(), e_step = step();
    const double e_hand = hand_loop();
    state.SetIterationTime(e_step);
    sweep_s += e_sweep, stepper_s += e_step, hand_s += e_hand;
    (first ? stepper_first : stepper_second).push_back(e_step / e_sweep);
    hand_ratios.push_back(e_hand / e_sweep);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? NAN : v[v.size() / 2];
  };
  const double rows = static_cast<double>(state.iterations() * (steps + 1));
  state.counters["sweep_us_per_step"] = 1e6 * sweep_s / rows;
  state.counters["stepper_us_per_step"] = 1e6 * stepper_s / rows;
  state.counters["hand_loop_us_per_step"] = 1e6 * hand_s / rows;
  state.counters["stepper_per_sweep"] = std::sqrt(median(stepper_first) * median(stepper_second));
  state.counters["stepper_first_per_sweep"] = median(stepper_first);
  state.counters["stepper_second_per_sweep"] = median(stepper_second);
  state.counters["hand_loop_per_sweep"] = median(hand_ratios);
  const double r = static_cast<double>(steps + 1);
  const std::pair<const char*, const WorkCounters*> works[] = {
      {"sweep", &sweep_work}, {"stepper", &stepper_work}, {"hand", &hand_work}};
  for (const auto& [name, work] : works) {
    state.counters[std::string(name) + "_newton_per_step"] = static_cast<double>(work->newton_iterations) / r;
    state.counters[std::string(name) + "_factorizations_per_step"] = static_cast<double>(work->factorizations) / r;
  }
}
BENCHMARK(BM_StepperVsSweep)
    ->ArgName("N")
    ->Arg(10)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(20);

}  // namespace

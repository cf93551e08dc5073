// Very long chains do not drift (issue 5, "Hard cases stay numerically stable"): nfourbar with N = 10^5 four-bars
// (200 003 coordinates) swept over 1000 steps of a quarter turn, θ = π/4 … 3π/4, each step started from the previous
// solutions. The exact solution is the parallelogram x_i = i + cos θ, y_i = sin θ at every step; the counters are
// the largest scaled residual max_i |Φ_i| / scale_i (metres: every link is 1 m) at the first and last drive steps
// and over the first and last 100, and the largest deviation from the parallelogram over all steps. One iteration
// (a single sweep; the figure is the drift, not the time). Figures and command: bench/README.md, "Long chains: no
// drift". Arguments: N and derivs (0 positions only, 1 positions, velocities and accelerations).
//
//   ./build/bench/phiq_bench_long_chain --benchmark_filter=N:100000/ --benchmark_counters_tabular=true
//
// A run fails (SkipWithError, "ERROR OCCURRED") when the sweep fails, a value is not finite, a residual exceeds
// the tolerance plus its rounding floor, or a coordinate is more than 1e-9 off the parallelogram (ten times the
// tolerance; tests/test_hard_cases.cpp checks the same at N = 10^4).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "closed_forms.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

double max_of(const std::vector<double>& v, std::size_t from, std::size_t to) {
  return *std::max_element(v.begin() + static_cast<std::ptrdiff_t>(from), v.begin() + static_cast<std::ptrdiff_t>(to));
}

void BM_LongChainNoDrift(benchmark::State& state) {
  const Index n = state.range(0);
  const bool derivs = state.range(1) != 0;
  constexpr Index kSteps = 1000;
  const double w = M_PI / 2;
  const Model m = phiq_bench::nfourbar(n, M_PI / 4, w);
  SweepOptions opt;
  opt.t_begin = 0.0;
  opt.t_end = 1.0;
  opt.steps = kSteps;
  opt.velocities = opt.accelerations = derivs;
  opt.residuals = true;
  opt.threads = 1;
  // the exact motion: the parallelogram (tools/accuracy/closed_forms.hpp), θ = π/4 + w t
  auto exact = phiq::tools::make_closed_form("nfourbar");  // defaults: from π/4 to 3π/4 over t in [0, 1]
  exact->bind(m.coordinate_names());
  std::vector<double> residual, deviation;
  double deviation_v = 0.0;
  bool finite = true;
  SweepSummary sum;
  for (auto _ : state) {
    residual.clear(), deviation.clear(), finite = true;
    phiq::tools::ClosedFormErrors err(*exact);
    Workspace ws(m);
    (void)run_sweep(
        m, opt, ws,
        [&](const StepView& s) {  // its status is sum.status, checked below
          finite = finite && s.q.allFinite() && s.phi && s.phi->allFinite() && (!s.qd || s.qd->allFinite()) &&
                   (!s.qdd || s.qdd->allFinite());
          residual.push_back(s.phi ? scaled_residual(m, *s.phi) : INFINITY);
          deviation.push_back(err.add(s.t, s.q.data(), s.qd ? s.qd->data() : nullptr, s.qdd ? s.qdd->data() : nullptr));
          return true;
        },
        &sum);
    deviation_v = std::max(err.v_error, err.a_error);
    state.SetIterationTime(sum.solve_seconds);
  }
  if (sum.status != SolveStatus::kSuccess || residual.size() != static_cast<std::size_t>(kSteps + 1)) {
    state.SkipWithError(sum.message.c_str());
    return;
  }
  const double max_residual = max_of(residual, 0, residual.size());
  const double max_deviation = max_of(deviation, 0, deviation.size());
  state.counters["coordinates"] = static_cast<double>(m.num_coordinates());
  state.counters["residual_first"] = residual[1];  // step 0 is the assembly from the exact placement
  state.counters["residual_last"] = residual[kSteps];
  state.counters["residual_max_first100"] = max_of(residual, 1, 101);
  state.counters["residual_max_last100"] = max_of(residual, kSteps - 99, kSteps + 1);
  state.counters["deviation_max"] = max_deviation;
  state.counters["deviation_va_max"] = deviation_v;
  state.counters["newton_per_step"] = static_cast<double>(sum.counters.newton_iterations) / kSteps;
  state.counters["factorizations_per_step"] = static_cast<double>(sum.counters.factorizations) / kSteps;
  state.counters["ms_per_step"] = 1e3 * sum.solve_seconds / (kSteps + 1);
  const double floor = opt.newton.tolerance + ToleranceScales::kUlpFloor * static_cast<double>(n + 1);
  if (!finite)
    state.SkipWithError("a value is not finite");
  else if (max_residual > floor)
    state.SkipWithError("a residual exceeds the tolerance");
  else if (max_deviation > 1e-9 || deviation_v > 1e-9)
    state.SkipWithError("off the parallelogram by more than 1e-9");
}

BENCHMARK(BM_LongChainNoDrift)
    ->ArgNames({"N", "derivs"})
    ->ArgsProduct({{100, 100000}, {0, 1}})
    ->Unit(benchmark::kSecond)
    ->UseManualTime()
    ->Iterations(1);

// A sweep that starts exactly on the flat position (θ = 0: every crank, coupler and the ground collinear, Φq singular
// in every loop at once; issue "Trust" §2), 10 steps of 0.01 at rate π/2, against the same sweep started at π/4
// (regular): flat_start_cost = the flat sweep's time ÷ the regular one's (the six sides of the singular start, the
// first assembled block by block). Counters: the start row's q̇ and q̈ against the exact branch (relative to |q̇| = w
// and |q̈| = w²), and the largest position error over the rows. Fails (SkipWithError) when the sweep fails or the
// start row's derivatives are off by more than 1e-6 relative. The sides' rounding, divided by Φq's smallest singular
// value O(δ) (twice for q̈), adds up along the chain: q̈ is within 1e-8 up to N ≈ 10^4 at this rate
// (tests/test_singular_positions.cpp checks N = 10^4 at rate 3π/4), and the start's warning states the spread.
//
//   ./build/bench/phiq_bench_long_chain --benchmark_filter=FlatStart --benchmark_counters_tabular=true
void BM_LongChainFlatStart(benchmark::State& state) {
  const Index n = state.range(0);
  const bool derivs = state.range(1) != 0;
  const double w = M_PI / 2;
  const Model flat = phiq_bench::nfourbar(n, 0.0, w), regular = phiq_bench::nfourbar(n, M_PI / 4, w);
  SweepOptions opt;
  opt.t_begin = 0.0, opt.t_end = 0.1, opt.steps = 10;
  opt.velocities = opt.accelerations = derivs;
  opt.threads = 1;
  char spec[96];
  std::snprintf(spec, sizeof spec, "nfourbar:from=0,to=%.17g", w);
  auto exact = phiq::tools::make_closed_form(spec);
  exact->bind(flat.coordinate_names());
  double flat_seconds = 0.0, regular_seconds = 0.0, q_error = 0.0, v_start = 0.0, a_start = 0.0;
  SweepSummary sum, reg;
  for (auto _ : state) {
    Workspace ws(flat), ws_regular(regular);
    phiq::tools::ClosedFormErrors err(*exact), start(*exact);
    (void)run_sweep(
        flat, opt, ws,
        [&](const StepView& s) {  // its status is sum.status, checked below
          err.add(s.t, s.q.data(), nullptr, nullptr);
          if (s.t == 0.0 && derivs) start.add(s.t, s.q.data(), s.qd->data(), s.qdd->data());
          return true;
        },
        &sum);
    (void)run_sweep(regular, opt, ws_regular, nullptr, &reg);
    flat_seconds += sum.solve_seconds, regular_seconds += reg.solve_seconds;
    q_error = err.q_error, v_start = start.v_error / w, a_start = start.a_error / (w * w);
    state.SetIterationTime(sum.solve_seconds);
  }
  if (sum.status != SolveStatus::kSuccess || reg.status != SolveStatus::kSuccess) {
    state.SkipWithError((sum.message + reg.message).c_str());
    return;
  }
  state.counters["coordinates"] = static_cast<double>(flat.num_coordinates());
  state.counters["flat_start_cost"] = flat_seconds / regular_seconds;
  state.counters["q_error"] = q_error;
  if (derivs) state.counters["start_v_error_rel"] = v_start, state.counters["start_a_error_rel"] = a_start;
  if (q_error > 1e-7 || v_start > 1e-6 || a_start > 1e-6) {
    char why[160];
    std::snprintf(why, sizeof why, "off the exact branch: q %.3g, start q̇ %.3g and q̈ %.3g relative", q_error, v_start,
                  a_start);
    state.SkipWithError(why);
  }
}

BENCHMARK(BM_LongChainFlatStart)
    ->ArgNames({"N", "derivs"})
    ->ArgsProduct({{100, 10000, 100000}, {0, 1}})
    ->Unit(benchmark::kSecond)
    ->UseManualTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();

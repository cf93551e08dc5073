// What sensitivities to design parameters cost: nfourbar (natural coordinates, the scene phiq generate writes) with
// its cranks' and couplers' lengths as parameters, swept a quarter turn in 100 steps with q, q̇, q̈ on one thread,
// with 0, 1 and 2 parameters' ∂q/∂p, ∂q̇/∂p and ∂q̈/∂p. Counters: seconds per row, and per_parameter: the extra
// time of each parameter as a fraction of the sweep without sensitivities. Part of phiq_bench (BENCHMARK_MAIN is in
// bench_kinematics.cpp).
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

// `phiq generate nfourbar N` with the lengths as parameters R (cranks) and L (couplers).
std::string nfourbar_scene(Index n, int parameters) {
  const char* list = parameters == 0 ? "[]" : parameters == 1 ? "[L]" : "[L, R]";
  return "phiq: 1\nparameters: {N: " + std::to_string(n) +
         ", c: 0.7071067811865476, s: 0.7071067811865475, R: 1, L: 1}\n"
         "coordinates:\n  for i in 0..N:\n    x{i}: i + c\n    y{i}: s\n  theta: 0.7853981633974483\n"
         "points:\n  O: [0, 0]\n  for i in 0..N:\n    P{i}: [\"x{i}\", \"y{i}\"]\n"
         "constraints:\n  - for i in 0..N:\n      - {name: \"crank{i}\", type: distance, points: [[i, 0], \"P{i}\"], "
         "length: R}\n  - for i in 0..N-1:\n      - {name: \"coupler{i}\", type: distance, points: [\"P{i}\", "
         "\"P{i+1}\"], length: L}\n  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n"
         "drivers:\n  - {name: motor, coordinate: theta, law: {type: linear, initial: 0.7853981633974483, rate: "
         "1.5707963267948966}}\ntime: {start: 0, end: 1, steps: 100}\n"
         "output: {velocities: true, accelerations: true, sensitivities: " +
         std::string(list) + "}\n";
}

double sweep_seconds(const Scene& s, SweepOptions o) {
  Workspace ws(*s.model);
  SweepSummary sum;
  const auto t0 = std::chrono::steady_clock::now();
  const SolveStatus st = run_sweep(*s.model, o, ws, nullptr, &sum);
  if (st != SolveStatus::kSuccess) throw Error(sum.message);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// range(0) = N, range(1) = parameters. Manual time: the sweep with sensitivities; each iteration also sweeps
// without them (per_parameter compares the two, iteration by iteration, summed).
void BM_SensitivitySweep(benchmark::State& state) {
  const Index n = state.range(0);
  const int parameters = static_cast<int>(state.range(1));
  const Scene s = parse_scene(nfourbar_scene(n, parameters), "nfourbar.yaml");
  SweepOptions o = s.sweep;
  o.threads = 1;
  SweepOptions plain = o;
  plain.sensitivities.clear();
  double with = 0, without = 0;
  for (auto _ : state) {
    const double a = sweep_seconds(s, o), b = sweep_seconds(s, plain);
    with += a, without += b;
    state.SetIterationTime(a);
  }
  const double rows = static_cast<double>(o.steps + 1) * static_cast<double>(state.iterations());
  state.counters["s_per_row"] = with / rows;
  state.counters["per_parameter"] = parameters ? (with / without - 1.0) / parameters : 0.0;
}
BENCHMARK(BM_SensitivitySweep)
    ->ArgsProduct({{10, 1000, 10000}, {0, 1, 2}})
    ->ArgNames({"N", "params"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The adjoint form against the direct one where the parameters outnumber the outputs: nfourbar N with the first P
// cranks' lengths as parameters R0 … R(P−1), one output coordinate (the far tip's y), q, q̇, q̈, 100 steps, one
// thread. adjoint_vs_direct = the adjoint sweep's time ÷ the direct one's (interleaved, summed over iterations);
// both also compute each parameter's right-hand sides along p (four models each), which the adjoint form does not
// save: what it saves is the solves, 3 per parameter against 4 per output.
//
//   build/bench/phiq_bench --benchmark_filter=SensitivityForms --benchmark_counters_tabular=true
std::string nfourbar_parameters_scene(Index n, int parameters) {
  std::string s = "phiq: 1\nparameters: {N: " + std::to_string(n) + ", c: 0.7071067811865476, s: 0.7071067811865475";
  std::string list;
  for (int p = 0; p < parameters; ++p) {
    s += ", R" + std::to_string(p) + ": 1";
    list += (p ? ", R" : "R") + std::to_string(p);
  }
  s += "}\ncoordinates:\n  for i in 0..N:\n    x{i}: i + c\n    y{i}: s\n  theta: 0.7853981633974483\n"
       "points:\n  O: [0, 0]\n  for i in 0..N:\n    P{i}: [\"x{i}\", \"y{i}\"]\nconstraints:\n";
  for (int p = 0; p < parameters; ++p)
    s += "  - {name: crank" + std::to_string(p) + ", type: distance, points: [[" + std::to_string(p) + ", 0], P" +
         std::to_string(p) + "], length: R" + std::to_string(p) + "}\n";
  s += "  - for i in " + std::to_string(parameters) +
       "..N:\n      - {name: \"crank{i}\", type: distance, points: [[i, 0], \"P{i}\"], length: 1}\n"
       "  - for i in 0..N-1:\n      - {name: \"coupler{i}\", type: distance, points: [\"P{i}\", \"P{i+1}\"], "
       "length: 1}\n  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n"
       "drivers:\n  - {name: motor, coordinate: theta, law: {type: linear, initial: 0.7853981633974483, rate: "
       "1.5707963267948966}}\ntime: {start: 0, end: 1, steps: 100}\n"
       "output: {coordinates: [y" +
       std::to_string(n) + "], velocities: true, accelerations: true, sensitivities: [" + list + "]}\n";
  return s;
}

// range(0) = N, range(1) = P.
void BM_SensitivityForms(benchmark::State& state) {
  const Index n = state.range(0);
  const int parameters = static_cast<int>(state.range(1));
  const Scene s = parse_scene(nfourbar_parameters_scene(n, parameters), "nfourbar.yaml");
  SweepOptions adjoint = s.sweep, direct = s.sweep;
  adjoint.threads = direct.threads = 1;
  adjoint.sensitivity_form = SensitivityForm::kAdjoint;
  direct.sensitivity_form = SensitivityForm::kDirect;
  double a = 0, d = 0;
  for (auto _ : state) {
    const double ta = sweep_seconds(s, adjoint), td = sweep_seconds(s, direct);
    a += ta, d += td;
    state.SetIterationTime(ta);
  }
  state.counters["adjoint_vs_direct"] = a / d;
}
BENCHMARK(BM_SensitivityForms)
    ->ArgNames({"N", "P"})
    ->Args({1000, 1})
    ->Args({1000, 2})
    ->Args({1000, 4})
    ->Args({1000, 8})
    ->Args({1000, 32})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);

// What evaluating only a parameter's reach saves (ParameterReach): the scene of BM_SensitivityForms (P cranks'
// lengths, each read by its one bar), swept with each parameter's reach as parameter_reach() finds it against the
// same sweep with every constraint evaluated along every parameter (the reach set to everything, as the sweeps
// evaluated before reaches were found). range(2): 1 the adjoint form, 0 the direct one. reach_vs_everything = the
// first's time ÷ the second's (interleaved, summed over iterations).
//
//   build/bench/phiq_bench --benchmark_filter=SensitivityReach --benchmark_counters_tabular=true

// range(0) = N, range(1) = P, range(2) = adjoint.
void BM_SensitivityReach(benchmark::State& state) {
  const Index n = state.range(0);
  const int parameters = static_cast<int>(state.range(1));
  SceneOverrides keep;  // the models along each parameter, for the sweep that reads every constraint of them
  keep.keep_sensitivity_models = true;
  const Scene s = parse_scene(nfourbar_parameters_scene(n, parameters), "nfourbar.yaml", {}, keep);
  SweepOptions reach = s.sweep;
  reach.threads = 1;
  reach.sensitivity_form = state.range(2) ? SensitivityForm::kAdjoint : SensitivityForm::kDirect;
  SweepOptions everything = reach;
  const auto all = std::make_shared<const ParameterReach>(whole_model_reach(*s.model));
  for (OutputSensitivity& p : everything.sensitivities) p.reach = all;
  double a = 0, e = 0;
  for (auto _ : state) {
    const double ta = sweep_seconds(s, reach), te = sweep_seconds(s, everything);
    a += ta, e += te;
    state.SetIterationTime(ta);
  }
  state.counters["reach_vs_everything"] = a / e;
  state.counters["everything_ms"] = 1e3 * e / static_cast<double>(state.iterations());
}
BENCHMARK(BM_SensitivityReach)
    ->ArgNames({"N", "P", "adjoint"})
    ->ArgsProduct({{1000}, {2, 8, 32}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);

}  // namespace

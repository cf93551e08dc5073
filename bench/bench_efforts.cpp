// What driver efforts cost: nfourbar (natural coordinates, the scene `phiq generate` writes) with a unit mass on
// every link (the derived parts of drawn_parts(): a bar per crank and coupler, mass 1 kg at its middle, I = L²/12)
// under gravity, swept a quarter turn in 100 steps on one thread, each row formatted as a CSV line. With efforts:
// the motor's torque and power by inverse dynamics (one transposed solve per row), and with `reactions` 1 the
// reactions at every moving joint point P{i} (phiq/natural_joints.hpp: on crank i, of the crank and couplers there).
// Counter `ratio`: the sweep with efforts ÷ the sweep with q, q̇, q̈ only, interleaved iteration by iteration and
// summed (issue target ≤ 1.3, with torques and reactions); `cpu_ratio` the same in the process's CPU time.
// BM_EffortSensitivitySweep: the efforts' sensitivities ∂τ/∂p (phiq/effort_sensitivity.hpp) on
// models/dynamics/fourbar_motor_torque.yaml, 2000 steps on one thread, to the motor's speed w (it reaches the
// driver alone) or to the crank's length L2 (it moves a centre and an inertia too: their rates enter dQ/dp), and on
// fourbar_pin_friction.yaml to its journals' μ or L2 (the losses solved with λ: their adjoint and forces' rate).
// Counters: `ratio`, the sweep with efforts and their sensitivities ÷ the sweep with the sensitivities of q only.
//
//   build/bench/phiq_bench --benchmark_filter='EffortsSweep|EffortSensitivitySweep' --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "phiq/drawn_parts.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/natural_joints.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

std::string massive_nfourbar_scene(Index n) {
  return "phiq: 1\nparameters: {N: " + std::to_string(n) +
         ", c: 0.7071067811865476, s: 0.7071067811865475}\n"
         "coordinates:\n  for i in 0..N:\n    x{i}: i + c\n    y{i}: s\n  theta: 0.7853981633974483\n"
         "points:\n  O: [0, 0]\n  for i in 0..N:\n    P{i}: [\"x{i}\", \"y{i}\"]\n"
         "constraints:\n  - for i in 0..N:\n      - {name: \"crank{i}\", type: distance, points: [[i, 0], \"P{i}\"], "
         "length: 1}\n  - for i in 0..N-1:\n      - {name: \"coupler{i}\", type: distance, points: [\"P{i}\", "
         "\"P{i+1}\"], length: 1}\n  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n"
         "drivers:\n  - {name: motor, coordinate: theta, law: {type: linear, initial: 0.7853981633974483, rate: "
         "1.5707963267948966}}\ntime: {start: 0, end: 1, steps: 100}\n"
         "loads: {gravity: [0, -9.81]}\noutput: {velocities: true, accelerations: true}\n";
}

// The process's CPU time (s): what a one-thread sweep costs whatever else the machine runs (its thread may be
// an arena's worker, not the caller).
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Wall-clock seconds of the sweep; the process's CPU seconds added to `cpu` when given.
double csv_sweep_seconds(const Scene& s, const SweepOptions& o, double* cpu = nullptr) {
  Workspace ws(*s.model);
  SweepSummary sum;
  const CsvFormat format(*s.model, o);
  std::string line;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = process_cpu_seconds();
  const SolveStatus st = run_sweep(
      *s.model, o, ws,
      [&](const StepView& v) {
        line.clear();
        format.append_row(v, line);
        benchmark::DoNotOptimize(line.data());
        return true;
      },
      &sum);
  if (st != SolveStatus::kSuccess) throw Error(sum.message);
  if (cpu) *cpu += process_cpu_seconds() - c0;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// range(0) = N, range(1) = reactions (0, 1). Manual time: the sweep with efforts.
void BM_EffortsSweep(benchmark::State& state) {
  const Scene s = parse_scene(massive_nfourbar_scene(state.range(0)), "nfourbar.yaml");
  auto parts = std::make_shared<std::vector<Part>>();
  for (Part p : drawn_parts(s)) {
    if (p.fixed) continue;
    constexpr double kLength = 1.0;  // every link of this scene, along its frame's x from its origin
    p.mass.mass = 1.0, p.mass.center = {kLength / 2, 0, 0};
    p.mass.inertia = {0, 0, 0, 0, kLength * kLength / 12, 0, 0, 0, kLength * kLength / 12};  // a slender bar
    p.mass_source = MassSource::kStated, p.shapes.clear();
    parts->push_back(std::move(p));
  }
  SweepOptions plain = s.sweep;
  plain.threads = 1;
  SweepOptions with = plain;
  with.efforts.parts = parts;
  with.efforts.loads = std::make_shared<const Loads>(s.loads);
  with.efforts.constraints = rheonomic_constraints(*s.model);
  with.efforts.power = true;
  if (state.range(1) != 0) {  // each crank's moving point, named by its coordinate
    std::vector<std::pair<std::string, Attachment3>> points;
    for (const Part& p : *parts)
      if (p.frame.kind == PartFrameKind::kPoints && !p.frame.origin.r[0].is_coordinate())
        points.emplace_back("P" + std::to_string(p.frame.x_toward.r[0].coord()), p.frame.x_toward);
    auto natural = std::make_shared<NaturalJoints>(
        find_natural_joints(*parts, s.loads, points, s.model->num_coordinates(), false));
    for (std::size_t j = 0; j < natural->joints.size(); ++j)
      with.efforts.reactions.push_back({-1, false, static_cast<int>(j)});
    with.efforts.natural = natural;
  }
  double a_sum = 0, b_sum = 0, a_cpu = 0, b_cpu = 0;
  for (auto _ : state) {
    const double a = csv_sweep_seconds(s, with, &a_cpu), b = csv_sweep_seconds(s, plain, &b_cpu);
    a_sum += a, b_sum += b;
    state.SetIterationTime(a);
  }
  state.counters["parts"] = static_cast<double>(parts->size());
  state.counters["reactions"] = static_cast<double>(with.efforts.reactions.size());
  state.counters["ratio"] = a_sum / b_sum;
  state.counters["cpu_ratio"] = a_cpu / b_cpu;  // the same in CPU time (a loaded machine)
}
BENCHMARK(BM_EffortsSweep)
    ->ArgsProduct({{10, 1000, 10000}, {0, 1}})
    ->ArgNames({"N", "reactions"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// models/dynamics/fourbar_motor_torque.yaml with the motor's speed a parameter w, 2000 steps, its efforts (or
// none) and the sensitivities to `parameter`; `friction`: fourbar_pin_friction.yaml instead, its pins' journals'
// coefficient a parameter mu.
Scene motor_torque_scene(const std::string& parameter, bool efforts, bool friction = false) {
  const std::string file = friction ? "fourbar_pin_friction.yaml" : "fourbar_motor_torque.yaml";
  std::ifstream in(std::string(PHIQ_MODELS_DIR) + "/dynamics/" + file);
  std::stringstream read;
  read << in.rdbuf();
  std::string text = read.str();
  auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    if (at == std::string::npos) throw Error(file + ": no '" + from + "'");
    text.replace(at, from.size(), to);
  };
  if (friction) {
    replace("L4: 1.0}", "L4: 1.0, mu: 0.15}");
    for (int pin = 0; pin < 4; ++pin) replace("coefficient: 0.15", "coefficient: mu");
    replace("steps: 72", "steps: 2000");
  } else {
    replace("L4: 1.0}", "L4: 1.0, w: 6.283185307179586}");
    replace("rate: 2*pi", "rate: w");
    replace("steps: 120", "steps: 2000");
  }
  text.erase(text.find("output:"));
  text += "output: {velocities: true, accelerations: true, " + std::string(efforts ? "efforts: all, " : "") +
          "sensitivities: [" + parameter + "]}\n";
  return parse_scene(text, "fourbar_motor_torque.yaml");
}

// range(0) = param: 0 the parameter w, 1 L2; 2 mu, 3 L2 of the four-bar with its pins' journals (the losses'
// adjoint and their forces' rate). Manual time: the sweep with efforts and their sensitivities.
void BM_EffortSensitivitySweep(benchmark::State& state) {
  const std::string parameter = state.range(0) == 0 ? "w" : state.range(0) == 2 ? "mu" : "L2";
  const bool friction = state.range(0) >= 2;
  const Scene with = motor_torque_scene(parameter, true, friction),
              plain = motor_torque_scene(parameter, false, friction);
  SweepOptions a_options = with.sweep, b_options = plain.sweep;
  a_options.threads = b_options.threads = 1;
  double a_sum = 0, b_sum = 0;
  for (auto _ : state) {
    const double a = csv_sweep_seconds(with, a_options), b = csv_sweep_seconds(plain, b_options);
    a_sum += a, b_sum += b;
    state.SetIterationTime(a);
  }
  const OutputSensitivity& p = with.sweep.sensitivities.front();
  state.counters["moves_forces"] = p.parts_along[0] || p.loads_along[0] ? 1.0 : 0.0;
  state.counters["ratio"] = a_sum / b_sum;
}
BENCHMARK(BM_EffortSensitivitySweep)
    ->DenseRange(0, 3)
    ->ArgName("param")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

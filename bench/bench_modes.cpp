// Every assembly mode (phiq/modes.hpp): the paths per second and total time of the homotopy on the four-bar, the
// 3-RPR parallel robot and the general Stewart–Gough platform (40 poses, each twice in Euler parameters ±e), on the
// threads TBB gives (--threads: PHIQ_MODES_THREADS), against PHCpack's `phc -b` on the same polynomial systems in
// the same run (the subprocess timed as a whole: its start, root count, tracking and output). bench/README.md.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "modes_stewart.hpp"  // tests/: the general Stewart–Gough platform the modes tests solve too
#include "phiq/phiq.hpp"

namespace {

std::string bench_modes_model(const std::string& rel) {
  std::string path = PHIQ_MODELS_DIR;
  path += '/';
  path += rel;
  return path;
}

phiq::Scene bench_modes_scene(const std::string& which) {
  if (which == "fourbar") return phiq::load_scene(bench_modes_model("seed/fourbar_mixed.yaml"));
  if (which == "rpr3") return phiq::load_scene(bench_modes_model("benchmarks/rpr3.yaml"));
  return phiq::parse_scene(phiq::test::kModesStewartScene, which + ".yaml");
}

void BM_ModesPhiq(benchmark::State& state, const std::string& which) {
  const phiq::Scene scene = bench_modes_scene(which);
  phiq::ModesOptions o;
  o.time = scene.sweep.t_begin;
  if (const char* t = std::getenv("PHIQ_MODES_THREADS")) o.threads = std::atoi(t);
  phiq::AssemblyModes r;
  for (auto _ : state) {
    r = phiq::find_assembly_modes(*scene.model, o);
    benchmark::DoNotOptimize(r.summary.endpoints.data());
  }
  if (r.summary.status != phiq::ModesStatus::kSuccess) state.SkipWithError(r.summary.message.c_str());
  state.counters["paths"] = static_cast<double>(r.summary.paths);
  state.counters["paths/s"] =
      benchmark::Counter(static_cast<double>(r.summary.paths) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["real"] = r.summary.real;
  state.counters["complex"] = r.summary.complex;
  state.counters["singular"] = r.summary.singular;
  state.counters["failed"] = r.summary.failed_paths;
  state.counters["at_infinity"] = r.summary.at_infinity;
  state.counters["end_game"] = r.summary.end_game_paths;
}

void BM_ModesPhc(benchmark::State& state, const std::string& which) {
  if (std::system("command -v phc > /dev/null 2>&1") != 0) {
    state.SkipWithError("phc (Debian package phcpack) is not installed");
    for (auto _ : state) {
    }
    return;
  }
  const phiq::Scene scene = bench_modes_scene(which);
  phiq::ModesOptions o;
  o.time = scene.sweep.t_begin;
  const phiq::ModelPolynomials p = phiq::find_polynomial_system(*scene.model, o);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("phiq_bench_phc_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "in.phc") << phiq::phc_input_text(p.system);
  const std::string command = "cd '" + dir.string() + "' && phc -b in.phc out.phc < /dev/null > /dev/null 2>&1";
  for (auto _ : state) {
    std::filesystem::remove(dir / "out.phc");
    if (std::system(command.c_str()) != 0) state.SkipWithError("phc -b failed");
  }
  std::filesystem::remove_all(dir);
}

BENCHMARK_CAPTURE(BM_ModesPhiq, fourbar, std::string("fourbar"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ModesPhc, fourbar, std::string("fourbar"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ModesPhiq, rpr3, std::string("rpr3"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ModesPhc, rpr3, std::string("rpr3"))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ModesPhiq, stewart, std::string("stewart"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_ModesPhc, stewart, std::string("stewart"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();

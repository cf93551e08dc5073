// Batch throughput (issue 25, "Batches at sweep speed"): the seed's crank-slider swept for many parameter sets as
// `phiq batch SCENE CASES.csv -o OUT.csv` sweeps them (tools/cli/batch_file.cpp) — the scene parsed once per
// thread (ParsedScene), each case read from the tree with its parameters and the shared analysis, made square,
// swept on its own workspace, its rows formatted as CSV with the case column — in steps per second over all the
// cases. Beside it (`setup:0`) the same sweeps and rows on the scene's one model: what the cases cost without
// their per-case set-up, the ceiling of this way of running them. No file is written: the CLI's figure is in
// bench/README.md ("Batches").
#include <benchmark/benchmark.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <string>
#include <vector>

#include "nfourbar_model.hpp"
#include "phiq/parsed_scene.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

// Case k's link lengths: L2 and L3 on a 40 × 50 grid within ±3 % of the scene's 0.3 and 1.0 (as the CLI figure's
// cases file, bench/README.md).
std::pair<double, double> lengths(std::size_t k) {
  return {0.3 * (1 + 0.03 * (static_cast<double>(k % 40) / 19.5 - 1)),
          1.0 * (1 + 0.03 * (static_cast<double>(k / 40 % 50) / 24.5 - 1))};
}

// Arguments: cases, threads, setup (1: each case's scene read from the tree, as the CLI; 0: the scene's own model
// swept for every case).
void BM_BatchCases(benchmark::State& state) {
  const auto cases = static_cast<std::size_t>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const bool setup = state.range(2) != 0;
  std::vector<ParsedScene> trees;
  trees.push_back(ParsedScene::load(std::string(PHIQ_MODELS_DIR) + "/seed/crank_slider_mixed.yaml"));
  for (int w = 1; w < threads; ++w) trees.push_back(trees.front());
  const Scene reference = trees.front().read();
  std::atomic<long long> rows{0}, bytes{0}, failed{0};
  double seconds = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    std::atomic<std::size_t> next{0};
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(
          0, threads,
          [&](int w) {
            std::string text;
            for (std::size_t k; (k = next++) < cases;) {
              Scene own;
              const Scene* scene = &reference;
              if (setup) {
                SceneOverrides o;
                const auto [l2, l3] = lengths(k);
                o.parameters = {{"L2", l2}, {"L3", l3}};
                o.share_analysis_with = reference.model.get();
                own = trees[static_cast<std::size_t>(w)].read(o);
                scene = &own;
              }
              SquareScene square;
              if (prepare_scene(*scene->model, scene->sweep.t_begin, scene->sweep.assembly, &square) !=
                  SolveStatus::kSuccess) {
                ++failed;
                continue;
              }
              const Model& model = square.model(*scene->model);
              Workspace ws(model);
              ws.q = square.start;
              SweepOptions one = scene->sweep;
              one.threads = 1;
              const CsvFormat format(*scene->model, scene->sweep);
              const std::string prefix = std::to_string(k) + ",";
              text.clear();
              SweepSummary s;
              (void)run_sweep(
                  model, one, ws,
                  [&](const StepView& step) {
                    text += prefix;
                    format.append_row(step, text);
                    return true;
                  },
                  &s);
              if (s.status != SolveStatus::kSuccess) ++failed;
              rows += s.steps_completed;
              bytes += static_cast<long long>(text.size());
            }
          },
          tbb::simple_partitioner());
    });
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (failed.load() > 0) state.SkipWithError("a case failed");
  state.counters["steps_per_s"] = static_cast<double>(rows.load()) / seconds;
  state.counters["us_per_case"] = 1e6 * seconds / static_cast<double>(cases * state.iterations());
  state.counters["csv_MB"] = static_cast<double>(bytes.load()) / 1e6 / static_cast<double>(state.iterations());
}
BENCHMARK(BM_BatchCases)
    ->ArgNames({"cases", "threads", "setup"})
    ->Args({2000, 1, 1})
    ->Args({2000, 2, 1})
    ->Args({2000, 1, 0})
    ->Args({2000, 2, 0})
    ->Args({20, 2, 1})  // the smoke size (ctest bench_smoke)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A batch of large cases (issue 25: "nfourbar N = 10³ batches at ≥ 80 % of a single sweep's steps per second per
// core"): 16 cases of nfourbar N = 10³ (2 003 coordinates), each its own start angle and rate, 500 steps with q, q̇,
// q̈, run_batch on `threads` threads (one case per thread at a time), against one sweep of the first case on one
// thread, interleaved. per_core_vs_single = (the batch's steps per second ÷ threads) ÷ the single sweep's (median
// of the iterations' ratios). The cases' models are built before the clock starts (setup_ms_per_case).
//
//   build/bench/phiq_bench --benchmark_filter=BatchNFourBar
void BM_BatchNFourBar(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  constexpr int kCases = 16;
  constexpr Index kLoops = 1000, kSteps = 500;
  const auto b0 = std::chrono::steady_clock::now();
  std::vector<Model> models;
  models.reserve(kCases);
  for (int k = 0; k < kCases; ++k)
    models.push_back(phiq_bench::nfourbar(kLoops, M_PI / 4 + 0.01 * k, M_PI / 2 * (1 + 0.01 * k)));
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - b0).count();
  std::vector<const Model*> pointers;
  for (const Model& m : models) pointers.push_back(&m);
  SweepOptions o;
  o.steps = kSteps;
  o.velocities = o.accelerations = true;
  std::vector<double> ratios;
  double batch_rate = 0.0;
  for (auto _ : state) {
    BatchSummary bs = run_batch(pointers, o, threads, [](std::size_t, const StepView&) { return true; });
    if (bs.failed > 0) {
      state.SkipWithError("a case failed");
      return;
    }
    SweepOptions one = o;
    one.threads = 1;
    Workspace ws(models.front());
    SweepSummary s;
    const auto t0 = std::chrono::steady_clock::now();
    (void)run_sweep(models.front(), one, ws, nullptr, &s);
    const double single = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (s.status != SolveStatus::kSuccess) {
      state.SkipWithError(s.message.c_str());
      return;
    }
    batch_rate = static_cast<double>(kCases * (kSteps + 1)) / bs.solve_seconds;
    ratios.push_back(batch_rate / bs.threads / (static_cast<double>(kSteps + 1) / single));
    state.SetIterationTime(bs.solve_seconds);
  }
  std::sort(ratios.begin(), ratios.end());
  state.counters["steps_per_s"] = batch_rate;
  state.counters["per_core_vs_single"] = ratios[ratios.size() / 2];
  state.counters["setup_ms_per_case"] = 1e3 * setup / kCases;
}
BENCHMARK(BM_BatchNFourBar)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(5);

}  // namespace

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

#include <atomic>
#include <chrono>
#include <string>
#include <vector>

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
              (void)run_sweep(model, one, ws, [&](const StepView& step) {
                text += prefix;
                format.append_row(step, text);
                return true;
              }, &s);
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

}  // namespace

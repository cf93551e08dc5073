// HDF5 results (phiq/hdf5_writer.hpp): what writing a sweep's q, q̇, q̈ to HDF5 costs against solving it, and what
// the deflate and shuffle filters cost and save (bench/README.md, "Writing HDF5").
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_kinematics_timing.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::Clock;
using phiq_bench::nfourbar;
using phiq_bench::seconds_since;

// One thread sweeps nfourbar N (q, q̇, q̈, 200 steps) and hands every row to an Hdf5Writer with filter
// `filter` (0: none, 1: deflate level 1, 2: shuffle + deflate 1, 3: shuffle + deflate 4), in $TMPDIR (use a tmpfs,
// /dev/shm, to time HDF5 and not the disk). Counters: write_per_solve = the writer's time ÷ the solve's (the run
// summary's write_seconds ÷ solve_seconds), file_per_raw = the file's size ÷ the doubles it holds; the real rows
// of a sweep, since rows repeated would compress as no sweep does.
void BM_Hdf5SweepWriting(benchmark::State& state) {
  const Index n = state.range(0);
  const int filter = static_cast<int>(state.range(1));
  const Index steps = 200;
  const Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  OutputPlan plan;
  for (Index j = 0; j < m.num_coordinates(); ++j) plan.coordinate_columns.push_back(j);
  SweepOptions o;
  o.steps = steps;
  o.threads = 1;
  Hdf5Options h;
  h.expected_rows = static_cast<std::size_t>(steps) + 1;
  h.deflate = filter == 0 ? 0 : filter == 3 ? 4 : 1;
  h.shuffle = filter >= 2;
  const std::string path = (std::filesystem::temp_directory_path() / "phiq_bench_hdf5.h5").string();
  double write_s = 0, sweep_s = 0;
  std::uintmax_t bytes = 0;
  for (auto _ : state) {
    Workspace ws(m);
    const auto s0 = Clock::now();
    Hdf5Writer w(path, m, plan, h);
    double wr = 0;
    if (run_sweep(
            m, o, ws,
            [&](const StepView& s) {
              const auto w0 = Clock::now();
              w.append_row(s);
              wr += seconds_since(w0);
              return true;
            },
            nullptr) != SolveStatus::kSuccess)
      state.SkipWithError("the sweep failed");
    const auto c0 = Clock::now();
    w.close();
    wr += seconds_since(c0);
    const double all = seconds_since(s0);
    state.SetIterationTime(all);
    write_s += wr, sweep_s += all - wr;
    bytes = std::filesystem::file_size(path);
  }
  std::filesystem::remove(path);
  const double raw = static_cast<double>(steps + 1) * (3.0 * static_cast<double>(m.num_coordinates()) + 1.0) * 8.0;
  state.counters["write_per_solve"] = write_s / sweep_s;
  state.counters["file_per_raw"] = static_cast<double>(bytes) / raw;
  state.counters["write_MB_per_s"] = raw * static_cast<double>(state.iterations()) / write_s / 1e6;
}
BENCHMARK(BM_Hdf5SweepWriting)
    ->ArgNames({"N", "filter"})
    ->ArgsProduct({{10000}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);

}  // namespace

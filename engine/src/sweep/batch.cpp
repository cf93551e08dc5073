#include "phiq/batch.hpp"

#include <atomic>
#include <chrono>

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "sweep/resources.hpp"

namespace phiq {

BatchSummary run_batch(const std::vector<const Model*>& models, const SweepOptions& options, int threads,
                       const std::function<bool(std::size_t, const StepView&)>& on_step) {
  return run_batch(models, std::vector<SweepOptions>(models.size(), options), threads, on_step);
}

BatchSummary run_batch(const std::vector<const Model*>& models, const std::vector<SweepOptions>& options, int threads,
                       const std::function<bool(std::size_t, const StepView&)>& on_step,
                       const std::vector<Eigen::VectorXd>* starts) {
  if (options.size() != models.size()) throw Error("run_batch: one SweepOptions per model is needed");
  for (const Model* m : models)
    if (!m) throw Error("run_batch: null model");
  if (starts) {
    if (starts->size() != models.size()) throw Error("run_batch: one start per model is needed");
    for (std::size_t c = 0; c < models.size(); ++c)
      if ((*starts)[c].size() != models[c]->num_coordinates())
        throw Error("run_batch: start " + std::to_string(c) + " has the wrong size");
  }
  if (threads < 0 || threads > detail::kMaxThreads)
    throw Error("run_batch: threads must be from 0 (all cores) to 1000000, not " + std::to_string(threads));
  BatchSummary out;
  out.cases.resize(models.size());
  out.threads = threads == 0 ? tbb::info::default_concurrency() : threads;
  const auto start = std::chrono::steady_clock::now();
  tbb::task_arena arena(out.threads);
  arena.execute([&] {
    // one case per task: cases are whole sweeps, far above any scheduling cost
    tbb::parallel_for(std::size_t{0}, models.size(), [&](std::size_t c) {
      Workspace ws(*models[c]);
      if (starts) ws.q = (*starts)[c];
      SweepOptions one = options[c];
      one.threads = 1;  // parallel over cases, not within one
      (void)run_sweep(  // the status is the case summary's (out.cases[c].status)
          *models[c], one, ws,
          on_step ? [&](const StepView& s) { return on_step(c, s); } : std::function<bool(const StepView&)>{},
          &out.cases[c]);
    });
  });
  for (std::size_t c = 0; c < models.size(); ++c) {
    if (out.cases[c].status != SolveStatus::kSuccess) ++out.failed;
    if (c > 0 && models[c]->symbolic() && models[c]->symbolic() == models[0]->symbolic()) ++out.shared_analyses;
  }
  out.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace phiq

/// @file
/// Batch mode: one model structure swept for many parameter sets in parallel.
#pragma once

#include <functional>
#include <vector>

#include "phiq/sweep.hpp"

namespace phiq {

/// What run_batch() did: one SweepSummary per case, in the order of the models.
struct BatchSummary {
  std::vector<SweepSummary> cases;  ///< the summary of each case's sweep
  int threads = 1;                  ///< threads the cases ran on
  Index failed = 0;                 ///< cases whose sweep did not succeed
  double solve_seconds = 0.0;       ///< wall time of the whole batch
  Index shared_analyses = 0;        ///< cases whose model shares the first model's symbolic analysis
};

/// Sweeps every model of `models` with `options` (each case sequentially, SweepOptions::threads is ignored), the
/// cases in parallel on `threads` threads (0: all cores), each on its own Workspace. The models are typically the
/// same scene built for different parameter values, with ModelBuilder::share_analysis_with() so that they share
/// one symbolic analysis. `on_step(case, step)` is called for every row, from the thread running that case: rows
/// of one case in time order, different cases concurrently (the callback must be thread-safe across cases).
/// Returning false stops that case (kCancelled). A failed case does not stop the others.
/// Pre-conditions (phiq::Error): no null model; threads from 0 to 1000000.
BatchSummary run_batch(const std::vector<const Model*>& models, const SweepOptions& options, int threads,
                       const std::function<bool(std::size_t, const StepView&)>& on_step);
/// run_batch() with options per case (`options[c]` for `models[c]`; as many as models, else phiq::Error): for cases
/// whose sweep or outputs depend on their parameters (a time range, an output point at a parameter's distance).
/// `starts`, when given (as many as models, each of its model's size, else phiq::Error), is each case's rough
/// placement instead of its model's initial positions: what prepare_scene() gives a redundant scene (its
/// assembled position, for the model without the redundant rows).
BatchSummary run_batch(const std::vector<const Model*>& models, const std::vector<SweepOptions>& options, int threads,
                       const std::function<bool(std::size_t, const StepView&)>& on_step,
                       const std::vector<Eigen::VectorXd>* starts = nullptr);

}  // namespace phiq

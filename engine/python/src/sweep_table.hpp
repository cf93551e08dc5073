// The rows of one sweep as one table of doubles, what phiq.SweepResult views without a copy: sweep_result.cpp
// fills one for run_sweep, batch_result.cpp one per case of run_batch.
#pragma once

#include "bindings.hpp"

#include <functional>
#include <memory>

namespace phiq::python {

/// The delivered rows of a sweep and its summary. Columns: t, the q columns, the q̇ columns, the q̈ columns, then
/// the outputs (points, drivers, residuals, rcond, sensitivities), named as the CSV's.
struct SweepTable {
  std::unique_ptr<double[]> data;  // rows × columns, row-major; room for the rows a successful sweep delivers
  Index rows = 0;
  std::vector<std::string> columns;
  Index q_columns = 0, v_columns = 0, a_columns = 0, output_columns = 0;
  SweepSummary summary;
  Index width() const { return static_cast<Index>(columns.size()); }
};

/// `scene` swept with `opt` as `phiq run` sweeps it (made square first: the redundant rows of a consistent model
/// left out; an inconsistent or under-driven scene sweeps nothing, its reason in the summary), its rows written
/// into a new table. Runs without the GIL, on the calling thread (opt.threads as set). `keep_going()` is asked
/// every 50 ms at a delivered row, from that thread: false stops the sweep there (kCancelled).
std::shared_ptr<SweepTable> sweep_into_table(const Scene& scene, const SweepOptions& opt, bool identifier_names,
                                             const std::function<bool()>& keep_going);

}  // namespace phiq::python

// `phiq run --summary FILE.json`: the run summary (format phiq::kRunSummaryFormat, tools/README.md), written on
// success and on a failure to solve alike, so that a harness reads why a run failed instead of scraping stderr.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "phiq/phiq.hpp"

namespace phiq::tools {

// Timings of a run, in seconds (tools/README.md, `--summary`).
struct RunTimes {
  double load = 0.0, solve = 0.0, write = 0.0;
};

// The outcome of one sweep as the summaries write it (`run --summary`, `batch --summary`'s cases): status,
// message, failed_step and failed_time (null on success), worst_constraints (the rows of s.worst_rows, named by
// `swept`), appended to `j`.
void add_outcome(nlohmann::ordered_json& j, const Model& swept, const SweepSummary& s);

// Where a report was made: {name, cpu} of the host (host_info.hpp).
nlohmann::ordered_json host_json();

// The summary's JSON text. `swept`: the model the sweep ran on, which names the rows of s.worst_rows (the scene's
// model, or the square model solved on its independent rows). `modes`: the summary's `modes` (mode_count.hpp; null
// when not known).
std::string run_summary_json(const Scene& scene, const Model& swept, const SweepSummary& s, const RunTimes& times,
                             const nlohmann::ordered_json& modes);

}  // namespace phiq::tools

// `phiq run --summary FILE.json`: the run summary (format phiq::kRunSummaryFormat, tools/README.md), written on
// success and on a failure to solve alike, so that a harness reads why a run failed instead of scraping stderr.
#pragma once

#include <string>

#include "phiq/phiq.hpp"

namespace phiq::tools {

// Timings of a run, in seconds (tools/README.md, `--summary`).
struct RunTimes {
  double load = 0.0, solve = 0.0, write = 0.0;
};

// The summary's JSON text. `swept`: the model the sweep ran on, which names the rows of s.worst_rows (the scene's
// model, or the square model solved on its independent rows).
std::string run_summary_json(const Scene& scene, const Model& swept, const SweepSummary& s, const RunTimes& times);

}  // namespace phiq::tools

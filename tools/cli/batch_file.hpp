// `phiq batch SCENE CASES.csv -o OUT.csv|OUT.h5`: every case in one file, committed in case order as the cases
// complete (batch_file.cpp). The per-directory form (`-o DIR`) is batch.cpp's.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "batch_ranks.hpp"
#include "cli_support.hpp"       // OutputSet
#include "phiq/csv_compare.hpp"  // CsvTable: the cases
#include "phiq/scene.hpp"

namespace phiq::tools {

// What `phiq batch` was given.
struct BatchArgs {
  std::string scene, cases, out, summary;
  bool quiet = false;
  int threads = 0;  // 0: all cores
  bool identifier_names = false;
  bool resume = false;  // go on after the cases an earlier run committed to `out` (batch_resume.hpp)
  // --sensitivity: the parameters whose sensitivities every case delivers instead of the scene's
  // output.sensitivities (empty: the scene's)
  std::vector<SensitivityRequest> sensitivities;
};

// True when `-o PATH` names one output file rather than a directory of case files: PATH ends in .csv, .h5 or
// .hdf5 (any case), does not end in '/', and is not an existing directory.
bool is_one_file_output(const std::string& path);

// Case k's parameters (row k of the cases, by the header's names) as scene overrides; the header (line 1 of
// `cases_path`) is where an unknown name is blamed.
SceneOverrides case_overrides(const CsvTable& cases, std::size_t k, const std::string& cases_path);

// What a batch's --summary says of the whole batch (format kBatchSummaryFormat, tools/README.md), for both forms.
struct BatchTotals {
  std::string scene_name;  // the scene's `name` (empty: none)
  std::string directory;   // -o DIR (empty for one file)
  std::string output;      // -o OUT.csv|OUT.h5 (empty for a directory)
  std::size_t cases = 0, failed = 0, written = 0, shared_analyses = 0;
  int threads = 1;          // on every rank
  int ranks = 1;            // MPI ranks (batch_ranks.hpp)
  std::string interrupted;  // the signal that stopped a one-file batch ("SIGTERM"), else empty
  double load_seconds = 0.0, solve_seconds = 0.0;
};

// Writes the batch summary (the totals, then `results`, one entry per case) to `file` and commits it. Returns
// `status`, or 3 when it cannot be written (the error printed).
int commit_batch_summary(OutputSet& outputs, AtomicOutputFile& file, const BatchArgs& args, const BatchTotals& totals,
                         nlohmann::ordered_json results, int status);

// The batch into one file (CSV, or HDF5 for .h5 / .hdf5), on the ranks of `ranks` (rank 0 writes; on one rank,
// the same file). Exit status (rank 0's; the others return 0 once their part is done, or rank 0's set-up error):
// 0 all cases written, 1 some failed (left out, named), 2 bad scene or cases, 3 output error, 128 + signal when
// interrupted (the cases committed by then published, the missing ones named).
int batch_to_one_file(const BatchArgs& args, const CsvTable& cases, BatchRanks& ranks);

}  // namespace phiq::tools

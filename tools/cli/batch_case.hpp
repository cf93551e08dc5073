// One case of a one-file batch (batch_file.cpp): swept on a worker's own parsed tree, its rows formatted in the
// thread that swept it, and what is said of it; and the same as a message from a worker rank to rank 0.
#pragma once

#include <atomic>
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "batch_file.hpp"   // BatchArgs
#include "batch_ranks.hpp"  // CaseMessage
#include "phiq/csv_compare.hpp"
#include "phiq/parsed_scene.hpp"

namespace phiq::tools {

// A finished case's rows, formatted in the thread that swept it: CSV text (the case column first), or the HDF5
// row values (Hdf5Writer::append_values: the case first).
struct CaseRows {
  bool any = false;  // false: a failed case, left out
  std::string text;
  std::vector<double> values;
};

// What is said about a case once the batch ends: its line on standard error and its --summary entry.
struct CaseReport {
  bool complete = false;  // swept to its end (written or failed); not: a case the batch stopped before it ended
  bool failed = false;
  std::string line;
  nlohmann::ordered_json outcome;
};

// A case as its worker leaves it, on any rank: what rank 0 reports and writes of it.
struct CaseResult {
  CaseReport report;
  CaseRows rows;
  bool on_shared_analysis = false;
  long long setup_ns = 0, sweep_ns = 0, format_ns = 0;
};

// A case's --summary entry before it runs.
nlohmann::ordered_json initial_outcome(std::size_t k);

// What every case of the batch is swept with: the command's arguments, the cases, the reference model whose
// symbolic analysis the cases share, the output's kind, and what stops a case at its next row (a signal here, an
// output error, a signal on another rank).
struct BatchCaseSetting {
  const BatchArgs& args;
  const CsvTable& cases;
  const Model& reference;
  bool hdf5 = false;
  const std::atomic<bool>& stop;
  const std::atomic<bool>& abort;
  const std::atomic<int>& remote_signal;
  std::string left_out = "; left out of " + args.out;  // a failed case's line ends with it (built once a batch)
  bool halted() const { return stop.load() || abort.load() || remote_signal.load() != 0; }
};

// Case k, on the thread's own tree: built, made square, swept, its rows formatted into `rows` (a written case's
// buffers, reused). A case that cannot be built, assembled or swept is failed (its line says why); one stopped
// before its end is neither complete nor failed.
CaseResult run_batch_case(const BatchCaseSetting& setting, std::size_t k, ParsedScene& tree, CaseRows rows);

// A worker rank's case, for rank 0 (`signal`: the signal that stopped it, if one did).
CaseMessage to_message(std::size_t k, const CaseResult& r, int signal);

// ... and back, on rank 0: the same report and rows as had the case run there (doubles travel as their bytes).
CaseResult from_message(CaseMessage m);

}  // namespace phiq::tools

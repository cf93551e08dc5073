// `phiq batch SCENE CASES.csv -o OUT.csv|OUT.h5`: every case in one file. The scene is parsed once (a ParsedScene
// per thread); each case is built from the parsed tree in the thread that sweeps it, when it is its turn, so that
// no more cases are held than threads run; the cases go to the file in case order as they complete (a finished
// case waits only for those before it), so that an interrupted or failing batch publishes whole cases, in order.
#include "batch_file.hpp"

#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>

#include "batch_resume.hpp"
#include "cli_support.hpp"
#include "command_support.hpp"
#include "result_file.hpp"
#include "run_summary.hpp"  // a case's outcome as run --summary writes it
#include "phiq/hdf5_reader.hpp"
#include "phiq/parsed_scene.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

bool is_one_file_output(const std::string& path) {
  if (path.empty() || path.back() == '/') return false;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return false;
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".csv" || phiq::has_hdf5_extension(path);
}

SceneOverrides case_overrides(const CsvTable& cases, std::size_t k, const std::string& cases_path) {
  SceneOverrides o;
  for (std::size_t c = 0; c < cases.columns.size(); ++c) o.parameters.emplace_back(cases.columns[c], cases.rows[k][c]);
  o.parameters_source = cases_path + ":1";  // the header names them: its errors are no case's
  return o;
}

int commit_batch_summary(OutputSet& outputs, AtomicOutputFile& file, const BatchArgs& args, const BatchTotals& t,
                         nlohmann::ordered_json results, int status) {
  const auto or_null = [](const std::string& s) {
    return s.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s);
  };
  nlohmann::ordered_json j;
  j["format"] = phiq::kBatchSummaryFormat;
  j["phiq"] = phiq::version();
  j["scene"] = args.scene;
  j["name"] = or_null(t.scene_name);
  j["host"] = host_json();
  j["cases_file"] = args.cases;
  j["directory"] = or_null(t.directory);
  j["output"] = or_null(t.output);
  j["cases"] = t.cases;
  j["failed"] = t.failed;
  j["written"] = t.written;
  j["interrupted"] = or_null(t.interrupted);
  j["ranks"] = t.ranks;
  j["threads"] = t.threads;
  j["shared_analyses"] = t.shared_analyses;
  j["load_seconds"] = t.load_seconds;
  j["solve_seconds"] = t.solve_seconds;
  j["results"] = std::move(results);
  try {
    file.write(json_text(j, 2) + "\n");
    outputs.commit_one(file);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  return status;
}

namespace {

using Nanos = std::atomic<long long>;
void add_time(Nanos& total, Clock::time_point since_t) {
  total += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - since_t).count();
}
double seconds(const Nanos& n) { return static_cast<double>(n.load()) * 1e-9; }

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

// Writes finished cases in case order: a case is written once every case before it has completed; those that
// complete early wait here (about one per thread when cases take alike). `write` runs under the lock: one case
// at a time, in order.
class InOrder {
 public:
  // `first`: the first case to write (cases before it are in the file already: --resume)
  InOrder(std::size_t first, std::function<void(std::size_t, CaseRows&)> write)
      : write_(std::move(write)), next_(first) {}
  // The first case not written yet.
  std::size_t next() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return next_;
  }
  void complete(std::size_t k, CaseRows rows) {
    const std::lock_guard<std::mutex> lock(mutex_);
    waiting_.emplace(k, std::move(rows));
    for (auto it = waiting_.begin(); it != waiting_.end() && it->first == next_; it = waiting_.erase(it), ++next_) {
      write_(it->first, it->second);
      it->second.any = false, it->second.text.clear(), it->second.values.clear();
      spare_.push_back(std::move(it->second));
    }
  }
  // The buffers of a written case, emptied, for the next case: a case's 100 KB of rows freed and allocated again
  // made malloc return memory to the system and take it back each time (brk, TLB flushes: 10 % of a batch).
  CaseRows spare() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (spare_.empty()) return {};
    CaseRows rows = std::move(spare_.back());
    spare_.pop_back();
    return rows;
  }

 private:
  std::function<void(std::size_t, CaseRows&)> write_;
  std::mutex mutex_;
  std::map<std::size_t, CaseRows> waiting_;
  std::vector<CaseRows> spare_;
  std::size_t next_ = 0;
};

// A case as its worker leaves it, on any rank: what rank 0 reports and writes of it.
struct CaseResult {
  CaseReport report;
  CaseRows rows;
  bool on_shared_analysis = false;
  long long setup_ns = 0, sweep_ns = 0, format_ns = 0;
};

// A case's --summary entry before it runs.
nlohmann::ordered_json initial_outcome(std::size_t k) {
  return nlohmann::ordered_json{{"case", k}, {"line", k + 2}, {"file", nullptr}};
}

// A worker rank's case, for rank 0 (`signal`: the signal that stopped it, if one did).
CaseMessage to_message(std::size_t k, const CaseResult& r, int signal) {
  CaseMessage m;
  m.kind = r.report.complete ? CaseMessage::Kind::kDone : CaseMessage::Kind::kStopped;
  m.k = static_cast<std::int64_t>(k);
  m.complete = r.report.complete, m.failed = r.report.failed, m.on_shared_analysis = r.on_shared_analysis;
  m.line = r.report.line;
  m.outcome_json = r.report.outcome.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  m.text = r.rows.text;
  if (!r.rows.values.empty())
    m.values.assign(reinterpret_cast<const char*>(r.rows.values.data()), r.rows.values.size() * sizeof(double));
  m.setup_ns = r.setup_ns, m.sweep_ns = r.sweep_ns, m.format_ns = r.format_ns;
  m.signal = signal;
  return m;
}

// ... and back, on rank 0: the same report and rows as had the case run there (doubles travel as their bytes).
CaseResult from_message(CaseMessage m) {
  CaseResult r;
  r.report.complete = m.complete, r.report.failed = m.failed;
  r.report.line = std::move(m.line);
  r.report.outcome = nlohmann::ordered_json::parse(m.outcome_json);
  r.rows.any = m.complete && !m.failed;
  r.rows.text = std::move(m.text);
  r.rows.values.resize(m.values.size() / sizeof(double));
  if (!r.rows.values.empty())  // (a CSV batch's cases carry none: memcpy to an empty vector's null is undefined)
    std::memcpy(r.rows.values.data(), m.values.data(), r.rows.values.size() * sizeof(double));
  r.on_shared_analysis = m.on_shared_analysis;
  r.setup_ns = m.setup_ns, r.sweep_ns = m.sweep_ns, r.format_ns = m.format_ns;
  return r;
}

}  // namespace
int batch_to_one_file(const BatchArgs& args, const CsvTable& cases, BatchRanks& ranks) {
  BatchArgs a = args;
  if (a.threads <= 0) a.threads = tbb::info::default_concurrency();  // 0: all cores (of this rank)
  const bool hdf5 = phiq::has_hdf5_extension(a.out);
  const bool writer = ranks.rank() == 0;  // the other ranks sweep cases and print nothing
  const std::size_t n = cases.rows.size();
  {
    std::vector<NamedPath> outs{{"-o", a.out}};
    if (!a.summary.empty()) outs.push_back({"--summary", a.summary});
    if (const auto clash = output_clash(outs, {{"the scene", a.scene}, {"the cases", a.cases}}))
      return fail("batch: " + *clash, 2);
  }
  set_interrupt_subject(a.scene, "; no output written");
  // The scene parsed once; its own parameters' scene is the model every case shares its analysis with, and the
  // columns' names.
  const auto load_start = Clock::now();
  std::vector<phiq::ParsedScene> trees;
  std::optional<phiq::Scene> reference;
  try {
    trees.push_back(phiq::ParsedScene::load(a.scene));
    phiq::SceneOverrides plain;
    plain.sensitivities = a.sensitivities, plain.sensitivities_source = "--sensitivity";  // (empty: the scene's)
    reference = trees.front().read(plain);
  } catch (const phiq::SceneError& e) {
    return fail(e.what(), 2);
  }
  try {  // a header naming no parameter is no case's error: refused before anything runs
    phiq::SceneOverrides o = case_overrides(cases, 0, a.cases);
    o.share_analysis_with = reference->model.get();
    (void)trees.front().read(o);
  } catch (const phiq::SceneError& e) {
    if (std::string(e.what()).rfind(a.cases + ":1: ", 0) == 0) return fail(e.what(), 2);
  }  // (case 0's own error is its own: reported as its failure below)
  phiq::CsvFormat format(*reference->model, reference->sweep);
  try {
    if (a.identifier_names) format.set_naming(phiq::ColumnNaming::kIdentifiers);
  } catch (const phiq::Error& e) {
    return fail(a.scene + ": --names identifiers: " + e.what(), 2);
  }
  {
    const std::vector<std::string> names = format.column_names();
    if (std::find(names.begin(), names.end(), "case") != names.end())
      return fail(a.scene + ": a column is named 'case', the batch's case column: rename it", 2);
  }
  for (int w = 1; w < a.threads; ++w) trees.push_back(trees.front());  // a tree per thread (ParsedScene)
  const double load_s = since(load_start);

  // The output now (rank 0's alone): an unwritable path fails before any case runs, and leaves nothing. With
  // --resume, the cases already in the file are copied first and the batch goes on after the last of them.
  OutputSet outputs;
  phiq::AtomicOutputFile* file = nullptr;
  phiq::AtomicOutputFile* summary_file = nullptr;
  std::unique_ptr<phiq::Hdf5Writer> h5;  // after `outputs`: closed before its temporary is removed
  std::uint64_t committed_bytes = 0;
  ResumePoint resumed;  // nothing earlier: the batch from case 0
  int status = 0;
  if (writer) {
    const std::string header = "case," + format.header();
    try {
      if (a.resume && hdf5) {
        std::vector<std::string> columns{"case"};
        for (const std::string& c : format.column_names()) columns.push_back(c);
        resumed = read_resume_point_hdf5(a.out, columns, n);
      } else if (a.resume) {
        resumed = read_resume_point(a.out, header, n);
      }
      if (resumed.first > 0) {  // an earlier run cut inside its last case: that case runs again
        phiq::SceneOverrides o = case_overrides(cases, resumed.first - 1, a.cases);
        o.share_analysis_with = reference->model.get();
        std::size_t case_rows = 0;  // (a case whose scene cannot be read writes none)
        try {
          case_rows = static_cast<std::size_t>(phiq::rows_written(trees.front().read(o).sweep));
        } catch (const phiq::SceneError&) {
        }
        drop_unfinished_case(resumed, case_rows, a.out);
      }
      if (hdf5) check_hdf5_target(a.out);
      file = &outputs.add(
          a.out, hdf5 ? phiq::AtomicOutputFile::Hold::kClosedBetweenWrites : phiq::AtomicOutputFile::Hold::kOpen);
      if (!a.summary.empty()) summary_file = &outputs.add(a.summary);
      if (hdf5) {
        phiq::Hdf5Options o;
        o.scene_path = reference->path;
        o.scene_text = reference->text;
        o.expected_rows = static_cast<std::size_t>(phiq::rows_written(reference->sweep)) * n;
        o.shown_path = file->path();
        o.case_column = true;
        if (a.identifier_names) o.naming = phiq::ColumnNaming::kIdentifiers;
        if (resumed.first > 0) {  // the earlier file, copied to be appended to (its own stays whole meanwhile)
          std::filesystem::copy_file(a.out, file->temporary_path(), std::filesystem::copy_options::overwrite_existing);
          o.append = true;
          o.append_after_rows = resumed.rows;
        }
        h5 = std::make_unique<phiq::Hdf5Writer>(file->temporary_path(), *reference->model, reference->sweep, o);
      } else if (resumed.first > 0) {
        committed_bytes = copy_resumed_cases(a.out, resumed, *file);
      } else {
        file->write(header);
        committed_bytes = header.size();
      }
    } catch (const ResumeError& e) {
      status = fail(e.what(), 2);
    } catch (const phiq::Error& e) {
      status = fail(e.what(), 3);
    } catch (const std::filesystem::filesystem_error& e) {  // copying an HDF5 output to resume it
      status = fail(a.out + ": cannot write: " + e.code().message(), 3);
    }
  }
  if ((status = ranks.agree(status)) != 0) return status;  // every rank stops where rank 0 could not go on

  // Cases commit in order as they complete. A write error stops the batch: the CSV is cut back to the cases it
  // holds whole and published; an HDF5 file is not (a failed write may have left its structure half-written).
  std::atomic<bool> abort{false};
  std::atomic<int> remote_signal{0};  // a signal that stopped a case on another rank
  std::string write_error;
  std::vector<char> written(n, 0);
  std::size_t cases_written = resumed.cases_in_file;
  Nanos setup_ns{0}, sweep_ns{0}, format_ns{0}, write_ns{0};
  InOrder in_order(resumed.first, [&](std::size_t k, CaseRows& rows) {
    if (!rows.any || !write_error.empty()) return;
    const auto w0 = Clock::now();
    try {
      if (h5) {
        const std::size_t m = h5->row_values(), rows_before = h5->rows();
        for (std::size_t at = 0; at < rows.values.size(); at += m) h5->append_values(rows.values.data() + at);
        hand_blocks_to_disk(*h5, rows_before, *file);
      } else {
        file->write(rows.text);
        committed_bytes += rows.text.size();
      }
      written[k] = 1;
      ++cases_written;
    } catch (const phiq::Error& e) {
      write_error = e.what();
      abort = true;
    }
    add_time(write_ns, w0);
  });

  std::vector<CaseReport> reports(n);
  for (std::size_t k = 0; k < n; ++k) reports[k].outcome = initial_outcome(k);
  for (std::size_t k = 0; k < resumed.first; ++k) {  // --resume: the cases before the first it runs
    CaseReport& r = reports[k];
    written[k] = resumed.in_file[k];
    if (written[k]) {
      r.outcome["status"] = "written earlier";  // by the run resumed (its summary has the rest)
    } else {  // it failed in the run resumed (or that run's file had already left it out)
      r.complete = r.failed = true;
      r.outcome["status"] = "failed earlier";
      r.line = a.scene + ": case " + std::to_string(k) + ": not in " + a.out + " (left out by the run resumed)";
    }
  }
  std::atomic<std::size_t> shared{0};  // cases swept on the reference's symbolic analysis
  const std::atomic<bool>& stop = stop_flag();
  auto halted = [&] { return stop.load() || abort.load() || remote_signal.load() != 0; };
  const std::string left_out = "; left out of " + a.out;
  // One case, on the thread's own tree: built, made square, swept, its rows formatted into `rows` (a written
  // case's buffers, reused).
  auto run_case = [&](std::size_t k, phiq::ParsedScene& tree, CaseRows rows) {
    CaseResult result;
    result.report.outcome = initial_outcome(k);
    CaseReport& report = result.report;
    auto fails = [&](const std::string& why) {
      report.complete = report.failed = true;
      report.line = a.scene + ": case " + std::to_string(k) + ": " + why + left_out;
      return std::move(result);
    };
    const auto t0 = Clock::now();
    auto setup_done = [&] {
      result.setup_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
    };
    phiq::SceneOverrides o = case_overrides(cases, k, a.cases);
    o.share_analysis_with = reference->model.get();
    o.sensitivities = a.sensitivities, o.sensitivities_source = "--sensitivity";
    std::optional<phiq::Scene> scene;
    try {
      scene = tree.read(o);
    } catch (const phiq::SceneError& e) {  // its parameters make the scene impossible (a negative length)
      report.outcome["status"] = "scene error";
      report.outcome["message"] = e.what();
      setup_done();
      return fails(std::string(e.what()) + " (line " + std::to_string(k + 2) + " of " + a.cases + ")");
    }
    phiq::SquareScene square;
    if (const auto why = make_square(*scene, &square)) {  // as `phiq run`: one that cannot be fails alone
      phiq::SweepSummary at_start;                        // the first position, before any sweep
      at_start.status = square.assembly.status;
      at_start.message = *why;
      at_start.failed_step = 0;
      at_start.failed_time = scene->sweep.t_begin;
      at_start.worst_rows = square.assembly.worst_rows;
      add_outcome(report.outcome, *scene->model, at_start);
      setup_done();
      return fails(*why);
    }
    const phiq::Model& model = square.model(*scene->model);
    result.on_shared_analysis = model.symbolic() && model.symbolic() == reference->model->symbolic();
    phiq::Workspace ws(model);
    ws.q = square.start;
    phiq::SweepOptions one = scene->sweep;
    one.threads = 1;  // parallel over cases, not within one: each case computed alike on any thread or rank
    const phiq::CsvFormat rows_format(*scene->model, scene->sweep);  // the case's own output points
    const std::string prefix = std::to_string(k) + ",";
    bool last = false;
    std::vector<double> row(hdf5 ? 1 + rows_format.num_values() : 0);  // the case, then the row's values
    setup_done();
    long long format_case_ns = 0;
    phiq::SweepSummary s;
    (void)phiq::run_sweep(
        model, one, ws,
        [&](const phiq::StepView& step) {
          const auto f0 = Clock::now();
          if (hdf5) {  // the values Hdf5Writer::append_row() would store, the case first
            row[0] = static_cast<double>(k);
            rows_format.append_values(step, row.data() + 1);
            rows.values.insert(rows.values.end(), row.begin(), row.end());
          } else {
            rows.text += prefix;
            rows_format.append_row(step, rows.text);
          }
          last = step.step == one.steps;
          format_case_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - f0).count();
          return !halted();
        },
        &s);
    result.format_ns = format_case_ns;
    result.sweep_ns = static_cast<long long>(s.solve_seconds * 1e9) - format_case_ns;
    add_outcome(report.outcome, model, s);
    report.outcome["steps"] = s.steps_completed;
    report.outcome["newton_iterations"] = s.counters.newton_iterations;
    // (a case whose last row was delivered is complete, even if a signal asked it to stop there)
    if (s.status == phiq::SolveStatus::kSuccess || (s.status == phiq::SolveStatus::kCancelled && last)) {
      report.complete = true;
      report.line = a.scene + ": case " + std::to_string(k) + ": " + s.BriefReport();
      rows.any = true;
      result.rows = std::move(rows);
      return result;
    }
    if (s.status != phiq::SolveStatus::kCancelled) return fails(s.message);
    return result;  // stopped before its end: it never completes, and no case after it is written
  };
  // A case's result, wherever it ran, reaches rank 0's report and file here.
  auto deliver = [&](std::size_t k, CaseResult r) {
    setup_ns += r.setup_ns, sweep_ns += r.sweep_ns, format_ns += r.format_ns;
    shared += r.on_shared_analysis ? 1 : 0;
    const bool complete = r.report.complete;
    // the case's time on its thread (set-up, sweep, rows): the costs tools/simulate_batch_ranks.py schedules
    r.report.outcome["seconds"] = static_cast<double>(r.setup_ns + r.sweep_ns + r.format_ns) * 1e-9;
    reports[k] = std::move(r.report);
    if (complete) in_order.complete(k, std::move(r.rows));
  };

  const auto solve_start = Clock::now();
  int all_threads = a.threads;  // on every rank
  {
    StopOnSignal stop_on_signal;  // a signal stops every case at its next row
    std::vector<CaseRows> worker_rows(static_cast<std::size_t>(a.threads));  // a worker rank's buffers, reused
    CaseHandlers h;
    h.run_here = [&](std::size_t k, int w) { deliver(k, run_case(k, trees[w], in_order.spare())); };
    h.run_for_0 = [&](std::size_t k, int w) {
      CaseRows& rows = worker_rows[static_cast<std::size_t>(w)];
      CaseResult r = run_case(k, trees[w], std::move(rows));
      CaseMessage m = to_message(k, r, stop.load() ? interrupt_signal() : 0);
      rows = std::move(r.rows);
      rows.any = false, rows.text.clear(), rows.values.clear();
      return m;
    };
    h.deliver = [&](CaseMessage m) {
      if (m.kind == CaseMessage::Kind::kStopped) remote_signal = m.signal > 0 ? m.signal : 15;
      if (m.kind == CaseMessage::Kind::kDone) deliver(static_cast<std::size_t>(m.k), from_message(std::move(m)));
    };
    h.halted = halted;
    try {
      all_threads = run_cases(ranks, resumed.first, n, a.threads, h);
    } catch (const std::bad_alloc& e) {  // a worker's, any rank's: nothing is published (temporaries go with `outputs`)
      return fail(a.scene + ": out of memory after " + std::to_string(cases_written) + " of " + std::to_string(n) +
                      " cases " + out_of_memory_where(e, a.threads) + " (fewer --threads); no output written",
                  1);
    }
    if (!writer) return 0;  // (rank 0 says how the batch went)
  }
  const double solve_s = since(solve_start);
  const int signal = stop.load() ? interrupt_signal() : remote_signal.load();
  const bool interrupted = signal != 0;

  // Publish what was committed: every case in order, or (interrupted, write error) the cases before the first
  // that did not complete.
  std::string publish_error;
  bool published = false;
  try {
    if (!write_error.empty() && h5) {
      outputs.drop(*file);
    } else {
      if (!write_error.empty()) file->truncate(committed_bytes);
      if (h5) h5->close();
      outputs.commit_one(*file);
      published = true;
    }
  } catch (const phiq::Error& e) {
    publish_error = e.what();
  }
  const std::string written_text =
      std::to_string(published ? cases_written : 0) + " of " + std::to_string(n) + " cases written to " + a.out;
  // Interrupted (not by an output error): the cases from the first unfinished one on are missing from the file.
  const bool stopped = interrupted && write_error.empty() && publish_error.empty();
  const std::size_t first_missing = in_order.next();
  std::size_t failed = 0;
  for (std::size_t k = 0; k < n; ++k) {
    CaseReport& r = reports[k];
    failed += r.failed;
    if (written[k] && published) r.outcome["file"] = a.out;
    if (stopped && k >= first_missing && !r.failed)
      r.outcome["status"] = "missing";  // what --resume runs
    else if (!r.outcome.contains("status"))
      r.outcome["status"] = "not run";  // the batch stopped before its turn
    if (stopped) continue;              // (the one line below says it all)
    if (r.failed)
      std::cerr << "phiq: " << printable(r.line) << "\n";
    else if (!a.quiet && r.complete)
      std::cerr << "phiq: " << printable(r.line) << "\n";
  }
  auto totals = [&] {
    BatchTotals t;
    t.scene_name = reference->name;
    t.output = a.out;
    t.cases = n, t.failed = failed, t.written = published ? cases_written : 0, t.shared_analyses = shared.load();
    t.threads = all_threads;
    t.ranks = ranks.size();
    t.load_seconds = load_s, t.solve_seconds = solve_s;
    if (stopped) t.interrupted = signal_name(signal);
    return t;
  };
  auto results = [&] {
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (CaseReport& r : reports) all.push_back(std::move(r.outcome));
    return all;
  };
  if (stopped) {
    std::string missing;
    if (first_missing < n)
      missing = "; cases " + std::to_string(first_missing) + " to " + std::to_string(n - 1) +
                " missing: the same command with --resume runs only those";
    const int code = fail(a.scene + ": interrupted (" + signal_name(signal) + "); " + written_text +
                              " (the cases before the first unfinished one)" + missing,
                          128 + signal);
    if (summary_file) (void)commit_batch_summary(outputs, *summary_file, a, totals(), results(), code);
    return code;
  }
  const bool output_error = !write_error.empty() || !publish_error.empty();
  if (output_error)  // (the summary, as for -o DIR, is still written: it says which cases are in the file)
    (void)fail((write_error.empty() ? publish_error : write_error) + "; " + written_text +
                   (published ? " (whole cases, in order)" : ""),
               3);
  else if (!a.quiet)
    std::cerr << "phiq: " << printable(a.scene) << ": " << n - failed << " of " << n << " cases in " << printable(a.out)
              << ", " << (ranks.size() > 1 ? ranks.describe() + ", " : "") << all_threads << " threads, "
              << shared.load() << " cases on the scene's symbolic analysis, load " << scientific(load_s, 3)
              << " s, solve " << scientific(solve_s, 3) << " s (thread-seconds: set-up "
              << scientific(seconds(setup_ns), 3) << ", sweep " << scientific(seconds(sweep_ns), 3) << ", rows "
              << scientific(seconds(format_ns), 3) << ", write " << scientific(seconds(write_ns), 3) << ")\n";
  if (summary_file)
    return commit_batch_summary(outputs, *summary_file, a, totals(), results(), output_error ? 3 : failed ? 1 : 0);
  return output_error ? 3 : failed ? 1 : 0;
}

}  // namespace phiq::tools

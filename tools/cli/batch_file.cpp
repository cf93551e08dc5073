// `phiq batch SCENE CASES.csv -o OUT.csv|OUT.h5`: every case in one file. The scene is parsed once (a ParsedScene
// per thread); each case is built from the parsed tree in the thread that sweeps it, when it is its turn, so that
// no more cases are held than threads run; the cases go to the file in case order as they complete (a finished
// case waits only for those before it), so that an interrupted or failing batch publishes whole cases, in order.
#include "batch_file.hpp"

#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>

#include "batch_case.hpp"
#include "batch_resume.hpp"
#include "cli_support.hpp"
#include "command_support.hpp"
#include "result_file.hpp"
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

// The scene parsed once (a tree per thread); its own parameters' scene, `reference`, is the model every case
// shares its analysis with, and `format` its columns' names.
struct BatchScene {
  std::vector<phiq::ParsedScene> trees;
  std::optional<phiq::Scene> reference;
  std::optional<phiq::CsvFormat> format;
  double load_s = 0.0;
};
// Returns the status (2: a bad scene, cases header or column name, its line printed).
int read_batch_scene(const BatchArgs& a, const CsvTable& cases, BatchScene& s) {
  const auto load_start = Clock::now();
  try {
    s.trees.push_back(phiq::ParsedScene::load(a.scene));
    phiq::SceneOverrides plain;
    plain.sensitivities = a.sensitivities, plain.sensitivities_source = "--sensitivity";  // (empty: the scene's)
    s.reference = s.trees.front().read(plain);
  } catch (const phiq::SceneError& e) {
    return fail(e.what(), 2);
  }
  try {  // a header naming no parameter is no case's error: refused before anything runs
    phiq::SceneOverrides o = case_overrides(cases, 0, a.cases);
    o.share_analysis_with = s.reference->model.get();
    (void)s.trees.front().read(o);
  } catch (const phiq::SceneError& e) {
    if (std::string(e.what()).rfind(a.cases + ":1: ", 0) == 0) return fail(e.what(), 2);
  }  // (case 0's own error is its own: reported as its failure below)
  phiq::CsvFormat& format = s.format.emplace(*s.reference->model, s.reference->sweep);
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
  for (int w = 1; w < a.threads; ++w) s.trees.push_back(s.trees.front());  // a tree per thread (ParsedScene)
  s.load_s = since(load_start);
  return 0;
}

// The output (rank 0's alone), made before any case runs so that an unwritable path fails then and leaves nothing:
// the file (and the HDF5 writer on its temporary), the --summary file, the bytes of whole cases in a CSV (what it is
// cut back to on a write error), and with --resume, where the earlier run's file ends.
struct BatchOutput {
  OutputSet outputs;
  phiq::AtomicOutputFile* file = nullptr;
  phiq::AtomicOutputFile* summary_file = nullptr;
  std::unique_ptr<phiq::Hdf5Writer> h5;  // after `outputs`: closed before its temporary is removed
  std::uint64_t committed_bytes = 0;
  ResumePoint resumed;  // nothing earlier: the batch from case 0
};
// With --resume, the cases already in the file are copied first and the batch goes on after the last of them.
// Returns the status (2: a file --resume cannot go on from, 3: an output error; its line printed).
int open_batch_output(const BatchArgs& a, const CsvTable& cases, bool hdf5, BatchScene& s, BatchOutput& out) {
  const std::size_t n = cases.rows.size();
  const phiq::Scene& reference = *s.reference;
  const std::string header = "case," + s.format->header();
  try {
    if (a.resume && hdf5) {
      std::vector<std::string> columns{"case"};
      for (const std::string& c : s.format->column_names()) columns.push_back(c);
      out.resumed = read_resume_point_hdf5(a.out, columns, n);
    } else if (a.resume) {
      out.resumed = read_resume_point(a.out, header, n);
    }
    if (out.resumed.first > 0) {  // an earlier run cut inside its last case: that case runs again
      phiq::SceneOverrides o = case_overrides(cases, out.resumed.first - 1, a.cases);
      o.share_analysis_with = reference.model.get();
      std::size_t case_rows = 0;  // (a case whose scene cannot be read writes none)
      try {
        case_rows = static_cast<std::size_t>(phiq::rows_written(s.trees.front().read(o).sweep));
      } catch (const phiq::SceneError&) {
      }
      drop_unfinished_case(out.resumed, case_rows, a.out);
    }
    if (hdf5) check_hdf5_target(a.out);
    out.file = &out.outputs.add(
        a.out, hdf5 ? phiq::AtomicOutputFile::Hold::kClosedBetweenWrites : phiq::AtomicOutputFile::Hold::kOpen);
    if (!a.summary.empty()) out.summary_file = &out.outputs.add(a.summary);
    if (hdf5) {
      phiq::Hdf5Options o;
      o.scene_path = reference.path;
      o.scene_text = reference.text;
      o.expected_rows = static_cast<std::size_t>(phiq::rows_written(reference.sweep)) * n;
      o.shown_path = out.file->path();
      o.case_column = true;
      if (a.identifier_names) o.naming = phiq::ColumnNaming::kIdentifiers;
      if (out.resumed.first > 0) {  // the earlier file, copied to be appended to (its own stays whole meanwhile)
        std::filesystem::copy_file(a.out, out.file->temporary_path(),
                                   std::filesystem::copy_options::overwrite_existing);
        o.append = true;
        o.append_after_rows = out.resumed.rows;
      }
      out.h5 = std::make_unique<phiq::Hdf5Writer>(out.file->temporary_path(), *reference.model, reference.sweep, o);
    } else if (out.resumed.first > 0) {
      out.committed_bytes = copy_resumed_cases(a.out, out.resumed, *out.file);
    } else {
      out.file->write(header);
      out.committed_bytes = header.size();
    }
  } catch (const ResumeError& e) {
    return fail(e.what(), 2);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  } catch (const std::filesystem::filesystem_error& e) {  // copying an HDF5 output to resume it
    return fail(a.out + ": cannot write: " + e.code().message(), 3);
  }
  return 0;
}

// How the cases went, as rank 0 gathers it: each case's report and whether it is in the file, the cases written,
// the first write error (it stops the batch: `abort`), a signal that stopped a case on another rank, the
// thread-seconds of each part, the cases on the reference's symbolic analysis, the threads on every rank, the
// solve's seconds, and the first case not written when the sweep ended.
struct BatchProgress {
  std::vector<CaseReport> reports;
  std::vector<char> written;
  std::size_t cases_written = 0;
  std::string write_error;
  std::atomic<bool> abort{false};
  std::atomic<int> remote_signal{0};
  Nanos setup_ns{0}, sweep_ns{0}, format_ns{0}, write_ns{0};
  std::atomic<std::size_t> shared{0};
  int all_threads = 0;
  double solve_s = 0.0;
  std::size_t first_missing = 0;
};

// The cases swept on every rank's threads (run_cases); on rank 0 each committed to the file in case order as it
// completes. A write error stops the batch. Returns a status to exit with at once (out of memory, its line printed;
// 0 on a rank other than 0, which reports nothing), or nothing: rank 0 goes on to publish.
std::optional<int> sweep_batch_cases(const BatchArgs& a, const CsvTable& cases, BatchRanks& ranks, bool hdf5,
                                     BatchScene& s, BatchOutput& out, BatchProgress& p) {
  const std::size_t n = cases.rows.size();
  const ResumePoint& resumed = out.resumed;
  p.written.assign(n, 0);
  p.cases_written = resumed.cases_in_file;
  InOrder in_order(resumed.first, [&](std::size_t k, CaseRows& rows) {
    if (!rows.any || !p.write_error.empty()) return;
    const auto w0 = Clock::now();
    try {
      if (out.h5) {
        const std::size_t m = out.h5->row_values(), rows_before = out.h5->rows();
        for (std::size_t at = 0; at < rows.values.size(); at += m) out.h5->append_values(rows.values.data() + at);
        hand_blocks_to_disk(*out.h5, rows_before, *out.file);
      } else {
        out.file->write(rows.text);
        out.committed_bytes += rows.text.size();
      }
      p.written[k] = 1;
      ++p.cases_written;
    } catch (const phiq::Error& e) {
      p.write_error = e.what();
      p.abort = true;
    }
    add_time(p.write_ns, w0);
  });
  p.reports.resize(n);
  for (std::size_t k = 0; k < n; ++k) p.reports[k].outcome = initial_outcome(k);
  for (std::size_t k = 0; k < resumed.first; ++k) {  // --resume: the cases before the first it runs
    CaseReport& r = p.reports[k];
    p.written[k] = resumed.in_file[k];
    if (p.written[k]) {
      r.outcome["status"] = "written earlier";  // by the run resumed (its summary has the rest)
    } else {  // it failed in the run resumed (or that run's file had already left it out)
      r.complete = r.failed = true;
      r.outcome["status"] = "failed earlier";
      r.line = a.scene + ": case " + std::to_string(k) + ": not in " + a.out + " (left out by the run resumed)";
    }
  }
  const std::atomic<bool>& stop = stop_flag();
  const BatchCaseSetting setting{a, cases, *s.reference->model, hdf5, stop, p.abort, p.remote_signal};
  // A case's result, wherever it ran, reaches rank 0's report and file here.
  auto deliver = [&](std::size_t k, CaseResult r) {
    p.setup_ns += r.setup_ns, p.sweep_ns += r.sweep_ns, p.format_ns += r.format_ns;
    p.shared += r.on_shared_analysis ? 1 : 0;
    const bool complete = r.report.complete;
    // the case's time on its thread (set-up, sweep, rows): the costs tools/simulate_batch_ranks.py schedules
    r.report.outcome["seconds"] = static_cast<double>(r.setup_ns + r.sweep_ns + r.format_ns) * 1e-9;
    p.reports[k] = std::move(r.report);
    if (complete) in_order.complete(k, std::move(r.rows));
  };

  const auto solve_start = Clock::now();
  p.all_threads = a.threads;  // on every rank
  {
    StopOnSignal stop_on_signal;  // a signal stops every case at its next row
    std::vector<CaseRows> worker_rows(static_cast<std::size_t>(a.threads));  // a worker rank's buffers, reused
    CaseHandlers h;
    h.run_here = [&](std::size_t k, int w) { deliver(k, run_batch_case(setting, k, s.trees[w], in_order.spare())); };
    h.run_for_0 = [&](std::size_t k, int w) {
      CaseRows& rows = worker_rows[static_cast<std::size_t>(w)];
      CaseResult r = run_batch_case(setting, k, s.trees[w], std::move(rows));
      CaseMessage m = to_message(k, r, stop.load() ? interrupt_signal() : 0);
      rows = std::move(r.rows);
      rows.any = false, rows.text.clear(), rows.values.clear();
      return m;
    };
    h.deliver = [&](CaseMessage m) {
      if (m.kind == CaseMessage::Kind::kStopped) p.remote_signal = m.signal > 0 ? m.signal : 15;
      if (m.kind == CaseMessage::Kind::kDone) deliver(static_cast<std::size_t>(m.k), from_message(std::move(m)));
    };
    h.halted = [&] { return setting.halted(); };
    try {
      p.all_threads = run_cases(ranks, resumed.first, n, a.threads, h);
    } catch (const std::bad_alloc& e) {  // a worker's, any rank's: nothing is published (temporaries go with `outputs`)
      return fail(a.scene + ": out of memory after " + std::to_string(p.cases_written) + " of " + std::to_string(n) +
                      " cases " + out_of_memory_where(e, a.threads) + " (fewer --threads); no output written",
                  1);
    }
    if (ranks.rank() != 0) return 0;  // (rank 0 says how the batch went)
  }
  p.solve_s = since(solve_start);
  p.first_missing = in_order.next();
  return std::nullopt;
}

// Rank 0, once the cases are done: publishes what was committed (every case in order, or, interrupted or after a
// write error, the cases before the first that did not complete; an HDF5 file after a write error is not: its
// structure may be half-written), says how the batch went and writes the --summary. Returns the exit status.
int publish_batch(const BatchArgs& a, BatchRanks& ranks, std::size_t n, BatchScene& s, BatchOutput& out,
                  BatchProgress& p) {
  const int signal = stop_flag().load() ? interrupt_signal() : p.remote_signal.load();
  const bool interrupted = signal != 0;
  std::string publish_error;
  bool published = false;
  try {
    if (!p.write_error.empty() && out.h5) {
      out.outputs.drop(*out.file);
    } else {
      if (!p.write_error.empty()) out.file->truncate(out.committed_bytes);
      if (out.h5) out.h5->close();
      out.outputs.commit_one(*out.file);
      published = true;
    }
  } catch (const phiq::Error& e) {
    publish_error = e.what();
  }
  const std::string written_text =
      std::to_string(published ? p.cases_written : 0) + " of " + std::to_string(n) + " cases written to " + a.out;
  // Interrupted (not by an output error): the cases from the first unfinished one on are missing from the file.
  const bool stopped = interrupted && p.write_error.empty() && publish_error.empty();
  const std::size_t first_missing = p.first_missing;
  std::size_t failed = 0;
  for (std::size_t k = 0; k < n; ++k) {
    CaseReport& r = p.reports[k];
    failed += r.failed;
    if (p.written[k] && published) r.outcome["file"] = a.out;
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
    t.scene_name = s.reference->name;
    t.output = a.out;
    t.cases = n, t.failed = failed, t.written = published ? p.cases_written : 0, t.shared_analyses = p.shared.load();
    t.threads = p.all_threads;
    t.ranks = ranks.size();
    t.load_seconds = s.load_s, t.solve_seconds = p.solve_s;
    if (stopped) t.interrupted = signal_name(signal);
    return t;
  };
  auto results = [&] {
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    for (CaseReport& r : p.reports) all.push_back(std::move(r.outcome));
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
    if (out.summary_file) (void)commit_batch_summary(out.outputs, *out.summary_file, a, totals(), results(), code);
    return code;
  }
  const bool output_error = !p.write_error.empty() || !publish_error.empty();
  if (output_error)  // (the summary, as for -o DIR, is still written: it says which cases are in the file)
    (void)fail((p.write_error.empty() ? publish_error : p.write_error) + "; " + written_text +
                   (published ? " (whole cases, in order)" : ""),
               3);
  else if (!a.quiet)
    std::cerr << "phiq: " << printable(a.scene) << ": " << n - failed << " of " << n << " cases in " << printable(a.out)
              << ", " << (ranks.size() > 1 ? ranks.describe() + ", " : "") << p.all_threads << " threads, "
              << p.shared.load() << " cases on the scene's symbolic analysis, load " << scientific(s.load_s, 3)
              << " s, solve " << scientific(p.solve_s, 3) << " s (thread-seconds: set-up "
              << scientific(seconds(p.setup_ns), 3) << ", sweep " << scientific(seconds(p.sweep_ns), 3) << ", rows "
              << scientific(seconds(p.format_ns), 3) << ", write " << scientific(seconds(p.write_ns), 3) << ")\n";
  if (out.summary_file)
    return commit_batch_summary(out.outputs, *out.summary_file, a, totals(), results(),
                                output_error ? 3
                                : failed     ? 1
                                             : 0);
  return output_error ? 3 : failed ? 1 : 0;
}

}  // namespace

int batch_to_one_file(const BatchArgs& args, const CsvTable& cases, BatchRanks& ranks) {
  BatchArgs a = args;
  if (a.threads <= 0) a.threads = tbb::info::default_concurrency();  // 0: all cores (of this rank)
  const bool hdf5 = phiq::has_hdf5_extension(a.out);
  const bool writer = ranks.rank() == 0;  // the other ranks sweep cases and print nothing
  {
    std::vector<NamedPath> outs{{"-o", a.out}};
    if (!a.summary.empty()) outs.push_back({"--summary", a.summary});
    if (const auto clash = output_clash(outs, {{"the scene", a.scene}, {"the cases", a.cases}}))
      return fail("batch: " + *clash, 2);
  }
  set_interrupt_subject(a.scene, "; no output written");
  BatchScene scene;
  if (const int status = read_batch_scene(a, cases, scene)) return status;
  BatchOutput out;
  int status = writer ? open_batch_output(a, cases, hdf5, scene, out) : 0;
  if ((status = ranks.agree(status)) != 0) return status;  // every rank stops where rank 0 could not go on
  BatchProgress progress;
  if (const auto stopped = sweep_batch_cases(a, cases, ranks, hdf5, scene, out, progress)) return *stopped;
  return publish_batch(a, ranks, cases.rows.size(), scene, out, progress);
}

}  // namespace phiq::tools

// `phiq batch SCENE CASES.csv -o DIR`: the scene swept once per parameter set, the cases in parallel on one
// symbolic analysis, each case's CSV published only when it succeeded. `-o OUT.csv|OUT.h5` (one file for every
// case) is batch_file.cpp's.
#include <atomic>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "batch_file.hpp"
#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "run_summary.hpp"       // a case's outcome as run --summary writes it
#include "phiq/csv_compare.hpp"  // read_csv_table: the cases
#include "phiq/parsed_scene.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// Case k's file in the output directory (k from 0, the row order of the cases).
std::string case_file(const std::string& dir, std::size_t k) { return dir + "/case" + std::to_string(k) + ".csv"; }

// Every case's scene, built in order from the scene parsed once (each shares the first one's analysis). Returns
// the status (non-zero: a scene or case error, its line printed).
int load_case_scenes(const BatchArgs& a, const phiq::CsvTable& cases, std::vector<phiq::Scene>& scenes) {
  scenes.reserve(cases.rows.size());
  std::optional<phiq::ParsedScene> tree;
  try {
    tree.emplace(phiq::ParsedScene::load(a.scene));
  } catch (const phiq::SceneError& e) {
    return fail(e.what(), 2);
  }
  for (std::size_t k = 0; k < cases.rows.size(); ++k) {
    phiq::SceneOverrides o = case_overrides(cases, k, a.cases);
    if (!scenes.empty()) o.share_analysis_with = scenes.front().model.get();
    o.sensitivities = a.sensitivities, o.sensitivities_source = "--sensitivity";  // (empty: the scene's own)
    try {
      scenes.push_back(tree->read(o));
    } catch (const phiq::SceneError& e) {
      // The case is named only when its parameters cause the error: an error of the scene itself (its YAML, a
      // field) is the same without them. Cases after the first loaded the same scene, so theirs are theirs.
      bool from_case = k > 0;
      const std::string what = e.what();
      if (what.rfind(o.parameters_source + ": ", 0) == 0) return fail(what, 2);
      // the first case's error in --sensitivity is the option's (an unknown name); a later one's is its case's
      if (k == 0 && what.rfind(o.sensitivities_source + ": ", 0) == 0) return fail(what, 2);
      if (!from_case) {
        try {
          (void)tree->read();
          from_case = true;
        } catch (const phiq::SceneError& plain) {
          from_case = std::string(plain.what()) != e.what();
        }
      }
      return fail(std::string(e.what()) + (from_case ? " (case " + std::to_string(k) + " of " + a.cases + ", line " +
                                                           std::to_string(k + 2) + ")"
                                                     : ""),
                  2);
    }
  }
  return 0;
}

// The cases made square as `phiq run` does (one that cannot be fails alone, `prepare_errors[k]` saying why), with
// what run_batch takes of those that run (`models`, `starts`, `swept`: their case numbers, in order) and every
// case's CSV format and row buffer (its header first).
struct SquaredCases {
  std::vector<phiq::SquareScene> squares;
  std::vector<std::string> prepare_errors;
  std::vector<const phiq::Model*> models;
  std::vector<Eigen::VectorXd> starts;
  std::vector<std::size_t> swept;
  std::vector<phiq::CsvFormat> formats;
  std::vector<std::string> buffers;
};
// Returns the status (non-zero: --names identifiers refused for the scene, its line printed).
int square_cases(const BatchArgs& a, const std::vector<phiq::Scene>& scenes, SquaredCases& q) {
  q.squares.resize(scenes.size());
  q.prepare_errors.resize(scenes.size());
  q.buffers.resize(scenes.size());
  for (std::size_t k = 0; k < scenes.size(); ++k)
    if (const auto why = make_square(scenes[k], &q.squares[k])) q.prepare_errors[k] = *why;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const phiq::Scene& sc = scenes[k];
    if (q.prepare_errors[k].empty()) {
      q.models.push_back(&q.squares[k].model(*sc.model));
      q.starts.push_back(q.squares[k].start);
      q.swept.push_back(k);
    }
    q.formats.emplace_back(*sc.model, sc.sweep);
    try {  // (names that collide are the scene's, whichever case: the first says so)
      if (a.identifier_names) q.formats[k].set_naming(phiq::ColumnNaming::kIdentifiers);
    } catch (const phiq::Error& e) {
      return fail(a.scene + ": --names identifiers: " + e.what(), 2);
    }
    q.buffers[k] = q.formats[k].header();
  }
  return 0;
}

// The outputs: each case's file (created at its first write, committed when the case completes: `written[k]`), why
// a case's file could not be written, and the --summary file.
struct CaseFiles {
  OutputSet outputs;
  std::vector<phiq::AtomicOutputFile*> files;
  std::vector<char> written;
  std::vector<std::string> write_errors;
  phiq::AtomicOutputFile* summary_file = nullptr;
};

// The swept cases in parallel, each writing its rows to its own file (every 1 MB and at its last row). Each case
// touches only its own buffer and file: the callback is safe across cases without a lock (OutputSet locks what the
// cases share). Each case's own sweep: its output points (and time range) may depend on its parameters.
phiq::BatchSummary sweep_to_case_files(const BatchArgs& a, const std::vector<phiq::Scene>& scenes, SquaredCases& q,
                                       CaseFiles& out) {
  out.write_errors.resize(scenes.size());
  std::vector<phiq::SweepOptions> sweeps;
  for (std::size_t k : q.swept) sweeps.push_back(scenes[k].sweep);
  const std::atomic<bool>& stop = stop_flag();
  StopOnSignal stop_on_signal;  // a signal stops every case at its next row
  return phiq::run_batch(
      q.models, sweeps, a.threads,
      [&](std::size_t c, const phiq::StepView& step) {
        const std::size_t k = q.swept[c];
        q.formats[k].append_row(step, q.buffers[k]);
        // written every 1 MB and at the case's last row: a finished case holds no rows in memory while others run
        const bool last = step.step == sweeps[c].steps;
        if (q.buffers[k].size() > (1u << 20) || last) {
          try {
            if (!out.files[k])  // held open (unnamed) when written at once, else closed between writes
              out.files[k] =
                  &out.outputs.add(case_file(a.out, k), last ? phiq::AtomicOutputFile::Hold::kOpen
                                                             : phiq::AtomicOutputFile::Hold::kClosedBetweenWrites);
            out.files[k]->write(q.buffers[k]);
            if (last) {
              out.outputs.commit_one(*out.files[k]);
              out.written[k] = 1;
            }
          } catch (const phiq::Error& e) {
            out.write_errors[k] = e.what();
            if (out.files[k]) out.outputs.drop(*out.files[k]);
            out.files[k] = nullptr;
            return false;
          }
          if (last)
            std::string().swap(q.buffers[k]);
          else
            q.buffers[k].clear();
        }
        return !stop.load();
      },
      &q.starts);
}

// How the batch went: interrupted (the cases written by then), else each case's line on standard error, the totals
// unless --quiet, and the --summary. Returns the exit status.
int report_directory_batch(const BatchArgs& a, const std::vector<phiq::Scene>& scenes, const SquaredCases& q,
                           CaseFiles& out, const phiq::BatchSummary& sum, double load_s) {
  std::size_t cases_written = 0;
  for (char w : out.written) cases_written += w != 0;
  if (stop_flag().load())
    return fail(a.scene + ": " + interrupt_message() + "; " + std::to_string(cases_written) + " of " +
                    std::to_string(scenes.size()) + " cases written (the others not)",
                interrupt_exit_status());
  int failed = 0;
  bool output_error = false;
  nlohmann::ordered_json results = nlohmann::ordered_json::array();  // each case's outcome, for --summary
  auto result = [&](std::size_t k, const phiq::Model& swept, const phiq::SweepSummary& s, const std::string& error) {
    nlohmann::ordered_json r{{"case", k}, {"line", k + 2}};
    r["file"] = out.written[k] ? nlohmann::ordered_json(case_file(a.out, k)) : nlohmann::ordered_json(nullptr);
    add_outcome(r, swept, s);
    if (!error.empty()) r["status"] = "output error", r["message"] = error;
    r["steps"] = s.steps_completed;
    r["newton_iterations"] = s.counters.newton_iterations;
    results.push_back(r);
  };
  std::size_t c = 0;  // index of case k among the swept ones
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    if (!q.prepare_errors[k].empty()) {
      ++failed;
      std::cerr << "phiq: "
                << printable(a.scene + ": case " + std::to_string(k) + ": " + q.prepare_errors[k]) +
                       "; no output written\n";
      phiq::SweepSummary at_start;  // the first position, before any sweep
      at_start.status = q.squares[k].assembly.status;
      at_start.message = q.prepare_errors[k];
      at_start.failed_step = 0;
      at_start.failed_time = scenes[k].sweep.t_begin;
      at_start.worst_rows = q.squares[k].assembly.worst_rows;
      result(k, *scenes[k].model, at_start, "");
      continue;
    }
    const phiq::SweepSummary& s = sum.cases[c++];
    const std::string& write_error = out.write_errors[k];
    // (a case whose last row was written is complete, even if a signal or a later case asked it to stop)
    const std::string why = !write_error.empty()                      ? write_error
                            : out.written[k]                          ? ""
                            : s.status != phiq::SolveStatus::kSuccess ? s.message
                                                                      : "not written";
    output_error |= !write_error.empty();
    result(k, *q.models[c - 1], s, write_error);
    if (!why.empty()) {
      ++failed;
      std::cerr << "phiq: "
                << printable(a.scene + ": case " + std::to_string(k) + ": " + why) + "; no output written\n";
    } else if (!a.quiet) {
      std::cerr << "phiq: " << printable(a.scene + ": case " + std::to_string(k) + ": " + s.BriefReport()) << "\n";
    }
  }
  if (!a.quiet)
    std::cerr << "phiq: " << printable(a.scene) << ": " << scenes.size() - failed << " of " << scenes.size()
              << " cases in " << printable(a.out) << ", " << sum.threads << " threads, " << sum.shared_analyses + 1
              << " cases on one symbolic analysis, load " << scientific(load_s, 3) << " s, solve "
              << scientific(sum.solve_seconds, 3) << " s\n";
  const int status = output_error ? 3 : failed ? 1 : 0;
  if (out.summary_file) {
    BatchTotals t;
    t.scene_name = scenes.front().name;
    t.directory = a.out;
    t.cases = scenes.size(), t.failed = static_cast<std::size_t>(failed), t.written = cases_written;
    t.shared_analyses = static_cast<std::size_t>(sum.shared_analyses);
    t.threads = sum.threads;
    t.load_seconds = load_s, t.solve_seconds = sum.solve_seconds;
    return commit_batch_summary(out.outputs, *out.summary_file, a, t, std::move(results), status);
  }
  return status;
}

// The batch into a directory of case files, on one rank.
int batch_to_directory(const BatchArgs& a, const phiq::CsvTable& cases) {
  // No case file may replace the scene, the cases or the summary. Each case file is checked against those alone:
  // the case files are distinct names in one directory, and checking them pairwise (output_clash of all of them)
  // stat()ed 4 million pairs for 2 000 cases, 31 s before anything ran.
  for (std::size_t k = 0; k < cases.rows.size(); ++k) {
    std::vector<NamedPath> outs{{"-o", case_file(a.out, k)}};
    if (!a.summary.empty()) outs.push_back({"--summary", a.summary});
    if (const auto clash = output_clash(outs, {{"the scene", a.scene}, {"the cases", a.cases}}))
      return fail("batch: " + *clash, 2);
  }
  set_interrupt_subject(a.scene, "; no output written");
  // Build every case's model from the scene parsed once, then sweep them in parallel.
  std::vector<phiq::Scene> scenes;
  const auto load_start = Clock::now();
  if (const int status = load_case_scenes(a, cases, scenes)) return status;
  const double load_s = since(load_start);
  std::error_code ec;
  std::filesystem::create_directories(a.out, ec);
  if (ec) return fail(a.out + ": cannot create the output directory: " + ec.message(), 3);
  // An unwritable directory fails now, not after the sweeps: a first case file is created and dropped (an unnamed
  // temporary leaves nothing). Each case's file is then created at its first write (its first 1 MB of rows, or
  // its last row) and committed as soon as the case completes, so that an interrupted or failing batch keeps the
  // cases it finished, and no more descriptors are open than cases are running.
  SquaredCases squared;
  CaseFiles out;
  out.files.assign(scenes.size(), nullptr);
  out.written.assign(scenes.size(), 0);
  try {
    if (!phiq::resolve_output_path(case_file(a.out, 0)).direct) out.outputs.drop(out.outputs.add(case_file(a.out, 0)));
    if (!a.summary.empty()) out.summary_file = &out.outputs.add(a.summary);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  if (const int status = square_cases(a, scenes, squared)) return status;
  const phiq::BatchSummary sum = sweep_to_case_files(a, scenes, squared, out);
  return report_directory_batch(a, scenes, squared, out, sum, load_s);
}

// `phiq batch SCENE CASES.csv -o DIR`: the scene swept once per row of CASES.csv (columns: parameter names), the
// cases in parallel, sharing one symbolic analysis; DIR/case<k>.csv per successful case (k from 0, the row order).
int cmd_batch(const std::string& scene_path, const std::string& cases_path, const std::string& dir, bool quiet,
              int threads, const std::string& summary_path, bool identifier_names, bool resume,
              const std::vector<std::string>& sensitivity_args) {
  int join_status = 0;
  const std::unique_ptr<BatchRanks> ranks = BatchRanks::join_command("batch", "batch", &join_status);
  if (!ranks) return join_status;
  phiq::CsvTable cases;
  try {
    cases = phiq::read_csv_table(cases_path);
  } catch (const phiq::Error& e) {
    return ranks->finish(fail(e.what(), 2));
  }
  if (cases.rows.empty()) return ranks->finish(fail(cases_path + ": no cases (one row per parameter set)", 2));
  std::vector<phiq::SensitivityRequest> asked;
  try {
    asked = sensitivity_requests(sensitivity_args);
  } catch (const phiq::Error& e) {  // a STEP that is not a number
    return ranks->finish(fail(e.what(), 2));
  }
  const BatchArgs a{scene_path, cases_path, dir, summary_path, quiet, threads, identifier_names, resume, asked};
  if (is_one_file_output(dir))  // OUT.csv / OUT.h5: every case in one file (batch_file.cpp)
    return ranks->finish(batch_to_one_file(a, cases, *ranks));
  if (ranks->size() > 1)
    return ranks->finish(fail("batch: -o " + dir + ": under mpirun a batch writes one file (-o OUT.csv or OUT.h5)", 2));
  if (resume)
    return fail("batch: --resume continues a one-file output (-o OUT.csv or OUT.h5), not a directory of cases", 2);
  return batch_to_directory(a, cases);
}

// An output directory: not empty, not standard output.
CLI::Validator directory_given() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty()) return "the path is empty";
        return text == "-" ? "'-' (standard output) cannot hold the case files: give a directory or a file" : "";
      },
      "DIR");
}

}  // namespace

Command register_batch(CLI::App& app) {
  struct Args {
    std::string scene, cases, dir;
    bool quiet = false;
    int threads = 0;
    std::string summary;
    std::string names = "dotted";
    bool resume = false;
    std::vector<std::string> sensitivities;
  };
  auto a = std::make_shared<Args>();
  CLI::App* batch =
      app.add_subcommand("batch", "Sweep the scene once per parameter set of a CSV, the cases in parallel");
  batch->add_option("scene", a->scene, "Scene file (YAML)")->required();
  batch->add_option("cases", a->cases, "CSV: a header of parameter names, one row of values per case")->required();
  batch
      ->add_option("-o,--output", a->dir,
                   "OUT.csv or OUT.h5: one file, a `case` column (row of CASES.csv, from 0) first; else a directory "
                   "for case<k>.csv")
      ->required()
      ->check(directory_given());
  batch->add_flag("-q,--quiet", a->quiet, "Print only failures on standard error");
  batch->add_option("--threads", a->threads, "Threads for the cases (0: all cores)")
      ->capture_default_str()
      ->check(thread_count());
  batch
      ->add_option("--summary", a->summary,
                   "Write the batch summary as JSON (each case's outcome, why it failed) to this file ('-': standard "
                   "output)")
      ->transform(output_path("", false));
  batch->add_option("--names", a->names, "Column names: dotted (theta2.v) or identifiers (theta2__v), as run's")
      ->capture_default_str()
      ->check(one_of({"dotted", "identifiers"}));
  batch->add_flag("--resume", a->resume,
                  "Keep the cases an interrupted run of this batch wrote to OUT.csv or OUT.h5 and run only the "
                  "others (a missing OUT: the whole batch)");
  add_sensitivity_option(batch, &a->sensitivities);
  return {batch, [a] {
            const int cases_threads = cap_threads("batch", a->threads, a->quiet);
            return cmd_batch(a->scene, a->cases, a->dir, a->quiet, cases_threads, a->summary, a->names == "identifiers",
                             a->resume, a->sensitivities);
          }};
}

}  // namespace phiq::tools

// `phiq run SCENE [-o OUT.csv|OUT.h5]`: the scene's sweep of positions, velocities and accelerations as CSV or HDF5
// (result_file.hpp), with its summary (stderr, --summary JSON). The CSV goes to its file, or to standard output
// once the sweep succeeded; HDF5 goes to a file only.
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "mode_count.hpp"
#include "progress_bar.hpp"
#include "result_file.hpp"
#include "run_summary.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// The rows a sweep in chunks may hold before they are written in order (SweepOptions::row_buffer_bytes), larger
// than the library's 512 MiB: at 10^6 four-bars a row of q, q̇, q̈ is 48 MB, and 512 MiB held chunks of 11 rows for
// one thread only (threads_reduced); 2 GiB holds two threads' chunks of 16 rows to HDF5 (as doubles: 0.86 GB each).
// (CSV text is about three times wider: one thread there.) Where 512 MiB held a whole chunk's rows (rows under
// 8 MB: up to about 3·10^5 coordinates with q, q̇, q̈), the chunks, and so the rows' bits, are the same.
constexpr std::size_t kRunRowBufferBytes = std::size_t{2} << 30;

// The rows of `phiq run`: encoded by the sweep's threads as CSV text or, for HDF5, packed doubles
// (CsvFormat::append_values: the same doubles as the CSV's), and written here in order, on the calling thread.
class ResultRows : public phiq::RowWriter {
 public:
  // `h5` null: CSV to `file`, or with no file to `spool`.
  ResultRows(const phiq::CsvFormat& csv, phiq::Hdf5Writer* h5, phiq::AtomicOutputFile* file, std::FILE* spool,
             ProgressBar& progress)
      : csv_(csv), h5_(h5), file_(file), spool_(spool), progress_(progress), stop_(stop_flag()) {}
  void encode(const phiq::StepView& step, std::string& out) const override {
    if (step.step == 0) first_q = step.q;  // one thread writes it, read once the sweep is over
    if (!h5_) return csv_.append_row(step, out);
    thread_local std::vector<double> row;  // (the bytes of `out` are not doubles: packed by a copy)
    row.resize(csv_.num_values());
    csv_.append_values(step, row.data());
    out.append(reinterpret_cast<const char*>(row.data()), row.size() * sizeof(double));
  }
  std::size_t max_row_bytes() const override { return h5_ ? csv_.num_values() * sizeof(double) : csv_.max_row_chars(); }
  bool write(const std::string& encoded, phiq::Index, phiq::Index last_step) override {
    const auto w0 = Clock::now();
    if (h5_) {
      const std::size_t rows_before = h5_->rows();
      h5_->append_packed_rows(encoded);
      if (file_) hand_blocks_to_disk(*h5_, rows_before, *file_);
    } else if (pending_.size() + encoded.size() <= kPendingBytes) {  // rows one by one: gathered
      pending_ += encoded;
    } else {  // a chunk's rows: written as they are
      flush();
      put(encoded);
    }
    progress_.update(last_step + 1);
    seconds += since(w0);
    return !stop_.load();
  }
  // A row computed on this thread: formatted straight into what is gathered for the file (CSV), or into the HDF5
  // writer's block, with no encoded copy in between.
  bool write_row(const phiq::StepView& step) override {
    const auto w0 = Clock::now();
    if (step.step == 0) first_q = step.q;
    if (h5_) {
      const std::size_t rows_before = h5_->rows();
      h5_->append_row(step);
      if (file_) hand_blocks_to_disk(*h5_, rows_before, *file_);
    } else {
      csv_.append_row(step, pending_);
      if (pending_.size() > kPendingBytes) flush();
    }
    progress_.update(step.step + 1);
    seconds += since(w0);
    return !stop_.load();
  }
  // The CSV text gathered and not yet written (the header, rows one by one) goes out.
  void flush() {
    put(pending_);
    pending_.clear();
  }
  std::string& pending() { return pending_; }
  double seconds = 0.0;             // writing rows (and formatting those computed on this thread: write_row())
  mutable Eigen::VectorXd first_q;  // the first row's positions (empty until it is solved): the summary's mode

 private:
  static constexpr std::size_t kPendingBytes = std::size_t{1} << 20;
  void put(const std::string& text) {
    if (text.empty()) return;
    if (file_)
      file_->write(text);
    else if (std::fwrite(text.data(), 1, text.size(), spool_) != text.size())
      throw phiq::Error("cannot write the temporary file for standard output");
  }
  const phiq::CsvFormat& csv_;
  phiq::Hdf5Writer* h5_;
  phiq::AtomicOutputFile* file_;
  std::FILE* spool_;
  ProgressBar& progress_;
  const std::atomic<bool>& stop_;
  std::string pending_;
};

// `--mode K`: `start` moved to real assembly mode K of the scene at its first time (phiq/modes.hpp), as `phiq modes`
// numbers them; nothing for K = 0 (the rough placement). Else why not (": --mode …; no output written"): bad input.
// The modes found are left in `found`.
std::optional<std::string> mode_start(const phiq::Scene& scene, int mode, int threads, Eigen::VectorXd* start,
                                      std::optional<phiq::AssemblyModes>* found) {
  if (mode <= 0) return std::nullopt;
  phiq::ModesOptions o;
  o.time = scene.sweep.t_begin;
  o.threads = threads;
  const phiq::AssemblyModes& modes = found->emplace(phiq::find_assembly_modes(*scene.model, o));
  if (modes.summary.status != phiq::ModesStatus::kSuccess)
    return ": --mode: " + modes.summary.message + "; no output written";
  if (static_cast<std::size_t>(mode) > modes.modes.size())
    return ": --mode " + std::to_string(mode) + ": the scene has " + std::to_string(modes.modes.size()) +
           " real assembly modes at t = " + phiq::shortest(scene.sweep.t_begin) +
           " (phiq modes lists them); no output written";
  *start = modes.modes[static_cast<std::size_t>(mode - 1)].q;
  return std::nullopt;
}

// The stderr line's note on rows known only to the rounding level, in the worst coordinate's own unit ("; 22
// row(s) known only to the rounding level: worst 'yB' known to ±2.7e-10 m at t = …"); empty when there are none.
std::string rounding_level_note(const phiq::RowClassAccuracy& r) {
  if (r.rows == 0) return "";
  std::string s = "; " + std::to_string(r.rows) + " row(s) known only to the rounding level: worst ";
  s += r.worst_coordinate.empty() ? phiq::significant(r.worst_error, 3) + " × the tolerance test"
                                  : phiq::known_to_text(r.worst_coordinate, r.worst_known_to, r.worst_unit);
  return s + " at t = " + phiq::format_time(r.worst_time);
}

// Why a sweep failed: its message, and for a square model not assembled at its first position, what the rank
// analysis says: singular there (redundant constraints and missing drivers in equal numbers, or a singular
// placement), or Newton found no descent from the placement (the Jacobian of a Cardan joint at 90° drops rank
// there). The minimum-norm assembly and its rank analysis say which. (Not when the first position was assembled and
// the sweep stopped at its singular start: the rank there counts the loops lying flat at once as freedoms not
// driven.)
std::string failure_message(const phiq::Scene& scene, const phiq::SweepSummary& summary, bool reduced) {
  std::string why = summary.message;
  if (summary.failed_step == 0 && summary.assembly.status != phiq::SolveStatus::kSuccess &&
      summary.status != phiq::SolveStatus::kOutsideTimeDomain && summary.status != phiq::SolveStatus::kOutsideDomain &&
      summary.status != phiq::SolveStatus::kNonFinite && !reduced) {
    Eigen::VectorXd q = scene.model->initial_positions();
    phiq::AssemblySummary as;
    std::unique_ptr<phiq::Model> unused;
    if (phiq::prepare_square(*scene.model, scene.sweep.t_begin, assembly_options(scene), q, &unused, &as) !=
        phiq::SolveStatus::kSuccess)
      why += "; rank analysis: " + as.message;
  }
  return why;
}

// The summary's `modes`: the real assembly modes at the start and the one the first row is in (mode_count.hpp;
// those `--mode` found, else counted within the bound); first_q empty: no row was solved (`assembled` false, the
// count then says why: none real, say).
nlohmann::ordered_json summary_modes(const phiq::Scene& scene, std::optional<phiq::AssemblyModes>& found,
                                     const Eigen::VectorXd& first_q, int threads) {
  const double t = scene.sweep.t_begin;
  const Eigen::VectorXd* position = first_q.size() ? &first_q : nullptr;
  return mode_count_json(found ? counted_modes(scene, t, std::move(*found), position)
                               : count_modes(scene, t, position, threads));
}

// The run's outputs, each made (as a temporary, or a device opened) before the solve so that an unwritable path
// fails before the sweep, and committed together at the end (or none of them appears): -o's file (null: the CSV
// goes to standard output) and --summary's.
struct RunOutputs {
  OutputSet outputs;
  phiq::AtomicOutputFile* file = nullptr;
  phiq::AtomicOutputFile* summary_file = nullptr;
};
// Returns the status (3: a path that cannot be written, its line printed).
int open_run_outputs(const std::string& out_path, const std::string& summary_path, bool hdf5, RunOutputs& out) {
  try {
    if (hdf5) check_hdf5_target(out_path);
    // HDF5 opens its file by name, and its name must be a real path (not /proc/self/fd/N): a named temporary
    if (!out_path.empty())
      out.file = &out.outputs.add(
          out_path, hdf5 ? phiq::AtomicOutputFile::Hold::kClosedBetweenWrites : phiq::AtomicOutputFile::Hold::kOpen);
    if (!summary_path.empty()) out.summary_file = &out.outputs.add(summary_path);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  return 0;
}

// A successful sweep's outputs finished and committed together: the HDF5 file closed, the CSV's last rows written
// (to its file, or the spool copied to standard output), the summary (`found`: the modes --mode found). Returns the
// status (3: an output error, its line printed).
int commit_run(const std::string& scene_path, const phiq::Scene& scene, const phiq::Model& model,
               const phiq::SweepSummary& summary, double load_s, ResultRows& rows, phiq::Hdf5Writer* h5,
               std::FILE* spool, RunOutputs& out, std::optional<phiq::AssemblyModes>& found, int threads) {
  double write_s = rows.seconds;  // writing rows (the sweep's threads encode them: in solve_seconds)
  const double solve_s = summary.solve_seconds - write_s;
  const auto final_write = Clock::now();
  try {
    if (h5) h5->close();
    rows.flush();
    if (out.file) {
      out.file->finish();
    } else {
      // what reaches standard output cannot be taken back: a signal from here on says so
      set_interrupt_subject(scene_path, "; standard output incomplete");
      std::rewind(spool);
      char chunk[1 << 16];
      for (std::size_t n; (n = std::fread(chunk, 1, sizeof chunk, spool)) > 0;)
        if (std::fwrite(chunk, 1, n, stdout) != n)
          throw phiq::Error(std::string("standard output: cannot write: ") + std::strerror(errno));
      if (const auto bad = stdout_error()) throw phiq::Error(*bad);
    }
    write_s += since(final_write);
    if (out.summary_file)
      out.summary_file->write(run_summary_json(scene, model, summary, {load_s, solve_s, write_s},
                                               summary_modes(scene, found, rows.first_q, threads)));
    out.outputs.commit();
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  return 0;
}

// A successful run's lines on standard error (unless --quiet): the redundant equations left out, the sweep's
// warnings, and its brief report (`wrote`: the output file, empty for standard output).
void report_run(const std::string& scene_path, const phiq::AssemblySummary& redundancy,
                const phiq::SweepSummary& summary, const std::string& wrote) {
  if (!redundancy.rank.redundant.empty())
    std::cerr << "phiq: " << printable(scene_path)
              << ": redundant equations left out of the solve (consistent): " << joined(redundancy.rank.redundant)
              << "\n";
  for (const auto& w : summary.warnings)
    std::cerr << "phiq: " << printable(scene_path) << ": warning: t = " << phiq::format_time(w.t) << ": " << w.kind
              << ": " << w.message << "\n";
  std::cerr << "phiq: " << printable(scene_path) << ": " << summary.BriefReport();
  if (summary.min_rcond > 0)
    std::cerr << ", min rcond " << scientific(summary.min_rcond, 3)
              << " at t = " << phiq::format_time(summary.min_rcond_time);
  std::cerr << rounding_level_note(summary.accuracy.rounding_level);
  if (!wrote.empty()) std::cerr << "; wrote " << printable(wrote);
  std::cerr << "\n";
}

// `drv`: the drivers and time grid given to a robot description (--drive, --time; phiq/import_model.hpp).
int cmd_run(const std::string& scene_arg, const std::string& out_path, const std::string& format, int deflate,
            bool quiet, const std::string& summary_path, int threads, double memory_gb, ProgressBar::Mode progress_mode,
            bool identifier_names, const std::vector<std::string>& sets,
            const std::vector<std::string>& sensitivity_args, int mode, const ImportOptions& drv) {
  const std::string scene_path = scene_label(scene_arg);  // "-": standard input, named <stdin>
  // Outputs that would replace the scene or each other are refused before anything is read or solved.
  std::vector<NamedPath> outs;
  if (!out_path.empty()) outs.push_back({"-o", out_path});
  if (!summary_path.empty()) outs.push_back({"--summary", summary_path});
  if (const auto clash = output_clash(outs, {{"the scene", scene_arg == "-" ? "" : scene_arg}}))
    return fail("run: " + *clash, 2);
  const bool hdf5 = result_format(format, out_path) == ResultFormat::kHdf5;
  if (deflate > 0 && !hdf5) return fail("run: --deflate compresses HDF5 results only (-o FILE.h5 or --format hdf5)", 2);
  if (hdf5 && out_path.empty())
    return fail("run: --format hdf5 needs -o FILE: HDF5 is not written to standard output", 2);
  if (out_path.empty() && stdout_was_closed()) return fail("run: standard output: cannot write: it is closed", 3);
  set_interrupt_subject(scene_path, "; no output written");
  const auto load_start = Clock::now();
  // (--sensitivity's parameters in place of the scene's output.sensitivities, whose models are then not made)
  std::optional<phiq::Scene> loaded = load_or_report(scene_arg, sets, sensitivity_args, drv);
  if (!loaded) return 2;
  phiq::Scene& scene = *loaded;
  const double load_s = since(load_start);

  RunOutputs out;
  if (const int status = open_run_outputs(out_path, summary_path, hdf5, out)) return status;
  OutputSet& outputs = out.outputs;
  phiq::AtomicOutputFile* const file = out.file;
  phiq::AtomicOutputFile* const summary_file = out.summary_file;

  std::optional<phiq::AssemblyModes> found;  // by --mode
  // A run that cannot be solved still commits its summary (status, where, why: for harnesses), never the CSV. Its
  // message is the line stderr gets.
  auto failed = [&](const phiq::Model& swept, phiq::SweepSummary s, const RunTimes& times, const std::string& why,
                    const Eigen::VectorXd& first_q = {}) {
    s.message = why;
    if (summary_file) try {
        summary_file->write(run_summary_json(scene, swept, s, times, summary_modes(scene, found, first_q, threads)));
        outputs.commit_one(*summary_file);
      } catch (const phiq::Error& e) {
        return fail(e.what(), 3);
      }
    return fail(scene_path + ": " + why +
                    (summary_file   ? "; wrote the summary only"
                     : outs.empty() ? ""
                                    : "; no output written"),
                1);
  };
  // inconsistent or under-driven models stop here, naming the constraints
  phiq::SquareScene square;
  if (const auto why = make_square(scene, &square)) {
    phiq::SweepSummary at_start;  // the first position, before any sweep
    at_start.status = square.assembly.status;
    at_start.failed_step = 0;
    at_start.failed_time = scene.sweep.t_begin;
    at_start.worst_rows = square.assembly.worst_rows;
    return failed(*scene.model, at_start, {load_s, 0.0, 0.0}, *why);
  }
  if (const auto bad = mode_start(scene, mode, threads, &square.start, &found)) return fail(scene_path + *bad, 2);
  const phiq::AssemblySummary& redundancy = square.assembly;
  const phiq::Model& model = square.model(*scene.model);
  scene.sweep.threads = threads;
  scene.sweep.memory_budget = static_cast<std::size_t>(memory_gb * 1e9);
  scene.sweep.row_buffer_bytes = kRunRowBufferBytes;
  phiq::Workspace ws(model);
  ws.q = square.start;
  // columns from the scene's output plan and model (its constraints); residuals of a model solved on its
  // independent rows are evaluated on the whole scene model (CsvFormat)
  phiq::CsvFormat csv(*scene.model, scene.sweep);
  const phiq::ColumnNaming naming =  // the CSV's and the HDF5 file's column names alike
      identifier_names ? phiq::ColumnNaming::kIdentifiers : phiq::ColumnNaming::kDotted;
  try {
    csv.set_naming(naming);
  } catch (const phiq::Error& e) {  // names that would collide: the scene's to change
    return fail(scene_path + ": --names identifiers: " + e.what(), 2);
  }
  std::unique_ptr<phiq::Hdf5Writer> h5;  // after `outputs`: closed before its temporary is removed
  try {
    if (hdf5) h5 = open_hdf5_results(*file, scene, deflate, naming);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }

  // Where the CSV goes: the output file, or standard output after success, spooled through an anonymous temporary
  // file so that memory stays bounded however long the sweep is.
  std::FILE* spool = nullptr;
  if (!file && !(spool = std::tmpfile())) return fail("cannot create a temporary file for standard output", 3);
  struct CloseSpool {
    std::FILE* f;
    ~CloseSpool() {
      if (f) std::fclose(f);
    }
  } close_spool{spool};

  phiq::SweepSummary summary;
  ProgressBar progress(scene.sweep.steps + 1, quiet ? ProgressBar::Mode::kNever : progress_mode);
  ResultRows rows(csv, h5.get(), file, spool, progress);
  if (!h5) rows.pending() = csv.header();
  try {
    StopOnSignal stop_on_signal;                                    // a signal stops the sweep at its next rows
    (void)phiq::run_sweep(model, scene.sweep, ws, rows, &summary);  // its status is summary.status, read below
  } catch (const phiq::Error& e) {
    progress.finish();
    return fail(scene_path + ": " + e.what(), 3);
  }
  progress.finish();

  // (also a signal that came after the last row: the command stops before committing, as it said it would)
  if (summary.status == phiq::SolveStatus::kCancelled || stop_flag().load())
    return fail(scene_path + ": " + interrupt_message() + "; no output written", interrupt_exit_status());
  if (summary.status != phiq::SolveStatus::kSuccess) {
    const std::string why = failure_message(scene, summary, square.reduced != nullptr);
    return failed(model, summary, {load_s, summary.solve_seconds - rows.seconds, rows.seconds}, why, rows.first_q);
  }
  if (const int status =
          commit_run(scene_path, scene, model, summary, load_s, rows, h5.get(), spool, out, found, threads))
    return status;
  if (!quiet) report_run(scene_path, redundancy, summary, file ? out_path : "");
  return 0;
}

}  // namespace

Command register_run(CLI::App& app) {
  struct Args {
    std::string scene_path, out_path, summary_path, format;
    bool quiet = false;
    int threads = 0;
    double memory_gb = 0.0;
    std::string progress = "auto";
    int deflate = 0;
    std::string names = "dotted";
    std::vector<std::string> sets;
    std::vector<std::string> sensitivities;
    int mode = 0;
    std::vector<std::string> drives;  // of a URDF, MJCF or SDF file, as `phiq convert` adds them
    std::vector<double> time;
    std::string gravity;          // --gravity X,Y,Z
    phiq::ImportOptions outputs;  // --rates, --forces
  };
  auto a = std::make_shared<Args>();
  CLI::App* run = app.add_subcommand("run", "Solve position, velocity and acceleration over the scene's time sweep");
  run->add_option("scene", a->scene_path, "Scene file (YAML; '-': standard input)")->required();
  run->add_option("-o,--output", a->out_path,
                  "Results file to write, CSV or HDF5 (--format; default or '-': CSV on standard output)")
      ->transform(output_path(" (without the option, or '-': standard output)", true));
  run->add_option("--format", a->format,
                  "Results format: csv or hdf5 (default: hdf5 for an output ending in .h5 or .hdf5, else csv)")
      ->check(one_of({"csv", "hdf5"}));
  run->add_option(
         "--deflate", a->deflate,
         "HDF5: shuffle and deflate (gzip) every dataset at this level, 1-9 (0: uncompressed; bench/README.md: "
         "it costs more time than it saves on a fast disk)")
      ->capture_default_str()
      ->check(whole_number(0, 9, "uncompressed"));
  run->add_flag("-q,--quiet", a->quiet, "Do not print the run summary on standard error");
  run->add_option("--summary", a->summary_path,
                  "Write the run summary as JSON (counts, timings; on a failure to solve, why) to this file ('-': "
                  "standard output)")
      ->transform(output_path("", false));
  run->add_option("--threads", a->threads, "Threads for the drive steps (0: all cores; 1: in order)")
      ->capture_default_str()
      ->check(thread_count());
  run->add_option(
         "--memory", a->memory_gb,
         "GB the whole process may reach with --threads 0: fewer threads when theirs would not fit (0: what the "
         "system reports available)")
      ->capture_default_str()
      ->check(number(0.0, 1e6, false, "a number of GB from 0 (what the system reports available) to 1000000"));
  run->add_option("--progress", a->progress,
                  "Progress bar on standard error: auto (when it is a terminal), always, never")
      ->capture_default_str()
      ->check(one_of({"auto", "always", "never"}));
  run->add_option("--names", a->names,
                  "Column names: dotted (theta2.v) or identifiers (theta2__v: kept by numpy and pandas)")
      ->capture_default_str()
      ->check(one_of({"dotted", "identifiers"}));
  add_set_option(run, &a->sets);
  add_sensitivity_option(run, &a->sensitivities);
  run->add_option("--mode", a->mode,
                  "Start from real assembly mode K as `phiq modes` numbers them (0: the rough placement)")
      ->capture_default_str()
      ->check(whole_number(0, 1000000, "the rough placement"));
  add_import_options(run, &a->drives, &a->time, &a->gravity, &a->outputs);
  return {
      run, [a] {
        using Mode = ProgressBar::Mode;
        const Mode mode = a->progress == "always" ? Mode::kAlways : a->progress == "never" ? Mode::kNever : Mode::kAuto;
        phiq::ImportOptions drives = a->outputs;
        if (const auto bad = import_options("run", a->scene_path, a->drives, a->time, a->gravity, &drives))
          return fail(*bad, 2);
        return with_stdout_checked(cmd_run(a->scene_path, a->out_path, a->format, a->deflate, a->quiet, a->summary_path,
                                           cap_threads("run", a->threads, a->quiet), a->memory_gb, mode,
                                           a->names == "identifiers", a->sets, a->sensitivities, a->mode, drives));
      }};
}

}  // namespace phiq::tools

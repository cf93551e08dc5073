// phiq — command line front end. See tools/README.md.
//
// Exit status: 0 success; 1 the mechanism could not be solved (the message names step, time and constraints), or
// `compare` found a difference; 2 bad input (scene, CSV or command line); 3 an output (a file, standard output)
// could not be written; 128 + the signal when interrupted (130 SIGINT, 143 SIGTERM, 129 SIGHUP).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include <tbb/info.h>

#include "cli_support.hpp"
#include "generate.hpp"
#include "generate_linkages.hpp"
#include "plot_svg.hpp"
#include "progress_bar.hpp"
#include "sweep_accuracy.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/phiq.hpp"

namespace {

using phiq::tools::NamedPath;
using phiq::tools::OutputSet;

int fail(const std::string& msg, int code) {
  std::cerr << "phiq: " << msg << "\n";
  return code;
}

// The scene at `path`; on a scene error its one line is printed and the result is empty (the command exits 2).
std::optional<phiq::Scene> load_or_report(const std::string& path) {
  try {
    return phiq::load_scene(path);
  } catch (const phiq::SceneError& e) {
    fail(e.what(), 2);
    return std::nullopt;
  }
}

std::string sci(double v) {
  std::ostringstream s;
  s.precision(3);
  s << std::scientific << v;
  return s.str();
}

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The scene's assembly settings (tolerance, iteration budget) for the minimum-norm assembly.
phiq::AssemblyOptions assembly_options(const phiq::Scene& scene) { return phiq::assembly_options(scene.sweep.assembly); }

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}


// `phiq run --summary FILE.json`: the run summary, format version 1 (tools/README.md).
std::string summary_json(const phiq::Scene& scene, const phiq::Workspace& ws, const phiq::SweepSummary& s,
                         double load_s, double solve_s, double write_s) {
  nlohmann::ordered_json j;
  j["format"] = 1;
  j["scene"] = scene.path;
  j["status"] = phiq::to_string(s.status);
  j["message"] = s.message;
  j["steps"] = s.steps_completed;
  j["threads"] = s.threads;
  j["parallel_chunks"] = s.parallel_chunks;
  j["coordinates"] = scene.model->num_coordinates();
  j["linear_solver"] = phiq::to_string(scene.model->linear_solver());
  j["load_seconds"] = load_s;
  j["solve_seconds"] = solve_s;
  // the sweep's wall time: the solve and the writing done in its callback, which other threads' solving overlaps
  j["sweep_seconds"] = s.solve_seconds;
  j["write_seconds"] = write_s;
  j["newton_iterations"] = s.counters.newton_iterations;
  j["factorizations"] = s.counters.factorizations;
  j["pivoting_factorizations"] = ws.lu ? ws.lu->pivoting_factorizations() : 0;
  j["velocity_solves"] = s.counters.velocity_solves;
  j["acceleration_solves"] = s.counters.acceleration_solves;
  j["phi_t_evaluations"] = s.counters.phi_t_evaluations;
  j["gamma_evaluations"] = s.counters.gamma_evaluations;
  j["residual_evaluations"] = s.counters.residual_evaluations;
  j["point_evaluations"] = s.counters.point_evaluations;
  j["subdivisions"] = s.subdivisions;
  j["singular_positions"] = s.singular_positions;
  // 0 in the summary means no row measured it (a positions-only sweep factorises at Newton iterates, not at the
  // solutions): null, not a condition number of 0, which would read as a singular Jacobian
  if (s.min_rcond > 0.0)
    j["min_rcond"] = s.min_rcond;
  else
    j["min_rcond"] = nullptr;
  j["warnings"] = nlohmann::ordered_json::array();
  for (const auto& w : s.warnings) j["warnings"].push_back({{"t", w.t}, {"kind", w.kind}, {"message", w.message}});
  return j.dump(2) + "\n";
}

// The scene made square for the sweep (prepare_scene(): a model with redundant constraints assembled by minimum
// norm and solved on its independent rows), or, when it cannot be (inconsistent, under-driven), the reason with
// the time it applies to.
std::optional<std::string> make_square(const phiq::Scene& scene, phiq::SquareScene* square) {
  const phiq::SolveStatus st = phiq::prepare_scene(*scene.model, scene.sweep.t_begin, scene.sweep.assembly, square);
  if (st == phiq::SolveStatus::kSuccess) return std::nullopt;
  return "t = " + phiq::format_time(scene.sweep.t_begin) + ": " + square->assembly.message;
}

int cmd_run(const std::string& scene_path, const std::string& out_path, bool quiet, const std::string& summary_path,
            int threads, double memory_gb, phiq::tools::ProgressBar::Mode progress_mode) {
  // Outputs that would replace the scene or each other are refused before anything is read or solved.
  std::vector<NamedPath> outs;
  if (!out_path.empty()) outs.push_back({"-o", out_path});
  if (!summary_path.empty()) outs.push_back({"--summary", summary_path});
  if (const auto clash = phiq::tools::output_clash(outs, {{"the scene", scene_path}})) return fail("run: " + *clash, 2);
  if (out_path.empty() && phiq::tools::stdout_was_closed())
    return fail("run: standard output: cannot write: it is closed", 3);
  phiq::tools::set_interrupt_subject(scene_path, "; no output written");
  const auto load_start = Clock::now();
  std::optional<phiq::Scene> loaded = load_or_report(scene_path);
  if (!loaded) return 2;
  phiq::Scene& scene = *loaded;
  const double load_s = since(load_start);

  // Every output exists (as a temporary, or a device opened) before the solve: an unwritable path fails now, not
  // after the sweep; they are committed together at the end, or none of them appears.
  OutputSet outputs;
  phiq::AtomicOutputFile* file = nullptr;
  phiq::AtomicOutputFile* summary_file = nullptr;
  try {
    if (!out_path.empty()) file = &outputs.add(out_path);
    if (!summary_path.empty()) summary_file = &outputs.add(summary_path);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }

  // inconsistent or under-driven models stop here, naming the constraints
  phiq::SquareScene square;
  if (const auto why = make_square(scene, &square))
    return fail(scene_path + ": " + *why + (outs.empty() ? "" : "; no output written"), 1);
  const phiq::AssemblySummary& redundancy = square.assembly;
  const phiq::Model& model = square.model(*scene.model);
  scene.sweep.threads = threads;
  scene.sweep.memory_budget = static_cast<std::size_t>(memory_gb * 1e9);
  phiq::Workspace ws(model);
  ws.q = square.start;
  // columns from the scene (its constraints and outputs); residuals of a model solved on its independent rows
  // are evaluated on the whole scene model (CsvFormat)
  phiq::CsvFormat csv(scene);

  // Where the CSV goes: the output file, or standard output after success, spooled through an anonymous temporary
  // file so that memory stays bounded however long the sweep is.
  std::FILE* spool = nullptr;
  std::string buffer = csv.header();
  if (!file && !(spool = std::tmpfile())) return fail("cannot create a temporary file for standard output", 3);
  struct CloseSpool {
    std::FILE* f;
    ~CloseSpool() {
      if (f) std::fclose(f);
    }
  } close_spool{spool};
  auto flush = [&] {
    if (file) file->write(buffer);
    else if (std::fwrite(buffer.data(), 1, buffer.size(), spool) != buffer.size())
      throw phiq::Error("cannot write the temporary file for standard output");
    buffer.clear();
  };

  phiq::SweepSummary summary;
  double write_s = 0.0;  // formatting and writing rows, timed inside the step callback
  phiq::tools::ProgressBar progress(scene.sweep.steps + 1,
                                    quiet ? phiq::tools::ProgressBar::Mode::kNever : progress_mode);
  try {
    phiq::tools::StopOnSignal stop_on_signal;  // a signal stops the sweep at its next row
    const std::atomic<bool>& stop = phiq::tools::stop_flag();
    phiq::run_sweep(model, scene.sweep, ws, [&](const phiq::StepView& step) {
      const auto w0 = Clock::now();
      csv.append_row(step, buffer);
      if (buffer.size() > (1u << 20)) flush();
      progress.update(step.step + 1);
      write_s += since(w0);
      return !stop.load();
    }, &summary);
  } catch (const phiq::Error& e) {
    progress.finish();
    return fail(scene_path + ": " + e.what(), 3);
  }
  progress.finish();

  // (also a signal that came after the last row: the command stops before committing, as it said it would)
  if (summary.status == phiq::SolveStatus::kCancelled || phiq::tools::stop_flag().load())
    return fail(scene_path + ": " + phiq::tools::interrupt_message() + "; no output written",
                phiq::tools::interrupt_exit_status());
  if (summary.status != phiq::SolveStatus::kSuccess) {
    std::string why = summary.message;
    // A square model not assembled at its first position: singular there (redundant constraints and missing
    // drivers in equal numbers, or a singular placement), or Newton found no descent from the placement (the
    // Jacobian of a Cardan joint at 90° drops rank there). The minimum-norm assembly and its rank analysis say which.
    if (summary.failed_step == 0 && summary.status != phiq::SolveStatus::kOutsideTimeDomain &&
        summary.status != phiq::SolveStatus::kNonFinite && !square.reduced) {
      Eigen::VectorXd q = scene.model->initial_positions();
      phiq::AssemblySummary as;
      std::unique_ptr<phiq::Model> unused;
      if (phiq::prepare_square(*scene.model, scene.sweep.t_begin, assembly_options(scene), q, &unused, &as) !=
          phiq::SolveStatus::kSuccess)
        why += "; rank analysis: " + as.message;
    }
    return fail(scene_path + ": " + why + (outs.empty() ? "" : "; no output written"), 1);
  }
  const double solve_s = summary.solve_seconds - write_s;
  const auto final_write = Clock::now();
  try {
    flush();
    if (file) {
      file->finish();
    } else {
      // what reaches standard output cannot be taken back: a signal from here on says so
      phiq::tools::set_interrupt_subject(scene_path, "; standard output incomplete");
      std::rewind(spool);
      char chunk[1 << 16];
      for (std::size_t n; (n = std::fread(chunk, 1, sizeof chunk, spool)) > 0;)
        if (std::fwrite(chunk, 1, n, stdout) != n)
          throw phiq::Error(std::string("standard output: cannot write: ") + std::strerror(errno));
      if (const auto bad = phiq::tools::stdout_error()) throw phiq::Error(*bad);
    }
    write_s += since(final_write);
    if (summary_file) summary_file->write(summary_json(scene, ws, summary, load_s, solve_s, write_s));
    outputs.commit();
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  if (!quiet) {
    if (!redundancy.rank.redundant.empty())
      std::cerr << "phiq: " << scene_path << ": redundant equations left out of the solve (consistent): "
                << joined(redundancy.rank.redundant) << "\n";
    for (const auto& w : summary.warnings)
      std::cerr << "phiq: " << scene_path << ": warning: t = " << phiq::format_time(w.t) << ": " << w.kind << ": "
                << w.message << "\n";
    std::cerr << "phiq: " << scene_path << ": " << summary.BriefReport();
    if (summary.min_rcond > 0)
      std::cerr << ", min rcond " << sci(summary.min_rcond) << " at t = " << phiq::format_time(summary.min_rcond_time);
    if (file) std::cerr << "; wrote " << out_path;
    std::cerr << "\n";
  }
  return 0;
}

// `phiq batch SCENE CASES.csv -o DIR`: the scene swept once per row of CASES.csv (columns: parameter names), the
// cases in parallel, sharing one symbolic analysis; DIR/case<k>.csv per successful case (k from 0, the row order).
int cmd_batch(const std::string& scene_path, const std::string& cases_path, const std::string& dir, bool quiet,
              int threads) {
  phiq::CsvTable cases;
  try {
    cases = phiq::read_csv_table(cases_path);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 2);
  }
  if (cases.rows.empty()) return fail(cases_path + ": no cases (one row per parameter set)", 2);
  auto case_file = [&](std::size_t k) { return dir + "/case" + std::to_string(k) + ".csv"; };
  {  // no case file may replace the scene or the cases
    std::vector<NamedPath> outs;
    for (std::size_t k = 0; k < cases.rows.size(); ++k) outs.push_back({"-o", case_file(k)});
    if (const auto clash = phiq::tools::output_clash(outs, {{"the scene", scene_path}, {"the cases", cases_path}}))
      return fail("batch: " + *clash, 2);
  }
  phiq::tools::set_interrupt_subject(scene_path, "; no output written");
  // Build every case's model (in order: each shares the first one's analysis), then sweep them in parallel.
  std::vector<phiq::Scene> scenes;
  scenes.reserve(cases.rows.size());
  const auto load_start = Clock::now();
  for (std::size_t k = 0; k < cases.rows.size(); ++k) {
    phiq::SceneOverrides o;
    for (std::size_t c = 0; c < cases.columns.size(); ++c) o.parameters.emplace_back(cases.columns[c], cases.rows[k][c]);
    if (!scenes.empty()) o.share_analysis_with = scenes.front().model.get();
    try {
      scenes.push_back(phiq::load_scene(scene_path, phiq::SceneLimits{}, o));
    } catch (const phiq::SceneError& e) {
      // The case is named only when its parameters cause the error: an error of the scene itself (its YAML, a
      // field) is the same without them. Cases after the first loaded the same scene, so theirs are theirs.
      bool from_case = k > 0;
      if (!from_case) {
        try {
          (void)phiq::load_scene(scene_path);
          from_case = true;
        } catch (const phiq::SceneError& plain) {
          from_case = std::string(plain.what()) != e.what();
        }
      }
      return fail(std::string(e.what()) + (from_case ? " (case " + std::to_string(k) + " of " + cases_path +
                                                           ", line " + std::to_string(k + 2) + ")"
                                                     : ""),
                  2);
    }
  }
  const double load_s = since(load_start);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(dir + ": cannot create the output directory: " + ec.message(), 3);
  // Each case made square as `phiq run` does; one that cannot be fails alone.
  std::vector<phiq::SquareScene> squares(scenes.size());
  std::vector<std::string> prepare_errors(scenes.size());
  std::vector<const phiq::Model*> models;
  std::vector<Eigen::VectorXd> starts;
  std::vector<std::size_t> swept;  // the cases that run, in order
  std::vector<phiq::CsvFormat> formats;
  std::vector<std::string> buffers(scenes.size());
  // every case's file exists (as a temporary) before the work; those of the cases that succeed are renamed at the
  // end, the others removed. They are closed between writes: a batch of 10 000 cases holds no 10 000 descriptors.
  OutputSet outputs;
  std::vector<phiq::AtomicOutputFile*> files(scenes.size());
  try {
    for (std::size_t k = 0; k < scenes.size(); ++k)
      files[k] = &outputs.add(case_file(k), phiq::AtomicOutputFile::Hold::kClosedBetweenWrites);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  for (std::size_t k = 0; k < scenes.size(); ++k)
    if (const auto why = make_square(scenes[k], &squares[k])) prepare_errors[k] = *why;
  std::vector<std::string> write_errors(scenes.size());
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const phiq::Scene& sc = scenes[k];
    if (prepare_errors[k].empty()) {
      models.push_back(&squares[k].model(*sc.model));
      starts.push_back(squares[k].start);
      swept.push_back(k);
    }
    formats.emplace_back(sc);
    buffers[k] = formats[k].header();
  }
  // Each case touches only its own buffer and file: the callback is safe across cases without a lock.
  // each case's own sweep: its output points (and time range) may depend on its parameters
  std::vector<phiq::SweepOptions> sweeps;
  for (std::size_t k : swept) sweeps.push_back(scenes[k].sweep);
  const std::atomic<bool>& stop = phiq::tools::stop_flag();
  phiq::BatchSummary sum;
  {
    phiq::tools::StopOnSignal stop_on_signal;  // a signal stops every case at its next row
    sum = phiq::run_batch(models, sweeps, threads, [&](std::size_t c, const phiq::StepView& step) {
      const std::size_t k = swept[c];
      formats[k].append_row(step, buffers[k]);
      // written every 1 MB and at the case's last row: a finished case holds no rows in memory while others run
      const bool last = step.step == sweeps[c].steps;
      if (buffers[k].size() > (1u << 20) || last) {
        try {
          files[k]->write(buffers[k]);
        } catch (const phiq::Error& e) {
          write_errors[k] = e.what();
          return false;
        }
        if (last)
          std::string().swap(buffers[k]);
        else
          buffers[k].clear();
      }
      return !stop.load();
    }, &starts);
  }
  if (stop.load())
    return fail(scene_path + ": " + phiq::tools::interrupt_message() + "; no output written",
                phiq::tools::interrupt_exit_status());
  int failed = 0;
  std::size_t c = 0;  // index of case k among the swept ones
  std::vector<std::string> reports(scenes.size());
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    if (!prepare_errors[k].empty()) {
      ++failed;
      reports[k] = "phiq: " + scene_path + ": case " + std::to_string(k) + ": " + prepare_errors[k] +
                   "; no output written\n";
      continue;
    }
    const phiq::SweepSummary& s = sum.cases[c++];
    std::string why = !write_errors[k].empty() ? write_errors[k] : s.status != phiq::SolveStatus::kSuccess ? s.message : "";
    if (why.empty()) {
      try {
        files[k]->write(buffers[k]);
        files[k]->finish();
      } catch (const phiq::Error& e) {
        why = e.what();
      }
    }
    if (!why.empty()) {
      ++failed;
      reports[k] = "phiq: " + scene_path + ": case " + std::to_string(k) + ": " + why + "; no output written\n";
    } else if (!quiet) {
      reports[k] = "phiq: " + scene_path + ": case " + std::to_string(k) + ": " + s.BriefReport() + "\n";
    }
  }
  try {
    outputs.publish_finished();
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  for (const std::string& r : reports) std::cerr << r;
  if (!quiet)
    std::cerr << "phiq: " << scene_path << ": " << scenes.size() - failed << " of " << scenes.size() << " cases in "
              << dir << ", " << sum.threads << " threads, " << sum.shared_analyses + 1
              << " cases on one symbolic analysis, load " << sci(load_s) << " s, solve " << sci(sum.solve_seconds)
              << " s\n";
  return failed ? 1 : 0;
}

int cmd_check(const std::string& scene_path, bool json, std::optional<double> at) {
  std::optional<phiq::Scene> loaded = load_or_report(scene_path);
  if (!loaded) return 2;
  const phiq::Scene& scene = *loaded;
  const phiq::Model& model = *scene.model;
  int drivers = 0;
  for (const auto& c : model.constraints()) drivers += c.depends_on_time ? c.rows : 0;

  // Minimum-norm assembly from the rough placement, with the rank analysis at the assembled position (or where it
  // stopped): works for square, redundant and under-driven models alike.
  Eigen::VectorXd q = model.initial_positions();
  phiq::AssemblySummary as;
  const double t0 = at ? *at : scene.sweep.t_begin;  // rank belongs to a configuration: `--time` picks another
  phiq::assemble(model, t0, assembly_options(scene), q, &as);
  const bool ok = as.status == phiq::SolveStatus::kSuccess;
  const bool analysed = as.rank.coordinates == model.num_coordinates() && as.status != phiq::SolveStatus::kOutsideTimeDomain;
  const phiq::RankReport& rk = as.rank;
  // inconsistent names its conflicts; not consistent without any is "not known" (the independent equations
  // themselves do not hold: AssemblySummary::consistent)
  const bool consistency_known = as.consistent || !as.conflicts.empty();

  if (json) {
    // `phiq check --json`, format version 1 (tools/README.md): one object on standard output.
    nlohmann::ordered_json j;
    j["format"] = phiq::kCheckJsonFormat;
    j["phiq"] = phiq::kVersion;
    j["scene"] = scene_path;
    j["name"] = scene.name;
    j["coordinates"] = model.num_coordinates();
    j["equations"] = model.num_equations();
    j["kinematic_equations"] = model.num_equations() - drivers;
    j["driver_equations"] = drivers;
    j["constraints"] = model.constraints().size();
    j["nonzeros"] = model.jacobian_pattern().nnz();
    j["length_scale"] = model.length_scale();
    j["linear_solver"] = phiq::to_string(model.linear_solver());
    nlohmann::ordered_json a;
    a["time"] = t0;
    a["status"] = phiq::to_string(as.status);
    a["iterations"] = as.iterations;
    a["residual"] = as.residual;
    a["tolerance"] = scene.sweep.assembly.tolerance;
    a["message"] = as.message;
    a["worst"] = nlohmann::ordered_json::array();
    for (const auto& [row, value] : as.worst_rows)
      a["worst"].push_back({{"constraint", model.constraints()[model.constraint_of_row(row)].name},
                            {"row", row},
                            {"residual", value}});
    j["assembly"] = a;
    // The redundancy analysis at the assembled position (or where the assembly stopped); null when not run.
    auto or_null = [&](auto v) { return analysed ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
    j["rank"] = or_null(rk.rank);
    j["dof"] = or_null(rk.dof);
    j["driven_dof"] = or_null(rk.driven_dof);
    j["grubler"] = rk.grubler ? nlohmann::ordered_json(*rk.grubler) : nlohmann::ordered_json();
    j["redundant"] = rk.redundant;
    j["redundant_rows"] = nlohmann::ordered_json::array();
    for (phiq::Index r : rk.redundant_rows)
      j["redundant_rows"].push_back({{"constraint", model.constraints()[model.constraint_of_row(r)].name},
                                     {"row", r},
                                     {"name", model.row_name(r)}});
    j["consistent"] = consistency_known ? nlohmann::ordered_json(as.consistent) : nlohmann::ordered_json();
    j["conflicts"] = as.conflicts;
    j["rank_tolerance"] = rk.tolerance;
    j["rank_uncertain"] = rk.uncertain;
    j["rank_message"] = rk.message;
    std::cout << j.dump(2) << "\n";
    return ok ? 0 : 1;
  }

  std::cout << "scene         " << scene_path << (scene.name.empty() ? "" : " (" + scene.name + ")") << "\n"
            << "coordinates   " << model.num_coordinates() << "\n"
            << "equations     " << model.num_equations() << " (" << model.num_equations() - drivers
            << " kinematic, " << drivers << " rheonomic)\n"
            << "constraints   " << model.constraints().size() << "\n"
            << "jacobian      " << model.num_equations() << " x " << model.num_coordinates() << ", "
            << model.jacobian_pattern().nnz() << " non-zeros\n"
            << "length scale  " << model.length_scale() << " m\n"
            << "linear solver " << phiq::to_string(model.linear_solver()) << "\n";
  if (!analysed) {
    std::cout << "assembly      not attempted: " << as.message << "\n";
    return 1;
  }
  std::cout << "assembly      " << phiq::to_string(as.status) << " at t = " << phiq::format_time(t0) << " in "
            << as.iterations << " iterations, scaled residual " << sci(as.residual) << " (tolerance "
            << sci(scene.sweep.assembly.tolerance) << ")\n"
            << "rank          " << rk.rank << " of " << rk.kinematic_equations << " kinematic equations ("
            << rk.driven_rank << " of " << rk.equations << " with the drivers)\n"
            << "dof           " << rk.dof << " (" << rk.driven_dof << " not driven)\n"
            << "grubler       " << (rk.grubler ? std::to_string(*rk.grubler) : std::string("not defined")) << "\n"
            << "redundant     " << (rk.redundant.empty() ? "none" : joined(rk.redundant)) << "\n"
            << "consistent    "
            << (!consistency_known ? "not known: the independent equations do not hold"
                : as.consistent     ? "yes"
                                    : "no: conflicting " + joined(as.conflicts))
            << "\n";
  if (rk.uncertain) std::cout << "uncertain     " << rk.message << "\n";
  if (!ok) std::cout << "diagnosis     " << as.message << "\n";
  return ok ? 0 : 1;
}

// `phiq assemble SCENE [-o OUT.csv]`: the assembled position at time.start as a one-row CSV (the columns of
// `phiq run`'s positions). Nothing is written when the assembly fails.
int cmd_assemble(const std::string& scene_path, const std::string& out_path, bool quiet) {
  if (!out_path.empty()) {
    if (const auto clash = phiq::tools::output_clash({{"-o", out_path}}, {{"the scene", scene_path}}))
      return fail("assemble: " + *clash, 2);
  } else if (phiq::tools::stdout_was_closed()) {
    return fail("assemble: standard output: cannot write: it is closed", 3);
  }
  phiq::tools::set_interrupt_subject(scene_path, "; no output written");
  std::optional<phiq::Scene> loaded = load_or_report(scene_path);
  if (!loaded) return 2;
  const phiq::Scene& scene = *loaded;
  const phiq::Model& model = *scene.model;
  OutputSet outputs;  // created before the assembly, committed after it
  phiq::AtomicOutputFile* file = nullptr;
  try {
    if (!out_path.empty()) file = &outputs.add(out_path);
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  Eigen::VectorXd q = model.initial_positions();
  phiq::AssemblySummary as;
  const double t0 = scene.sweep.t_begin;
  if (phiq::assemble(model, t0, assembly_options(scene), q, &as) != phiq::SolveStatus::kSuccess)
    return fail(scene_path + ": t = " + phiq::format_time(t0) + ": " + as.message + "; no output written", 1);
  std::vector<phiq::Index> all(static_cast<std::size_t>(model.num_coordinates()));
  for (std::size_t j = 0; j < all.size(); ++j) all[j] = static_cast<phiq::Index>(j);
  phiq::CsvFormat csv(model, all, false, false);
  std::string text = csv.header();
  csv.append_row(phiq::StepView{0, t0, q, nullptr, nullptr}, text);
  try {
    if (file) {
      file->write(text);
      outputs.commit();
    } else {
      std::cout << text;
      if (const auto bad = phiq::tools::stdout_error()) throw phiq::Error(*bad);
    }
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  if (!quiet) std::cerr << "phiq: " << scene_path << ": " << as.BriefReport() << ", moved " << sci(as.moved) << "\n";
  return 0;
}

int cmd_compare(const std::string& a_path, const std::string& b_path, const phiq::CompareOptions& options) {
  phiq::CompareResult r;
  try {
    const phiq::CsvTable a = phiq::read_csv_table(a_path), b = phiq::read_csv_table(b_path);
    try {
      r = phiq::compare_csv(a, b, options);
    } catch (const phiq::Error& e) {  // a --columns name not in a file: a command-line error names its option
      return fail("compare: --columns: " + std::string(e.what()), 2);
    }
  } catch (const phiq::Error& e) {  // the file and line are named
    return fail(e.what(), 2);
  }
  if (r.equal) {
    std::cerr << "phiq: compare " << a_path << " " << b_path << ": " << r.summary() << "\n";
    return 0;
  }
  return fail("compare " + a_path + " " + b_path + ": " + r.summary(), 1);
}

// ---- the command line: validators with readable one-line messages, and CLI11's errors made one line ----------

// A whole number from lo to hi; `lo_means` explains the lowest value ("0: all cores").
CLI::Validator whole_number(long long lo, long long hi, const std::string& lo_means = "") {
  const std::string range = "a whole number from " + std::to_string(lo) +
                            (lo_means.empty() ? "" : " (" + lo_means + ")") + " to " + std::to_string(hi);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        long long v = 0;
        const char* end = text.data() + text.size();
        const auto [p, ec] = std::from_chars(text.data(), end, v);
        if (ec != std::errc() || p != end || v < lo || v > hi) return "expected " + range + ", got '" + text + "'";
        return "";
      },
      "INT");
}

// A whole number of any size the option's type holds (its range is checked by the command).
CLI::Validator any_whole_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        long long v = 0;
        const char* end = text.data() + text.size();
        const auto [p, ec] = std::from_chars(text.data(), end, v);
        if (ec != std::errc() || p != end) return "expected a whole number, got '" + text + "'";
        return "";
      },
      "INT");
}

// A number (decimal or exponent form, an optional '+'); finite unless `allow_inf`, ≥ lo, ≤ hi.
CLI::Validator number(double lo, double hi, bool allow_inf, const std::string& what) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* first = text.data() + (!text.empty() && text.front() == '+');
        const char* end = text.data() + text.size();
        double v = 0.0;
        const auto [p, ec] = std::from_chars(first, end, v);
        const bool ok = ec == std::errc() && p == end && first != end && !std::isnan(v) &&
                        (std::isfinite(v) || (allow_inf && v > 0)) && v >= lo && v <= hi;
        return ok ? "" : "expected " + what + ", got '" + text + "'";
      },
      "NUMBER");
}

// One of the listed words.
CLI::Validator one_of(const std::vector<std::string>& words) {
  std::string list;
  for (std::size_t k = 0; k < words.size(); ++k)
    list += (k == 0 ? "" : k + 1 == words.size() ? " or " : ", ") + words[k];
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        if (std::find(words.begin(), words.end(), text) != words.end()) return "";
        return "expected " + list + ", got '" + text + "'";
      },
      "WORD");
}

// An output path that is not empty (an empty one used to mean standard output, silently).
// An output path where "-" is standard output, as in most tools (a file named "-" is still `./-`). `spooled`: as if
// the option were absent (run, assemble: the CSV is spooled and written whole once the solve succeeded); otherwise
// /dev/stdout, the descriptor itself (written in place, as a pipe or a terminal is).
CLI::Validator output_path(const std::string& instead, bool spooled) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        if (text.empty()) return "the path is empty" + instead;
        if (text == "-") text = spooled ? "" : "/dev/stdout";
        return "";
      },
      "PATH");
}

// More threads than the cores TBB runs (tbb::info::default_concurrency(), which honours the process's affinity
// mask) would not run at once: TBB warns (several lines) and keeps its limit while the summary would claim the
// number asked for. Capped, with a note.
int cap_threads(const std::string& command, int threads, bool quiet) {
  const int cores = tbb::info::default_concurrency();
  if (threads <= cores) return threads;
  if (!quiet)
    std::cerr << "phiq: " << command << ": --threads " << threads << ": " << cores << " cores here; running on "
              << cores << " threads\n";
  return cores;
}

// CLI11's error made one line: "phiq: <command>: <what>" (command-line errors exit 2).
int usage_error(CLI::App& app, int argc, char** argv, const CLI::ParseError& e) {
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) commands.push_back(sub->get_name());
  std::string command_list;
  for (const auto& c : commands) command_list += (command_list.empty() ? "" : ", ") + c;
  std::string command;  // the first word that is not an option: the command
  for (int i = 1; i < argc && command.empty(); ++i)
    if (argv[i][0] != '-' || std::string(argv[i]) == "-") command = argv[i];
  if (!command.empty() && std::find(commands.begin(), commands.end(), command) == commands.end())
    return fail("unknown command '" + phiq::single_line(command) + "' (commands: " + command_list + ")", 2);
  std::string what = e.what();
  std::replace(what.begin(), what.end(), '\n', ' ');
  while (!what.empty() && what.back() == ' ') what.pop_back();
  auto after = [&](const std::string& head) {
    const std::size_t at = what.find(head);
    return at == std::string::npos ? std::string() : what.substr(at + head.size());
  };
  // (by type: an error's get_name() is sometimes the subcommand's name)
  if (command.empty() && dynamic_cast<const CLI::RequiredError*>(&e)) {
    std::string option;  // `phiq --bogus`: CLI11 says only that a command is required
    for (int i = 1; i < argc && option.empty(); ++i) option = argv[i];
    what = option.empty() ? "a command is required (" + command_list + "); phiq --help says more"
                          : "unknown option " + phiq::single_line(option) + " (commands: " + command_list + ")";
  } else if (dynamic_cast<const CLI::ExtrasError*>(&e)) {
    const std::string extras = after("not expected: ");
    what = (extras.empty() || extras[0] == '-' ? "unknown option " : "unexpected argument ") + extras;
  } else if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && what.find(" required ") != std::string::npos &&
             what.find("missing") != std::string::npos) {
    what = what.substr(0, what.find(':')) + ": a value is required";
  } else if (dynamic_cast<const CLI::ConversionError*>(&e) && what.rfind("Could not convert: ", 0) == 0) {
    const std::string rest = after("Could not convert: ");
    const std::size_t eq = rest.find(" = ");
    what = eq == std::string::npos ? "cannot read " + rest
                                   : rest.substr(0, eq) + ": cannot read '" + rest.substr(eq + 3) + "'";
  }
  return fail((command.empty() ? "" : command + ": ") + phiq::single_line(what), 2);
}

}  // namespace

int main(int argc, char** argv) {
  // before anything opens a file or starts a thread
  phiq::tools::ensure_standard_descriptors();
  phiq::tools::start_interrupts();

  CLI::App app{"phiq: sparse, large-scale multibody kinematics"};
  app.set_version_flag("--version", std::string("phiq ") + phiq::kVersion + " (scene format " +
                                        std::to_string(phiq::kSceneFormat) + ", CSV format " +
                                        std::to_string(phiq::kCsvFormat) + ", check --json format " +
                                        std::to_string(phiq::kCheckJsonFormat) + ")");
  app.require_subcommand(1);
  const CLI::Validator threads_range = whole_number(0, 1000000, "all cores");
  const CLI::Validator path_given = output_path("", false);
  const CLI::Validator path_or_stdout = output_path(" (without the option, or '-': standard output)", false);
  const CLI::Validator spooled_or_stdout = output_path(" (without the option, or '-': standard output)", true);
  const CLI::Validator directory_given = CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty()) return "the path is empty";
        return text == "-" ? "'-' (standard output) cannot hold the case files: give a directory" : "";
      },
      "DIR");

  std::string scene_path, out_path, summary_path;
  bool quiet = false;
  CLI::App* run = app.add_subcommand("run", "Solve position, velocity and acceleration over the scene's time sweep");
  run->add_option("scene", scene_path, "Scene file (YAML)")->required();
  run->add_option("-o,--output", out_path, "CSV file to write (default or '-': standard output)")
      ->transform(spooled_or_stdout);
  run->add_flag("-q,--quiet", quiet, "Do not print the run summary on standard error");
  run->add_option("--summary", summary_path,
                  "Write the run summary as JSON (counts and timings) to this file ('-': standard output)")
      ->transform(path_given);
  int threads = 0;
  run->add_option("--threads", threads, "Threads for the drive steps (0: all cores; 1: in order)")
      ->capture_default_str()
      ->check(threads_range);
  double memory_gb = 0.0;
  run->add_option("--memory", memory_gb,
                  "GB the drive steps may use with --threads 0: fewer threads when theirs would not fit (0: what the "
                  "system reports available)")
      ->capture_default_str()
      ->check(number(0.0, 1e6, false, "a number of GB from 0 (what the system reports available) to 1000000"));
  std::string progress = "auto";
  run->add_option("--progress", progress, "Progress bar on standard error: auto (when it is a terminal), always, never")
      ->capture_default_str()
      ->check(one_of({"auto", "always", "never"}));

  phiq::tools::GenerateOptions gen;
  std::string gen_out, gen_outputs = "q,v,a";
  CLI::App* generate = app.add_subcommand("generate", "Write a scalable scene (nfourbar, scissor, grid, chain3d)");
  generate->add_option("kind", gen.kind, "nfourbar, scissor, grid or chain3d")->required();
  generate->add_option("N", gen.n, "Size: four-bars (nfourbar), stages (scissor), cells (grid), spatial loops (chain3d)")
      ->required()
      ->check(any_whole_number());
  generate->add_option("-o,--output", gen_out, "Scene file to write ('-': standard output)")
      ->required()
      ->transform(path_given);
  generate->add_option("--steps", gen.steps, "Sweep intervals")->capture_default_str()->check(any_whole_number());
  const CLI::Validator any_number = number(-HUGE_VAL, HUGE_VAL, false, "a finite number");
  CLI::Option* gen_from =
      generate->add_option("--from", gen.from, "Driven angle at t = 0 (rad; default pi/4, scissor 0.3)");
  gen_from->check(any_number);
  CLI::Option* gen_to = generate->add_option("--to", gen.to, "Driven angle at t = 1 (rad; default 3pi/4, scissor 1.2)");
  gen_to->check(any_number);
  generate->add_option("--coords", gen.coords, "natural or reference-point")->capture_default_str();
  generate->add_option("--twist", gen.twist,
                       "chain3d: phase between neighbouring cranks on one hinge line (rad; 0: the parallelogram row)")
      ->capture_default_str()
      ->check(any_number);
  generate->add_option("--outputs", gen_outputs, "Which of q (positions), v, a the scene asks for")
      ->capture_default_str();

  std::string check_path;
  bool check_json = false;
  CLI::App* batch = app.add_subcommand("batch", "Sweep the scene once per parameter set of a CSV, the cases in parallel");
  std::string batch_scene, batch_cases, batch_dir;
  bool batch_quiet = false;
  int batch_threads = 0;
  batch->add_option("scene", batch_scene, "Scene file (YAML)")->required();
  batch->add_option("cases", batch_cases, "CSV: a header of parameter names, one row of values per case")->required();
  batch->add_option("-o,--output", batch_dir, "Directory for case<k>.csv (k = row, from 0)")
      ->required()
      ->check(directory_given);
  batch->add_flag("-q,--quiet", batch_quiet, "Print only failures on standard error");
  batch->add_option("--threads", batch_threads, "Threads for the cases (0: all cores)")
      ->capture_default_str()
      ->check(threads_range);
  std::string asm_path, asm_out;
  bool asm_quiet = false;
  CLI::App* assemble_cmd =
      app.add_subcommand("assemble", "Assemble the rough placement (minimum-norm) and write the coordinates as CSV");
  assemble_cmd->add_option("scene", asm_path, "Scene file (YAML)")->required();
  assemble_cmd->add_option("-o,--output", asm_out, "CSV file to write (default or '-': standard output)")
      ->transform(spooled_or_stdout);
  assemble_cmd->add_flag("-q,--quiet", asm_quiet, "Do not print the summary on standard error");
  CLI::App* check = app.add_subcommand("check", "Count coordinates and equations, rank, dof, redundancy; try the assembly");
  check->add_option("scene", check_path, "Scene file (YAML)")->required();
  check->add_flag("--json", check_json, "Print one JSON object (format: tools/README.md)");
  double check_time = 0.0;
  CLI::Option* check_at =
      check->add_option("--time", check_time, "Assemble and analyse at this time instead of time.start")
          ->check(any_number);

  phiq::tools::PlotOptions plot_options;
  CLI::App* plot = app.add_subcommand("plot", "Draw the mechanism at a few positions with its traced points, and "
                                              "columns against time, as SVG");
  plot->add_option("scene", plot_options.scene, "Scene file (YAML)")->required();
  plot->add_option("result", plot_options.csv, "CSV written by `phiq run` for this scene")->required();
  plot->add_option("-o,--output", plot_options.out, "SVG file to write ('-': standard output)")
      ->required()
      ->transform(path_given);
  plot->add_option("--columns", plot_options.columns, "Columns to plot against t (default: the coordinates, at most 6)")
      ->delimiter(',');
  plot->add_option("--positions", plot_options.positions, "Rows at which the mechanism is drawn, evenly spread")
      ->capture_default_str()
      ->check(whole_number(1, 50));

  std::string cmp_a, cmp_b;
  phiq::CompareOptions cmp;
  CLI::App* compare = app.add_subcommand("compare", "Compare two result CSVs column by column within tolerances");
  compare->add_option("a", cmp_a, "First CSV (e.g. the reference)")->required();
  compare->add_option("b", cmp_b, "Second CSV")->required();
  const CLI::Validator tolerance = number(0.0, HUGE_VAL, true, "a number >= 0 (inf: any difference)");
  compare->add_option("--rtol", cmp.rtol, "Relative tolerance: |a-b| <= atol + rtol*max(|a|,|b|)")
      ->capture_default_str()
      ->check(tolerance);
  compare->add_option("--atol", cmp.atol, "Absolute tolerance")->capture_default_str()->check(tolerance);
  compare->add_option("--columns", cmp.columns, "Compare only these columns (default: all; headers must match)")
      ->delimiter(',');

  phiq::tools::SweepAccuracyArgs acc;  // `phiq sweep-accuracy`: tools/sweep_accuracy.hpp
  CLI::App* accuracy = app.add_subcommand("sweep-accuracy", "Error against a reference and time per step, per solver setting");
  accuracy->add_option("scene", acc.scene, "Scene file (YAML)")->required();
  accuracy->add_option("-o,--output", acc.csv_path, "CSV to write (default: standard output unless --json)")
      ->transform(path_or_stdout);
  accuracy->add_option("--json", acc.json_path, "JSON to write ('-': standard output)")->transform(path_given);
  accuracy->add_option("--tolerances", acc.tolerances, "Newton tolerances (default 1e-4,1e-5,...,1e-14)");
  accuracy->add_option("--steps-list", acc.steps, "Step counts (default: the scene's x 1/4, 1, 4)");
  accuracy->add_option("--predictors", acc.predictors, "Of previous,secant,parabolic,linear,quadratic,cubic,auto (default: all but auto)");
  accuracy->add_option("--newton", acc.newton, "Of modified,full (default: both)");
  accuracy->add_option("--linear-solvers", acc.linear_solvers, "Of klu,umfpack,dense (default: klu,umfpack)");
  accuracy->add_option("--reference", acc.reference, "auto, numerical or closed-form:KIND[:NAME=VALUE,...]")->capture_default_str();
  accuracy->add_option("--repeat", acc.repeat, "Timed runs per setting (best of)")
      ->capture_default_str()
      ->check(whole_number(1, 1000));
  accuracy->add_flag("-q,--quiet", acc.quiet, "Print only errors on standard error");
  accuracy->add_flag("-v,--verbose", acc.verbose, "One line per setting on standard error");

  // The command's exit status, made 3 when what it wrote to standard output was lost (a full disk, a closed
  // descriptor): a report that never arrived is not a success.
  auto finished = [](int status) {
    if (status == 0 || status == 1)
      if (const auto bad = phiq::tools::stdout_error()) return fail(*bad, 3);
    return status;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return finished(app.exit(e));  // --help, --version
    return usage_error(app, argc, argv, e);
  }
  try {
    if (*run) {
      using Mode = phiq::tools::ProgressBar::Mode;
      return finished(cmd_run(scene_path, out_path, quiet, summary_path, cap_threads("run", threads, quiet), memory_gb,
                              progress == "always" ? Mode::kAlways : progress == "never" ? Mode::kNever : Mode::kAuto));
    }
    if (*generate) {
      if (auto range = phiq::tools::kind_default_range(gen.kind)) {  // kinds whose default range differs
        if (gen_from->count() == 0) gen.from = range->from;
        if (gen_to->count() == 0) gen.to = range->to;
      }
      gen.q = gen.v = gen.a = false;
      std::stringstream ss(gen_outputs);
      for (std::string item; std::getline(ss, item, ',');) {
        bool* wanted = item == "q" ? &gen.q : item == "v" ? &gen.v : item == "a" ? &gen.a : nullptr;
        if (!wanted) return fail("generate: --outputs: unknown output '" + item + "' (q, v, a)", 2);
        // a repeat is most likely another item mistyped (q,v,v for q,v,a): said, not merged
        if (*wanted) return fail("generate: --outputs: '" + item + "' given twice in '" + gen_outputs + "'", 2);
        *wanted = true;
      }
      std::string text;
      try {
        text = phiq::tools::generate_scene(gen);
      } catch (const std::invalid_argument& e) {
        return fail(std::string("generate: ") + e.what(), 2);
      }
      phiq::tools::set_interrupt_subject("generate: " + gen_out, "; no output written");
      try {
        OutputSet outputs;
        outputs.add(gen_out).write(text);
        outputs.commit();
      } catch (const phiq::Error& e) {
        return fail(e.what(), 3);
      }
      return 0;
    }
    if (*check)
      return finished(
          cmd_check(check_path, check_json, check_at->count() ? std::optional<double>(check_time) : std::nullopt));
    if (*assemble_cmd) return finished(cmd_assemble(asm_path, asm_out, asm_quiet));
    if (*batch) {
      const int cases_threads = cap_threads("batch", batch_threads, batch_quiet);
      return cmd_batch(batch_scene, batch_cases, batch_dir, batch_quiet, cases_threads);
    }
    if (*compare) return cmd_compare(cmp_a, cmp_b, cmp);
    if (*plot) {
      if (const auto clash = phiq::tools::output_clash(
              {{"-o", plot_options.out}}, {{"the scene", plot_options.scene}, {"the result", plot_options.csv}}))
        return fail("plot: " + *clash, 2);
      return phiq::tools::plot_svg(plot_options);
    }
    if (*accuracy) return finished(phiq::tools::run_sweep_accuracy_command(acc));
  } catch (const std::exception& e) {
    return fail(std::string("internal error: ") + e.what(), 4);
  }
  return 2;
}

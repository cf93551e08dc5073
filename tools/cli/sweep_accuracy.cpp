// `phiq sweep-accuracy SCENE`: the command around measure_accuracy() (tools/accuracy/sweep_accuracy.hpp): its
// options, the outputs created before the long run and committed together, the signals that stop it.
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "host_info.hpp"
#include "sweep_accuracy.hpp"
#include "phiq/text.hpp"

namespace phiq::tools {

namespace {

// The command line of `phiq sweep-accuracy`, as given (lists unparsed: they are checked with one-line errors).
struct SweepAccuracyArgs {
  std::string scene, csv_path, json_path;
  std::string tolerances, steps, predictors, newton, linear_solvers, reference = "auto";
  int repeat = 3;
  bool quiet = false, verbose = false;
};

// Runs the command: exit status 0, 1 (the reference could not be computed), 2 (bad input: scene, option, a
// reference that does not fit, an output that is the scene or the other output), 3 (an output could not be
// written), 128 + the signal (SIGINT, SIGTERM, SIGHUP: the running sweep stops, nothing is written; signals as
// cli_support.hpp). Errors are one line on stderr ("phiq: ..."). Without -o and --json the CSV goes to standard
// output; the files are written whole or not at all, both or neither.
int run_sweep_accuracy_command(const SweepAccuracyArgs& a) {
  auto fail = [](const std::string& msg, int code) {
    std::cerr << "phiq: sweep-accuracy: " << printable(msg) << "\n";
    return code;
  };
  AccuracyOptions o;
  try {
    if (!a.tolerances.empty()) o.tolerances = parse_tolerances(a.tolerances);
    if (!a.steps.empty()) o.steps = parse_steps(a.steps);
    if (!a.predictors.empty()) o.predictors = parse_predictors(a.predictors);
    if (!a.newton.empty()) o.newton = parse_newton(a.newton);
    if (!a.linear_solvers.empty()) o.linear_solvers = parse_linear_solvers(a.linear_solvers);
    if (a.repeat < 1 || a.repeat > 1000) throw std::invalid_argument("--repeat must be 1 to 1000");
  } catch (const std::invalid_argument& e) {
    return fail(e.what(), 2);
  }
  o.reference = a.reference;
  o.repeat = a.repeat;
  // Outputs that would replace the scene or each other are refused before anything is read or run.
  std::vector<NamedPath> outs;
  if (!a.csv_path.empty()) outs.push_back({"-o", a.csv_path});
  if (!a.json_path.empty()) outs.push_back({"--json", a.json_path});
  if (const auto clash = output_clash(outs, {{"the scene", a.scene}})) return fail(*clash, 2);
  if (outs.empty() && stdout_was_closed()) return fail("standard output: cannot write: it is closed", 3);
  set_interrupt_subject("sweep-accuracy: " + a.scene, "; no output written");
  Scene scene;
  try {
    scene = load_scene(a.scene);
  } catch (const SceneError& e) {
    return fail(e.what(), 2);
  }
  // Files are created (as temporaries) before the long run, so that an unwritable path fails at once; a signal
  // (SIGINT, SIGTERM, SIGHUP) stops the running sweep, and the temporaries are then removed (nothing is written).
  OutputSet outputs;
  AtomicOutputFile* csv_file = nullptr;
  AtomicOutputFile* json_file = nullptr;
  try {
    if (!a.csv_path.empty()) csv_file = &outputs.add(a.csv_path);
    if (!a.json_path.empty()) json_file = &outputs.add(a.json_path);
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  o.stop = &stop_flag();
  AccuracyReport rep;
  const auto t0 = Clock::now();
  try {
    StopOnSignal stop_on_signal;
    rep = measure_accuracy(scene, o,
                           a.verbose ? std::function<void(const std::string&)>([](const std::string& l) {
                             std::cerr << "phiq: sweep-accuracy: " << l << "\n";
                           })
                                     : std::function<void(const std::string&)>());
  } catch (const AccuracyCancelled&) {
    return fail(a.scene + ": " + interrupt_message() + "; no output written", interrupt_exit_status());
  } catch (const std::invalid_argument& e) {
    return fail(a.scene + ": " + e.what(), 2);
  } catch (const std::runtime_error& e) {
    // the JSON is a report for programs: it says why, as stderr does (the CSV, a table of settings, is not written)
    if (json_file) try {
        AccuracyReport failed;
        failed.scene_path = scene.path, failed.scene_name = scene.name;
        failed.host = host_name(), failed.cpu = cpu_model();
        failed.status = "failed", failed.message = a.scene + ": " + e.what();
        json_file->write(accuracy_json(failed));
        outputs.commit_one(*json_file);
      } catch (const Error& w) {
        return fail(w.what(), 3);
      }
    return fail(a.scene + ": " + e.what() + (json_file ? "; wrote the JSON only" : ""), 1);
  }
  if (stop_flag().load())  // a signal after the last sweep: stopped all the same
    return fail(a.scene + ": " + interrupt_message() + "; no output written", interrupt_exit_status());
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  rep.host = host_name(), rep.cpu = cpu_model();
  try {
    const std::string csv = accuracy_csv(rep);
    if (csv_file) csv_file->write(csv);
    if (json_file) json_file->write(accuracy_json(rep));
    if (!csv_file && !json_file) {
      std::fwrite(csv.data(), 1, csv.size(), stdout);
      if (const auto bad = stdout_error()) throw Error(*bad);
    }
    outputs.commit();  // both files, or neither
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  if (!a.quiet) {
    for (const std::string& note : rep.notes) std::cerr << "phiq: sweep-accuracy: note: " << note << "\n";
    std::size_t failed = 0;
    for (const AccuracyRow& r : rep.rows) failed += r.status != "ok";
    std::cerr << "phiq: sweep-accuracy: " << printable(a.scene) << ": " << rep.rows.size() << " settings (" << failed
              << " failed) against " << rep.reference << " in " << significant(seconds, 3) << " s";
    if (csv_file) std::cerr << "; wrote " << printable(a.csv_path);
    if (json_file) std::cerr << (csv_file ? " and " : "; wrote ") << printable(a.json_path);
    std::cerr << "\n";
  }
  return 0;
}

}  // namespace

Command register_sweep_accuracy(CLI::App& app) {
  auto acc = std::make_shared<SweepAccuracyArgs>();
  CLI::App* accuracy =
      app.add_subcommand("sweep-accuracy", "Error against a reference and time per step, per solver setting");
  accuracy->add_option("scene", acc->scene, "Scene file (YAML)")->required();
  accuracy->add_option("-o,--output", acc->csv_path, "CSV to write (default: standard output unless --json)")
      ->transform(output_path(" (without the option, or '-': standard output)", false));
  accuracy->add_option("--json", acc->json_path, "JSON to write ('-': standard output)")
      ->transform(output_path("", false));
  accuracy->add_option("--tolerances", acc->tolerances, "Newton tolerances (default 1e-4,1e-5,...,1e-14)");
  accuracy->add_option("--steps-list", acc->steps, "Step counts (default: the scene's x 1/4, 1, 4)");
  accuracy->add_option("--predictors", acc->predictors,
                       "Of previous,secant,parabolic,linear,hermite,quadratic,cubic,auto (default: all but auto)");
  accuracy->add_option("--newton", acc->newton, "Of modified,full (default: both)");
  accuracy->add_option("--linear-solvers", acc->linear_solvers, "Of klu,umfpack,dense (default: klu,umfpack)");
  accuracy->add_option("--reference", acc->reference, "auto, numerical or closed-form:KIND[:NAME=VALUE,...]")
      ->capture_default_str();
  accuracy->add_option("--repeat", acc->repeat, "Timed runs per setting (best of)")
      ->capture_default_str()
      ->check(whole_number(1, 1000));
  accuracy->add_flag("-q,--quiet", acc->quiet, "Print only errors on standard error");
  accuracy->add_flag("-v,--verbose", acc->verbose, "One line per setting on standard error");
  return {accuracy, [acc] { return with_stdout_checked(run_sweep_accuracy_command(*acc)); }};
}

}  // namespace phiq::tools

// `phiq clearance SCENE [-o OUT.csv|OUT.h5] [--summary FILE.json] [--fail-on-interference]`: the scene's
// `output.clearance` measured along its sweep (phiq/clearance.hpp): each pair's distance per row as CSV, or as HDF5
// with the summary (phiq/clearance_files.hpp), and a summary of each pair's worst pose, interference intervals and
// whether the bound between rows held, on standard error and as JSON (clearance_report.hpp).
#include <iostream>
#include <memory>
#include <sstream>

#include "clearance_report.hpp"
#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "result_file.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// The exit status of --fail-on-interference when a pair overlaps or the bound cannot exclude it (tools/README.md).
constexpr int kInterferenceStatus = 4;

std::string point_text(kin3::V3 p) { return "(" + shortest(p.x) + ", " + shortest(p.y) + ", " + shortest(p.z) + ")"; }

// Each pair's worst pose, its sensitivities, its interference and whether the speed bound held.
std::string clearance_summary(const Scene& scene, const ClearanceReport& r) {
  std::ostringstream s;
  s << "clearance: " << r.pairs.size() << " pair(s) reported of " << r.pairs_selected << " selected, threshold "
    << shortest(r.threshold) << " m, " << r.times.size() << " rows, " << r.positions_solved
    << " positions solved between rows\n";
  for (const PairClearance& p : r.pairs) {
    const ClearanceMinimum& w = p.worst;
    s << "  " << scene.parts[static_cast<std::size_t>(p.a)].name << " / "
      << scene.parts[static_cast<std::size_t>(p.b)].name << ": worst " << shortest(w.at.distance)
      << " m at t = " << format_time(w.t) << (w.refined ? " (between rows)" : " (on a row)") << ", witness points "
      << point_text(w.at.point_a) << " and " << point_text(w.at.point_b);
    if (w.at.distance < r.threshold) s << ", below the threshold";
    for (std::size_t j = 0; j < w.sensitivities.size(); ++j)
      s << ", d/d" << r.parameters[j] << " = " << shortest(w.sensitivities[j]);
    s << "\n";
    if (p.minima.size() > 1 && !w.sensitivities.empty())  // the other minima, each with its own sensitivities
      for (const ClearanceMinimum& m : p.minima) {
        if (m.t == w.t && m.at.distance == w.at.distance) continue;
        s << "    minimum " << shortest(m.at.distance) << " m at t = " << format_time(m.t);
        for (std::size_t j = 0; j < m.sensitivities.size(); ++j)
          s << ", d/d" << r.parameters[j] << " = " << shortest(m.sensitivities[j]);
        s << "\n";
      }
    for (const InterferenceInterval& i : p.interference)
      s << "    interferes from t = " << format_time(i.entry) << " to " << format_time(i.exit) << "\n";
    if (p.unproven_intervals > 0)
      s << "    the speed bound did not prove " << p.unproven_intervals << " step(s) clear\n";
  }
  s << (r.bound_held() ? "  between rows: the speed bound held on every step not refined\n"
                       : "  between rows: the speed bound did not hold everywhere (see above)\n");
  return s.str();
}

int cmd_clearance(const std::string& scene_arg, const std::string& out_path, const std::string& summary_path,
                  bool fail_on_interference, bool quiet, const std::vector<std::string>& sets) {
  const std::string scene_path = scene_label(scene_arg);
  std::vector<NamedPath> outs;
  if (!out_path.empty()) outs.push_back({"-o", out_path});
  if (!summary_path.empty()) outs.push_back({"--summary", summary_path});
  if (const auto clash = output_clash(outs, {{"the scene", scene_arg == "-" ? "" : scene_arg}}))
    return fail("clearance: " + *clash, 2);
  if (out_path.empty() && stdout_was_closed()) return fail("clearance: standard output: cannot write: it is closed", 3);
  const bool hdf5 = !out_path.empty() && result_format("", out_path) == ResultFormat::kHdf5;
  set_interrupt_subject(scene_path, "; no output written");
  std::optional<Scene> loaded = load_or_report(scene_arg, sets);
  if (!loaded) return 2;
  const Scene& scene = *loaded;
  if (!scene.clearance.requested)
    return fail(scene_path + ": output.clearance: missing: the scene names no pairs of parts to measure", 2);
  OutputSet outputs;  // created before the sweep, committed together after it
  AtomicOutputFile* file = nullptr;
  AtomicOutputFile* summary_file = nullptr;
  try {
    if (hdf5) check_hdf5_target(out_path);
    // HDF5 opens its file by name: a named temporary (result_file.hpp)
    if (!out_path.empty())
      file =
          &outputs.add(out_path, hdf5 ? AtomicOutputFile::Hold::kClosedBetweenWrites : AtomicOutputFile::Hold::kOpen);
    if (!summary_path.empty()) summary_file = &outputs.add(summary_path);
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  SweepSummary summary;
  ClearanceReport report;
  try {
    report = scene_clearance(scene, &summary);
  } catch (const Error& e) {
    return fail(scene_path + ": " + e.what() + "; no output written", 1);
  }
  if (summary.status != SolveStatus::kSuccess)
    return fail(scene_path + ": " + summary.message + "; no output written", 1);
  try {
    if (summary_file) summary_file->write(clearance_summary_json(scene, scene_path, report));
    if (hdf5) {
      ClearanceHdf5Options o;
      o.scene_path = scene.path;
      o.scene_text = scene.text;
      o.parameters = scene.parameters;
      o.shown_path = file->path();
      write_clearance_hdf5(file->temporary_path(), report, scene.parts, o);
    } else if (file) {
      file->write(clearance_csv(report, scene.parts));
    } else {
      std::cout << clearance_csv(report, scene.parts);
      if (const auto bad = stdout_error()) throw Error(*bad);
    }
    outputs.commit();
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  if (!quiet) std::cerr << "phiq: " << printable(scene_path) << ": " << clearance_summary(scene, report);
  if (fail_on_interference && (report.interferes() || !report.bound_held())) {
    std::cerr << "phiq: " << printable(scene_path) << ": "
              << (report.interferes() ? "parts interfere" : "interference not excluded between rows") << "\n";
    return kInterferenceStatus;
  }
  return 0;
}

}  // namespace

Command register_clearance(CLI::App& app) {
  struct Args {
    std::string path, out, summary;
    bool fail_on_interference = false, quiet = false;
    std::vector<std::string> sets;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "clearance", "Measure the distances between the scene's parts along its motion (output.clearance)");
  cmd->add_option("scene", a->path, "Scene file (YAML; '-': standard input)")->required();
  cmd->add_option("-o,--output", a->out,
                  "CSV file to write (default or '-': standard output); *.h5 or *.hdf5: HDF5 with the summary")
      ->transform(output_path(" (without the option, or '-': standard output)", true));
  cmd->add_option("--summary", a->summary, "Write the summary as JSON to FILE (tools/README.md)")
      ->transform(output_path("", false));
  cmd->add_flag("--fail-on-interference", a->fail_on_interference,
                "Exit with status 4 when parts interfere (or the bound between rows cannot exclude it)");
  cmd->add_flag("-q,--quiet", a->quiet, "Do not print the summary on standard error");
  add_set_option(cmd, &a->sets);
  return {cmd, [a] {
            return with_stdout_checked(
                cmd_clearance(a->path, a->out, a->summary, a->fail_on_interference, a->quiet, a->sets));
          }};
}

}  // namespace phiq::tools

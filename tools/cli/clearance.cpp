// `phiq clearance SCENE [-o OUT.csv] [--fail-on-interference]`: the scene's `output.clearance` measured along its
// sweep (phiq/clearance.hpp): a CSV of each pair's distance per row, and a summary on standard error of each pair's
// worst pose, interference intervals and whether the bound between rows held.
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// The exit status of --fail-on-interference when a pair overlaps or the bound cannot exclude it (tools/README.md).
constexpr int kInterferenceStatus = 4;

std::string point_text(kin3::V3 p) { return "(" + shortest(p.x) + ", " + shortest(p.y) + ", " + shortest(p.z) + ")"; }

// The rows: t, then each pair's distance (m), named `A.B`.
std::string clearance_csv(const Scene& scene, const ClearanceReport& r) {
  std::string text = "t";
  for (const PairClearance& p : r.pairs)
    text +=
        "," + scene.parts[static_cast<std::size_t>(p.a)].name + "." + scene.parts[static_cast<std::size_t>(p.b)].name;
  text += "\n";
  for (std::size_t k = 0; k < r.times.size(); ++k) {
    text += shortest(r.times[k]);
    for (const PairClearance& p : r.pairs) text += "," + shortest(p.row_distance[k]);
    text += "\n";
  }
  return text;
}

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
    for (const InterferenceInterval& i : p.interference)
      s << "    interferes from t = " << format_time(i.entry) << " to " << format_time(i.exit) << "\n";
    if (p.unproven_intervals > 0)
      s << "    the speed bound did not prove " << p.unproven_intervals << " step(s) clear\n";
  }
  s << (r.bound_held() ? "  between rows: the speed bound held on every step not refined\n"
                       : "  between rows: the speed bound did not hold everywhere (see above)\n");
  return s.str();
}

int cmd_clearance(const std::string& scene_arg, const std::string& out_path, bool fail_on_interference, bool quiet,
                  const std::vector<std::string>& sets) {
  const std::string scene_path = scene_label(scene_arg);
  if (!out_path.empty()) {
    if (const auto clash = output_clash({{"-o", out_path}}, {{"the scene", scene_arg == "-" ? "" : scene_arg}}))
      return fail("clearance: " + *clash, 2);
  } else if (stdout_was_closed()) {
    return fail("clearance: standard output: cannot write: it is closed", 3);
  }
  set_interrupt_subject(scene_path, "; no output written");
  std::optional<Scene> loaded = load_or_report(scene_arg, sets);
  if (!loaded) return 2;
  const Scene& scene = *loaded;
  if (!scene.clearance.requested)
    return fail(scene_path + ": output.clearance: missing: the scene names no pairs of parts to measure", 2);
  OutputSet outputs;  // created before the sweep, committed after it
  AtomicOutputFile* file = nullptr;
  try {
    if (!out_path.empty()) file = &outputs.add(out_path);
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
    const std::string text = clearance_csv(scene, report);
    if (file) {
      file->write(text);
      outputs.commit();
    } else {
      std::cout << text;
      if (const auto bad = stdout_error()) throw Error(*bad);
    }
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
    std::string path, out;
    bool fail_on_interference = false, quiet = false;
    std::vector<std::string> sets;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "clearance", "Measure the distances between the scene's parts along its motion (output.clearance) as CSV");
  cmd->add_option("scene", a->path, "Scene file (YAML; '-': standard input)")->required();
  cmd->add_option("-o,--output", a->out, "CSV file to write (default or '-': standard output)")
      ->transform(output_path(" (without the option, or '-': standard output)", true));
  cmd->add_flag("--fail-on-interference", a->fail_on_interference,
                "Exit with status 4 when parts interfere (or the bound between rows cannot exclude it)");
  cmd->add_flag("-q,--quiet", a->quiet, "Do not print the summary on standard error");
  add_set_option(cmd, &a->sets);
  return {cmd, [a] {
            return with_stdout_checked(cmd_clearance(a->path, a->out, a->fail_on_interference, a->quiet, a->sets));
          }};
}

}  // namespace phiq::tools

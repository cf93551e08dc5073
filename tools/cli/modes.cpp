// `phiq modes SCENE [--at T] [-o OUT.yaml|.csv|.json] [--threads N] [--max-paths N]`: every real assembly mode of
// the scene's equations at time T, by polynomial homotopy continuation (phiq/modes.hpp), and which of them the
// rough placement assembles into. The report goes to standard output; -o writes the modes as YAML, CSV or JSON (by
// the file's extension). `--along N`: the count at N times over the sweep instead, and where it changes.
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// Where the rough placement assembled, and the modes nearest to it.
struct Placement {
  bool assembled = false;
  std::string failure;  // why it did not assemble
  int nearest = -1;     // index into the modes
  double distance = 0.0;
  int next = -1;  // the next nearest
  double next_distance = 0.0;
};

Placement placement_mode(const Scene& scene, double t, const std::vector<AssemblyMode>& modes) {
  Placement p;
  const Model& model = *scene.model;
  Eigen::VectorXd q = model.initial_positions();
  AssemblySummary summary;
  (void)assemble(model, t, assembly_options(scene), q, &summary);  // its status is summary.status
  if (summary.status != SolveStatus::kSuccess) {
    p.failure = summary.message.empty() ? std::string(to_string(summary.status)) : summary.message;
    return p;
  }
  p.assembled = true;
  const ModeLocation where = locate_mode(model, q, modes);
  p.nearest = where.mode, p.distance = where.distance, p.next = where.next, p.next_distance = where.next_distance;
  return p;
}

std::string mode_coordinates(const Model& model, const AssemblyMode& m, const char* separator) {
  std::string text;
  for (Index j = 0; j < model.num_coordinates(); ++j)
    text += (j ? separator : "") + model.coordinate_names()[static_cast<std::size_t>(j)] +
            (*separator == ',' ? ": " : " = ") + shortest(m.q(j));
  return text;
}

std::string report_text(const std::string& scene_path, double t, const AssemblyModes& r, const Placement& p,
                        const Model& model) {
  const ModesSummary& s = r.summary;
  std::ostringstream o;
  o << scene_path << " at t = " << shortest(t) << ": " << r.modes.size() << " real assembly mode"
    << (r.modes.size() == 1 ? "" : "s") << " (" << s.paths << " paths: " << s.real << " real, " << s.complex
    << " complex, " << s.singular << " singular, " << s.at_infinity << " at infinity, " << s.failed_paths << " failed, "
    << s.duplicate_paths << " duplicate, " << s.retracked_paths << " tracked twice; " << r.polynomials.system.variables
    << " unknowns, " << r.polynomials.eliminated_rows.size() << " coordinates fixed by their own rows; "
    << modes_method_name(s.method);
  if (s.method == ModesMethod::kBlocks) o << ", " << s.blocks << " blocks";
  o << "; start: " << s.start_system << " (total degree " << s.total_degree << "), " << s.end_game_paths
    << " ends by the end game; " << shortest(std::round(s.seconds * 1e4) / 1e4) << " s)\n";
  if (!s.method_note.empty()) o << "  " << s.method_note << ": the whole system solved instead\n";
  for (const auto& [path, why] : s.failures) o << "  path " << path + 1 << " failed: " << why << "\n";
  for (std::size_t k = 0; k < r.modes.size(); ++k) {
    const AssemblyMode& m = r.modes[k];
    o << "  mode " << k + 1 << (m.singular ? " (singular)" : "") << ": " << mode_coordinates(model, m, "; ")
      << " (residual " << shortest(m.residual) << ", condition " << shortest(std::round(m.condition)) << ")\n";
  }
  if (!p.assembled)
    o << "  the rough placement does not assemble at t = " << shortest(t) << ": " << p.failure << "\n";
  else if (p.nearest < 0)
    o << "  the rough placement assembles, but into no real mode found (the scene has none at this time)\n";
  else {
    o << "  the rough placement assembles into mode " << p.nearest + 1 << " (distance " << shortest(p.distance) << ")";
    if (p.next >= 0) o << "; the next nearest, mode " << p.next + 1 << ", is " << shortest(p.next_distance) << " away";
    o << "\n";
  }
  return o.str();
}

std::string modes_csv(const Model& model, const AssemblyModes& r) {
  std::string text = "mode,singular,residual,condition";
  for (const std::string& n : model.coordinate_names()) text += "," + n;
  text += "\n";
  for (std::size_t k = 0; k < r.modes.size(); ++k) {
    const AssemblyMode& m = r.modes[k];
    text += std::to_string(k + 1) + "," + (m.singular ? "1" : "0") + "," + shortest(m.residual) + "," +
            shortest(m.condition);
    for (Index j = 0; j < model.num_coordinates(); ++j)
      text.append(1, ',').append(shortest(m.q(j)));  // (a literal + std::string: GCC 12's false -Wrestrict)
    text += "\n";
  }
  return text;
}

nlohmann::ordered_json modes_json(const std::string& scene_path, double t, const Model& model, const AssemblyModes& r,
                                  const Placement& p) {
  nlohmann::ordered_json j;
  j["format"] = 1;
  j["scene"] = scene_path;
  j["time"] = t;
  j["paths"] = r.summary.paths;
  j["real"] = r.modes.size();
  j["complex"] = r.summary.complex;
  j["singular"] = r.summary.singular;
  j["at_infinity"] = r.summary.at_infinity;
  j["failed_paths"] = r.summary.failed_paths;
  j["duplicate_paths"] = r.summary.duplicate_paths;
  j["method"] = modes_method_name(r.summary.method);
  j["blocks"] = r.summary.blocks;
  j["method_note"] = r.summary.method_note;
  j["start_system"] = r.summary.start_system;
  j["total_degree"] = r.summary.total_degree;
  j["end_game_paths"] = r.summary.end_game_paths;
  auto failures = nlohmann::ordered_json::array();
  for (const auto& [path, why] : r.summary.failures) failures.push_back({{"path", path + 1}, {"reason", why}});
  j["failures"] = failures;
  j["coordinates"] = model.coordinate_names();
  auto modes = nlohmann::ordered_json::array();
  for (const AssemblyMode& m : r.modes) {
    nlohmann::ordered_json e;
    e["q"] = std::vector<double>(m.q.data(), m.q.data() + m.q.size());
    e["residual"] = m.residual;
    e["condition"] = m.condition;
    e["singular"] = m.singular;
    modes.push_back(e);
  }
  j["modes"] = modes;
  nlohmann::ordered_json pj;
  pj["assembled"] = p.assembled;
  pj["mode"] = p.nearest >= 0 ? nlohmann::ordered_json(p.nearest + 1) : nlohmann::ordered_json();
  pj["distance"] = p.nearest >= 0 ? nlohmann::ordered_json(p.distance) : nlohmann::ordered_json();
  pj["next_distance"] = p.next >= 0 ? nlohmann::ordered_json(p.next_distance) : nlohmann::ordered_json();
  j["placement"] = pj;
  return j;
}

std::string modes_yaml(const std::string& scene_path, double t, const Model& model, const AssemblyModes& r,
                       const Placement& p) {
  std::ostringstream o;
  o << "scene: " << nlohmann::ordered_json(scene_path).dump() << "\ntime: " << shortest(t)
    << "\npaths: " << r.summary.paths << "\nreal: " << r.modes.size() << "\ncomplex: " << r.summary.complex
    << "\nsingular: " << r.summary.singular << "\nat_infinity: " << r.summary.at_infinity
    << "\nfailed_paths: " << r.summary.failed_paths << "\nmethod: " << modes_method_name(r.summary.method)
    << "\nblocks: " << r.summary.blocks << "\nmethod_note: " << nlohmann::ordered_json(r.summary.method_note).dump()
    << "\nstart_system: " << nlohmann::ordered_json(r.summary.start_system).dump()
    << "\ntotal_degree: " << r.summary.total_degree << "\nend_game_paths: " << r.summary.end_game_paths << "\nmodes:\n";
  for (std::size_t k = 0; k < r.modes.size(); ++k) {
    const AssemblyMode& m = r.modes[k];
    o << "  - {mode: " << k + 1 << ", singular: " << (m.singular ? "true" : "false")
      << ", residual: " << shortest(m.residual) << ", condition: " << shortest(m.condition) << ", q: {"
      << mode_coordinates(model, m, ", ") << "}}\n";
  }
  if (r.modes.empty()) o << "  []\n";
  o << "placement: {assembled: " << (p.assembled ? "true" : "false");
  if (p.nearest >= 0) o << ", mode: " << p.nearest + 1 << ", distance: " << shortest(p.distance);
  if (p.next >= 0) o << ", next_distance: " << shortest(p.next_distance);
  o << "}\n";
  return o.str();
}

bool modes_path_ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// `--along N`: the number of real modes at N times evenly spread over time.start … time.end, and where it changes
// (two modes meet between: a singular position); -o OUT.csv: t, real, complex, singular, at_infinity, failed_paths.
int modes_along(const Scene& scene, const std::string& scene_path, int samples, OutputSet& outputs,
                AtomicOutputFile* file, ModesOptions options, bool quiet) {
  const double t0 = scene.sweep.t_begin, t1 = scene.sweep.t_end;
  std::ostringstream report;
  std::string csv = "t,real,complex,singular,at_infinity,failed_paths\n", changes;
  int changed = 0;
  std::size_t before = 0;
  for (int k = 0; k < samples; ++k) {
    const double t = k + 1 == samples ? t1 : t0 + (t1 - t0) * k / (samples - 1);
    options.time = t;
    AssemblyModes r;
    try {
      r = find_assembly_modes(*scene.model, options);
    } catch (const Error& e) {
      return fail(scene_path + ": --along: t = " + format_time(t) + ": " + e.what() + "; no output written", 2);
    }
    if (r.summary.status != ModesStatus::kSuccess)
      return fail(scene_path + ": --along: t = " + format_time(t) + ": " + r.summary.message + "; no output written",
                  2);
    const ModesSummary& s = r.summary;
    int singular = 0;
    for (const AssemblyMode& m : r.modes) singular += m.singular ? 1 : 0;
    report << "  t = " << format_time(t) << ": " << r.modes.size() << " real (" << singular << " singular), "
           << s.complex << " complex\n";
    csv += shortest(t) + "," + std::to_string(r.modes.size()) + "," + std::to_string(s.complex) + "," +
           std::to_string(s.singular) + "," + std::to_string(s.at_infinity) + "," + std::to_string(s.failed_paths) +
           "\n";
    if (k > 0 && r.modes.size() != before) {
      ++changed;
      changes += "  the count changes from " + std::to_string(before) + " to " + std::to_string(r.modes.size()) +
                 " between t = " + format_time(t0 + (t1 - t0) * (k - 1) / (samples - 1)) +
                 " and t = " + format_time(t) + ": a singular position (two modes meet) lies between\n";
    }
    before = r.modes.size();
  }
  try {
    if (file) {
      file->write(csv);
      outputs.commit();
    }
    if (!quiet)
      std::cout << printable(scene_path) << ": real assembly modes at " << samples
                << " times from t = " << format_time(t0) << " to " << format_time(t1) << " (" << changed << " change"
                << (changed == 1 ? "" : "s") << ")\n"
                << report.str() << changes;
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  return 0;
}

int cmd_modes(const std::string& scene_arg, std::optional<double> at, const std::string& out_path, int threads,
              long long max_paths, bool quiet, const std::vector<std::string>& sets, int along) {
  const std::string scene_path = scene_label(scene_arg);
  if (along > 0 && at) return fail("modes: --along: the times are spread over the scene's sweep: no --at with it", 2);
  if (along > 0 && !out_path.empty() && out_path != "-" && !modes_path_ends_with(out_path, ".csv"))
    return fail("modes: -o " + out_path + ": --along writes CSV (.csv)", 2);
  if (!out_path.empty() && out_path != "-") {
    if (!modes_path_ends_with(out_path, ".yaml") && !modes_path_ends_with(out_path, ".yml") &&
        !modes_path_ends_with(out_path, ".csv") && !modes_path_ends_with(out_path, ".json"))
      return fail("modes: -o " + out_path + ": the file's extension says its format: .yaml, .csv or .json", 2);
    if (const auto clash = output_clash({{"-o", out_path}}, {{"the scene", scene_arg == "-" ? "" : scene_arg}}))
      return fail("modes: " + *clash, 2);
  }
  set_interrupt_subject(scene_path, "; no output written");
  std::optional<Scene> loaded = load_or_report(scene_arg, sets);
  if (!loaded) return 2;
  const Scene& scene = *loaded;
  const Model& model = *scene.model;
  const double t = at ? *at : scene.sweep.t_begin;
  if (!(t >= model.time_domain_begin() && t <= model.time_domain_end()))
    return fail(scene_path + ": --at " + shortest(t) + ": outside the drivers' time domain [" +
                    shortest(model.time_domain_begin()) + ", " + shortest(model.time_domain_end()) + "]",
                2);
  OutputSet outputs;
  AtomicOutputFile* file = nullptr;
  try {
    if (!out_path.empty() && out_path != "-") file = &outputs.add(out_path);
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  ModesOptions options;
  options.time = t;
  options.threads = threads;
  options.max_paths = max_paths;
  if (along > 0) return modes_along(scene, scene_path, along, outputs, file, options, quiet);
  AssemblyModes r;
  try {
    r = find_assembly_modes(model, options);
  } catch (const Error& e) {
    return fail(scene_path + ": " + e.what() + "; no output written", 2);
  }
  if (r.summary.status != ModesStatus::kSuccess)
    return fail(scene_path + ": " + r.summary.message + "; no output written", 2);
  const Placement p = placement_mode(scene, t, r.modes);
  try {
    if (file) {
      const std::string text = modes_path_ends_with(out_path, ".csv") ? modes_csv(model, r)
                               : modes_path_ends_with(out_path, ".json")
                                   ? json_text(modes_json(scene_path, t, model, r, p), 2) + "\n"
                                   : modes_yaml(scene_path, t, model, r, p);
      file->write(text);
      outputs.commit();
    }
    if (!quiet) std::cout << report_text(printable(scene_path), t, r, p, model);
  } catch (const Error& e) {
    return fail(e.what(), 3);
  }
  return 0;
}

}  // namespace

Command register_modes(CLI::App& app) {
  struct Args {
    std::string path, out;
    double at = 0.0;
    int threads = 0;
    long long max_paths = 100000;
    bool quiet = false;
    std::vector<std::string> sets;
    int along = 0;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("modes",
                         "Every real assembly mode of the scene at one time (homotopy continuation), and which one the "
                         "rough placement assembles into");
  cmd->add_option("scene", a->path, "Scene file (YAML; '-': standard input)")->required();
  CLI::Option* at = cmd->add_option("--at", a->at, "The time at which the drivers are evaluated (default: time.start)")
                        ->check(any_number());
  cmd->add_option("-o,--output", a->out, "The modes as YAML, CSV or JSON, by the file's extension")
      ->transform(output_path(" (without the option: the report only)", false));
  cmd->add_option("--threads", a->threads, "Threads for the paths (0: all cores); the result is the same on any")
      ->capture_default_str()
      ->check(thread_count());
  cmd->add_option("--max-paths", a->max_paths, "Refuse a scene whose homotopy has more paths than this")
      ->capture_default_str()
      ->check(whole_number(1, std::numeric_limits<int>::max()));
  cmd->add_option("--along", a->along,
                  "The count of real modes at N times spread over time.start … time.end, and where it changes "
                  "(singular positions); -o: CSV")
      ->check(whole_number(2, 1000000));
  cmd->add_flag("-q,--quiet", a->quiet, "Do not print the report on standard output");
  add_set_option(cmd, &a->sets);
  return {cmd, [a, at] {
            return with_stdout_checked(cmd_modes(a->path, at->count() ? std::optional<double>(a->at) : std::nullopt,
                                                 a->out, cap_threads("modes", a->threads, a->quiet), a->max_paths,
                                                 a->quiet, a->sets, a->along));
          }};
}

}  // namespace phiq::tools

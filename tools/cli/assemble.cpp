// `phiq assemble SCENE [-o OUT.csv]`: the rough placement assembled (minimum norm) at time.start, written as the
// one-row CSV of its coordinates.
#include <iostream>
#include <memory>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// `phiq assemble SCENE [-o OUT.csv]`: the assembled position at time.start as a one-row CSV (the columns of
// `phiq run`'s positions). Nothing is written when the assembly fails.
int cmd_assemble(const std::string& scene_arg, const std::string& out_path, bool quiet,
                 const std::vector<std::string>& sets) {
  const std::string scene_path = scene_label(scene_arg);  // "-": standard input, named <stdin>
  if (!out_path.empty()) {
    if (const auto clash = output_clash({{"-o", out_path}}, {{"the scene", scene_arg == "-" ? "" : scene_arg}}))
      return fail("assemble: " + *clash, 2);
  } else if (stdout_was_closed()) {
    return fail("assemble: standard output: cannot write: it is closed", 3);
  }
  set_interrupt_subject(scene_path, "; no output written");
  std::optional<phiq::Scene> loaded = load_or_report(scene_arg, sets);
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
      if (const auto bad = stdout_error()) throw phiq::Error(*bad);
    }
  } catch (const phiq::Error& e) {
    return fail(e.what(), 3);
  }
  if (!quiet)
    std::cerr << "phiq: " << printable(scene_path) << ": " << as.BriefReport() << ", moved " << scientific(as.moved, 3)
              << "\n";
  return 0;
}

}  // namespace

Command register_assemble(CLI::App& app) {
  struct Args {
    std::string path, out;
    bool quiet = false;
    std::vector<std::string> sets;
  };
  auto a = std::make_shared<Args>();
  CLI::App* assemble_cmd =
      app.add_subcommand("assemble", "Assemble the rough placement (minimum-norm) and write the coordinates as CSV");
  assemble_cmd->add_option("scene", a->path, "Scene file (YAML; '-': standard input)")->required();
  assemble_cmd->add_option("-o,--output", a->out, "CSV file to write (default or '-': standard output)")
      ->transform(output_path(" (without the option, or '-': standard output)", true));
  assemble_cmd->add_flag("-q,--quiet", a->quiet, "Do not print the summary on standard error");
  add_set_option(assemble_cmd, &a->sets);
  return {assemble_cmd, [a] { return with_stdout_checked(cmd_assemble(a->path, a->out, a->quiet, a->sets)); }};
}

}  // namespace phiq::tools

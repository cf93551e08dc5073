// `phiq animate SCENE [RESULT] -o OUT.glb|OUT.html`: the motion of a result as a glTF 2.0 binary
// (tools/animate/gltf_motion.*) or a self-contained HTML viewer (tools/animate/html_page.*), chosen by the output's
// extension; without RESULT, of the scene swept here with the outputs the drawing needs (drawn_result.hpp); with
// --modes, every real assembly mode of the scene at its start (phiq/modes.hpp), one pose per mode in the HTML
// viewer; its options, the checks of its input and the atomic write.
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "drawn_result.hpp"
#include "gltf_motion.hpp"
#include "html_page.hpp"
#include "motion_columns.hpp"
#include "phiq/drawn_parts.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

struct AnimateOptions {
  std::string scene, result, out;
  std::vector<std::string> columns;  // the HTML's plots (as phiq plot --columns)
  std::vector<std::string> sets;     // --set NAME=VALUE: the scene's parameters as the run had them
  bool modes = false;                // --modes: the real assembly modes at time.start instead of a motion
  double forces = 0.0;               // --forces SCALE: the efforts and reactions as arrows, m/N (0: none)
};

// What the messages and the page call the result of a sweep run here.
constexpr const char* kSwept = "its sweep";

// What the page calls the modes' table.
constexpr const char* kModes = "its assembly modes";

// The scene's `output.clearance` measured along its own sweep, as `phiq clearance` measures it, for the viewer to
// mark (html_clearance.hpp); none without it. Throws DrawError (status 1, as `phiq clearance`) when it cannot.
std::optional<ClearanceReport> animated_clearance(const Scene& scene) {
  if (!scene.clearance.requested) return std::nullopt;
  SweepSummary summary;
  try {
    ClearanceReport report = scene_clearance(scene, &summary);
    if (summary.status == SolveStatus::kSuccess) return report;
  } catch (const Error& e) {
    throw DrawError(scene.path + ": output.clearance: " + e.what(), 1);
  }
  throw DrawError(scene.path + ": " + summary.message, 1);
}

// Every real assembly mode of the scene at time.start as a table (t: the mode's number, 1 …, then every
// coordinate) and a label per mode. Throws DrawError: status 2 for a scene whose modes cannot be counted (a
// constraint not polynomial, named), 1 for one with no real mode at the start (it cannot be assembled there).
CsvTable modes_table(const Scene& scene, std::vector<std::string>& labels) {
  const Model& model = *scene.model;
  const double t = scene.sweep.t_begin;
  ModesOptions options;
  options.time = t;
  const AssemblyModes found = find_assembly_modes(model, options);
  if (found.summary.status != ModesStatus::kSuccess)
    throw DrawError(scene.path + ": --modes: " + found.summary.message, 2);
  if (found.modes.empty())
    throw DrawError(scene.path + ": --modes: no real assembly mode at t = " + format_time(t) + " (" +
                        std::to_string(found.summary.paths) + " paths: " + std::to_string(found.summary.complex) +
                        " complex, " + std::to_string(found.summary.singular) + " singular, " +
                        std::to_string(found.summary.at_infinity) +
                        " at infinity): the scene cannot be assembled there; nothing drawn",
                    1);
  // the mode the rough placement assembles into, named in its label
  Eigen::VectorXd q = model.initial_positions();
  AssemblySummary assembled;
  (void)assemble(model, t, assembly_options(scene), q, &assembled);  // its status is assembled.status
  const int placement = assembled.status == SolveStatus::kSuccess ? locate_mode(model, q, found.modes).mode : -1;
  CsvTable table;
  table.path = scene.path;
  table.columns.push_back("t");
  for (const std::string& name : model.coordinate_names()) table.columns.push_back(name);
  const std::string count = std::to_string(found.modes.size());
  for (std::size_t k = 0; k < found.modes.size(); ++k) {
    const AssemblyMode& m = found.modes[k];
    table.rows.emplace_back(1, static_cast<double>(k + 1));
    table.rows.back().insert(table.rows.back().end(), m.q.data(), m.q.data() + m.q.size());
    labels.push_back("mode " + std::to_string(k + 1) + " of " + count + " at t = " + format_time(t) +
                     (static_cast<int>(k) == placement ? " (the placement's)" : "") +
                     (m.singular ? " (singular)" : ""));
  }
  return table;
}

int cmd_animate(const AnimateOptions& o) {
  const bool html = o.out.ends_with(".html") || o.out.ends_with(".htm");
  if (!html && !o.out.ends_with(".glb"))
    return fail("animate: -o " + o.out + ": the output is a glTF binary (*.glb) or an HTML viewer (*.html)", 2);
  if (!html && !o.columns.empty())
    return fail("animate: --columns: the plots are the HTML viewer's; a .glb has none", 2);
  if (o.modes && (!html || !o.result.empty()))
    return fail(std::string("animate: --modes: the modes are drawn from the scene alone, in the HTML viewer (") +
                    (html ? "no RESULT" : "-o OUT.html") + ")",
                2);
  if (o.modes && o.forces != 0.0) return fail("animate: --forces: the modes are poses, with no efforts to draw", 2);
  if (!html && o.forces != 0.0)
    return fail("animate: --forces: the force arrows are the HTML viewer's; a .glb has none", 2);
  if (const auto clash = output_clash({{"-o", o.out}}, {{"the scene", o.scene}, {"the result", o.result}}))
    return fail("animate: " + *clash, 2);
  std::string text;
  try {
    // a robot description's meshes are what is drawn: one that cannot be found is an error here (need_geometry)
    const ModelFormat format = model_format(o.scene);
    ImportOptions drawn;
    drawn.need_geometry = true;
    const Scene scene =
        format == ModelFormat::kScene || format == ModelFormat::kAsmt
            ? load_scene(o.scene, SceneLimits{}, parameter_settings(o.sets))
            : parse_scene(import_model_file(o.scene, drawn).yaml, o.scene, SceneLimits{}, parameter_settings(o.sets));
    if (o.modes) {  // one pose per real assembly mode
      set_interrupt_subject("animate: " + o.out, "; no output written");
      std::vector<std::string> labels;
      const CsvTable table = modes_table(scene, labels);
      text = motion_html(scene, table, kModes, o.columns, nullptr, labels);
    } else if (o.result.empty()) {  // the scene swept here, with the coordinates the drawing reads (and joints to plot)
      set_interrupt_subject("animate: " + o.out, "; no output written");
      const MechanismSketch sketch = sketch_mechanism(*scene.model);
      const std::vector<Part> parts = drawn_parts(scene);
      const DrawnOutputs add{coordinates_of(html ? drawing_reads(sketch, parts) : glb_reads(scene, sketch, parts)),
                             html};
      const CsvTable table = sweep_scene(scene, add);
      const std::optional<ClearanceReport> clearance = animated_clearance(scene);
      text = html ? motion_html(scene, table, kSwept, o.columns, clearance ? &*clearance : nullptr, {}, o.forces)
                  : motion_glb(scene, table, kSwept, clearance ? &*clearance : nullptr);
    } else {
      const CsvTable table = read_scene_result(scene, o.result);
      const std::optional<ClearanceReport> clearance = animated_clearance(scene);
      text = html ? motion_html(scene, table, o.result, o.columns, clearance ? &*clearance : nullptr, {}, o.forces)
                  : motion_glb(scene, table, o.result, clearance ? &*clearance : nullptr);
    }
  } catch (const MissingCoordinate& e) {
    std::string again = "phiq animate " + o.scene + " -o " + o.out;
    for (const std::string& s : o.sets) again += " --set " + s;
    return fail("animate: " + std::string(e.what()) + ", or run `" + again + "` without a result", 2);
  } catch (const DrawError& e) {
    return fail("animate: " + std::string(e.what()), e.status());
  } catch (const SceneError& e) {
    return fail("animate: " + std::string(e.what()), 2);
  } catch (const Error& e) {
    return fail("animate: " + std::string(e.what()), 2);
  }
  try {
    OutputSet outputs;
    outputs.add(o.out).write(text);
    outputs.commit();
  } catch (const Error& e) {
    return fail("animate: " + std::string(e.what()), 3);
  }
  return 0;
}

}  // namespace

Command register_animate(CLI::App& app) {
  auto options = std::make_shared<AnimateOptions>();
  CLI::App* animate = app.add_subcommand(
      "animate",
      "Write the motion of a result (or, without one, of the scene swept here) as a glTF 2.0 binary "
      "(.glb: a node per body, link and joint, keyframed at the result's rows) or as one self-contained "
      "HTML page that plays it (.html)");
  animate->add_option("scene", options->scene, "Scene file (YAML)")->required();
  animate->add_option("result", options->result,
                      "Result of `phiq run` for this scene (CSV or HDF5); none: the "
                      "scene is swept here with the outputs the drawing needs");
  animate->add_option("-o,--output", options->out, "File to write: *.glb (glTF binary) or *.html (viewer)")->required();
  animate
      ->add_option("--columns", options->columns,
                   "HTML: columns plotted against t (default: as phiq plot, what "
                   "is driven, the joints' measures, the coordinates that move)")
      ->delimiter(',');
  animate->add_flag("--modes", options->modes,
                    "HTML: every real assembly mode of the scene at time.start, one pose per mode (the plots' t is "
                    "the mode's number)");
  animate
      ->add_option("--forces", options->forces,
                   "HTML: draw the scene's output.efforts and output.reactions as arrows, SCALE metres per "
                   "newton (moments: arcs of SCALE metres per N m in the plane, arrows along their axis in space)")
      // (0 is refused, not taken as the default's "no arrows")
      ->check(number(std::numeric_limits<double>::denorm_min(), HUGE_VAL, false,
                     "the scale, a positive number of metres per newton"));
  add_set_option(animate, &options->sets);
  return {animate, [options] { return cmd_animate(*options); }};
}

}  // namespace phiq::tools

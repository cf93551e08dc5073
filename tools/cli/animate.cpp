// `phiq animate SCENE [RESULT] -o OUT.glb|OUT.html`: the motion of a result as a glTF 2.0 binary
// (tools/animate/gltf_motion.*) or a self-contained HTML viewer (tools/animate/html_page.*), chosen by the output's
// extension; without RESULT, of the scene swept here with the outputs the drawing needs (drawn_result.hpp); its
// options, the checks of its input and the atomic write.
#include <cmath>
#include <memory>
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
  double forces = 0.0;               // --forces SCALE: the efforts and reactions as arrows, m/N (0: none)
};

// What the messages and the page call the result of a sweep run here.
constexpr const char* kSwept = "its sweep";

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int cmd_animate(const AnimateOptions& o) {
  const bool html = ends_with(o.out, ".html") || ends_with(o.out, ".htm");
  if (!html && !ends_with(o.out, ".glb"))
    return fail("animate: -o " + o.out + ": the output is a glTF binary (*.glb) or an HTML viewer (*.html)", 2);
  if (!html && !o.columns.empty())
    return fail("animate: --columns: the plots are the HTML viewer's; a .glb has none", 2);
  if (!html && o.forces != 0.0)
    return fail("animate: --forces: the force arrows are the HTML viewer's; a .glb has none", 2);
  if (!(o.forces >= 0.0) || !std::isfinite(o.forces))
    return fail(
        "animate: --forces " + shortest(o.forces) + ": the scale must be a positive number of metres per newton", 2);
  if (const auto clash = output_clash({{"-o", o.out}}, {{"the scene", o.scene}, {"the result", o.result}}))
    return fail("animate: " + *clash, 2);
  std::string text;
  try {
    const Scene scene = load_scene(o.scene, SceneLimits{}, parameter_settings(o.sets));
    if (o.result.empty()) {  // the scene swept here, with the coordinates the drawing reads (and joints to plot)
      set_interrupt_subject("animate: " + o.out, "; no output written");
      const MechanismSketch sketch = sketch_mechanism(*scene.model);
      const std::vector<Part> parts = drawn_parts(scene);
      const DrawnOutputs add{coordinates_of(html ? drawing_reads(sketch, parts) : glb_reads(scene, sketch, parts)),
                             html};
      const CsvTable table = sweep_scene(scene, add);
      text = html ? motion_html(scene, table, kSwept, o.columns, o.forces) : motion_glb(scene, table, kSwept);
    } else {
      const CsvTable table = read_scene_result(scene, o.result);
      text = html ? motion_html(scene, table, o.result, o.columns, o.forces) : motion_glb(scene, table, o.result);
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
  animate->add_option("--forces", options->forces,
                      "HTML: draw the scene's output.efforts and output.reactions as arrows, SCALE metres per "
                      "newton (moments: arcs of SCALE metres per N m in the plane, arrows along their axis in space)");
  add_set_option(animate, &options->sets);
  return {animate, [options] { return cmd_animate(*options); }};
}

}  // namespace phiq::tools

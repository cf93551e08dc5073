// `phiq animate SCENE RESULT -o OUT.glb`: the motion of a result as a glTF 2.0 binary (tools/animate/gltf_motion.*);
// its options, the checks of its input and the atomic write.
#include <memory>
#include <string>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "gltf_motion.hpp"
#include "phiq/hdf5_reader.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

struct AnimateOptions {
  std::string scene, result, out;
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int cmd_animate(const AnimateOptions& o) {
  if (!ends_with(o.out, ".glb"))
    return fail("animate: -o " + o.out + ": the output is a glTF binary, named *.glb (the HTML viewer is not built "
                "yet)", 2);
  if (const auto clash = output_clash({{"-o", o.out}}, {{"the scene", o.scene}, {"the result", o.result}}))
    return fail("animate: " + *clash, 2);
  std::string glb;
  try {
    const Scene scene = load_scene(o.scene);
    const CsvTable table = read_result_table(o.result);
    glb = motion_glb(scene, table, o.result);
  } catch (const SceneError& e) {
    return fail("animate: " + std::string(e.what()), 2);
  } catch (const Error& e) {
    return fail("animate: " + std::string(e.what()), 2);
  }
  try {
    OutputSet outputs;
    outputs.add(o.out).write(glb);
    outputs.commit();
  } catch (const Error& e) {
    return fail("animate: " + std::string(e.what()), 3);
  }
  return 0;
}

}  // namespace

Command register_animate(CLI::App& app) {
  auto options = std::make_shared<AnimateOptions>();
  CLI::App* animate = app.add_subcommand("animate", "Write the motion of a result as a glTF 2.0 binary (.glb): a "
                                                    "node per body, link and joint, keyframed at the result's rows");
  animate->add_option("scene", options->scene, "Scene file (YAML)")->required();
  animate->add_option("result", options->result, "Result of `phiq run` for this scene (CSV or HDF5)")->required();
  animate->add_option("-o,--output", options->out, "glTF binary to write (*.glb)")->required();
  return {animate, [options] { return cmd_animate(*options); }};
}

}  // namespace phiq::tools

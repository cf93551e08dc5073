// `phiq convert MODEL -o SCENE.yaml`: a FreeCAD Assembly / OndselSolver file (phiq/import_asmt.hpp), a URDF or an
// MJCF file (phiq/import_model.hpp) written as an editable phiq scene, the same text `phiq run MODEL` solves, so both
// runs give the same bytes. A robot description has no drivers: `--drive JOINT=EXPR` and `--time` add them.
#include <cmath>
#include <memory>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/import_asmt.hpp"
#include "phiq/import_model.hpp"

namespace phiq::tools {

Command register_convert(CLI::App& app) {
  struct Args {
    std::string model, out;
    std::vector<std::string> drives;
    std::vector<double> time;
  };
  auto a = std::make_shared<Args>();
  CLI::App* convert = app.add_subcommand(
      "convert",
      "Write a FreeCAD Assembly (.asmt), URDF (.urdf), MJCF (.xml, .mjcf) or SDF (.sdf) model as a phiq scene");
  convert->add_option("model", a->model, "The .asmt, .urdf, .xml, .mjcf or .sdf file")->required();
  convert->add_option("-o,--output", a->out, "Scene file to write ('-': standard output)")
      ->required()
      ->transform(output_path("", false));
  convert->add_option(
      "--drive", a->drives,
      "JOINT=EXPR (URDF, MJCF, SDF; repeatable): drive the joint's angle (rad, 0 at the file's pose) or "
      "travel (m) by an expression of t");
  convert
      ->add_option("--time", a->time,
                   "START END STEPS (URDF, MJCF, SDF): the time grid (default 0 0 0: the file's pose)")
      ->expected(3);
  return {convert, [a] {
            const ModelFormat format = model_format(a->model);
            if (format == ModelFormat::kScene)
              return fail("convert: " + a->model + ": not an .asmt, .urdf, .xml, .mjcf or .sdf file", 2);
            ImportOptions options;
            for (const std::string& d : a->drives) {
              const std::size_t eq = d.find('=');
              if (eq == std::string::npos || eq == 0 || eq + 1 == d.size())
                return fail("convert: --drive " + d + ": not JOINT=EXPR", 2);
              options.drives.emplace_back(d.substr(0, eq), d.substr(eq + 1));
            }
            if (!a->time.empty()) {
              const double steps = a->time[2];
              if (!(steps >= 0) || steps != std::floor(steps) || steps > 1e9)
                return fail("convert: --time: STEPS must be a whole number from 0 to 1e9", 2);
              options.t_start = a->time[0], options.t_end = a->time[1], options.steps = static_cast<int>(steps);
            }
            if (format == ModelFormat::kAsmt && (!options.drives.empty() || !a->time.empty()))
              return fail("convert: --drive and --time are for URDF, MJCF and SDF: an .asmt file has its motions", 2);
            const std::optional<std::string> imported = import_or_report(a->model, options);
            if (!imported) return 2;
            set_interrupt_subject("convert: " + a->out, "; no output written");
            try {
              OutputSet outputs;
              outputs.add(a->out).write(*imported);
              outputs.commit();
            } catch (const Error& e) {
              return fail(e.what(), 3);
            }
            return 0;
          }};
}

}  // namespace phiq::tools

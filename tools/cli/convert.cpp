// `phiq convert MODEL -o SCENE.yaml`: a FreeCAD Assembly / OndselSolver file (phiq/import_asmt.hpp), a URDF or an
// MJCF file (phiq/import_model.hpp) written as an editable phiq scene, the same text `phiq run MODEL` solves, so both
// runs give the same bytes. A robot description has no drivers: `--drive JOINT=EXPR` and `--time` add them.
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
    std::string gravity;    // --gravity X,Y,Z
    ImportOptions outputs;  // --rates, --forces
  };
  auto a = std::make_shared<Args>();
  CLI::App* convert = app.add_subcommand(
      "convert",
      "Write a FreeCAD Assembly (.asmt), URDF (.urdf), MJCF (.xml, .mjcf) or SDF (.sdf) model as a phiq scene");
  convert->add_option("model", a->model, "The .asmt, .urdf, .xml, .mjcf or .sdf file")->required();
  convert->add_option("-o,--output", a->out, "Scene file to write ('-': standard output)")
      ->required()
      ->transform(output_path("", false));
  add_import_options(convert, &a->drives, &a->time, &a->gravity, &a->outputs);
  return {convert, [a] {
            const ModelFormat format = model_format(a->model);
            if (format == ModelFormat::kScene)
              return fail("convert: " + a->model + ": not an .asmt, .urdf, .xml, .mjcf or .sdf file", 2);
            ImportOptions options = a->outputs;
            if (const auto bad = import_options("convert", a->model, a->drives, a->time, a->gravity, &options))
              return fail(*bad, 2);
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

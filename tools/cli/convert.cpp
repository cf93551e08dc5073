// `phiq convert MODEL.asmt -o SCENE.yaml`: a FreeCAD Assembly / OndselSolver file written as an editable phiq scene
// (phiq/import_asmt.hpp), the same text `phiq run MODEL.asmt` solves, so both runs give the same bytes.
#include <memory>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "phiq/import_asmt.hpp"

namespace phiq::tools {

Command register_convert(CLI::App& app) {
  struct Args {
    std::string model, out;
  };
  auto a = std::make_shared<Args>();
  CLI::App* convert = app.add_subcommand("convert", "Write a FreeCAD Assembly (.asmt) model as a phiq scene");
  convert->add_option("model", a->model, "The .asmt file (FreeCAD Assembly / OndselSolver)")->required();
  convert->add_option("-o,--output", a->out, "Scene file to write ('-': standard output)")
      ->required()
      ->transform(output_path("", false));
  return {convert, [a] {
            if (!is_asmt_path(a->model)) return fail("convert: " + a->model + ": not an .asmt file", 2);
            const std::optional<AsmtImport> imported = import_or_report(a->model);
            if (!imported) return 2;
            set_interrupt_subject("convert: " + a->out, "; no output written");
            try {
              OutputSet outputs;
              outputs.add(a->out).write(imported->yaml);
              outputs.commit();
            } catch (const Error& e) {
              return fail(e.what(), 3);
            }
            return 0;
          }};
}

}  // namespace phiq::tools

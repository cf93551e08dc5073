// `phiq plot SCENE [RESULT] -o OUT.svg`: its options and the check that the SVG replaces no input; the drawing
// itself is tools/plot/plot_svg.cpp.
#include <memory>

#include "cli_support.hpp"
#include "command_line.hpp"
#include "command_support.hpp"
#include "commands.hpp"
#include "plot_svg.hpp"

namespace phiq::tools {

Command register_plot(CLI::App& app) {
  auto options = std::make_shared<PlotOptions>();
  CLI::App* plot = app.add_subcommand("plot",
                                      "Draw the mechanism at a few positions with its traced points, and "
                                      "columns against time, as SVG");
  plot->add_option("scene", options->scene, "Scene file (YAML)")->required();
  plot->add_option("result", options->csv,
                   "Result of `phiq run` for this scene (CSV or HDF5); none: the scene is "
                   "swept here with the outputs the drawing needs");
  plot->add_option("-o,--output", options->out, "SVG file to write ('-': standard output)")
      ->required()
      ->transform(output_path("", false));
  plot->add_option(
          "--columns", options->columns,
          "Columns to plot against t (default: what is driven, the joints' measures, the coordinates that move, "
          "Euler parameters last; at most 6)")
      ->delimiter(',');
  plot->add_option("--positions", options->positions, "Rows at which the mechanism is drawn, evenly spread")
      ->capture_default_str()
      ->check(whole_number(1, 50));
  add_set_option(plot, &options->sets);
  return {plot, [options] {
            if (const auto clash =
                    output_clash({{"-o", options->out}}, {{"the scene", options->scene}, {"the result", options->csv}}))
              return fail("plot: " + *clash, 2);
            return plot_svg(*options);
          }};
}

}  // namespace phiq::tools
